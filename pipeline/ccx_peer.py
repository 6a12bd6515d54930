#!/usr/bin/env python3
"""Independent peer of rodstudy's FEM stage: the same rod model solved by CalculiX (ccx).

  ccx_peer.py MESH.rodmesh [--force 7500] [--ours RESULT.json] [--workdir DIR] [--ccx ccx]
  ccx_peer.py MESH.rodmesh --buckle [--force 7500] [--json]

Reads the very mesh the Rust solver used (the .rodmesh hand-off file, VTK tetra10 order, which is
also CalculiX's C3D10 order), and builds the same model independently, with numpy:
  * boundary faces from the tets (faces used by one tet), outward 6-node triangles;
  * bore walls around the pin axes through A = (0, 0, 0) and B = (180, 0, 0) mm, axis z (same rule:
    faces whose normal points at the axis within 30 degrees, all corners on the innermost radius
    within 1 %);
  * B fixed (all DOFs of every node of its faces), A loaded by a uniform traction with resultant F
    along +x (step 1) and along +y (step 2), as consistent nodal forces (*CLOAD) of the 6-node faces
    (6-point degree-4 triangle rule);
  * steel E = 210 GPa, nu = 0.3; units mm, N, MPa.
Runs ccx (SPOOLES, OMP_NUM_THREADS=2 unless set), reads the nodal stresses from the .frd (ccx
extrapolates the integration-point stresses to the nodes and averages them over the elements),
computes von Mises of the averaged tensors and prints its maxima, max displacement and wall time.
With --ours (the JSON of rodstudy's FemResult for the same mesh) it prints ours beside them.

With --buckle: linear buckling instead (CalculiX *BUCKLE, one buckling factor, accuracy 1e-8)
of the F_x case alone: the same supports, the same consistent nodal forces of the resultant F
along +x (A towards the fixed B: compression) as *CLOAD; prints the factor read from the .dat
("B U C K L I N G   F A C T O R   O U T P U T"); the buckling load is factor × F.

Exit status 0; a missing ccx is reported (exit 2).
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

EDGES = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)]
# faces as 6-node triangles, outward for positively oriented tets (same table as the Rust side)
FACES = [(0, 2, 1, 6, 5, 4), (0, 1, 3, 4, 8, 7), (1, 2, 3, 5, 9, 8), (0, 3, 2, 7, 9, 6)]
TA, TWA, TB, TWB = 0.44594849091596445, 0.1116907948390049, 0.0915762135097719, 0.05497587182766178
TRI_PTS = np.array([[TA, TA], [1 - 2 * TA, TA], [TA, 1 - 2 * TA], [TB, TB], [1 - 2 * TB, TB], [TB, 1 - 2 * TB]])
TRI_W = np.array([TWA] * 3 + [TWB] * 3)


def ccx_time_limit() -> float:
    """The time limit of one ccx run, s: the pipeline's (RODSTUDY_MESHER_TIMEOUT_S, default 600),
    a little less, so that ccx is stopped here with a message before the caller stops this script."""
    try:
        limit = float(os.environ.get("RODSTUDY_MESHER_TIMEOUT_S", "600"))
    except ValueError:
        limit = 600.0
    if not (limit > 0 and limit < float("inf")):
        limit = 600.0
    return limit - max(3.0, 0.05 * limit)


def run_ccx(ccx: str, work: pathlib.Path, env: dict):
    """`ccx -i rod` in `work` under the time limit; None (with a message) when it ran out."""
    limit = ccx_time_limit()
    try:
        return subprocess.run([ccx, "-i", "rod"], cwd=work, env=env, capture_output=True, text=True,
                              timeout=limit)
    except subprocess.TimeoutExpired:
        print(f"ccx stopped after {limit:.0f} s (the limit; set RODSTUDY_MESHER_TIMEOUT_S to change it)",
              file=sys.stderr)
        return None


def read_rodmesh(path: pathlib.Path):
    lines = [l.strip() for l in path.read_text().splitlines() if l.strip() and not l.startswith("#")]
    assert lines[0] == "rodmesh 1", "not a .rodmesh file"
    units = lines[1].split()[1]
    n = int(lines[2].split()[1])
    pts = np.array([[float(v) for v in l.split()] for l in lines[3:3 + n]])
    m = int(lines[3 + n].split()[1])
    tets = np.array([[int(v) for v in l.split()] for l in lines[4 + n:4 + n + m]], dtype=np.int64)
    if units == "m":
        pts = pts * 1e3
    return pts, tets


def tri6(st):
    s, t = st
    m = np.array([1 - s - t, s, t])
    dm = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])
    n = np.empty(6)
    g = np.empty((6, 2))
    for i in range(3):
        n[i] = m[i] * (2 * m[i] - 1)
        g[i] = (4 * m[i] - 1) * dm[i]
    for k, (a, b) in enumerate([(0, 1), (1, 2), (2, 0)]):
        n[3 + k] = 4 * m[a] * m[b]
        g[3 + k] = 4 * (m[b] * dm[a] + m[a] * dm[b])
    return n, g


def boundary_faces(tets: np.ndarray) -> np.ndarray:
    faces = np.concatenate([tets[:, list(f)] for f in FACES])
    keys = np.sort(faces[:, :3], axis=1)
    _, inv, cnt = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    if cnt.max() > 2:
        raise SystemExit("non-manifold mesh")
    return faces[cnt[inv.ravel()] == 1]


def face_geometry(pts, faces, st):
    n, g = tri6(st)
    x = pts[faces]  # (F, 6, 3)
    p = np.einsum("a,fak->fk", n, x)
    ts = np.einsum("a,fak->fk", g[:, 0], x)
    tt = np.einsum("a,fak->fk", g[:, 1], x)
    return p, np.cross(ts, tt), n


def find_bore(pts, faces, centre, axis, name):
    centre, axis = np.asarray(centre, float), np.asarray(axis, float) / np.linalg.norm(axis)

    def radial(p):
        v = p - centre
        return v - np.outer(v @ axis, axis)

    pc, c, _ = face_geometry(pts, faces, (1 / 3, 1 / 3))
    nrm = c / np.linalg.norm(c, axis=1)[:, None]
    rv = radial(pc)
    rc = np.linalg.norm(rv, axis=1)
    ok = rc > 0
    cand = ok & (np.einsum("fk,fk->f", nrm, rv) / np.where(ok, rc, 1) <= -np.cos(np.radians(30)))
    if not cand.any():
        raise SystemExit(f"{name}: no boundary face faces the pin axis")
    radii = np.linalg.norm(radial(pts[faces[:, :3].reshape(-1)]), axis=1).reshape(-1, 3)
    r = radii[cand].max(axis=1).min()
    sel = cand & np.all((radii >= 0.99 * r) & (radii <= 1.01 * r), axis=1)
    return faces[sel], r


def consistent_forces(pts, faces, resultant):
    area = 0.0
    weights = np.zeros(len(pts))
    for st, w in zip(TRI_PTS, TRI_W):
        _, c, n = face_geometry(pts, faces, st)
        da = w * np.linalg.norm(c, axis=1)
        area += da.sum()
        np.add.at(weights, faces, np.outer(da, n))
    traction = np.asarray(resultant, float) / area
    return np.outer(weights, traction), area


def write_deck(path, pts, tets, fixed_nodes, loads, e_mpa, nu):
    out = ["*HEADING", "rodstudy CalculiX peer (mm, N, MPa)", "*NODE"]
    # ccx reads at most 20 characters per number: 13 significant digits
    out += [f"{i + 1}, {x:.13g}, {y:.13g}, {z:.13g}" for i, (x, y, z) in enumerate(pts.tolist())]
    out.append("*ELEMENT, TYPE=C3D10, ELSET=EALL")
    out += [f"{e + 1}, " + ", ".join(str(v + 1) for v in row) for e, row in enumerate(tets.tolist())]
    out.append("*NSET, NSET=FIXED")
    ids = [str(n + 1) for n in fixed_nodes]
    out += [", ".join(ids[i:i + 12]) for i in range(0, len(ids), 12)]
    out += ["*MATERIAL, NAME=STEEL", "*ELASTIC", f"{e_mpa:.13g}, {nu:.13g}",
            "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL", "*BOUNDARY", "FIXED, 1, 3"]
    for k, f in enumerate(loads):
        out += ["*STEP", "*STATIC", "*CLOAD" + (", OP=NEW" if k else "")]
        for n in np.nonzero(np.abs(f).sum(axis=1))[0]:
            for j in range(3):
                if f[n, j] != 0.0:
                    out.append(f"{n + 1}, {j + 1}, {f[n, j]:.13g}")
        out += ["*NODE FILE", "U", "*EL FILE", "S", "*END STEP"]
    path.write_text("\n".join(out) + "\n")


def write_buckle_deck(path, pts, tets, fixed_nodes, load, e_mpa, nu, accuracy=1e-8):
    """The deck of write_deck with one *BUCKLE step of `load` (1 factor, Lanczos accuracy)."""
    write_deck(path, pts, tets, fixed_nodes, [], e_mpa, nu)
    out = ["*STEP", "*BUCKLE", f"1, {accuracy:g}", "*CLOAD"]
    for n in np.nonzero(np.abs(load).sum(axis=1))[0]:
        for j in range(3):
            if load[n, j] != 0.0:
                out.append(f"{n + 1}, {j + 1}, {load[n, j]:.13g}")
    out += ["*NODE FILE", "U", "*END STEP"]
    with path.open("a") as f:
        f.write("\n".join(out) + "\n")


def read_buckling_factors(path: pathlib.Path):
    """The buckling factors of a .dat ("MODE NO  BUCKLING FACTOR" table)."""
    factors, inside = [], False
    for line in path.read_text().splitlines():
        if "B U C K L I N G" in line:
            inside = True
            continue
        if inside:
            parts = line.split()
            if len(parts) == 2 and parts[0].isdigit():
                factors.append(float(parts[1]))
            elif factors and not parts:
                break
    return factors


def read_frd(path: pathlib.Path, n_nodes: int):
    """Blocks DISP and STRESS per step from an ASCII .frd, as arrays indexed by node."""
    steps = []
    block, data = None, None
    for line in path.read_text().splitlines():
        if line.startswith(" -4"):
            block = line.split()[1]
            data = np.zeros((n_nodes, 6 if block == "STRESS" else 3))
        elif line.startswith(" -1") and block in ("DISP", "STRESS"):
            node = int(line[3:13])
            vals = [float(line[13 + 12 * i:25 + 12 * i]) for i in range(data.shape[1])]
            data[node - 1] = vals
        elif line.startswith(" -3") and block is not None:
            if block == "DISP":
                steps.append({"DISP": data})
            elif block == "STRESS":
                steps[-1]["STRESS"] = data
            block = None
    return steps


def von_mises(s):
    sxx, syy, szz, sxy, syz, szx = s.T
    return np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2) + 3 * (sxy ** 2 + syz ** 2 + szx ** 2))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mesh", help=".rodmesh file (the mesh rodstudy solved)")
    ap.add_argument("--force", type=float, default=7500.0, help="resultant on bore A, N (default 7500)")
    ap.add_argument("--ours", help="rodstudy FemResult JSON for the same mesh, printed beside")
    ap.add_argument("--workdir", help="keep the deck and results here (default: a temporary folder)")
    ap.add_argument("--ccx", default="ccx")
    ap.add_argument("--json", action="store_true", help="print the figures as one JSON line")
    ap.add_argument("--buckle", action="store_true",
                    help="linear buckling (*BUCKLE) of the F_x case instead of the static cases")
    args = ap.parse_args(argv)
    ccx = shutil.which(args.ccx)
    if not ccx:
        print(f"ccx_peer: CalculiX '{args.ccx}' not found (Debian: apt-get install calculix-ccx)", file=sys.stderr)
        return 2
    pts, tets = read_rodmesh(pathlib.Path(args.mesh))
    faces = boundary_faces(tets)
    bore_a, ra = find_bore(pts, faces, (0, 0, 0), (0, 0, 1), "bore A")
    bore_b, rb = find_bore(pts, faces, (180, 0, 0), (0, 0, 1), "bore B")
    fixed = np.unique(bore_b)
    if args.buckle:
        return buckle(args, ccx, pts, tets, bore_a, bore_b, ra, rb, fixed)
    loads = []
    for d in ([1.0, 0, 0], [0, 1.0, 0]):
        f, area = consistent_forces(pts, bore_a, np.array(d) * args.force)
        loads.append(f)
    work = pathlib.Path(args.workdir) if args.workdir else pathlib.Path(tempfile.mkdtemp(prefix="ccx_peer_"))
    work.mkdir(parents=True, exist_ok=True)
    deck = work / "rod.inp"
    write_deck(deck, pts, tets, fixed, loads, 210000.0, 0.3)
    env = dict(os.environ)
    env.setdefault("OMP_NUM_THREADS", "2")
    env.setdefault("CCX_NPROC_EQUATION_SOLVER", env["OMP_NUM_THREADS"])
    t0 = time.perf_counter()
    run = run_ccx(ccx, work, env)
    wall = time.perf_counter() - t0
    if run is None:
        return 1
    if run.returncode != 0 or not (work / "rod.frd").exists():
        print(run.stdout[-3000:], run.stderr[-3000:], file=sys.stderr)
        return 1
    steps = read_frd(work / "rod.frd", len(pts))
    figures = {"ccx_wall_s": wall, "nodes": len(pts), "elements": len(tets),
               "bore_a_radius_mm": ra, "bore_b_radius_mm": rb, "loaded_faces": len(bore_a),
               "fixed_nodes": len(fixed), "loaded_area_mm2": area}
    for name, st in zip(("fx", "fy"), steps):
        vm = von_mises(st["STRESS"])
        umag = np.linalg.norm(st["DISP"], axis=1)
        i = int(np.argmax(vm))
        figures[name] = {"max_von_mises_averaged_mpa": float(vm[i]), "at_mm": pts[i].tolist(),
                         "max_displacement_mm": float(umag.max())}
    if args.json:
        print(json.dumps(figures))
        return 0
    print(f"mesh {args.mesh}: {len(pts)} nodes, {len(tets)} C3D10; bore A r = {ra:.3f} mm ({len(bore_a)} faces), "
          f"bore B r = {rb:.3f} mm ({len(fixed)} fixed nodes); F = {args.force} N")
    ours = json.loads(pathlib.Path(args.ours).read_text()) if args.ours else None
    print(f"{'':4} {'ccx avg VM [MPa]':>17} {'ours avg VM':>12} {'rel diff':>9} {'ccx |u| [mm]':>13} {'ours |u|':>10}")
    for name in ("fx", "fy"):
        c = figures[name]
        line = f"{name:4} {c['max_von_mises_averaged_mpa']:17.4f}"
        if ours:
            o = ours[name]
            rel = o["max_von_mises_averaged_mpa"] / c["max_von_mises_averaged_mpa"] - 1
            line += f" {o['max_von_mises_averaged_mpa']:12.4f} {rel:+9.2e} {c['max_displacement_mm']:13.6f} {o['max_displacement_mm']:10.6f}"
        else:
            line += f" {'':12} {'':9} {c['max_displacement_mm']:13.6f}"
        print(line)
    t = f"ccx wall time {wall:.2f} s (deck writing and .frd reading excluded)"
    if ours:
        tt = ours["timings"]
        ours_s = tt["assembly_s"] + tt["symbolic_s"] + tt["factorisation_s"] + tt["solve_s"] + tt["stress_s"]
        t += f"; ours {ours_s:.2f} s (assembly {tt['assembly_s']:.2f}, factorisation {tt['symbolic_s'] + tt['factorisation_s']:.2f}, " \
             f"solve {tt['solve_s']:.2f}, stress {tt['stress_s']:.2f})"
    print(t)
    if not args.workdir:
        shutil.rmtree(work, ignore_errors=True)
    return 0


def buckle(args, ccx, pts, tets, bore_a, bore_b, ra, rb, fixed) -> int:
    f, area = consistent_forces(pts, bore_a, np.array([1.0, 0.0, 0.0]) * args.force)
    work = pathlib.Path(args.workdir) if args.workdir else pathlib.Path(tempfile.mkdtemp(prefix="ccx_buckle_"))
    work.mkdir(parents=True, exist_ok=True)
    write_buckle_deck(work / "rod.inp", pts, tets, fixed, f, 210000.0, 0.3)
    env = dict(os.environ)
    env.setdefault("OMP_NUM_THREADS", "2")
    env.setdefault("CCX_NPROC_EQUATION_SOLVER", env["OMP_NUM_THREADS"])
    t0 = time.perf_counter()
    run = run_ccx(ccx, work, env)
    wall = time.perf_counter() - t0
    if run is None:
        return 1
    factors = read_buckling_factors(work / "rod.dat") if (work / "rod.dat").exists() else []
    if run.returncode != 0 or not factors:
        print(run.stdout[-3000:], run.stderr[-3000:], file=sys.stderr)
        return 1
    figures = {"ccx_wall_s": wall, "nodes": len(pts), "elements": len(tets), "force_n": args.force,
               "bore_a_radius_mm": ra, "bore_b_radius_mm": rb, "loaded_faces": len(bore_a),
               "fixed_nodes": len(fixed), "loaded_area_mm2": area, "buckling_factors": factors,
               "buckling_factor": factors[0], "buckling_load_n": factors[0] * args.force}
    if args.json:
        print(json.dumps(figures))
    else:
        print(f"mesh {args.mesh}: {len(pts)} nodes, {len(tets)} C3D10; F_x = {args.force} N on bore A "
              f"(r = {ra:.3f} mm), bore B fixed (r = {rb:.3f} mm): ccx *BUCKLE factor {factors[0]:.6g}, "
              f"buckling load {factors[0] * args.force:.6g} N ({wall:.2f} s)")
    if not args.workdir:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
