#!/usr/bin/env python3
"""Independent peer of rodstudy's pin-bore contact: the same rod, pins and mesh solved by CalculiX.

  ccx_contact_peer.py MESH.rodmesh [--force 20000] [--clearance-a 0.01] [--clearance-b 0.01]
                      [--slope K] [--pin-facets N] [--pin-layers 4] [--band 3] [--judged FILE]
                      [--json] [--workdir DIR [--reuse]] [--ccx ccx]

Reads the mesh rodstudy solved (the .rodmesh hand-off file, VTK tetra10 order = CalculiX's C3D10
order) and builds the contact model independently, with numpy (units mm, N, MPa):
  * bore walls around the pin axes through A = (0, 0, 0) and B = (180, 0, 0) mm (--bore-a,
    --bore-b), axis z, by the rule of ccx_peer.py (boundary faces whose normal points at the axis
    within 30 degrees, all corners on the innermost radius within 1 %): the slave surfaces,
    element faces of the C3D10;
  * each pin a tube of 20-node bricks (C3D20, every node on its circle) whose outer faces are the
    master surface: radius r - c (r the bore radius found, c the radial clearance; c < 0 an
    interference), one brick per node pitch of the wall around (--pin-facets), 4 along the axis
    (--pin-layers), reaching 1 mm past the wall at both ends (--pin-overhang). The pins are rigid:
    pin B's nodes fixed; pin A's nodes translate along x as one (*EQUATION on every node's x to
    its first node, which carries the force F along +x as *CLOAD), y and z fixed. With
    --elastic-pins ends|core the pins are steel and only their end faces or their inner surface
    are held so (the pin's wall: --pin-inner, --pin-radial);
  * frictionless face-to-face penalty contact (*CONTACT PAIR, TYPE=SURFACE TO SURFACE, no
    *FRICTION), PRESSURE-OVERCLOSURE=LINEAR with slope K (N/mm^3, default 100 E / h, h the mean
    edge of the walls) and no tension;
  * the motions frictionless contact leaves free: the rod's sliding along z held at one rod node
    (no load along z: no reaction); the rod's rotation about pin B by pin A's y being fixed (a
    rigid rotation of the rod about B is then the whole difference to rodstudy's support on the
    body; pin A's reaction along y is printed and must be ~0);
  * steel E = 210 GPa, nu = 0.3.
ccx (SPOOLES, OMP_NUM_THREADS=2 unless set) solves one *STATIC step; contact makes it nonlinear
and ccx iterates to its default criteria. Read back: nodal stresses from the
.frd (integration-point values extrapolated to the nodes and averaged; von Mises of the averaged
tensor), the nodal contact pressure CPRESS (.frd), the pressure at every active slave
integration point and each pair's contact area, normal and shear force (.dat, *CONTACT PRINT
CSTR and CF). Printed: the peak von Mises away from both bores (nodes farther than BAND mm from
both walls; with --judged FILE, a 0/1 per node, also over those nodes), per bore the peak nodal,
smoothed (as rodstudy smooths its own) and integration-point contact pressure, the resultant of
the nodal pressure, the contact arc (360 degrees - the largest angular gap
between wall nodes with CPRESS > 0), the element at each end of the arc (the angular span of the
outermost wall face with an integration point in contact: the arc ends inside it), the contact area and forces, an element's angular size, the pins'
reactions and pin A's travel.

ccx measures the gap between the quadratic wall faces and the pin: the walls must be curved
(midside nodes on the circle) and fine enough that a face is within a few nm of the circle
(3.75 degree elements on a 25 mm bore), else the contact gathers on the faces' high points.
Node-to-surface contact and *CLEARANCE were tried and are not usable here (docs/contact.md,
"Against CalculiX", measured 2026-11-29).

With --reuse the results already in --workdir are read instead of running ccx.

Exit status 0; 2 if ccx is missing; 1 if ccx fails.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import shutil
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from ccx_peer import FACES, TRI_PTS, TRI_W, face_geometry, read_rodmesh, run_ccx, von_mises  # noqa: E402

E_MPA, NU = 210000.0, 0.3
# ccx's C3D10 face numbers of the FACES table (S1 = 1-2-3, S2 = 1-4-2, S3 = 2-4-3, S4 = 3-4-1)
TET_FACE_ID = [1, 2, 3, 4]


def boundary_faces_with_elements(tets: np.ndarray):
    """Boundary faces (6-node, outward) with their element and ccx face number."""
    faces = np.concatenate([tets[:, list(f)] for f in FACES])
    elem = np.concatenate([np.arange(len(tets))] * len(FACES))
    side = np.repeat(TET_FACE_ID, len(tets))
    keys = np.sort(faces[:, :3], axis=1)
    _, inv, cnt = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    if cnt.max() > 2:
        raise SystemExit("non-manifold mesh")
    one = cnt[inv.ravel()] == 1
    return faces[one], elem[one], side[one]


def bore_faces(pts, faces, centre, name):
    """The wall faces of the bore around the z axis through `centre` (ccx_peer.py's rule)."""
    c = np.asarray(centre, float)

    def radial(p):
        v = p - c
        v[..., 2] = 0.0
        return v

    x = pts[faces[:, :3]]
    pc = x.mean(axis=1)
    nrm = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    rv = radial(pc)
    rc = np.linalg.norm(rv, axis=1)
    ok = rc > 0
    cand = ok & (np.einsum("fk,fk->f", nrm, rv) / np.where(ok, rc, 1) <= -np.cos(np.radians(30)))
    if not cand.any():
        raise SystemExit(f"{name}: no boundary face faces the pin axis")
    radii = np.linalg.norm(radial(pts[faces[:, :3].reshape(-1)]), axis=1).reshape(-1, 3)
    r = radii[cand].max(axis=1).min()
    sel = cand & np.all((radii >= 0.99 * r) & (radii <= 1.01 * r), axis=1)
    return sel, r


# C3D20 corner and midside nodes in (xi, eta, zeta), ccx's order
BRICK20 = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1),
           (0, -1, -1), (1, 0, -1), (0, 1, -1), (-1, 0, -1), (0, -1, 1), (1, 0, 1), (0, 1, 1), (-1, 0, 1),
           (-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]


def pin_mesh(centre, rho, z0, z1, n_theta, nz, first_node, inner=0.8, n_radial=1):
    """The pin of a bore: a tube of 20-node bricks (C3D20) of outer radius rho, inner `inner` rho,
    n_theta around, n_radial through the wall, nz along the axis from z0 to z1, every node on its
    circle, so that the outer
    faces (face S4 of each brick, the master surface) are quadratic arcs: 0.9 nm off the cylinder
    at rho = 25 mm and 3.75 degree bricks (computed), where flat facets of that size would be off
    by their sagitta, 13 um.
    Returns (nodes (n, 3), bricks (m, 20) global 0-based ids, the outer bricks' indices, the
    global ids of the nodes where an elastic pin is held: {"ends": on the end faces z0 and z1,
    "core": on the inner surface}); the first node is on both."""
    ids, nodes, bricks = {}, [], []

    def node(i2, j2, k2):  # on the doubled grid: around, radius (0 .. 2 n_radial), along the axis
        key = (i2 % (2 * n_theta), j2, k2)
        if key not in ids:
            t = np.pi * key[0] / n_theta
            rr = rho * (inner + (1.0 - inner) * j2 / (2 * n_radial))
            ids[key] = first_node + len(nodes)
            nodes.append([centre[0] + rr * np.cos(t), centre[1] + rr * np.sin(t), z0 + (z1 - z0) * k2 / (2 * nz)])
        return ids[key]

    for k in range(nz):
        for j in range(n_radial):
            for i in range(n_theta):
                # (xi, eta, zeta) = (radial, around, axial), right-handed: the outer face xi = +1
                # is S4
                bricks.append([node(2 * i + 1 + e, 2 * j + 1 + x, 2 * k + 1 + z) for x, e, z in BRICK20])
    outer = [b for b in range(len(bricks)) if (b // n_theta) % n_radial == n_radial - 1]
    held = {"ends": sorted(v for key, v in ids.items() if key[2] in (0, 2 * nz)),
            "core": sorted(v for key, v in ids.items() if key[1] == 0)}
    return np.array(nodes), np.array(bricks, dtype=np.int64), outer, held


def lines_of(ids, per=12):
    s = [str(i) for i in ids]
    return [", ".join(s[i:i + per]) for i in range(0, len(s), per)]


def write_deck(path, pts, tets, walls, pins, force, slope, rod_z_node, hold=None):
    """walls: [(elements, sides)] per bore; pins: [(nodes, bricks, outer bricks, held nodes)]
    (A first). Rigid pins (hold None): pin B's nodes fixed, pin A's nodes tied along x to its
    first node, which carries the force, y and z fixed. Elastic pins: the same on the held nodes
    only (hold "ends": the pins' two end faces, a pin held at its ends as in a piston's bosses or
    a crank's webs; "core": the inner surface, a pin with a rigid core), the rest deforms."""
    n_rod = len(pts)
    out = ["*HEADING", "rodstudy CalculiX contact peer (mm, N, MPa)", "*NODE"]
    allpts = np.concatenate([pts] + [p[0] for p in pins])
    out += [f"{i + 1}, {x:.13g}, {y:.13g}, {z:.13g}" for i, (x, y, z) in enumerate(allpts.tolist())]
    out.append("*ELEMENT, TYPE=C3D10, ELSET=ROD")
    out += [f"{e + 1}, " + ", ".join(str(v + 1) for v in row) for e, row in enumerate(tets.tolist())]
    first = len(tets)
    for k, (nodes, bricks, _, _) in enumerate(pins):
        out.append(f"*ELEMENT, TYPE=C3D20, ELSET=PIN{k}")
        for e, row in enumerate(bricks.tolist()):
            # at most 16 entries a line, a trailing comma continues it
            out.append(f"{first + e + 1}, " + ", ".join(str(v + 1) for v in row[:15]) + ",")
            out.append(", ".join(str(v + 1) for v in row[15:]))
        first += len(bricks)
    starts = [n_rod]
    for nodes, _, _, _ in pins:
        starts.append(starts[-1] + len(nodes))
    held = [[v + 1 for v in sets[hold]] if hold else list(range(starts[k] + 1, starts[k + 1] + 1))
            for k, (_, _, _, sets) in enumerate(pins)]
    for k in range(len(pins)):
        out.append(f"*NSET, NSET=NPIN{k}")
        out += lines_of(held[k])
    out.append("*NSET, NSET=NPINAREF")
    out.append(str(starts[0] + 1))
    first = len(tets)
    for k, ((elems, sides), (nodes, bricks, outer, _)) in enumerate(zip(walls, pins)):
        out.append(f"*SURFACE, NAME=WALL{k}, TYPE=ELEMENT")
        out += [f"{e + 1}, S{s}" for e, s in zip(elems.tolist(), sides.tolist())]
        out.append(f"*SURFACE, NAME=PIN{k}, TYPE=ELEMENT")
        out += [f"{first + e + 1}, S4" for e in outer]
        first += len(bricks)
    out += ["*MATERIAL, NAME=STEEL", "*ELASTIC", f"{E_MPA:.13g}, {NU:.13g}",
            "*SOLID SECTION, ELSET=ROD, MATERIAL=STEEL"]
    for k in range(len(pins)):
        out.append(f"*SOLID SECTION, ELSET=PIN{k}, MATERIAL=STEEL")
    out += ["*SURFACE INTERACTION, NAME=FRICTIONLESS",
            "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR", f"{slope:.13g}, 0.0"]
    for k in range(len(pins)):
        out += ["*CONTACT PAIR, INTERACTION=FRICTIONLESS, TYPE=SURFACE TO SURFACE",
                f"WALL{k}, PIN{k}"]
    # pin A: every held node's x equal to its first node's
    out.append("*EQUATION")
    for n in held[0][1:]:
        out += ["2", f"{n}, 1, 1.0, {starts[0] + 1}, 1, -1.0"]
    out += ["*BOUNDARY", "NPIN0, 2, 3", "NPIN1, 1, 3", f"{rod_z_node + 1}, 3, 3",
            "*STEP", "*STATIC", "1.0, 1.0",
            "*CLOAD", f"{starts[0] + 1}, 1, {force:.13g}",
            "*NODE FILE", "U", "*EL FILE", "S", "*CONTACT FILE", "CSTR",
            "*CONTACT PRINT", "CSTR, CDIS",
            "*CONTACT PRINT, SLAVE=WALL0, MASTER=PIN0", "CF",
            "*CONTACT PRINT, SLAVE=WALL1, MASTER=PIN1", "CF",
            "*NODE PRINT, NSET=NPIN0, TOTALS=ONLY", "RF",
            "*NODE PRINT, NSET=NPIN1, TOTALS=ONLY", "RF",
            "*END STEP"]
    path.write_text("\n".join(out) + "\n")


def read_frd_blocks(path: pathlib.Path):
    """The last value of each nodal block (DISP, STRESS, CONTACT, ...) of an ASCII .frd:
    name -> {node: [values]}."""
    blocks, name, cur = {}, None, None
    for line in path.read_text().splitlines():
        if line.startswith(" -4"):
            name = line.split()[1]
            cur = {}
        elif line.startswith(" -1") and cur is not None:
            node = int(line[3:13])
            rest = line[13:]
            cur[node] = [float(rest[12 * i:12 * i + 12]) for i in range(len(rest) // 12)]
        elif line.startswith(" -3") and cur is not None:
            blocks[name] = cur
            name, cur = None, None
    return blocks


def read_totals(path: pathlib.Path):
    """The 'total force' lines of a .dat, in order: [(set, [fx, fy, fz])]."""
    out, current = [], None
    for line in path.read_text().splitlines():
        t = line.strip()
        if t.startswith("total force"):
            w = t.split()
            current = w[w.index("set") + 1]
        elif current and t:
            v = [float(x) for x in t.split()[:3]]
            out.append((current, v))
            current = None
    return out


def read_contact_statistics(path: pathlib.Path):
    """Per contact pair of a .dat (*CONTACT PRINT CF): the slave surface's contact area (mm^2),
    normal force (N, + = tension) and shear force (N), in the pairs' order."""
    lines = path.read_text().splitlines()
    out = []
    for i, line in enumerate(lines):
        if line.strip().startswith("area,  normal force"):
            v = [float(x) for x in lines[i + 2].split()[:3]]
            out.append({"area_mm2": v[0], "normal_force_n": v[1], "shear_force_n": v[2]})
    return out


def read_integration_point_pressures(path: pathlib.Path):
    """The contact pressure at every active slave integration point of a .dat (*CONTACT PRINT
    CSTR): (element, face) -> [pressure, MPa]."""
    out, inside = {}, False
    for line in path.read_text().splitlines():
        if line.strip().startswith("contact stress"):
            inside = True
            continue
        if inside:
            w = line.split()
            if len(w) == 5:
                out.setdefault((int(w[0]), int(w[1])), []).append(float(w[2]))
            elif out:
                break
    return out


def smoothed_pressure(pts, wall, centre, nodal):
    """rodstudy's smoothed pressure of a nodal pressure field (`CylinderContact::
    smoothed_pressure_pa`): each face's mean pressure (p interpolated by the 6-node shape
    functions, 6-point rule), at each node the area-weighted mean of the face means around it.
    Also the resultant of the pressure on the body, sum of p e_r dA (N). `nodal`: node -> MPa."""
    p = np.array([[nodal.get(int(v), 0.0) for v in f] for f in wall])
    area = np.zeros(len(wall))
    force = np.zeros(len(wall))
    resultant = np.zeros(3)
    for st, w in zip(TRI_PTS, TRI_W):
        x, c, n = face_geometry(pts, wall, st)
        da = w * np.linalg.norm(c, axis=1)
        pq = p @ n
        area += da
        force += da * pq
        er = x - centre
        er[:, 2] = 0.0
        er /= np.linalg.norm(er, axis=1)[:, None]
        resultant += ((da * pq)[:, None] * er).sum(axis=0)
    mean = force / area
    num, den = {}, {}
    for f, m, a in zip(wall, mean, area):
        for v in set(int(x) for x in f):
            num[v] = num.get(v, 0.0) + m * a
            den[v] = den.get(v, 0.0) + a
    return {v: num[v] / den[v] for v in num}, resultant


def arc(angles_deg: np.ndarray):
    """Angular extent of a set of angles (360 - the largest gap between neighbours), and the
    ends (first, last) going round from the gap."""
    if len(angles_deg) == 0:
        return 0.0, (0.0, 0.0)
    a = np.sort(np.mod(angles_deg, 360.0))
    gaps = np.diff(np.concatenate([a, [a[0] + 360.0]]))
    i = int(np.argmax(gaps))
    lo, hi = a[(i + 1) % len(a)], a[i]
    ends = (float((lo + 180.0) % 360.0 - 180.0), float((hi + 180.0) % 360.0 - 180.0))
    return 360.0 - gaps[i], ends


def arc_end_elements(wall, keys, ip, pts, centre, direction_deg):
    """The angular span (degrees from `direction_deg`) of the outermost wall face on each side
    of the arc (negative, positive) with an integration point in contact: ccx's arc ends inside
    these faces. `wall`: the faces' node lists; `keys`: their (element, face) in ccx's numbering;
    `ip`: (element, face) -> integration-point pressures."""
    spans = []
    for f, key in zip(wall, keys):
        if max(ip.get(key, [0.0])) <= 0.0:
            continue
        c = pts[f[:3]]
        th = np.degrees(np.arctan2(c[:, 1] - centre[1], c[:, 0] - centre[0]))
        th = (th - direction_deg + 180.0) % 360.0 - 180.0
        spans.append((float(th.min()), float(th.max())))
    if not spans:
        return None
    return [list(min(spans)), list(max(spans, key=lambda s: s[1]))]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mesh", help=".rodmesh file (the mesh rodstudy solved)")
    ap.add_argument("--force", type=float, default=20000.0, help="pin A's force along +x, N (default 20000)")
    ap.add_argument("--clearance-a", type=float, default=0.01, help="radial clearance of pin A, mm (default 0.01)")
    ap.add_argument("--clearance-b", type=float, default=0.01, help="radial clearance of pin B, mm (default 0.01)")
    ap.add_argument("--slope", type=float, help="penalty slope K, N/mm^3 (default 100 E / h)")
    ap.add_argument("--pin-facets", type=int,
                    help="the pin's facets around (default: one per node pitch of the wall)")
    ap.add_argument("--pin-layers", type=int, default=4, help="the pin's bricks along its axis (default 4)")
    ap.add_argument("--elastic-pins", choices=["ends", "core"],
                    help="steel pins held only at their end faces (ends) or their inner surface (core) "
                         "instead of rigid pins")
    ap.add_argument("--pin-inner", type=float, default=0.8,
                    help="the pin's inner radius over its outer radius (default 0.8; a hollow piston pin 0.5-0.6)")
    ap.add_argument("--pin-radial", type=int, default=1, help="the pin's bricks through its wall (default 1)")
    ap.add_argument("--pin-overhang", type=float, default=1.0,
                    help="how far the pin reaches beyond the bore's faces on each side, mm (default 1)")
    ap.add_argument("--band", type=float, default=3.0,
                    help="nodes within this distance of a bore wall (mm) are left out of the peak von Mises")
    ap.add_argument("--judged", help="a 0/1 per node: the nodes of a second peak von Mises")
    ap.add_argument("--bore-a", type=float, nargs=3, default=[0.0, 0.0, 0.0], help="a point on pin A's axis, mm")
    ap.add_argument("--bore-b", type=float, nargs=3, default=[180.0, 0.0, 0.0], help="a point on pin B's axis, mm")
    ap.add_argument("--workdir", help="keep the deck and results here (default: a temporary folder)")
    ap.add_argument("--ccx", default="ccx")
    ap.add_argument("--reuse", action="store_true", help="read the results in --workdir instead of running ccx")
    ap.add_argument("--json", action="store_true", help="print the figures as one JSON line")
    args = ap.parse_args(argv)
    ccx = shutil.which(args.ccx)
    if not ccx:
        print(f"ccx_contact_peer: CalculiX '{args.ccx}' not found (Debian: apt-get install calculix-ccx)",
              file=sys.stderr)
        return 2
    pts, tets = read_rodmesh(pathlib.Path(args.mesh))
    faces, felem, fside = boundary_faces_with_elements(tets)
    centres = [np.array(args.bore_a), np.array(args.bore_b)]
    walls, pins, info = [], [], []
    node0 = len(pts)
    for k, (centre, clearance, name) in enumerate(zip(centres, (args.clearance_a, args.clearance_b), "AB")):
        sel, r = bore_faces(pts, faces, centre, f"bore {name}")
        wf = faces[sel]
        nodes = np.unique(wf)
        z = pts[nodes, 2]
        corners = wf[:, :3]
        edges = np.concatenate([corners[:, [0, 1]], corners[:, [1, 2]], corners[:, [2, 0]]])
        h = np.linalg.norm(pts[edges[:, 0]] - pts[edges[:, 1]], axis=1).mean()
        th = np.degrees(np.arctan2(pts[nodes, 1] - centre[1], pts[nodes, 0] - centre[0]))
        # an element's angular size: the mean over the wall faces of their corners' angular span
        tc = np.arctan2(pts[corners, 1] - centre[1], pts[corners, 0] - centre[0])
        element_deg = float(np.degrees(np.ptp(np.unwrap(tc, axis=1), axis=1).mean()))
        # facets per node pitch (half an element) around
        n_theta = args.pin_facets if args.pin_facets else int(round(2 * 360.0 / element_deg))
        pn, pb, outer, held = pin_mesh(centre, r - clearance, z.min() - args.pin_overhang,
                                       z.max() + args.pin_overhang, n_theta, args.pin_layers, node0,
                                       inner=args.pin_inner, n_radial=args.pin_radial)
        node0 += len(pn)
        walls.append((felem[sel], fside[sel]))
        pins.append((pn, pb, outer, held))
        info.append({"radius_mm": float(r), "faces": int(sel.sum()), "nodes": nodes, "theta": th, "wall": wf,
                     "edge_mm": float(h), "element_deg": element_deg, "pin_facets": n_theta})
    h_wall = np.mean([i["edge_mm"] for i in info])
    slope = args.slope if args.slope else 100.0 * E_MPA / h_wall
    centre_rod = 0.5 * (centres[0] + centres[1])
    centre_rod[2] = pts[:, 2].mean()
    rod_z_node = int(np.argmin(np.linalg.norm(pts - centre_rod, axis=1)))
    work = pathlib.Path(args.workdir) if args.workdir else pathlib.Path(tempfile.mkdtemp(prefix="ccx_contact_"))
    work.mkdir(parents=True, exist_ok=True)
    frd = work / "rod.frd"
    reuse = args.reuse and frd.exists()
    if not reuse:
        write_deck(work / "rod.inp", pts, tets, walls, pins, args.force, slope, rod_z_node,
                   hold=args.elastic_pins)
    env = dict(os.environ)
    env.setdefault("OMP_NUM_THREADS", "2")
    env.setdefault("CCX_NPROC_EQUATION_SOLVER", env["OMP_NUM_THREADS"])
    t0 = time.perf_counter()
    if not reuse:
        run = run_ccx(ccx, work, env)
        if run is None:
            return 1
        if run.returncode != 0 or not frd.exists() or "Job finished" not in run.stdout:
            print(run.stdout[-3000:], run.stderr[-3000:], file=sys.stderr)
            return 1
    wall = time.perf_counter() - t0
    blocks = read_frd_blocks(frd)
    n = len(pts)
    stress = np.zeros((n, 6))
    for node, v in blocks["STRESS"].items():
        if node <= n:
            stress[node - 1] = v[:6]
    vm = von_mises(stress)
    # nodes within `band` of a bore wall: radial distance from the axis < r + band
    away = np.ones(n, bool)
    for centre, i in zip(centres, info):
        d = np.hypot(pts[:, 0] - centre[0], pts[:, 1] - centre[1])
        away &= d > i["radius_mm"] + args.band
    figures = {"ccx_wall_s": wall, "nodes": n, "elements": len(tets), "force_n": args.force,
               "slope_n_per_mm3": slope, "band_mm": args.band}
    i_away = int(np.argmax(np.where(away, vm, -1.0)))
    figures["peak_von_mises_away_mpa"] = float(vm[i_away])
    figures["peak_von_mises_away_at_mm"] = pts[i_away].tolist()
    if args.judged:
        judged = np.array([int(v) for v in pathlib.Path(args.judged).read_text().split()], bool)
        if len(judged) != n:
            raise SystemExit(f"{args.judged}: {len(judged)} flags for {n} nodes")
        i_j = int(np.argmax(np.where(judged, vm, -1.0)))
        figures["peak_von_mises_judged_mpa"] = float(vm[i_j])
        figures["peak_von_mises_judged_at_mm"] = pts[i_j].tolist()
    contact = blocks.get("CONTACT", {})
    totals = read_totals(work / "rod.dat") if (work / "rod.dat").exists() else []
    reactions = {s: v for s, v in totals}
    stats = read_contact_statistics(work / "rod.dat")
    ip = read_integration_point_pressures(work / "rod.dat")
    figures["pin_a_reaction_n"] = reactions.get("NPIN0")
    figures["pin_a_displacement_mm"] = blocks["DISP"][n + 1][:3]
    figures["pin_b_reaction_n"] = reactions.get("NPIN1")
    wall_faces = [{(int(e) + 1, int(f)): True for e, f in zip(*w)} for w in walls]
    for k, (name, centre, i) in enumerate(zip("ab", centres, info)):
        nodes = i["nodes"]
        cp = np.array([contact.get(int(v) + 1, [0.0] * 4)[3] for v in nodes])
        copen = np.array([contact.get(int(v) + 1, [0.0] * 4)[0] for v in nodes])
        active = cp > 0
        direction = np.degrees(np.arctan2(0.0, 1.0 if name == "a" else -1.0))
        ang = (i["theta"] - direction + 180.0) % 360.0 - 180.0
        extent, ends = arc(ang[active])
        keys = [(int(e) + 1, int(f)) for e, f in zip(*walls[k])]
        end_elements = arc_end_elements(i["wall"], keys, ip, pts, centre, direction)
        smooth, resultant = smoothed_pressure(pts, i["wall"], centre, {int(v): q for v, q in zip(nodes, cp)})
        sp = np.array([smooth[int(v)] for v in nodes])
        figures[f"bore_{name}"] = {
            "radius_mm": i["radius_mm"], "wall_faces": i["faces"], "wall_nodes": int(len(nodes)),
            "edge_mm": i["edge_mm"], "element_deg": i["element_deg"],
            "peak_pressure_mpa": float(cp.max()), "peak_angle_deg": float(ang[int(np.argmax(cp))]),
            "peak_smoothed_pressure_mpa": float(sp.max()),
            "peak_smoothed_angle_deg": float(ang[int(np.argmax(sp))]),
            "cpress_resultant_n": resultant.tolist(),
            "active_nodes": int(active.sum()), "arc_deg": float(extent), "arc_ends_deg": list(ends),
            "arc_end_elements_deg": end_elements,
            "max_penetration_mm": float(max(0.0, -copen[active].min()) if active.any() else 0.0),
            "contact_area_mm2": stats[k]["area_mm2"] if k < len(stats) else None,
            "normal_force_n": stats[k]["normal_force_n"] if k < len(stats) else None,
            "shear_force_n": stats[k]["shear_force_n"] if k < len(stats) else None,
            "peak_integration_point_pressure_mpa": max(
                (max(v) for (e, f), v in ip.items() if wall_faces[k].get((e, f))), default=0.0),
            "pressure_mpa": cp.tolist(), "angle_deg": ang.tolist(), "node_ids": nodes.tolist(),
        }
    figures["converged"] = True
    if args.json:
        print(json.dumps(figures))
    else:
        print(f"mesh {args.mesh}: {n} nodes, {len(tets)} C3D10; F = {args.force} N; slope {slope:.4g} N/mm^3; "
              f"ccx {wall:.2f} s")
        print(f"peak von Mises {figures['peak_von_mises_away_mpa']:.4f} MPa at {figures['peak_von_mises_away_at_mm']} "
              f"(more than {args.band} mm from the bores)")
        for name in "ab":
            b = figures[f"bore_{name}"]
            print(f"bore {name.upper()}: r {b['radius_mm']:.3f} mm, {b['wall_nodes']} wall nodes, element "
                  f"{b['element_deg']:.2f} deg; peak pressure {b['peak_pressure_mpa']:.4f} MPa at "
                  f"{b['peak_angle_deg']:.1f} deg (smoothed {b['peak_smoothed_pressure_mpa']:.4f} MPa; CPRESS resultant "
                  f"{np.round(b['cpress_resultant_n'], 1).tolist()} N), arc {b['arc_deg']:.2f} deg {b['arc_ends_deg']}, "
                  f"penetration {b['max_penetration_mm']:.2e} mm; integration points: peak {b['peak_integration_point_pressure_mpa']:.4f} MPa, "
                  f"contact area {b['contact_area_mm2']} mm^2, normal force {b['normal_force_n']} N, shear force {b['shear_force_n']} N")
        print(f"reactions: pin A {figures['pin_a_reaction_n']}, pin B {figures['pin_b_reaction_n']}")
    if not args.workdir:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
