#!/usr/bin/env python3
"""NAFEMS LE10 (thick plate under pressure) as a CalculiX/Abaqus input deck of C3D10 elements.

  nafems_le10.py OUT.inp [--size 0.15] [--size-d 0.05]

The benchmark (NAFEMS, "The Standard NAFEMS Benchmarks", TNSB Rev. 3, 1990, test LE10; the
geometry and supports as FeenoX/Fino publish them, seamplex/feenox examples/nafems-le10*.geo):
  * quarter of a thick elliptic plate with an elliptic hole, metres: inner ellipse
    x^2/2^2 + y^2/1^2 = 1, outer ellipse x^2/3.25^2 + y^2/2.75^2 = 1, z from -0.3 to 0.3
    (thickness 0.6); A = (0, 1), B = (0, 2.75), C = (3.25, 0), D = (2, 0) (primed: lower face);
  * E = 210e9 Pa, nu = 0.3; uniform pressure 1e6 Pa on the upper face z = 0.3 (*DLOAD Pk on the
    element faces there);
  * supports: face DCD'C' (y = 0) zero y-displacement, face ABA'B' (x = 0) zero x-displacement,
    face BCB'C' (the outer elliptic face) zero x and y, and the mid-plane line of that face
    (z = 0) zero z;
  * target: sigma_yy = -5.38e6 Pa at D = (2, 0, 0.3) (*NODE PRINT of the node set D).

Units in the deck: m, N, Pa. The volume is made of two halves (z < 0, z > 0) fragmented together
so that the mid-plane line is a mesh curve; quadratic tetrahedra with their midside nodes on the
geometry (curved, gmsh's default), size --size overall and --size-d at D. Deterministic: one
thread, fixed algorithm and seed. Node ids are 1..N in gmsh's order, element ids 1..M.

Prints one JSON line: path, nodes, elements, DOFs, the node id at D.
"""

from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys

import gmsh
import numpy as np

# gmsh's tet10 -> C3D10 (= VTK) node order: gmsh's node 8 is on edge 2-3, node 9 on edge 1-3
GMSH_TO_C3D10 = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8]
# C3D10 faces by corners (CalculiX manual, "C3D10": face 1 = 1-2-3, 2 = 1-4-2, 3 = 2-4-3, 4 = 3-4-1)
FACES = [(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)]
A_IN, B_IN, A_OUT, B_OUT, H = 2.0, 1.0, 3.25, 2.75, 0.6
E, NU, P = 210e9, 0.3, 1e6


def build(size: float, size_d: float):
    gmsh.initialize(["-noenv"])
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)
    gmsh.model.add("le10")
    occ = gmsh.model.occ
    vols = []
    for z0 in (-H / 2, 0.0):
        p = [occ.addPoint(0, B_IN, z0), occ.addPoint(0, B_OUT, z0),
             occ.addPoint(A_OUT, 0, z0), occ.addPoint(A_IN, 0, z0)]
        c0 = occ.addPoint(0, 0, z0)
        l1 = occ.addLine(p[0], p[1])
        outer = occ.addEllipseArc(p[2], c0, p[2], p[1])
        l3 = occ.addLine(p[2], p[3])
        inner = occ.addEllipseArc(p[3], c0, p[3], p[0])
        loop = occ.addCurveLoop([l1, -outer, l3, inner])
        s = occ.addPlaneSurface([loop])
        ext = occ.extrude([(2, s)], 0, 0, H / 2)
        vols += [t for d, t in ext if d == 3]
    occ.fragment([(3, vols[0])], [(3, vols[1])])
    occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MeshSizeMin", min(size, size_d) / 4)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    # finer near D = (2, 0, 0.3)
    f = gmsh.model.mesh.field
    d = f.add("MathEval")
    f.setString(d, "F", f"{size_d} + {size - size_d} * Min(1, Sqrt((x-2)^2 + y^2 + (z-0.3)^2) / 1.0)")
    f.setAsBackgroundMesh(d)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(2)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    xyz = xyz.reshape(-1, 3)
    order = np.argsort(tags)
    tags, xyz = tags[order], xyz[order]
    index = {int(t): i for i, t in enumerate(tags)}
    tets = []
    for etype, _, conn in zip(*gmsh.model.mesh.getElements(3)):
        if etype != 11:
            raise SystemExit(f"unexpected element type {etype}")
        for row in conn.reshape(-1, 10):
            tets.append([index[int(row[k])] for k in GMSH_TO_C3D10])
    gmsh.finalize()
    tets = np.array(tets, dtype=np.int64)
    used = np.unique(tets)
    new = np.full(len(xyz), -1, dtype=np.int64)
    new[used] = np.arange(len(used))
    return xyz[used], new[tets]


def ids(nodes):
    s = [str(n + 1) for n in nodes]
    return [", ".join(s[i:i + 12]) for i in range(0, len(s), 12)]


def write(path: pathlib.Path, xyz, tets):
    x, y, z = xyz.T
    tol = 1e-7
    outer = np.abs((x / A_OUT) ** 2 + (y / B_OUT) ** 2 - 1.0) < 1e-6
    sets = {
        "YSYM": np.nonzero(np.abs(y) < tol)[0],
        "XSYM": np.nonzero(np.abs(x) < tol)[0],
        "OUTER": np.nonzero(outer)[0],
        "MIDLINE": np.nonzero(outer & (np.abs(z) < tol))[0],
    }
    d = np.nonzero((np.abs(x - A_IN) < tol) & (np.abs(y) < tol) & (np.abs(z - H / 2) < tol))[0]
    if len(d) != 1:
        raise SystemExit(f"point D: {len(d)} nodes")
    out = ["*HEADING", "NAFEMS LE10 thick plate under pressure (m, N, Pa), rodstudy pipeline/nafems_le10.py",
           "*NODE"]
    out += [f"{i + 1}, {a:.13g}, {b:.13g}, {c:.13g}" for i, (a, b, c) in enumerate(xyz.tolist())]
    out.append("*ELEMENT, TYPE=C3D10, ELSET=EALL")
    out += [f"{e + 1}, " + ", ".join(str(v + 1) for v in row) for e, row in enumerate(tets.tolist())]
    for name, nodes in sets.items():
        out.append(f"*NSET, NSET={name}")
        out += ids(nodes)
    out += ["*NSET, NSET=D", str(d[0] + 1)]
    out += ["*MATERIAL, NAME=STEEL", "*ELASTIC", f"{E:.13g}, {NU:.13g}",
            "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL",
            "*BOUNDARY", "YSYM, 2, 2", "XSYM, 1, 1", "OUTER, 1, 2", "MIDLINE, 3, 3",
            "*STEP", "*STATIC", "*DLOAD"]
    top = np.abs(z - H / 2) < tol
    loaded = 0
    for e, row in enumerate(tets):
        for k, f in enumerate(FACES):
            if all(top[row[c]] for c in f):
                out.append(f"{e + 1}, P{k + 1}, {P:.13g}")
                loaded += 1
    out += ["*NODE PRINT, NSET=D", "U, S, RF", "*NODE FILE", "U", "*EL FILE", "S", "*END STEP"]
    path.write_text("\n".join(out) + "\n")
    return int(d[0] + 1), loaded, {k: len(v) for k, v in sets.items()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", help="the .inp deck to write")
    ap.add_argument("--size", type=float, default=0.15, help="element size away from D, m")
    ap.add_argument("--size-d", type=float, default=0.05, help="element size at D, m")
    args = ap.parse_args(argv)
    xyz, tets = build(args.size, args.size_d)
    path = pathlib.Path(args.out)
    path.parent.mkdir(parents=True, exist_ok=True)
    node_d, loaded, sets = write(path, xyz, tets)
    print(json.dumps({"path": str(path), "nodes": len(xyz), "elements": len(tets), "dofs": 3 * len(xyz),
                      "node_d": node_d, "loaded_faces": loaded, "sets": sets,
                      "size": args.size, "size_d": args.size_d}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
