#!/usr/bin/env python3
"""Connecting rods drawn the way other people draw them, as test data for rodstudy.

Not the designs of `make_designs.py`: each rod here breaks one habit of those designs, so that the
bore finder, the validator and the mass stage meet what real CAD exports look like.

  fillets      fillets everywhere: shank-to-eye junctions R12, every edge of the (flat, 30 mm) faces R1 (the bore rims
               too), bores 200 mm apart along y (pins along z)
  capless      a rod body without its cap: the big end cut at the bore's centre plane (x = 0), so
               bore A is a half cylinder open towards -x
  rod_and_cap  the same rod with its cap as a second solid, touching the rod at the joint face
               (two shells in the STL, two solids in the STEP)
  inches       a rod drawn in inches, its pin axis along y (sidecar: units = "in" only)
  plain        a rod like the designs (bores R25 / R12.5, 180 mm apart along x, pins along z)
  stepped      the plain rod (shank 16 mm thick between 40 mm eyes) with every re-entrant edge an R1
               fillet (the shank-to-eye junctions and the steps from the shank faces to the eyes),
               also exported as NAME_chord.stl: 24 elements per turn but none below 0.8 mm, as an
               export with a minimum facet size (or a 0.1 mm chord tolerance) cuts a small fillet:
               each R1 fillet in two facets, kinks of 45°, above a 40° feature angle (a fillet,
               not a sharp edge)

Each rod is built with gmsh's OpenCASCADE kernel (as `make_designs.py` and `fillet_rod.py`) and
written as NAME.step (the exact B-rep) and as binary STL at two chord tolerances: NAME_coarse.stl
(24 elements per turn of curvature) and NAME_fine.stl (120 per turn; the stepped rod also
NAME_chord.stl, see above), each surface mesh welded by
float32 value and oriented outward body by body (make_designs' orient_outward and validate_mesh,
per solid). manifest.json holds, per rod: units, the true pin centres (file units), radii and pin
axis, the arc of bore A, the exact volume, centre of mass and inertia matrix from OCC
(getMass / getCenterOfMass / getMatrixOfInertia, unit density, file units), and per STL its file
name and triangle count.

Usage
-----
  foreign_rods.py OUTDIR [--only NAME]

Deterministic (fixed options, one thread): the same bytes on every run.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import math
import pathlib
import re
import sys

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent


def designs_module():
    spec = importlib.util.spec_from_file_location("make_designs", HERE / "make_designs.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules["make_designs"] = mod  # its dataclasses look themselves up there
    spec.loader.exec_module(mod)
    return mod


md = designs_module()
import gmsh  # noqa: E402  (after make_designs, which imports it too)

# Chord tolerances: elements per 2*pi of curvature, and size bounds in mm (scaled for inches).
TOLERANCES = {
    "coarse": {"Mesh.MeshSizeFromCurvature": 24, "Mesh.MeshSizeMin": 0.5, "Mesh.MeshSizeMax": 10.0,
               "Mesh.MeshSizeExtendFromBoundary": 0},
    "fine": {"Mesh.MeshSizeFromCurvature": 120, "Mesh.MeshSizeMin": 0.3, "Mesh.MeshSizeMax": 5.0,
             "Mesh.MeshSizeExtendFromBoundary": 0},
    "chord": {"Mesh.MeshSizeFromCurvature": 24, "Mesh.MeshSizeMin": 0.8, "Mesh.MeshSizeMax": 10.0,
              "Mesh.MeshSizeExtendFromBoundary": 0},
}

# The exports of each rod (default: coarse and fine).
EXPORTS = {"stepped": ["coarse", "fine", "chord"]}

MM_PER = {"mm": 1.0, "in": 25.4}


def rod_body(L, bore_a, bore_b, eye_a, eye_b, T, half_a, half_b, Ts, junction_r, edge_r, bores=True):
    """A rod in the local frame (A at the origin, B at (L, 0, 0), pin axis z, mid-plane z = 0):
    eyes, a tapered shank of thickness Ts, junction fillets on the z-parallel edges, optional R edge_r
    on every other edge, and the two bores through along z. Returns the volume tag."""
    occ = gmsh.model.occ
    ea = occ.addCylinder(0, 0, -T / 2, 0, 0, T, eye_a)
    eb = occ.addCylinder(L, 0, -T / 2, 0, 0, T, eye_b)
    shank = md.occ_prism([(0.0, -half_a), (L, -half_b), (L, half_b), (0.0, half_a)], -Ts / 2, Ts)
    out, _ = occ.fuse([(3, ea)], [(3, eb), (3, shank)])
    assert len(out) == 1, f"fuse gave {out}"
    body = out[0][1]
    if junction_r > 0:
        edges = [c for c, _, _ in md.z_parallel_edges(body)]
        out = occ.fillet([body], edges, [junction_r])
        assert len(out) == 1, "junction fillet failed"
        body = out[0][1]
    if bores:
        ba = occ.addCylinder(0, 0, -T, 0, 0, 2 * T, bore_a)
        bb = occ.addCylinder(L, 0, -T, 0, 0, 2 * T, bore_b)
        out, _ = occ.cut([(3, body)], [(3, ba), (3, bb)])
        assert len(out) == 1, f"bores cut gave {out}"
        body = out[0][1]
    if edge_r > 0:
        occ.synchronize()
        faces = gmsh.model.getBoundary([(3, body)], combined=False, oriented=False)
        curves = sorted({abs(c) for _, c in gmsh.model.getBoundary(faces, combined=False, oriented=False)})
        # every edge not yet rounded: those in the faces z = +-T/2 and +-Ts/2 (the z-parallel
        # junctions carry the larger fillets already)
        keep = []
        for c in curves:
            x0, y0, z0, x1, y1, z1 = occ.getBoundingBox(1, c)
            if abs(z1 - z0) < 1e-6:
                keep.append(c)
        out = occ.fillet([body], keep, [edge_r])
        assert len(out) == 1, "edge rounds failed"
        body = out[0][1]
    occ.synchronize()
    return body


def fillet_reentrant(body: int, L, eye_a, eye_b, Ts, r) -> int:
    """`body` (a rod of `rod_body` without junction fillets and bores) with its re-entrant edges
    filleted with radius r: the z-parallel shank-to-eye junctions and the arcs where the shank's
    faces z = +-Ts/2 meet the eye walls."""
    occ = gmsh.model.occ
    occ.synchronize()
    edges = [c for c, _, _ in md.z_parallel_edges(body)]
    faces = gmsh.model.getBoundary([(3, body)], combined=False, oriented=False)
    for c in sorted({abs(c) for _, c in gmsh.model.getBoundary(faces, combined=False, oriented=False)}):
        x0, y0, z0, x1, y1, z1 = occ.getBoundingBox(1, c)
        if abs(z1 - z0) < 1e-6 and abs(abs(z0) - Ts / 2) < 1e-6:
            lo, hi = gmsh.model.getParametrizationBounds(1, c)
            p = gmsh.model.getValue(1, c, [0.5 * (lo[0] + hi[0])])
            if abs(math.hypot(p[0], p[1]) - eye_a) < 1e-3 or abs(math.hypot(p[0] - L, p[1]) - eye_b) < 1e-3:
                edges.append(c)
    out = occ.fillet([body], edges, [r])
    assert len(out) == 1, "re-entrant fillets failed"
    return out[0][1]


def half_space(x_min: float, x_max: float, size: float) -> int:
    """A box x_min <= x <= x_max, large in y and z."""
    return gmsh.model.occ.addBox(x_min, -size, -size, x_max - x_min, 2 * size, 2 * size)


def build(name: str):
    """Builds rod `name` in a fresh model: returns (volume tags, facts for the manifest)."""
    occ = gmsh.model.occ
    gmsh.clear()
    gmsh.model.add(name)
    z = [0.0, 0.0, 1.0]
    if name == "plain":
        v = rod_body(180, 25, 12.5, 45, 24, 40, 16, 11, 16, 8, 0)
        facts = dict(units="mm", crank=[0, 0, 0], piston=[180, 0, 0], ra=25, rb=12.5, axis=z, arc_a=360)
        return [v], facts
    if name == "stepped":
        body = rod_body(180, 25, 12.5, 45, 24, 40, 16, 11, 16, 0, 0, bores=False)
        body = fillet_reentrant(body, 180, 45, 24, 16, 1.0)
        ba = occ.addCylinder(0, 0, -40, 0, 0, 80, 25)
        bb = occ.addCylinder(180, 0, -40, 0, 0, 80, 12.5)
        out, _ = occ.cut([(3, body)], [(3, ba), (3, bb)])
        assert len(out) == 1, f"bores cut gave {out}"
        occ.synchronize()
        facts = dict(units="mm", crank=[0, 0, 0], piston=[180, 0, 0], ra=25, rb=12.5, axis=z, arc_a=360)
        return [out[0][1]], facts
    if name == "fillets":
        v = rod_body(200, 26, 13, 48, 25, 30, 17, 12, 30, 12, 1.0)
        occ.rotate([(3, v)], 0, 0, 0, 0, 0, 1, math.pi / 2)  # A -> B along +y
        occ.synchronize()
        facts = dict(units="mm", crank=[0, 0, 0], piston=[0, 200, 0], ra=26, rb=13, axis=z, arc_a=360)
        return [v], facts
    if name in ("capless", "rod_and_cap"):
        body = rod_body(180, 25, 12.5, 45, 24, 40, 16, 11, 16, 8, 0)
        if name == "capless":
            out, _ = occ.cut([(3, body)], [(3, half_space(-500, 0, 500))])
            assert len(out) == 1, f"capless cut gave {out}"
            occ.synchronize()
            facts = dict(units="mm", crank=[0, 0, 0], piston=[180, 0, 0], ra=25, rb=12.5, axis=z, arc_a=180)
            return [out[0][1]], facts
        copy = occ.copy([(3, body)])[0][1]
        rod, _ = occ.cut([(3, body)], [(3, half_space(-500, 0, 500))])
        cap, _ = occ.intersect([(3, copy)], [(3, half_space(-500, 0, 500))])
        assert len(rod) == 1 and len(cap) == 1, f"rod/cap split gave {rod} {cap}"
        occ.synchronize()
        facts = dict(units="mm", crank=[0, 0, 0], piston=[180, 0, 0], ra=25, rb=12.5, axis=z, arc_a=360)
        return [rod[0][1], cap[0][1]], facts
    if name == "inches":
        v = rod_body(7.0, 1.0, 0.5, 1.8, 0.95, 1.5, 0.65, 0.45, 0.65, 0.3, 0)
        occ.rotate([(3, v)], 0, 0, 0, 1, 0, 0, -math.pi / 2)  # pin axis z -> +y
        occ.translate([(3, v)], 2.0, 1.0, -3.0)
        occ.synchronize()
        facts = dict(units="in", crank=[2.0, 1.0, -3.0], piston=[9.0, 1.0, -3.0], ra=1.0, rb=0.5,
                     axis=[0.0, 1.0, 0.0], arc_a=360)
        return [v], facts
    raise ValueError(f"unknown rod {name!r}")


RODS = ["fillets", "capless", "rod_and_cap", "inches", "plain", "stepped"]


def mesh_volumes(volumes, tolerance: str, units: str):
    """Surface mesh of the model at a chord tolerance: per volume, float32-welded and oriented
    outward; returns (vertices, triangles) of all volumes together."""
    md.gmsh_start()
    for k, val in TOLERANCES[tolerance].items():
        gmsh.option.setNumber(k, val / MM_PER[units] if k in ("Mesh.MeshSizeMin", "Mesh.MeshSizeMax") else val)
    gmsh.model.mesh.clear()
    gmsh.model.mesh.generate(2)
    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    xyz = np.asarray(coords, dtype=np.float64).reshape(-1, 3)
    index = np.zeros(int(node_tags.max()) + 1, dtype=np.int64)
    index[node_tags.astype(np.int64)] = np.arange(len(node_tags))
    all_v, all_t, offset = [], [], 0
    for vol in volumes:
        faces = gmsh.model.getBoundary([(3, vol)], combined=False, oriented=False)
        tri = []
        for _, f in faces:
            types, _, nodes = gmsh.model.mesh.getElements(2, abs(f))
            for ty, n in zip(types, nodes):
                if ty == 2:
                    tri.append(index[np.asarray(n, dtype=np.int64).reshape(-1, 3)])
        tri = np.concatenate(tri)
        used = np.unique(tri)
        xyz32 = xyz[used].astype(np.float32) + np.float32(0.0)
        remap = np.zeros(len(xyz), dtype=np.int64)
        uniq, inverse = np.unique(xyz32, axis=0, return_inverse=True)
        remap[used] = inverse.reshape(-1)
        tris = remap[tri]
        tris = md.orient_outward(tris, uniq)
        md.validate_mesh(uniq, tris, f"volume {vol}")
        all_v.append(uniq)
        all_t.append(tris + offset)
        offset += len(uniq)
    return np.concatenate(all_v), np.concatenate(all_t)


def exact_properties(volumes) -> dict:
    """OCC's exact integrals of all volumes (unit density, file units): volume, centre of mass and
    inertia matrix about the common centre of mass."""
    occ = gmsh.model.occ
    vols = [occ.getMass(3, v) for v in volumes]
    coms = [np.array(occ.getCenterOfMass(3, v)) for v in volumes]
    total = sum(vols)
    com = sum(m * c for m, c in zip(vols, coms)) / total
    inertia = np.zeros((3, 3))
    for m, c, v in zip(vols, coms, volumes):
        d = c - com
        inertia += np.array(occ.getMatrixOfInertia(3, v)).reshape(3, 3) + m * (d @ d * np.eye(3) - np.outer(d, d))
    return {"volume": total, "centre_of_mass": com.tolist(), "inertia_about_com": inertia.tolist(),
            "solids": len(volumes)}


def declare_inches(text: str) -> str:
    """gmsh writes every STEP in millimetres; a CAD system exporting a part drawn in inches declares
    the inch instead (ISO 10303-41 conversion-based unit: 1 in = 25.4 mm), and a STEP reader
    converts. The length unit entity of the file is replaced by that declaration."""
    m = re.search(r"#(\d+) = \( LENGTH_UNIT\(\) NAMED_UNIT\(\*\) SI_UNIT\(\.MILLI\.,\.METRE\.\) \);", text)
    if m is None:
        raise RuntimeError("no millimetre length unit in the STEP gmsh wrote")
    n = int(m.group(1))
    top = max(int(k) for k in re.findall(r"^#(\d+) =", text, re.M))
    a, b, c = top + 1, top + 2, top + 3
    inch = (f"#{n} = ( CONVERSION_BASED_UNIT('INCH',#{a}) LENGTH_UNIT() NAMED_UNIT(#{b}) );\n"
            f"#{a} = LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#{c});\n"
            f"#{b} = DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.);\n"
            f"#{c} = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );")
    return text[:m.start()] + inch + text[m.end():]


def write_rod(name: str, out: pathlib.Path) -> dict:
    volumes, facts = build(name)
    exact = exact_properties(volumes)
    step = out / f"{name}.step"
    gmsh.write(str(step))
    # the writer stamps the time into FILE_NAME: a fixed stamp keeps reruns byte-identical
    text = re.sub(r"'\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d'", "'2000-01-01T00:00:00'", step.read_text(), count=1)
    if facts["units"] == "in":
        text = declare_inches(text)
    step.write_text(text)
    entry = {"units": facts["units"], "crank_pin": facts["crank"], "piston_pin": facts["piston"],
             "crank_bore_radius": facts["ra"], "piston_bore_radius": facts["rb"], "pin_axis": facts["axis"],
             "crank_bore_arc_deg": facts["arc_a"], "step": f"{name}.step", "exact": exact, "stl": {}}
    for tol in EXPORTS.get(name, ["coarse", "fine"]):
        verts, tris = mesh_volumes(volumes, tol, facts["units"])
        file = f"{name}_{tol}.stl"
        (out / file).write_bytes(md.stl_bytes(verts, tris, f"rodstudy foreign rod {name} {tol}, {facts['units']}"))
        props = md.mesh_mass_properties(verts, tris, density=1.0)
        entry["stl"][tol] = {"file": file, "triangles": int(len(tris)),
                             "volume_rel_to_exact": float(props["volume"] / exact["volume"] - 1.0)}
        if facts["units"] != "mm":
            (out / f"{name}_{tol}.toml").write_text(f'units = "{facts["units"]}"\n')
    return entry


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir")
    ap.add_argument("--only", choices=RODS)
    args = ap.parse_args(argv)
    out = pathlib.Path(args.outdir)
    out.mkdir(parents=True, exist_ok=True)
    md.gmsh_start()
    manifest = {}
    for name in [args.only] if args.only else RODS:
        manifest[name] = write_rod(name, out)
    (out / "manifest.json").write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n")
    gmsh.finalize()
    return 0


if __name__ == "__main__":
    sys.exit(main())
