#!/usr/bin/env python3
"""A rod with fillets like the designs, for the accuracy of rodstudy's adaptive FEM.

The rod is built exactly as `make_designs.py` builds its rods (OpenCASCADE through gmsh: big-end
eye with bolt bosses, small-end eye, a solid tapered shank, every z-parallel junction edge filleted
with R8, boss corners R4, full 40 mm thickness so that no sharp re-entrant edge exists), with fixed
parameters (no calibration), so the exact B-rep is known and reproducible.

  fillet_rod.py stl OUT.stl [--per-turn N] [--min-size MM] [--max-size MM]
      The STL exactly as the designs are exported (gmsh surface mesh, 150 elements per turn of
      curvature, 0.8-6 mm, welded by float32 value, outward, validated): what rodstudy meshes.
      The options export the same B-rep at another chord tolerance: N elements per turn of
      curvature (a kink of 360/N degrees between facets), sizes between MIN and MAX. A CAD export
      that tessellates by chord alone has no MAX: `--per-turn 24 --max-size 200` covers the flat
      shank faces with two triangles each and the R8 fillets with 15 degree strips, 40 mm long
      (the case of the loop's size floor).

  fillet_rod.py step OUT.step [--design N]
      The exact B-rep of the same rod (or of design N) as a STEP file in mm, as a CAD system exports
      it: the input of rodstudy's STEP route (exact mass properties, curved tet10 on the true
      surfaces).

  fillet_rod.py reference OUT.msh --near H [--far 6] [--band 4] [--design N]
      A reference mesh made from the exact B-rep, independently of the STL route: curved 10-node
      tetrahedra (second-order nodes on the true fillets), element size H within BAND mm of the
      shank-to-eye fillets and the boss fillets, growing to FAR elsewhere. A sequence of H
      (e.g. 1.4, 1.0, 0.7, 0.5) solved with `rodstudy fem OUT.stl --mesh OUT.msh` and extrapolated
      (Richardson) gives the converged peak that the adaptive result on the STL is judged against.
      --design N does the same for design N of make_designs.py (calibrated again, as generated).

  fillet_rod.py project MESH STEP OUT.vtu [--fraction F]
      The geometry truth of a straight-sided tet10 mesh made from an STL of the same part (e.g. the
      last adaptive mesh, `OUT/mesh/adaptN/rod.msh`, rod frame = the STEP's frame): every node of
      its boundary faces moved onto the nearest point of the exact B-rep, midside nodes inside the
      body by the mean of their edge's corner moves (F of the way: 1 by default), written as VTU
      for `rodstudy fem STL --mesh OUT.vtu`. The difference of that run's judged peak from the
      straight mesh's is the true geometry error of the STL at that mesh, to compare with
      rodstudy's `estimated_geometry_error_rel` (the same move onto a smooth surface through the
      STL's vertices).

All print one JSON line (paths, counts, timings).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import pathlib
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent


def designs_module():
    spec = importlib.util.spec_from_file_location("make_designs", HERE / "make_designs.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules["make_designs"] = mod  # its dataclasses look themselves up there
    spec.loader.exec_module(mod)
    return mod


# The rod: make_designs' "solid" kind with a slender shank, so the F_y case bends it (peak at the
# shank-to-small-eye fillets, as in the designs).
PARAMS = {"boss_half_span": 55.0, "eye_b_r": 27.0, "shank_h": 15.0, "shank_dh": 4.0, "fillet_r": 8.0}


def build(md, design: int | None = None):
    """The fillet test rod, or design N of make_designs.py (calibrated again, as it generates it)."""
    md.gmsh_start()
    if design is not None:
        res = md.generate(md.DESIGNS[design])
        d, p = res["design"], res["params"]
    else:
        d = md.Design(0, "fillet test rod", "solid", dict(PARAMS), (), ())
        p = d.params()
    md.check_sensible(d, p)
    return d, p, md.build_rod(d, p)


def cmd_stl(args) -> dict:
    md = designs_module()
    t0 = time.perf_counter()
    d, p, vol = build(md)
    import gmsh

    for key, value in (("Mesh.MeshSizeFromCurvature", args.per_turn), ("Mesh.MeshSizeMin", args.min_size),
                       ("Mesh.MeshSizeMax", args.max_size)):
        if value is not None:
            gmsh.option.setNumber(key, value)
    verts, tris = md.surface_triangles()
    tris = md.orient_outward(tris, verts)
    md.validate_mesh(verts, tris, "fillet rod")
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_bytes(md.stl_bytes(verts, tris, "rodstudy fillet test rod, mm, gmsh OCC"))
    exact = md.occ_properties(vol)
    return {"stl": str(out), "triangles": int(len(tris)), "volume_mm3": float(exact["volume"]),
            "per_turn": gmsh.option.getNumber("Mesh.MeshSizeFromCurvature"),
            "min_size_mm": gmsh.option.getNumber("Mesh.MeshSizeMin"),
            "max_size_mm": gmsh.option.getNumber("Mesh.MeshSizeMax"),
            "params": p, "seconds": time.perf_counter() - t0}


def cmd_step(args) -> dict:
    """The exact B-rep of the fillet test rod as a STEP file (mm): what a CAD system would export."""
    import gmsh

    md = designs_module()
    t0 = time.perf_counter()
    d, p, vol = build(md, args.design)
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    gmsh.write(str(out))
    exact = md.occ_properties(vol)
    return {"step": str(out), "volume_mm3": float(exact["volume"]), "params": p,
            "seconds": time.perf_counter() - t0}


def fillet_surfaces(md, vol: int, p: dict) -> list:
    """Faces of the four shank-to-eye fillets: the curved faces whose xy extent is at most a fillet's
    (not the bores, not the eye outlines) beyond the bolt bosses."""
    import gmsh

    faces = gmsh.model.getBoundary([(3, vol)], combined=False, oriented=False)
    out = []
    for _, f in faces:
        x0, y0, _, x1, y1, _ = gmsh.model.getBoundingBox(2, abs(f))
        shank_junction = 0.5 * (x0 + x1) > p["boss_half_len"] + p["boss_corner_r"] + 1.0
        if (gmsh.model.getType(2, abs(f)) != "Plane" and max(x1 - x0, y1 - y0) <= 2.0 * p["fillet_r"] + 0.5
                and shank_junction):
            out.append(abs(f))
    return sorted(set(out))


def cmd_reference(args) -> dict:
    import gmsh

    md = designs_module()
    t0 = time.perf_counter()
    d, p, vol = build(md, args.design)
    fillets = fillet_surfaces(md, vol, p)
    gmsh.model.mesh.clear()
    for k, v in {"Mesh.MeshSizeFromCurvature": 0, "Mesh.MeshSizeMin": 0.0, "Mesh.MeshSizeMax": args.far,
                 "Mesh.MeshSizeExtendFromBoundary": 0, "Mesh.MeshSizeFromPoints": 0,
                 "Mesh.Algorithm": 6, "Mesh.Algorithm3D": 1, "Mesh.ElementOrder": 2,
                 "Mesh.SecondOrderLinear": 0, "Mesh.HighOrderOptimize": 0, "Mesh.Optimize": 1,
                 "Mesh.OptimizeNetgen": 1, "Mesh.RandomSeed": 1, "General.NumThreads": 1}.items():
        gmsh.option.setNumber(k, v)
    dist = gmsh.model.mesh.field.add("Distance")
    gmsh.model.mesh.field.setNumbers(dist, "SurfacesList", fillets)
    gmsh.model.mesh.field.setNumber(dist, "Sampling", 200)
    thr = gmsh.model.mesh.field.add("Threshold")
    gmsh.model.mesh.field.setNumber(thr, "InField", dist)
    gmsh.model.mesh.field.setNumber(thr, "SizeMin", args.near)
    gmsh.model.mesh.field.setNumber(thr, "SizeMax", args.far)
    gmsh.model.mesh.field.setNumber(thr, "DistMin", args.band)
    gmsh.model.mesh.field.setNumber(thr, "DistMax", args.band + 4.0 * args.far)
    gmsh.model.mesh.field.setAsBackgroundMesh(thr)
    gmsh.model.mesh.generate(3)
    types, tags, _ = gmsh.model.mesh.getElements(3)
    n = sum(len(t) for ty, t in zip(types, tags) if ty == 11)
    qual = np.asarray(gmsh.model.mesh.getElementQualities(
        np.concatenate([np.asarray(t) for ty, t in zip(types, tags) if ty == 11]), "minSJ"))
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    gmsh.option.setNumber("Mesh.SaveAll", 0)
    gmsh.write(str(out))
    return {"msh": str(out), "elements": int(n), "near_mm": args.near, "far_mm": args.far,
            "band_mm": args.band, "fillet_surfaces": len(fillets),
            "min_scaled_jacobian": float(qual.min()), "seconds": time.perf_counter() - t0}


# VTK tetra10: the corner and midside local indices of each face, and the edges of the midsides
TET10_FACES = [(0, 1, 2, 4, 5, 6), (0, 1, 3, 4, 8, 7), (1, 2, 3, 5, 9, 8), (0, 2, 3, 6, 9, 7)]
TET10_EDGES = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)]


def corner_volumes(pts, tets):
    a, b, c, d = (pts[tets[:, k]] for k in range(4))
    return np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)) / 6.0


def min_jacobians(pts, tets):
    """Smallest det J of each tet10 over its ten nodes, its centroid and the four Gauss points."""
    xi = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (.5, 0, 0), (.5, .5, 0), (0, .5, 0), (0, 0, .5),
          (.5, 0, .5), (0, .5, .5), (.25, .25, .25)]
    g1, g2 = 0.1381966011250105, 0.5854101966249685
    xi += [(g1, g1, g1), (g2, g1, g1), (g1, g2, g1), (g1, g1, g2)]
    dl = np.array([[-1, -1, -1], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    x = pts[tets]  # (m, 10, 3)
    out = np.full(len(tets), np.inf)
    for p in xi:
        l = np.array([1 - sum(p), p[0], p[1], p[2]])
        dn = np.zeros((10, 3))
        for i in range(4):
            dn[i] = (4 * l[i] - 1) * dl[i]
        for k, (a, b) in enumerate(TET10_EDGES):
            dn[4 + k] = 4 * (l[a] * dl[b] + l[b] * dl[a])
        jac = np.einsum("mai,aj->mij", x, dn)
        out = np.minimum(out, np.linalg.det(jac))
    return out


def cmd_project(args) -> dict:
    import gmsh
    import meshio

    t0 = time.perf_counter()
    m = meshio.read(args.mesh)
    tets = np.concatenate([c.data for c in m.cells if c.type == "tetra10"])
    pts = np.asarray(m.points, dtype=np.float64)[:, :3].copy()
    used = np.unique(tets)
    keys = {}
    for el in tets:
        for f in TET10_FACES:
            k = tuple(sorted(el[list(f[:3])]))
            keys[k] = keys.get(k, 0) + 1
    boundary = np.zeros(len(pts), dtype=bool)
    for el in tets:
        for f in TET10_FACES:
            if keys[tuple(sorted(el[list(f[:3])]))] == 1:
                boundary[el[list(f)]] = True
    nodes = np.nonzero(boundary)[0]
    gmsh.initialize(["fillet_rod"], readConfigFiles=False)
    gmsh.option.setNumber("General.Verbosity", 1)
    gmsh.model.occ.importShapes(args.step)
    gmsh.model.occ.synchronize()
    best = np.full(len(nodes), np.inf)
    target = pts[nodes].copy()
    flat = pts[nodes].reshape(-1).tolist()
    for _, tag in gmsh.model.getEntities(2):
        q, _ = gmsh.model.getClosestPoint(2, tag, flat)
        q = np.asarray(q).reshape(-1, 3)
        d = np.linalg.norm(q - pts[nodes], axis=1)
        better = d < best
        best[better] = d[better]
        target[better] = q[better]
    gmsh.finalize()
    full = np.zeros_like(pts)
    full[nodes] = args.fraction * (target - pts[nodes])
    touched = tets[boundary[tets].any(axis=1)]
    mids = np.array([tets[:, 4 + k] for k in range(6)]).T
    inner_mid = ~boundary[mids]

    def moves(damp):
        d = full * damp[:, None]
        for k, (a, b) in enumerate(TET10_EDGES):
            sel = inner_mid[:, k]
            d[mids[sel, k]] = 0.5 * (d[tets[sel, a]] + d[tets[sel, b]])
        return d

    # as rodstudy's curving (src/rod/smooth.rs): halve the moves of the boundary nodes of an element
    # whose det J falls below 0.3 of its straight value, up to eight times, then drop them
    damp = np.ones(len(pts))
    straight = 6.0 * corner_volumes(pts, touched)
    for rnd in range(9):
        d = moves(damp)
        bad = min_jacobians(pts + d, touched) < 0.3 * straight
        if not bad.any():
            break
        hit = np.unique(touched[bad])
        hit = hit[boundary[hit]]
        damp[hit] = 0.5 * damp[hit] if rnd < 8 else 0.0
    delta = moves(damp)
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    meshio.write(str(out), meshio.Mesh(pts + delta, [("tetra10", tets)]))
    return {"vtu": str(out), "boundary_nodes": int(len(nodes)), "nodes": int(len(used)),
            "damped_nodes": int((damp[nodes] < 1).sum()),
            "max_move_mm": float(best.max()), "mean_move_mm": float(best.mean()),
            "fraction": args.fraction, "seconds": time.perf_counter() - t0}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    ps = sub.add_parser("stl")
    ps.add_argument("out")
    ps.add_argument("--per-turn", type=float, help="elements per turn of curvature (default 150, as the designs)")
    ps.add_argument("--min-size", type=float, help="smallest facet size, mm (default 0.8)")
    ps.add_argument("--max-size", type=float, help="largest facet size, mm (default 6)")
    pt = sub.add_parser("step")
    pt.add_argument("out")
    pt.add_argument("--design", type=int, help="design N of make_designs.py instead of the fillet test rod")
    pr = sub.add_parser("reference")
    pr.add_argument("out")
    pr.add_argument("--near", type=float, required=True)
    pr.add_argument("--far", type=float, default=6.0)
    pr.add_argument("--band", type=float, default=4.0)
    pr.add_argument("--design", type=int, help="design N of make_designs.py instead of the fillet test rod")
    pj = sub.add_parser("project")
    pj.add_argument("mesh")
    pj.add_argument("step")
    pj.add_argument("out")
    pj.add_argument("--fraction", type=float, default=1.0)
    args = ap.parse_args(argv)
    info = {"stl": cmd_stl, "step": cmd_step, "reference": cmd_reference,
            "project": cmd_project}[args.cmd](args)
    print(json.dumps(info, sort_keys=True))
    return 0


if __name__ == "__main__":
    sys.exit(main())
