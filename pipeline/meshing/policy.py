"""The meshing policy as `mesh_rod.py` receives it (`--policy JSON`, from rodstudy's
`src/mesher/policy.rs`, where every meshing decision is written) and the gmsh options it makes;
the progress log every command writes to standard error."""

from __future__ import annotations

import sys


# The meshing policy (`--policy`, JSON), from rodstudy's `src/mesher/policy.rs`, where every meshing
# decision is written: the classification ladder, the fallbacks and their order, the local
# refinement's rounds, quality limits, gmsh options and the time limit. This script executes it
# and defines none of them.
POLICY: dict = {}


# gmsh's codes of the 3D algorithms the policy names
ALGORITHMS_3D = {"hxt": 10, "delaunay": 1}


def policy(key: str):
    """One entry of the policy; a clear error where the script was called without one."""
    if not POLICY:
        raise SystemExit("mesh_rod: no --policy given: rodstudy passes its meshing policy "
                         "(src/mesher/policy.rs); run the script as `rodstudy pipeline mesh_rod.py ...`")
    return POLICY[key]


def algorithm_code(fallback: bool) -> int:
    """gmsh's code of the policy's first 3D algorithm, or of its fallback."""
    return ALGORITHMS_3D[policy("algorithm_3d_fallback" if fallback else "algorithm_3d")]


def algorithm_name(code: int) -> str:
    return {v: k for k, v in ALGORITHMS_3D.items()}.get(code, "?")


def log(msg: str) -> None:
    print(f"mesh_rod: {msg}", file=sys.stderr, flush=True)


def gmsh_options(size_mm: float, curved: bool, size_field: bool = False) -> dict:
    """The policy's gmsh options in their order, with the request's size and midside nodes, and
    the options of a size-field or a uniform mesh set last. No option is left to gmsh's defaults
    or a user's gmsh configuration files (which are not read)."""
    opts = dict(policy("gmsh_options"))
    opts["Mesh.Algorithm3D"] = algorithm_code(False)
    opts["Mesh.MeshSizeMax"] = size_mm
    opts["Mesh.SecondOrderLinear"] = 0 if curved else 1
    opts.update(policy("size_field_options" if size_field else "uniform_options"))
    unset = [k for k, v in opts.items() if v is None]
    if unset:
        raise SystemExit(f"mesh_rod: the policy leaves gmsh options unset: {', '.join(unset)}")
    return opts


def set_options(size_mm: float, curved: bool, size_field: bool, delaunay: bool) -> None:
    import gmsh

    for k, v in gmsh_options(size_mm, curved, size_field).items():
        gmsh.option.setNumber(k, v)
    if delaunay:
        gmsh.option.setNumber("Mesh.Algorithm3D", algorithm_code(True))
