#!/usr/bin/env python3
"""A STEP design read through gmsh's OpenCASCADE kernel, for rodstudy's stage 1.

  step_solid.py read FILE.step OUT.stl [--fine]

Imports the STEP (AP203/AP214; one or more solids), fuses several solids into one bonded body
(rod, cap and bolts modelled as separate parts become one solid; bodies that do not touch stay
separate volumes and their properties add), and prints one JSON line:

  solids_in_file    the 3D entities the file holds
  volumes           the volumes after the fusion (1 for a bonded body)
  fused             whether several solids were fused
  (lengths are millimetres: OpenCASCADE converts from the unit the STEP file declares)
  volume            exact volume of the B-rep, mm^3 (sum over the volumes)
  centroid          exact centre of volume, file units
  inertia           exact second moment tensor about the centroid, unit density, file units^5
                    (OpenCASCADE's MatrixOfInertia: I_ii = integral of the squared distance to
                    axis i, I_ij = -integral of x_i x_j; about the centre of mass)
  per_volume        the same three figures per volume before they are combined
  stl, triangles    a surface triangulation of the solid in file units (binary STL, welded by
                    float32 value like the designs' exports): what the bore check, the rod frame
                    and the STL route of stage 3 see
  bounding_box, gmsh_version, seconds

Refuses, with a message on standard error and exit status 1: a file gmsh cannot read, a file with
no solid (only surfaces or curves: an open or unsewn shell), a solid of zero or negative volume.
The exact integrals are OpenCASCADE's (BRepGProp volume properties, to its default precision).
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
    sys.modules["make_designs"] = mod
    spec.loader.exec_module(mod)
    return mod


def fail(msg: str) -> None:
    print(f"error: {msg}", file=sys.stderr)
    sys.exit(1)


def combined_properties(per: list) -> tuple:
    """Volume, centroid and inertia about the combined centroid of several bodies (parallel axes)."""
    vol = sum(p["volume"] for p in per)
    c = sum(p["volume"] * np.asarray(p["centroid"]) for p in per) / vol
    inertia = np.zeros((3, 3))
    for p in per:
        d = np.asarray(p["centroid"]) - c
        inertia += np.asarray(p["inertia"]) + p["volume"] * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
    return vol, c, inertia


def shells_outward(md, solids: list) -> tuple:
    """The surface triangulation of every volume, welded by float32 value as the designs' exports
    are, each volume's shell oriented outward on its own (bodies that do not touch are separate
    closed shells of one file)."""
    import gmsh

    verts, tris = md.surface_triangles()  # generates the 2D mesh; all triangles, welded
    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    xyz = np.asarray(coords, dtype=np.float64).reshape(-1, 3).astype(np.float32) + np.float32(0.0)
    lookup = {tuple(v): i for i, v in enumerate(verts)}
    index = np.zeros(int(node_tags.max()) + 1, dtype=np.int64)
    index[node_tags.astype(np.int64)] = [lookup[tuple(v)] for v in xyz]
    out = []
    for t in solids:
        faces = {abs(f) for _, f in gmsh.model.getBoundary([(3, t)], combined=False, oriented=False)}
        shell = []
        for f in sorted(faces):
            types, _, nodes = gmsh.model.mesh.getElements(2, f)
            for ty, nn in zip(types, nodes):
                if ty == 2:
                    shell.append(index[np.asarray(nn, dtype=np.int64)].reshape(-1, 3))
        out.append(md.orient_outward(np.concatenate(shell), verts))
    return verts, np.concatenate(out) if len(out) > 1 else out[0]


# A plane or cylinder further than this share of the part's size from the edges that bound it is a
# broken B-rep (OpenCASCADE's own tolerances are 1e-7 mm; sloppy exports stay below 1e-3 of the part).
FACE_EDGE_REL = 1e-3


def faces_off_their_edges() -> tuple:
    """The largest distance from a point of a face's boundary curves (five per curve) to the face's
    own surface, over the planar and cylindrical faces (their closest points are exact; a B-spline
    projection may stop at a local minimum): (distance, face, surface type, the point)."""
    import gmsh
    worst = (0.0, 0, "", (0.0, 0.0, 0.0))
    for _, f in gmsh.model.getEntities(2):
        kind = gmsh.model.getType(2, f)
        if kind not in ("Plane", "Cylinder"):
            continue
        for c in gmsh.model.getAdjacencies(2, f)[1]:
            lo, hi = gmsh.model.getParametrizationBounds(1, c)
            ts = [lo[0] + (hi[0] - lo[0]) * k / 4.0 for k in range(5)]
            pts = np.reshape(gmsh.model.getValue(1, c, ts), (-1, 3))
            closest, _ = gmsh.model.getClosestPoint(2, f, pts.reshape(-1).tolist())
            d = np.linalg.norm(pts - np.reshape(closest, (-1, 3)), axis=1)
            k = int(np.argmax(d))
            if d[k] > worst[0]:
                worst = (float(d[k]), f, kind, tuple(pts[k]))
    return worst


def cmd_read(args) -> dict:
    import gmsh

    md = designs_module()
    t0 = time.perf_counter()
    path = pathlib.Path(args.step)
    if not path.is_file():
        fail(f"{path}: no such file")
    md.gmsh_start()
    gmsh.option.setNumber("General.Verbosity", 1)
    # lengths in millimetres whatever unit the file declares (OpenCASCADE converts)
    gmsh.option.setNumber("Geometry.OCCScaling", 1.0)
    gmsh.option.setString("Geometry.OCCTargetUnit", "MM")
    try:
        entities = gmsh.model.occ.importShapes(str(path))
    except Exception as e:  # gmsh raises a bare Exception with its last error
        fail(f"{path}: cannot read this STEP file ({e}): the file is not valid STEP (a syntax error "
             "or a cut-off export); export the part again from CAD")
    gmsh.model.occ.synchronize()
    solids = [t for d, t in entities if d == 3]
    if not solids:
        dims = sorted({d for d, _ in entities})
        counts = {d: sum(1 for dd, _ in entities if dd == d) for d in dims}
        what = ", ".join(f"{n} {['points', 'curves', 'surfaces'][d]}" for d, n in counts.items()) or "nothing"
        fail(f"{path}: no closed solid in the file (it holds {what}): an open or unsewn shell has no "
             "volume; export the part as a solid")
    off, face, kind, where = faces_off_their_edges()
    size = max(gmsh.model.getBoundingBox(-1, -1)[3 + k] - gmsh.model.getBoundingBox(-1, -1)[k] for k in range(3))
    if off > FACE_EDGE_REL * size:
        fail(f"{path}: face {face} (a {kind.lower()}) lies {off:.3f} mm from its own edges near "
             f"({where[0]:.3f}, {where[1]:.3f}, {where[2]:.3f}) mm: the B-rep is inconsistent (a face moved "
             "off its edges, as a broken export or a hand edit leaves it), so its volume and bores "
             "cannot be trusted; repair the solid in CAD and export it again, or study its STL")
    fused = False
    if len(solids) > 1:
        out, _ = gmsh.model.occ.fuse([(3, solids[0])], [(3, t) for t in solids[1:]])
        gmsh.model.occ.synchronize()
        solids = [t for d, t in out if d == 3]
        fused = True
    occ = gmsh.model.occ
    per = []
    for t in solids:
        v = occ.getMass(3, t)
        if not v > 0.0:
            fail(f"{path}: solid {t} has volume {v}: the solid is invalid (inside out or degenerate)")
        per.append({"tag": t, "volume": v, "centroid": list(occ.getCenterOfMass(3, t)),
                    "inertia": np.asarray(occ.getMatrixOfInertia(3, t)).reshape(3, 3).tolist()})
    vol, c, inertia = combined_properties(per)
    if args.fine:
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 360)
    size = max(gmsh.model.getBoundingBox(-1, -1)[3 + k] - gmsh.model.getBoundingBox(-1, -1)[k] for k in range(3))
    # the designs' options are in mm: scale the absolute sizes with the part (a part in inches or
    # metres gets the same number of triangles as the same part in mm)
    scale = size / 300.0
    gmsh.option.setNumber("Mesh.MeshSizeMin", md.MESH_OPTIONS["Mesh.MeshSizeMin"] * scale)
    gmsh.option.setNumber("Mesh.MeshSizeMax", md.MESH_OPTIONS["Mesh.MeshSizeMax"] * scale)
    verts, tris = shells_outward(md, solids)
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".stl.tmp")
    tmp.write_bytes(md.stl_bytes(verts, tris, f"rodstudy: {path.name} through gmsh OCC"))
    tmp.replace(out)
    return {
        "step": str(path), "solids_in_file": len([t for d, t in entities if d == 3]),
        "volumes": len(solids), "fused": fused, "volume": vol, "centroid": c.tolist(),
        "inertia": inertia.tolist(), "per_volume": per, "stl": str(out), "triangles": int(len(tris)),
        "bounding_box": list(gmsh.model.getBoundingBox(-1, -1)),
        "gmsh_version": gmsh.option.getString("General.Version"),
        "seconds": time.perf_counter() - t0,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("read", help="exact mass properties and a surface triangulation of a STEP solid")
    r.add_argument("step")
    r.add_argument("out", help="the surface triangulation (binary STL, file units)")
    r.add_argument("--fine", action="store_true", help="360 instead of 150 elements per turn of curvature")
    args = ap.parse_args(argv)
    try:
        report = cmd_read(args)
    except Exception as e:  # gmsh's bare Exception, or a triangulation that is not closed
        fail(f"{args.step}: OpenCASCADE cannot make a solid of this file ({type(e).__name__}: {e}): the "
             "geometry is malformed; export the part again as STEP, or study its STL instead")
    print(json.dumps(report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
