#!/usr/bin/env python3
"""Rods as other CAD systems write them: test data for rodstudy's stage 1, one habit per file.

Each file reproduces what a real export from another CAD system does, so that stage 1 meets it:

  solidworks.stl       the plain rod of `foreign_rods.py` as SolidWorks writes a binary STL: a vertex
                       on a coordinate plane is written as 0.0 in one facet and as 6.9e-15, 5.6e-14 or
                       -5.4e-14 in its neighbours, so that equality by value leaves the surface open
                       along those edges (closed once vertices within 1e-9 of the part are merged)
  bolted_capless       a 620 mm rod body without its cap (STEP and STL): a half bore R70 at the big
                       end A (the joint face x = 0), a full bore R35 at the small end B (620, 0, 0),
                       both along z, two R10 cap-bolt holes along x through the big-end block at
                       y = +-95 (longer walls than the pin bores', so that a finder choosing the pin
                       pair by wall area takes the bolt holes), a slotted shank
  metres               the plain rod whose numbers are metres while the STEP header declares
                       millimetres (as a FreeCAD export of a part drawn in metres): metres.step and
                       its sidecar metres.toml with `units = "m"`
  two_bodies           the plain rod and a loose block 80 mm beyond its small end: two closed
                       shells that do not touch (STL and STEP)
  crossed.stl          the plain rod's fine export with the vertex of the big eye's outer wall nearest
                       (0, 45, 0) pushed to y = 20, through the bore wall: a closed, consistently
                       oriented surface that crosses itself, which gmsh cannot mesh ("Invalid
                       boundary mesh (overlapping facets)")
  moved_bore.step      the plain rod's STEP with the cylinder of bore A moved 3 mm along x off the
                       edges that bound it (a broken B-rep, as a hand edit leaves it): refused

The sharp re-entrant corners of an exact STEP are `foreign_rods.py`'s plain rod (plain.step).
manifest.json holds, per rod, the true pin centres, radii and axis (in the units the numbers mean),
the exact volume from OpenCASCADE in mm^3 and what stage 1 must do with each file.

Usage
-----
  cad_quirks.py OUTDIR

Deterministic: the same bytes on every run.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import pathlib
import re
import sys

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent


def foreign_module():
    spec = importlib.util.spec_from_file_location("foreign_rods", HERE / "foreign_rods.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules["foreign_rods"] = mod
    spec.loader.exec_module(mod)
    return mod


fr = foreign_module()
md = fr.md
import gmsh  # noqa: E402

# SolidWorks' roundings of a coordinate that is 0.0 (seen in real exports)
ROUNDINGS = np.array([6.9e-15, 5.6e-14, -5.4e-14], dtype=np.float32)


def write_step(out: pathlib.Path, name: str, transform=None) -> pathlib.Path:
    step = out / f"{name}.step"
    gmsh.write(str(step))
    text = re.sub(r"'\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d'", "'2000-01-01T00:00:00'", step.read_text(), count=1)
    if transform is not None:
        text = transform(text)
    step.write_text(text)
    return step


def write_stl(out: pathlib.Path, name: str, volumes, header: str) -> np.ndarray:
    verts, tris = fr.mesh_volumes(volumes, "fine", "mm")
    (out / f"{name}.stl").write_bytes(md.stl_bytes(verts, tris, header))
    return verts


def solidworks(out: pathlib.Path) -> dict:
    """The plain rod's fine export with its zero coordinates rounded the way SolidWorks does: every
    other facet writes each 0.0 of its corners as one of ROUNDINGS."""
    volumes, _ = fr.build("plain")
    verts, tris = fr.mesh_volumes(volumes, "fine", "mm")
    corners = np.asarray(verts, dtype=np.float32)[tris].copy()  # (T, 3, 3)
    rounded = 0
    for t in range(1, len(corners), 2):
        zero = corners[t] == 0.0
        k = int(np.count_nonzero(zero))
        if k:
            corners[t][zero] = ROUNDINGS[(t // 3 + np.arange(k)) % len(ROUNDINGS)]
            rounded += k
    assert rounded > 5, f"only {rounded} coordinates rounded"
    head = b"rodstudy cad_quirks solidworks-like binary STL, mm".ljust(80, b" ")
    rec = np.zeros(len(corners), dtype=md.STL_RECORD)
    rec["v"] = corners
    c = corners.astype(np.float64)
    n = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    rec["normal"] = n / np.linalg.norm(n, axis=1, keepdims=True)
    (out / "solidworks.stl").write_bytes(head + np.uint32(len(corners)).tobytes() + rec.tobytes())
    exact = fr.exact_properties(volumes)
    return {"files": ["solidworks.stl"], "crank_pin": [0, 0, 0], "piston_pin": [180, 0, 0],
            "crank_bore_radius": 25, "piston_bore_radius": 12.5, "pin_axis": [0, 0, 1],
            "units": "mm", "volume_mm3": exact["volume"], "rounded_coordinates": rounded,
            "expect": "ranked; vertices_merged > 0"}


def bolted_capless(out: pathlib.Path) -> dict:
    occ = gmsh.model.occ
    gmsh.clear()
    gmsh.model.add("bolted_capless")
    L, T = 620.0, 40.0
    block = occ.addBox(0, -120, -T / 2, 160, 240, T)  # the big-end block, the joint face at x = 0
    eye_b = occ.addCylinder(L, 0, -T / 2, 0, 0, T, 60)
    shank = md.occ_prism([(100.0, -50.0), (L, -35.0), (L, 35.0), (100.0, 50.0)], -T / 2, T)
    body, _ = occ.fuse([(3, block)], [(3, eye_b), (3, shank)])
    assert len(body) == 1, body
    bore_a = occ.addCylinder(0, 0, -T, 0, 0, 2 * T, 70)
    bore_b = occ.addCylinder(L, 0, -T, 0, 0, 2 * T, 35)
    bolts = [occ.addCylinder(-1, y, 0, 162, 0, 0, 10) for y in (-95.0, 95.0)]
    slot = md.occ_prism([(250.0, -10.0), (450.0, -10.0), (450.0, 10.0), (250.0, 10.0)], -T, 2 * T)
    cut, _ = occ.cut(body, [(3, bore_a), (3, bore_b), (3, slot)] + [(3, b) for b in bolts])
    assert len(cut) == 1, cut
    occ.synchronize()
    volumes = [cut[0][1]]
    exact = fr.exact_properties(volumes)
    write_step(out, "bolted_capless")
    write_stl(out, "bolted_capless", volumes, "rodstudy cad_quirks bolted capless rod, mm")
    return {"files": ["bolted_capless.step", "bolted_capless.stl"], "crank_pin": [0, 0, 0],
            "piston_pin": [L, 0, 0], "crank_bore_radius": 70, "piston_bore_radius": 35,
            "pin_axis": [0, 0, 1], "crank_bore_arc_deg": 180, "units": "mm",
            "volume_mm3": exact["volume"],
            "expect": "ranked; pins found at the half bore and the small bore, not at the bolt holes"}


def metres(out: pathlib.Path) -> dict:
    """The plain rod drawn in metres (every dimension of `foreign_rods.build("plain")` times 1e-3;
    not a dilation, which OpenCASCADE does by turning every surface into an approximating B-spline)
    and written by gmsh, whose STEP header declares millimetres."""
    gmsh.model.add("metres")
    v = fr.rod_body(*(k * 1e-3 for k in (180, 25, 12.5, 45, 24, 40, 16, 11, 16, 8)), 0)
    exact_m = fr.exact_properties([v])
    step = write_step(out, "metres")
    assert "SI_UNIT(.MILLI.,.METRE.)" in step.read_text()
    (out / "metres.toml").write_text('units = "m"\n')
    return {"files": ["metres.step"], "crank_pin": [0, 0, 0], "piston_pin": [0.18, 0, 0],
            "crank_bore_radius": 0.025, "piston_bore_radius": 0.0125, "pin_axis": [0, 0, 1],
            "units": "m", "volume_mm3": exact_m["volume"] * 1e9,
            "expect": "ranked with the sidecar's units = \"m\" (the header says mm); refused "
                      "without it, the message saying to set units"}


def two_bodies(out: pathlib.Path) -> dict:
    volumes, _ = fr.build("plain")
    loose = gmsh.model.occ.addBox(180 + 24 + 80, -20, -20, 40, 40, 40)
    gmsh.model.occ.synchronize()
    volumes = volumes + [loose]
    exact = fr.exact_properties(volumes)
    write_step(out, "two_bodies")
    write_stl(out, "two_bodies", volumes, "rodstudy cad_quirks two loose bodies, mm")
    return {"files": ["two_bodies.step", "two_bodies.stl"], "crank_pin": [0, 0, 0],
            "piston_pin": [180, 0, 0], "crank_bore_radius": 25, "piston_bore_radius": 12.5,
            "pin_axis": [0, 0, 1], "units": "mm", "volume_mm3": exact["volume"], "gap_mm": 80.0,
            "expect": "mass of both bodies with a warning that they are 80 mm apart; FEM refused"}


def crossed(out: pathlib.Path) -> dict:
    volumes, _ = fr.build("plain")
    verts, tris = fr.mesh_volumes(volumes, "fine", "mm")
    verts = np.asarray(verts, dtype=np.float32).copy()
    k = int(np.argmin(np.linalg.norm(verts - np.array([0.0, 45.0, 0.0], dtype=np.float32), axis=1)))
    moved = verts[k].copy()
    verts[k, 1] = 20.0
    (out / "crossed.stl").write_bytes(md.stl_bytes(verts, tris, "rodstudy cad_quirks crossed surface, mm"))
    return {"files": ["crossed.stl"], "moved_vertex": moved.tolist(), "to_y": 20.0,
            "expect": "mass accepted; stage 3's mesher failure says where the facets cross"}


def moved_bore(out: pathlib.Path) -> dict:
    volumes, _ = fr.build("plain")

    def move(text: str) -> str:
        surface = re.search(r"#\d+ = CYLINDRICAL_SURFACE\('',#(\d+),25\.\);", text)
        placement = re.search(rf"#{surface.group(1)} = AXIS2_PLACEMENT_3D\('',#(\d+),", text)
        point = re.search(rf"#{placement.group(1)} = CARTESIAN_POINT\('',\(([^,]+),", text)
        x = float(point.group(1)) + 3.0
        return text[:point.start(1)] + f"{x:.1f}" + text[point.end(1):]

    write_step(out, "moved_bore", move)
    return {"files": ["moved_bore.step"], "moved_mm": 3.0,
            "expect": "refused: bore A's surface lies 3 mm from its edges"}


RODS = {"solidworks": solidworks, "bolted_capless": bolted_capless, "metres": metres,
        "two_bodies": two_bodies, "crossed": crossed, "moved_bore": moved_bore}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir")
    ap.add_argument("--only", choices=sorted(RODS))
    args = ap.parse_args(argv)
    out = pathlib.Path(args.outdir)
    out.mkdir(parents=True, exist_ok=True)
    md.gmsh_start()
    manifest = {}
    for name in [args.only] if args.only else RODS:
        gmsh.clear()
        manifest[name] = RODS[name](out)
    (out / "cad_quirks.json").write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n")
    gmsh.finalize()
    return 0


if __name__ == "__main__":
    sys.exit(main())
