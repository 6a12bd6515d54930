"""Each gmsh run of `mesh` in a child process (`mesh_rod.py _attempt` / `_fallback`: gmsh can crash
on a bad reparametrisation) under the command's time limit."""

from __future__ import annotations

import json
import math
import pathlib
import subprocess
import sys
import time

from .policy import POLICY, log, policy

# the entry script the children run
SCRIPT = pathlib.Path(__file__).resolve().parent.parent / "mesh_rod.py"


def run_attempt(stl: pathlib.Path, size: float, curved: bool, angle: float, curve_angle: float,
                msh: pathlib.Path, size_field=None, geometry_in=None,
                geometry_out=None, binary: bool = False) -> tuple[dict | None, str]:
    """One gmsh run in a child process (gmsh can crash on bad reparametrisations); HXT first, and
    gmsh's Delaunay with Netgen optimisation when HXT refuses the surface mesh."""
    info, why = run_attempt_with(stl, size, curved, angle, curve_angle, msh, size_field, geometry_in,
                                 geometry_out, False, binary)
    if info is None and "HXT" in why:
        log(f"  HXT failed ({why}); Delaunay instead")
        # the classification just written is reused (it is what takes the time)
        if geometry_in is None and geometry_out is not None and geometry_out.is_file():
            geometry_in = geometry_out
        info, why = run_attempt_with(stl, size, curved, angle, curve_angle, msh, size_field, geometry_in,
                                     None, True, binary)
        if info is not None:
            info["geometry_reused"] = False
    return info, why


def run_attempt_with(stl: pathlib.Path, size: float, curved: bool, angle: float, curve_angle: float,
                     msh: pathlib.Path, size_field, geometry_in, geometry_out,
                     delaunay: bool, binary: bool = False) -> tuple[dict | None, str]:
    cmd = [sys.executable, str(SCRIPT), "_attempt", str(stl), str(msh),
           "--size", repr(size), "--angle", repr(angle), "--curve-angle", repr(curve_angle), policy_arg()]
    if curved:
        cmd.append("--curved")
    if delaunay:
        cmd.append("--delaunay")
    if binary:
        cmd.append("--binary")
    for flag, value in (("--size-field", size_field), ("--geometry-in", geometry_in),
                        ("--geometry-out", geometry_out)):
        if value is not None:
            cmd += [flag, str(value)]
    return run_child(cmd)


# The time limit of the whole `mesh` command: the Rust side kills the mesher at its own limit; the
# policy's `time_limit_s` stops the children here a little before, so that a fallback that runs
# out of time still ends in a message that says what was tried.
DEADLINE = [math.inf]


def set_deadline(t0: float) -> None:
    DEADLINE[0] = t0 + float(policy("time_limit_s"))


def policy_arg() -> str:
    """The policy as a child's argument."""
    return "--policy=" + json.dumps(POLICY)


def out_of_time() -> bool:
    return time.perf_counter() >= DEADLINE[0]


def run_child(cmd: list) -> tuple[dict | None, str]:
    """Runs one gmsh child (this script) until DEADLINE: its JSON, or None and why it failed."""
    left = DEADLINE[0] - time.perf_counter()
    if left <= 0:
        return None, "not tried: the mesher's time limit was reached"
    try:
        run = subprocess.run(cmd, capture_output=True, text=True, timeout=None if math.isinf(left) else left)
    except subprocess.TimeoutExpired:
        return None, "stopped at the mesher's time limit (RODSTUDY_MESHER_TIMEOUT_S)"
    for line in run.stderr.splitlines():
        if line.startswith("mesh_rod:   "):  # a child's progress (the fallbacks' rounds)
            log(line[len("mesh_rod: "):])
    if run.returncode == 0:
        return json.loads(run.stdout.strip().splitlines()[-1]), ""
    lines = [l for l in run.stderr.strip().splitlines() if l.strip()]
    why = lines[-1] if lines else f"exit status {run.returncode}"
    if run.returncode < 0:
        why = f"gmsh crashed (signal {-run.returncode})"
    return None, why


def run_fallback(name: str, stl: pathlib.Path, size: float, angle: float, curve_angle: float,
                 msh: pathlib.Path, size_field, geometry_in, geometry_out) -> tuple[dict | None, str]:
    """One fallback of the policy's `fallbacks` in a child process."""
    cmd = [sys.executable, str(SCRIPT), "_fallback", name, str(stl), str(msh),
           "--size", repr(size), "--angle", repr(angle), "--curve-angle", repr(curve_angle), policy_arg()]
    for flag, value in (("--size-field", size_field), ("--geometry-in", geometry_in),
                        ("--geometry-out", geometry_out)):
        if value is not None:
            cmd += [flag, str(value)]
    return run_child(cmd)
