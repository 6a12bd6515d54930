"""What `make_designs.py` does: write the designs, print the table, write the STEP files, check the
committed designs against a fresh generation."""

from __future__ import annotations

import pathlib
import tempfile
import time

import gmsh

from .calibration import errors, generate, within
from .cross_checks import beam_bending_stress, peak_pin_force
from .definitions import DESIGNS, TABLE_5_1, TOL_REQUIRED, fmt_dimensions, fmt_params
from .export import read_stl, sidecar_text, stl_bytes
from .mass import mesh_mass_properties
from .solid import build_rod, gmsh_start
from .surface import validate_mesh


def write_design(res: dict, out_dir: pathlib.Path) -> pathlib.Path:
    d = res["design"]
    out_dir.mkdir(parents=True, exist_ok=True)
    stl_path = out_dir / f"design{d.number}.stl"
    header = f"rodstudy design{d.number} binary STL, mm, gmsh {gmsh.__version__} OCC"
    stl_path.write_bytes(stl_bytes(res["verts"], res["tris"], header))
    (out_dir / f"design{d.number}.toml").write_text(sidecar_text(d))
    # What the pipeline will see: re-read the file and integrate its float32 coordinates.
    verts, tris = read_stl(stl_path)
    validate_mesh(verts, tris, str(stl_path))
    res["file"] = mesh_mass_properties(verts, tris)
    res["n_tri"] = len(tris)
    res["size"] = stl_path.stat().st_size
    return stl_path


def report(results: list) -> bool:
    """Print the summary table; returns True when every design meets the required tolerance."""
    ok_all = True
    print()
    print(f"{'':2} {'mass [kg]':>22} {'l1 [mm]':>18} {'I_xx [kg m^2]':>24} {'I_zz [kg m^2]':>13}"
          f" {'tris':>7} {'MB':>5}")
    for res in results:
        d, f, tgt = res["design"], res["file"], TABLE_5_1[res["design"].number]
        e = errors(f, tgt)
        ok = within(e, TOL_REQUIRED)
        ok_all &= ok
        print(f"{d.number:<2} {f['mass']:12.7f} {e['mass_rel']:+9.1e} {f['l1']:9.4f} {e['l1_mm']:+8.4f}"
              f" {f['ixx']:13.10f} {e['ixx_rel']:+9.1e} {f['izz']:13.9f} {res['n_tri']:7d}"
              f" {res['size'] / 1e6:5.2f} {'ok' if ok else 'OUT OF TOLERANCE'}")
        print(f"{'':2} target {tgt.mass:.10f} kg, l1 {tgt.l1:.2f} mm, I_xx {tgt.ixx:.13f} kg m^2;"
              f" {d.name}")
        print(f"{'':2} parameters: {fmt_params(d, res['params'])}")
        print(f"{'':2} {fmt_dimensions(d, res['params'])}")
        c = f["centroid"]
        print(f"{'':2} centroid y {c[1]:+.1e} mm, z {c[2]:+.1e} mm; tessellation vs exact B-rep: mass"
              f" {res['chord_mass_rel']:+.1e}")
    print()
    print("Peak pin force cross-check, F = r w^2 [m4 (1 + r/l) + m3 (1 + (r/l)(l1/l))] (SPEC Stage 2),")
    print("and a beam-theory estimate of the F_y bending stress at the small-end junction (ranking aid):")
    print(f"{'':2} {'F [N]':>10} {'thesis [N]':>10} {'rel':>9}   {'sigma_Fy beam [MPa]':>20}")
    for res in results:
        d, f, tgt = res["design"], res["file"], TABLE_5_1[res["design"].number]
        force = peak_pin_force(f["mass"], f["l1"] * 1e-3)
        note = "  (Table 5.1 row 2 is physically unreachable, SPEC)" if d.number == 2 else ""
        sigma = beam_bending_stress(d, res["params"], force)
        print(f"{d.number:<2} {force:10.1f} {tgt.peak_force:10.0f} {force / tgt.peak_force - 1:+9.2e}"
              f"   {sigma:20.0f}{note}")
    return ok_all


def run(numbers, out_dir: pathlib.Path) -> list:
    gmsh_start()
    results = []
    for n in numbers:
        t0 = time.perf_counter()
        d = DESIGNS[n]
        res = generate(d)
        write_design(res, out_dir)
        print(f"  design {n}: {res['n_tri']} triangles, {fmt_params(d, res['params'])}"
              f" ({time.perf_counter() - t0:.1f} s)", flush=True)
        results.append(res)
    return results


def write_steps(numbers, step_dir: pathlib.Path) -> int:
    """The exact B-rep of each calibrated design (the parameters its STL is tessellated from) as
    STEP_DIR/designN.step: the reference geometry of the STL route's error estimates (stage 3 on
    a STEP meshes the exact surfaces with curved tet10 and has no facet floor; docs/fem.md)."""
    gmsh_start()
    step_dir.mkdir(parents=True, exist_ok=True)
    for n in numbers:
        d = DESIGNS[n]
        res = generate(d)
        build_rod(d, res["params"])
        gmsh.model.occ.synchronize()
        path = step_dir / f"design{n}.step"
        gmsh.write(str(path))
        print(f"  design {n}: wrote {path} ({fmt_params(d, res['params'])})", flush=True)
    return 0


def check(numbers, committed: pathlib.Path) -> int:
    """Regenerate into a temporary folder and compare with the committed files."""
    with tempfile.TemporaryDirectory(prefix="rodstudy-designs-") as tmp:
        tmp = pathlib.Path(tmp)
        results = run(numbers, tmp)
        ok_tol = report(results)
        problems = []
        for res in results:
            n = res["design"].number
            for ext in ("stl", "toml"):
                new, old = tmp / f"design{n}.{ext}", committed / f"design{n}.{ext}"
                if not old.exists():
                    problems.append(f"{old} is missing")
                    continue
                if new.read_bytes() == old.read_bytes():
                    continue
                if ext == "toml":
                    problems.append(f"{old} differs from the regenerated sidecar")
                    continue
                verts, tris = read_stl(old)
                try:
                    validate_mesh(verts, tris, str(old))
                    old_p = mesh_mass_properties(verts, tris)
                except ValueError as e:
                    problems.append(str(e))
                    continue
                e = errors(old_p, TABLE_5_1[n])
                problems.append(
                    f"{old} differs from the regenerated file ({len(tris)} vs {res['n_tri']} triangles); "
                    f"committed: mass {old_p['mass']:.7f} kg ({e['mass_rel']:+.1e}), l1 {old_p['l1']:.4f} mm "
                    f"({e['l1_mm']:+.4f}), I_xx {old_p['ixx']:.10f} ({e['ixx_rel']:+.1e})"
                    f"{'' if within(e, TOL_REQUIRED) else ' OUT OF TOLERANCE'}")
    if not ok_tol:
        problems.append("a regenerated design misses the Table 5.1 tolerance")
    if problems:
        print("\nCHECK FAILED:\n  " + "\n  ".join(problems))
        return 1
    print(f"\ncheck passed: designs {', '.join(map(str, numbers))} in {committed} are byte-identical"
          " to a fresh generation")
    return 0
