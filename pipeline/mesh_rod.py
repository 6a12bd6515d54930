#!/usr/bin/env python3
"""Volume meshing of a rod STL with quadratic tetrahedra for rodstudy's FEM stage (SPEC Stage 3).

A gmsh adapter: every meshing decision (the classification ladder, the fallbacks and their order,
the local refinement's rounds and floor, quality limits, every gmsh option, the time limit) comes
from rodstudy in `--policy JSON` (`src/mesher/policy.rs`, where each is written and explained); the
script executes it and defines none. `rodstudy pipeline mesh_rod.py ...` adds the policy to a call
by hand. Each command ends with one line of JSON on standard output (progress goes to standard
error):

  mesh_rod.py mesh STL OUT_DIR --size MM --policy JSON [--curved] [--name NAME] [--size-field FILE]
                               [--geometry FILE] [--no-rodmesh]
      STL as a CAD export comes (millimetres, triangle soup) -> gmsh: merge, classify the surface
      triangles into patches (`classifySurfaces`, angles in radians), `createGeometry` (reparametrised
      discrete surfaces), surface loop, volume, 3D mesh at the target size, second order (10-node
      tetrahedra), optimisation. Deterministic: the policy's options (one thread, fixed 3D algorithm
      and random seed), so the same STL and size give the same mesh bit for bit.
      Meshing a surface reconstructed from an STL is fragile where tiny faces meet large ones (gmsh
      may stop with "overlapping facets" or even crash), so the mesh is made in a child process and
      the policy's ladder of classification settings (dihedral angle, curve split angle) is tried
      in order until one succeeds; the JSON says which rung was used and why earlier ones failed.
      Where every rung fails, the surface is meshed differently (the policy's fallbacks, in its
      order): "local refinement" (the sizes reduced around the patches gmsh blames, round after
      round) and "STL surface kept" (the STL's own triangles as the boundary, only the interior
      meshed), both on the bonded body where the STL holds shells touching face to face
      (`bond_shells`); the JSON's `fallback` names the one that made the mesh (null for the usual
      mesh). A total failure ends in one line that lists everything tried and what to try. Children
      stop at the policy's `time_limit_s`, a little before the Rust side's time limit, so that line
      is written.
      Writes OUT_DIR/NAME.msh (gmsh MSH 4.1, for the user) and OUT_DIR/NAME.rodmesh (the hand-off
      file the Rust side reads, see below). The .rodmesh is made from the .msh through meshio, i.e.
      by the very same code path as `convert`. With --no-rodmesh it is not written: the caller reads
      the .msh with its native MSH 4.1 reader (the same mesh bit for bit; rodstudy's adaptive meshes,
      which saves meshio's 0.5 s per mesh), and the .msh is written binary (0.1 s faster than
      ASCII; `msh_binary` in the JSON): the caller rounds its coordinates to the 16 significant
      digits the ASCII file would print, so the mesh is the ASCII one to the last bit (exact
      coordinates would change the adaptive loop's later meshes). The classified surface stays
      ASCII.
      JSON: paths, node and element counts, min/mean scaled Jacobian and SICN (gmsh
      `getElementQualities` "minSJ" / "minSICN"), whether elements are curved, timings, the
      fallback used (`fallback`, `fallback_detail`: rounds and refined patches, or the boundary
      triangles kept).

      --size-field FILE: a local element size map for adaptive refinement, as gmsh's
      `examples/api/adapt_mesh.py` does it: a list-based post-processing view of scalar tetrahedra
      ("SS": per tetrahedron the x, y, z of its 4 corners, then the 4 sizes; FILE holds them as raw
      little-endian float64, 16 per tetrahedron) used as a `PostView` background field. --size is
      then the cap. With a size field, sizes come from it alone: `MeshSizeFromPoints`,
      `MeshSizeFromCurvature` and `MeshSizeExtendFromBoundary` are off.
      --geometry FILE: the classified surface (gmsh's `classifySurfaces` result, MSH) is written to
      FILE (with FILE.json naming the classification setting) on first use and read back on later
      calls, so an adaptive sequence classifies the STL once (classification is most of the time of
      a coarse mesh); a later call tries that classification only, then the fallbacks ("local
      refinement" on that classification, the size field's sizes reduced around the patches blamed).

      The 3D mesher is the policy's `algorithm_3d` (HXT); where it refuses a surface mesh, its
      `algorithm_3d_fallback` (gmsh's Delaunay with Netgen optimisation) is tried on the same
      classification.

      Second-order nodes are placed at the straight edge midpoints (`Mesh.SecondOrderLinear = 1`):
      snapping them onto a surface reconstructed from an STL (a faceted surface, so nothing is gained in
      accuracy) can invert elements. `--curved` tries snapped nodes and keeps them only if every
      element has a positive scaled Jacobian, otherwise it falls back to straight-sided elements
      (and says so in the JSON).

  mesh_rod.py mesh-step STEP OUT_DIR --frame OX,OY,OZ,XX,XY,XZ,YX,YY,YZ,ZX,ZY,ZZ --scale S
                                     --size MM --policy JSON [--name NAME] [--size-field FILE]
                                     [--no-rodmesh]
      A STEP solid (the exact B-rep, through gmsh's OpenCASCADE kernel; several solids fused into one
      bonded body) -> curved 10-node tetrahedra whose midside nodes lie on the true surfaces
      (`Mesh.SecondOrderLinear = 0`); an element whose minimum scaled Jacobian is below the policy's
      `curved_sj_min` (a fillet far smaller than the elements) is made straight-sided
      (`straighten_poor_curved`; gmsh's own high-order optimiser gives another mesh on every run).
      The solid is first moved
      into the rod frame in millimetres: p' = S R (p - O), R's rows the frame's x, y, z axes (file
      axes), O the crank pin, S millimetres per file unit; so sizes, the size field and every
      location are rod-frame millimetres, as for an STL. No surface classification and no facet
      floor: the geometry is exact. An element still inverted with straight sides (minimum
      scaled Jacobian <= 0) is refused with a message, never handed to the solver. Same outputs
      and JSON as `mesh` (`curved` true, `classify_angle_deg` 0).

  mesh_rod.py serve STL --geometry FILE --policy JSON
      One gmsh session for a whole adaptive sequence of meshes of one STL (rodstudy's stage 3): one
      JSON request per line on standard input, {"size": mm, "size_field": FILE or null, "out_dir":
      DIR, "name": NAME}, one JSON reply per line on standard output, the fields of `mesh`'s (read
      natively, as `--no-rodmesh`). gmsh starts once; every request then takes the steps of `mesh`'s
      first attempt in it on a new model (the cached classification of --geometry, else the
      ladder's first rung, cached after its first mesh; HXT), the same mesh bit for bit as `mesh`
      in a fresh process. This saves two Python start-ups and gmsh's start per mesh. Only the
      usual route is served: the first error (HXT's sliver, a classification that does not mesh)
      is replied as {"error": ...} and ends the session; the caller then uses `mesh`, with its
      ladder, Delaunay and fallbacks. (Keeping the reparametrised model between meshes would save
      0.25 s more, but remeshing it needs its classified triangles cleared first, which changes the
      meshes and made design 5's first mesh fail.)

  mesh_rod.py convert IN OUT [--units mm|m]
      A ready volume mesh (gmsh .msh, Abaqus/CalculiX .inp, VTU, Nastran .bdf/.nas, anything meshio
      reads) -> OUT in the .rodmesh format. Quadratic tetrahedra ("tetra10") are taken as meshio gives
      them; linear tetrahedra ("tetra") are promoted to straight-sided tetra10. Other cell types
      (surface triangles, lines, points) are dropped; nodes no tet uses are dropped.

The .rodmesh hand-off format (ASCII, one record per line, '#' starts a comment line):

  rodmesh 1
  units mm                 (or m)
  nodes N
  x y z                    (N lines, float64 printed with repr(): round-trips exactly)
  tet10 M
  n0 n1 ... n9             (M lines, 0-based node indices)

Node order of a tetra10 (the ONE order used inside rodstudy, VTK's = meshio's): corners 0-3, then the
midside nodes of edges 01, 12, 02, 03, 13, 23. gmsh numbers the last two the other way round (edge 23
before 13); meshio's gmsh reader already converts gmsh's order to VTK's, Abaqus/CalculiX C3D10 and
Nastran CTETRA use VTK's order. So no permutation is done here: the one conversion is meshio's, at the
point where a foreign format is read. The Rust reader checks geometrically that every midside node
sits near the midpoint of its edge, which catches a wrong order.
"""

from __future__ import annotations

import argparse
import ctypes
import json
import math
import os
import pathlib
import queue
import re
import subprocess
import sys
import threading
import time

import numpy as np

FORMAT_HEADER = "rodmesh 1"

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


# VTK/meshio tetra10 edges, in the order of the midside nodes 4..9.
TET10_EDGES = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)]


def log(msg: str) -> None:
    print(f"mesh_rod: {msg}", file=sys.stderr, flush=True)


# ---------------------------------------------------------------------------------------------
# Reproducible meshes: each in an allocator arena of its own
# ---------------------------------------------------------------------------------------------

def fixed_allocator() -> None:
    """gmsh hands HXT the surface vertices in the order of their memory addresses (`Gmsh2Hxt`
    collects them in a `std::set<MVertex *>`), and HXT's optimiser decides its ties in that order:
    the same model and size field made 12,228 or 12,229 nodes depending on what the process had
    allocated before (its paths' lengths, earlier meshes), and a fresh clone of the project in
    another folder made another design 5. So every mesh is made in a thread
    of its own (`in_fresh_arena`): glibc gives a new thread a new arena, whose blocks it hands out
    in the order the meshing asks for them, whatever the process did before. Two settings keep it
    so: the size above which a block is mapped on its own is fixed (glibc raises it as mapped
    blocks are freed, so a block could sit in the arena on one run and outside it on another),
    and the number of arenas is raised so that each thread gets a new one. Checked: one process
    meshing the same model 4 times after allocations of 5 sizes, from two folders, 40 of 40
    meshes the same (without: 10 of 40 differ)."""
    try:
        libc = ctypes.CDLL("libc.so.6")
    except OSError:  # not glibc
        return
    m_mmap_threshold, m_arena_max = -3, -8
    libc.mallopt(m_mmap_threshold, 128 * 1024)
    libc.mallopt(m_arena_max, 1024)


def in_fresh_arena(fn, *args):
    """`fn(*args)` in a new thread (a new allocator arena, `fixed_allocator`), which is then
    parked for the rest of the process: an ended thread's arena, with its free blocks, would be
    handed to the next thread. Returns what `fn` returns; raises what it raises."""
    done: dict = {}
    finished = threading.Event()

    def run():
        try:
            done["value"] = fn(*args)
        except BaseException as e:  # noqa: BLE001 - handed to the caller
            done["error"] = e
        finished.set()
        threading.Event().wait()

    threading.Thread(target=run, daemon=True).start()
    finished.wait()
    if "error" in done:
        raise done["error"]
    return done["value"]


class ArenaWorker:
    """One mesh of `serve` in a thread with an arena of its own (`in_fresh_arena`): it first
    runs `prepare` (the next model built while the caller solves the last mesh), then waits for
    the request's work, runs it, and parks."""

    def __init__(self, prepare):
        self.jobs: queue.Queue = queue.Queue()
        self.results: queue.Queue = queue.Queue()
        threading.Thread(target=self._run, args=(prepare,), daemon=True).start()

    def _run(self, prepare) -> None:
        prepare()
        job = self.jobs.get()
        try:
            self.results.put((True, job()))
        except BaseException as e:  # noqa: BLE001 - handed to the caller
            self.results.put((False, e))
        threading.Event().wait()

    def run(self, job):
        self.jobs.put(job)
        ok, value = self.results.get()
        if not ok:
            raise value
        return value


# ---------------------------------------------------------------------------------------------
# gmsh meshing
# ---------------------------------------------------------------------------------------------

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


def read_size_field(path: pathlib.Path) -> np.ndarray:
    """The size map of `path`, checked: one row of 16 float64 per tetrahedron."""
    data = np.fromfile(str(path), dtype="<f8")
    if data.size == 0 or data.size % 16:
        raise SystemExit(f"mesh_rod: {path}: a size field holds 16 float64 per tetrahedron, got {data.size} values")
    sizes = data.reshape(-1, 16)[:, 12:]
    if not (np.isfinite(data).all() and (sizes > 0).all()):
        raise SystemExit(f"mesh_rod: {path}: sizes must be finite and > 0")
    return data.reshape(-1, 16)


def add_size_field(path: pathlib.Path, background: bool = True) -> tuple[int, int]:
    """The size map of `path` (raw float64, 16 per tetrahedron: x0..x3, y0..y3, z0..z3, s0..s3) as a
    list-based view and a PostView field (the background field unless `background` is false);
    returns (tetrahedra, field tag)."""
    import gmsh

    data = read_size_field(path).reshape(-1)
    view = gmsh.view.add("size field")
    gmsh.view.addListData(view, "SS", data.size // 16, data.tolist())
    field = gmsh.model.mesh.field.add("PostView")
    gmsh.model.mesh.field.setNumber(field, "ViewTag", view)
    if background:
        gmsh.model.mesh.field.setAsBackgroundMesh(field)
    return data.size // 16, field


def written_mesh(qualities, msh_out: pathlib.Path, binary: bool = False) -> dict:
    """Writes the model's mesh to `msh_out` and returns the figures every meshing route reports:
    counts and the quality of the 10-node tetrahedra (`qualities` from `tet10_qualities`). `binary`:
    MSH 4.1 binary (0.01 s instead of 0.1 s for design 1's meshes) for a caller that reads it
    natively and rounds the coordinates as the ASCII file prints them (`"%.16g"`; the Rust side,
    `mesher::volume::read_msh_as_ascii`), so the mesh is the ASCII file's to the last bit."""
    import gmsh
    tags10, min_sj, min_sicn = qualities
    node_tags, _, _ = gmsh.model.mesh.getNodes()
    gmsh.option.setNumber("Mesh.Binary", 1 if binary else 0)
    try:
        gmsh.write(str(msh_out))
    finally:
        gmsh.option.setNumber("Mesh.Binary", 0)
    return {
        "elements": int(tags10.size),
        "gmsh_nodes": int(len(node_tags)),
        "min_scaled_jacobian": float(min_sj.min()),
        "mean_scaled_jacobian": float(min_sj.mean()),
        "min_sicn": float(min_sicn.min()),
        "mean_sicn": float(min_sicn.mean()),
        "elements_sicn_below_0.1": int((min_sicn < 0.1).sum()),
    }


def tet10_qualities() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The tags of the model's 10-node tetrahedra (the only elements of dimension 3 allowed) and
    their minSJ and minSICN."""
    import gmsh

    types, tags, _ = gmsh.model.mesh.getElements(3)
    tet10 = [t for ty, t in zip(types, tags) if ty == 11]
    if not tet10 or len(types) != 1:
        raise RuntimeError(f"gmsh produced element types {list(types)}, expected only 10-node tets (11)")
    tags10 = np.asarray(tet10[0])
    min_sj = np.asarray(gmsh.model.mesh.getElementQualities(tags10, "minSJ"))
    min_sicn = np.asarray(gmsh.model.mesh.getElementQualities(tags10, "minSICN"))
    return tags10, min_sj, min_sicn



def cap_open_cut() -> list[int]:
    """The half model's cap: the Rust side hands over the half of a mirror-symmetric rod open at
    its cut (z = c), and the classification leaves the cut as curves that bound one surface each.
    They are chained into loops (outline and holes, nested by their bounding boxes) and each
    outline closed with a plane surface on the very curves (`geo.addCurveLoop` /
    `addPlaneSurface`), so that gmsh meshes the cap as one plane and no parametrisation cut of
    the classification crosses it or meets the cut's edge. Returns the plane surfaces' tags, none
    for a closed surface (every whole rod). An open surface whose open edges are not in one plane
    z = const, or do not form simple loops, is refused."""
    import gmsh

    open_curves = [c for _, c in gmsh.model.getEntities(1)
                   if len(gmsh.model.getAdjacencies(1, c)[0]) == 1]
    if not open_curves:
        return []
    boxes = {c: gmsh.model.getBoundingBox(1, c) for c in open_curves}
    zs = [v for b in boxes.values() for v in (b[2], b[5])]
    plane_tol_rel = policy("cut_plane_tol_rel")
    whole = gmsh.model.getBoundingBox(-1, -1)
    extent = max(whole[3] - whole[0], whole[4] - whole[1], whole[5] - whole[2])
    if max(zs) - min(zs) > plane_tol_rel * extent:
        raise RuntimeError(f"the surface is open, and its open edges do not lie in one plane z = const "
                           f"(z from {min(zs)} to {max(zs)} mm)")
    ends = {}
    for c in open_curves:
        b = [t for _, t in gmsh.model.getBoundary([(1, c)], combined=False, oriented=False)]
        ends[c] = (b[0], b[-1]) if b else (None, None)
    by_point: dict = {}
    for c, (a, b) in ends.items():
        if a is not None and a != b:
            by_point.setdefault(a, []).append(c)
            by_point.setdefault(b, []).append(c)
    left = set(open_curves)
    loops = []
    for c0 in open_curves:
        if c0 not in left:
            continue
        left.discard(c0)
        a, b = ends[c0]
        loop = [c0]
        if a is not None and a != b:
            start, at = a, b
            while at != start:
                nxt = [c for c in by_point.get(at, []) if c in left]
                if len(nxt) != 1:
                    raise RuntimeError(f"the open edges do not form simple loops at point {at}")
                c = nxt[0]
                left.discard(c)
                if ends[c][0] == at:
                    loop.append(c)
                    at = ends[c][1]
                else:
                    loop.append(-c)
                    at = ends[c][0]
        loops.append(loop)

    def box(loop):  # (x_min, y_min, x_max, y_max) of a loop
        bs = [boxes[abs(c)] for c in loop]
        return (min(b[0] for b in bs), min(b[1] for b in bs), max(b[3] for b in bs), max(b[4] for b in bs))

    lb = [box(loop) for loop in loops]

    def inside(i, j):  # loop i's box within loop j's
        return (i != j and lb[j][0] <= lb[i][0] and lb[j][1] <= lb[i][1]
                and lb[i][2] <= lb[j][2] and lb[i][3] <= lb[j][3])

    # an outline has an even number of loops around it, a hole an odd one
    depth = [sum(inside(i, j) for j in range(len(loops))) for i in range(len(loops))]
    tags = [gmsh.model.geo.addCurveLoop(loop) for loop in loops]
    caps = []
    for i in range(len(loops)):
        if depth[i] % 2:
            continue
        holes = [tags[k] for k in range(len(loops)) if depth[k] == depth[i] + 1 and inside(k, i)]
        caps.append(gmsh.model.geo.addPlaneSurface([tags[i]] + holes))
    return caps


def build_volume(stl: pathlib.Path, angle_deg: float, curve_angle_deg: float,
                 geometry_in: pathlib.Path | None = None, geometry_out: pathlib.Path | None = None) -> int:
    """The model "rod": the STL's surface classified into patches (or the classification of
    `geometry_in`), reparametrised (`createGeometry`), closed into one volume (a half model's open
    cut capped first, `cap_open_cut`). Returns the number of surface patches, caps included."""
    import gmsh

    gmsh.model.add("rod")
    if geometry_in is not None:
        gmsh.merge(str(geometry_in))
    else:
        gmsh.merge(str(stl))
        # Patches from the triangle soup: split at sharp edges (angle in radians), keep
        # boundaries, make each patch parametrisable so that it can be remeshed at the target size.
        gmsh.model.mesh.classifySurfaces(math.radians(angle_deg), True, True, math.radians(curve_angle_deg))
        if geometry_out is not None:
            # written and read back, so that a first mesh and a later one from the cached
            # classification start from the same data (same mesh, bit for bit)
            gmsh.write(str(geometry_out))
            gmsh.clear()
            gmsh.merge(str(geometry_out))
    gmsh.model.mesh.createGeometry()
    surfaces = [tag for _, tag in gmsh.model.getEntities(2)] + cap_open_cut()
    loop = gmsh.model.geo.addSurfaceLoop(surfaces)
    gmsh.model.geo.addVolume([loop])
    gmsh.model.geo.synchronize()
    return len(surfaces)


def mesh_volume(msh_out: pathlib.Path, size_field: pathlib.Path | None, delaunay: bool,
                binary: bool = False) -> dict:
    """Meshes the volume of `build_volume`'s model (options set by the caller) and writes it to
    `msh_out`. The model still holds the classified STL triangles on its patches, as
    `createGeometry` leaves them: gmsh remeshes from that state (clearing them first changes the
    meshes and made design 5's first mesh fail with overlapping facets)."""
    import gmsh

    size_field_tets = add_size_field(size_field)[0] if size_field is not None else 0
    t1 = time.perf_counter()
    gmsh.logger.start()
    try:
        gmsh.model.mesh.generate(3)
        log_lines = gmsh.logger.get()
    finally:
        gmsh.logger.stop()
    t2 = time.perf_counter()
    tags10, min_sj, min_sicn = tet10_qualities()
    t3 = time.perf_counter()
    min_sicn_ok = policy("min_sicn")
    if delaunay is False and min_sicn.min() < min_sicn_ok:
        # HXT can leave a sliver its optimiser does not remove; the caller retries with
        # Delaunay + Netgen, whose optimiser does
        raise RuntimeError(f"HXT left a sliver (min SICN {min_sicn.min():.2e} < {min_sicn_ok})")
    written = written_mesh((tags10, min_sj, min_sicn), msh_out, binary)
    phases = {**meshing_phases(log_lines), "qualities": t3 - t2, "write": time.perf_counter() - t3}
    return {
        **written,
        "phases_s": phases,
        "msh_binary": binary,
        "size_field_tetrahedra": size_field_tets,
        "algorithm_3d": algorithm_name(int(gmsh.option.getNumber("Mesh.Algorithm3D"))),
        "seconds_mesh": t2 - t1,
        "gmsh_version": gmsh.option.getString("General.Version"),
    }


def meshing_phases(log_lines: list[str]) -> dict:
    """gmsh's own wall times of `generate(3)`, from its log: `mesh_1d`, `mesh_2d`, `mesh_3d` (with
    HXT's optimisation, also given alone as `hxt_optimise` when HXT ran) and `order_2` (the midside
    nodes), s. A phase gmsh did not log is absent."""
    phases = {}
    names = {"1D": "mesh_1d", "2D": "mesh_2d", "3D": "mesh_3d", "order 2": "order_2"}
    for line in log_lines:
        done = re.search(r"Done meshing (1D|2D|3D|order 2) \(Wall ([0-9.eE+-]+)s", line)
        if done:
            phases[names[done.group(1)]] = float(done.group(2))
        hxt = re.search(r"tOptimize\s*=\s*([0-9.eE+-]+)", line)
        if hxt:
            phases["hxt_optimise"] = float(hxt.group(1))
    return phases


def set_options(size_mm: float, curved: bool, size_field: bool, delaunay: bool) -> None:
    import gmsh

    for k, v in gmsh_options(size_mm, curved, size_field).items():
        gmsh.option.setNumber(k, v)
    if delaunay:
        gmsh.option.setNumber("Mesh.Algorithm3D", algorithm_code(True))


def gmsh_volume_mesh(stl: pathlib.Path, size_mm: float, curved: bool, angle_deg: float,
                     curve_angle_deg: float, msh_out: pathlib.Path, size_field: pathlib.Path | None = None,
                     geometry_in: pathlib.Path | None = None,
                     geometry_out: pathlib.Path | None = None, delaunay: bool = False,
                     binary: bool = False) -> dict:
    import gmsh

    t0 = time.perf_counter()
    gmsh.initialize(["mesh_rod"], readConfigFiles=False, interruptible=False)
    try:
        set_options(size_mm, curved, size_field is not None, delaunay)
        patches = build_volume(stl, angle_deg, curve_angle_deg, geometry_in, geometry_out)
        t1 = time.perf_counter()
        info = mesh_volume(msh_out, size_field, delaunay, binary)
        return {
            **info,
            "surface_patches": patches,
            "geometry_reused": geometry_in is not None,
            "seconds_geometry": t1 - t0,
        }
    finally:
        gmsh.finalize()


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
    cmd = [sys.executable, str(pathlib.Path(__file__).resolve()), "_attempt", str(stl), str(msh),
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


# ---------------------------------------------------------------------------------------------
# fallbacks: a new surface mesh where every classification of the policy's ladder fails
# ---------------------------------------------------------------------------------------------

def patch_facts(classified: pathlib.Path) -> tuple[dict, dict]:
    """Area (mm²) and centroid (mean of the nodes) of every patch of a classified surface, from its
    STL triangles."""
    import gmsh

    gmsh.initialize(["mesh_rod"], readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.merge(str(classified))
        node_tags, coords, _ = gmsh.model.mesh.getNodes()
        xyz = np.zeros((int(node_tags.max()) + 1, 3))
        xyz[node_tags.astype(np.int64)] = np.asarray(coords).reshape(-1, 3)
        areas, centroids = {}, {}
        for _, tag in gmsh.model.getEntities(2):
            types, _, nodes = gmsh.model.mesh.getElements(2, tag)
            t = np.concatenate([np.asarray(n, dtype=np.int64) for ty, n in zip(types, nodes) if ty == 2])
            t = t.reshape(-1, 3)
            a, b, c = xyz[t[:, 0]], xyz[t[:, 1]], xyz[t[:, 2]]
            areas[tag] = 0.5 * float(np.linalg.norm(np.cross(b - a, c - a), axis=1).sum())
            centroids[tag] = xyz[np.unique(t)].mean(axis=0)
        return areas, centroids
    finally:
        gmsh.finalize()


def field_size_near(data: np.ndarray, p: np.ndarray) -> float:
    """The smallest size of the size-field tetrahedron whose centroid is nearest to `p`."""
    centroids = np.stack([data[:, 0:4].mean(axis=1), data[:, 4:8].mean(axis=1), data[:, 8:12].mean(axis=1)],
                         axis=1)
    k = int(np.argmin(((centroids - p) ** 2).sum(axis=1)))
    return float(data[k, 12:16].min())


def add_refinement(refine: dict, size: float, base_field: int | None) -> None:
    """Background field: the smaller of `base_field` (the size field, if any) and, per refined
    patch, its size h within h of the patch's boundary curves, growing linearly to `size` at h +
    g·size (g the policy's `grow_sizes`)."""
    import gmsh

    lr = policy("local_refinement")

    F = gmsh.model.mesh.field
    fields = [] if base_field is None else [base_field]
    for tag, h in sorted(refine.items()):
        curves = sorted({abs(c) for _, c in gmsh.model.getBoundary([(2, tag)], oriented=False)})
        if not curves:
            continue
        # sample the curves (their bounding box diagonal as the length) as the policy says
        longest = max(math.dist(bb[:3], bb[3:]) for bb in (gmsh.model.getBoundingBox(1, c) for c in curves))
        samples = math.ceil(lr["samples_per_size"] * longest / h)
        distance = F.add("Distance")
        F.setNumbers(distance, "CurvesList", curves)
        F.setNumber(distance, "Sampling", int(min(lr["samples_max"], max(lr["samples_min"], samples))))
        threshold = F.add("Threshold")
        F.setNumber(threshold, "InField", distance)
        F.setNumber(threshold, "SizeMin", h)
        F.setNumber(threshold, "SizeMax", size)
        F.setNumber(threshold, "DistMin", h)
        F.setNumber(threshold, "DistMax", h + lr["grow_sizes"] * size)
        fields.append(threshold)
    if not fields:
        return
    if len(fields) == 1:
        F.setAsBackgroundMesh(fields[0])
        return
    smallest = F.add("Min")
    F.setNumbers(smallest, "FieldsList", fields)
    F.setAsBackgroundMesh(smallest)


def surfaces_named(error: str, messages: list[str]) -> list[int]:
    """The entities gmsh blames for a failed boundary recovery: the surfaces of "Invalid boundary
    mesh (overlapping facets) on surface A surface B", else those of the last "1st: [...] #A" and
    "2nd: [...] #B" lines of its log (a facet or segment and the entity it lies on)."""
    if "overlapping facets" in error:
        return [int(t) for t in re.findall(r"surface (\d+)", error)]
    tags = []
    for m in reversed(messages[-40:]):
        hit = re.search(r"(1st|2nd): \[[^\]]*\] #(\d+)", m)
        if hit:
            tags.append(int(hit.group(2)))
            if len(tags) == 2:
                break
    return tags


def gmsh_local_refinement(stl: pathlib.Path, size_mm: float, angle_deg: float, curve_angle_deg: float,
                          msh_out: pathlib.Path, size_field: pathlib.Path | None,
                          geometry_in: pathlib.Path | None, geometry_out: pathlib.Path | None) -> dict:
    """The fallback "local refinement" (the policy's `fallbacks` and `local_refinement`)."""
    import gmsh

    t0 = time.perf_counter()
    if geometry_in is not None:
        classified = geometry_in
    else:
        if geometry_out is None:
            raise SystemExit("mesh_rod: local refinement needs --geometry-in or --geometry-out")
        classified = geometry_out
        gmsh.initialize(["mesh_rod"], readConfigFiles=False, interruptible=False)
        try:
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.merge(str(stl))
            gmsh.model.mesh.classifySurfaces(math.radians(angle_deg), True, True, math.radians(curve_angle_deg))
            gmsh.write(str(classified))
        finally:
            gmsh.finalize()
    lr = policy("local_refinement")
    areas, centroids = patch_facts(classified)
    field_data = read_size_field(size_field) if size_field is not None else None
    refine: dict[int, float] = {}
    errors = []
    last = None
    for rounds in range(lr["rounds"] + 1):
        gmsh.initialize(["mesh_rod"], readConfigFiles=False, interruptible=False)
        try:
            # Delaunay: its errors name the surfaces
            set_options(size_mm, False, size_field is not None, delaunay=True)
            patches = build_volume(stl, angle_deg, curve_angle_deg, geometry_in=classified)
            size_field_tets, base = add_size_field(size_field, background=False) if size_field else (0, None)
            if refine:
                add_refinement(refine, size_mm, base)
            elif base is not None:
                gmsh.model.mesh.field.setAsBackgroundMesh(base)
            t1 = time.perf_counter()
            gmsh.logger.start()
            try:
                gmsh.model.mesh.generate(3)
            except Exception as e:  # gmsh raises Exception with its last error
                error = str(e)
                errors.append(error)
                messages = gmsh.logger.get()
                for m in messages[-40:]:
                    if re.search(r"(1st|2nd): ", m):
                        log(f"    {m.strip()}")
                named = [t for t in surfaces_named(error, messages) if t in areas]
                log(f"  local refinement round {rounds}: {error}")
                if not named:
                    # TetGen's "PLC Error" names no entity: most likely near what was refined last
                    named = [last] if last is not None else []
                if not named:
                    raise RuntimeError(f"local refinement: {error} (no surface named to refine)")
                current = {t: refine.get(t, start_size(t, size_mm, field_data, centroids)) for t in named}
                open_ = [t for t in named if current[t] * lr["factor"] >= lr["min_size_mm"]]
                if not open_:
                    raise RuntimeError(f"local refinement: {error} (sizes there already at "
                                       f"{lr['min_size_mm']} mm)")
                patch = min(open_, key=lambda t: (areas[t], t))
                refine[patch] = current[patch] * lr["factor"]
                last = patch
                continue
            t2 = time.perf_counter()
            return {
                **written_mesh(tet10_qualities(), msh_out),
                "surface_patches": patches,
                "size_field_tetrahedra": size_field_tets,
                "algorithm_3d": policy("algorithm_3d_fallback"),
                "geometry_reused": geometry_in is not None,
                "fallback": "local refinement",
                "fallback_detail": {
                    "rounds": rounds,
                    "refined_patches": [{"surface": t, "area_mm2": areas[t], "size_mm": h}
                                        for t, h in sorted(refine.items())],
                    "errors": errors,
                },
                "seconds_geometry": t1 - t0,
                "seconds_mesh": t2 - t1,
                "gmsh_version": gmsh.option.getString("General.Version"),
            }
        finally:
            gmsh.finalize()
    raise RuntimeError(f"local refinement: still failing after {lr['rounds']} rounds: {errors[-1]}")


def start_size(tag: int, size_mm: float, field_data, centroids: dict) -> float:
    """The size a patch is meshed at before it is refined: the target, or with a size field the
    field's size near the patch (at most the target)."""
    if field_data is None:
        return size_mm
    return min(size_mm, field_size_near(field_data, centroids[tag]))


def has_open_edges() -> bool:
    """Whether the triangles of the model (a merged STL) have an edge used by one triangle only."""
    import gmsh

    _, _, nodes = gmsh.model.mesh.getElements(2)
    tri = np.concatenate([n for n in nodes]).reshape(-1, 3) if nodes else np.zeros((0, 3), dtype=np.uint64)
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return bool((counts == 1).any())


def gmsh_surface_kept(stl: pathlib.Path, size_mm: float, msh_out: pathlib.Path,
                      size_field: pathlib.Path | None) -> dict:
    """The fallback "STL surface kept" (the policy's `fallbacks`)."""
    import gmsh

    t0 = time.perf_counter()
    gmsh.initialize(["mesh_rod"], readConfigFiles=False, interruptible=False)
    try:
        for k, v in gmsh_options(size_mm, False, size_field is not None).items():
            gmsh.option.setNumber(k, v)
        gmsh.option.setNumber("Mesh.Algorithm3D", algorithm_code(True))
        gmsh.model.add("rod")
        gmsh.merge(str(stl))
        surfaces = [tag for _, tag in gmsh.model.getEntities(2)]
        if has_open_edges():
            # the half model's open cut: its boundary curves, then the cap on them
            gmsh.model.mesh.createTopology()
            surfaces = [tag for _, tag in gmsh.model.getEntities(2)] + cap_open_cut()
        loop = gmsh.model.geo.addSurfaceLoop(surfaces)
        gmsh.model.geo.addVolume([loop])
        gmsh.model.geo.synchronize()
        size_field_tets = add_size_field(size_field)[0] if size_field is not None else 0
        t1 = time.perf_counter()
        gmsh.model.mesh.generate(3)
        t2 = time.perf_counter()
        boundary = sum(len(t) for t in gmsh.model.mesh.getElements(2)[1])
        return {
            **written_mesh(tet10_qualities(), msh_out),
            "surface_patches": 0,
            "size_field_tetrahedra": size_field_tets,
            "algorithm_3d": policy("algorithm_3d_fallback"),
            "geometry_reused": False,
            "fallback": "STL surface kept",
            "fallback_detail": {"boundary_triangles": int(boundary)},
            "seconds_geometry": t1 - t0,
            "seconds_mesh": t2 - t1,
            "gmsh_version": gmsh.option.getString("General.Version"),
        }
    finally:
        gmsh.finalize()


def bond_shells(stl: pathlib.Path, out: pathlib.Path) -> int:
    """Where an STL holds several shells that touch face to face (a rod and its cap exported as two
    bodies: `mass` treats them as one bonded body), the touching faces come as pairs of the same
    triangle with opposite orientations, and gmsh cannot classify the edges where four triangles
    meet. Removing those pairs leaves the surface of the bonded body. Writes it to `out` (binary
    STL) and returns the number of pairs removed; 0 (nothing written) for any other STL, or one
    that is not binary."""
    data = stl.read_bytes()
    if len(data) < 84:
        return 0
    n = int.from_bytes(data[80:84], "little")
    if len(data) != 84 + 50 * n or n == 0:
        return 0
    rec = np.frombuffer(data[84:], dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
    _, ids = np.unique(rec["v"].reshape(-1, 3), axis=0, return_inverse=True)
    tri = ids.reshape(-1, 3)
    # a triangle and its reverse: the same three vertices, opposite cyclic order
    key = np.sort(tri, axis=1)
    rot = np.argmin(tri, axis=1)
    canon = np.stack([np.roll(t, -r) for t, r in zip(tri.tolist(), rot.tolist())])  # smallest first
    forward = canon[:, 1] < canon[:, 2]
    _, group, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    group = group.reshape(-1)
    drop = np.zeros(n, dtype=bool)
    for g in np.flatnonzero(counts == 2):
        a, b = np.flatnonzero(group == g)
        if forward[a] != forward[b]:
            drop[[a, b]] = True
    pairs = int(drop.sum()) // 2
    if pairs:
        kept = rec[~drop]
        out.write_bytes(data[:80] + len(kept).to_bytes(4, "little") + kept.tobytes())
    return pairs


def run_fallback(name: str, stl: pathlib.Path, size: float, angle: float, curve_angle: float,
                 msh: pathlib.Path, size_field, geometry_in, geometry_out) -> tuple[dict | None, str]:
    """One fallback of the policy's `fallbacks` in a child process."""
    cmd = [sys.executable, str(pathlib.Path(__file__).resolve()), "_fallback", name, str(stl), str(msh),
           "--size", repr(size), "--angle", repr(angle), "--curve-angle", repr(curve_angle), policy_arg()]
    for flag, value in (("--size-field", size_field), ("--geometry-in", geometry_in),
                        ("--geometry-out", geometry_out)):
        if value is not None:
            cmd += [flag, str(value)]
    return run_child(cmd)


def handed_off(msh: pathlib.Path, rodmesh: pathlib.Path, info: dict, no_rodmesh: bool) -> dict:
    """The hand-off of a mesh written to `msh`: the `.rodmesh` converted from it by meshio (the
    node count of the tetrahedra, the largest midside offset), or with `no_rodmesh` none (the Rust
    side reads the MSH 4.1 natively, the same mesh bit for bit; `nodes` is then gmsh's count, which
    the reader replaces by the tetrahedra's)."""
    if no_rodmesh:
        return {"rodmesh": None, "nodes": info["gmsh_nodes"]}
    conv = convert(msh, rodmesh, "mm")
    if conv["elements"] != info["elements"]:
        raise RuntimeError(f"meshio read {conv['elements']} tetra10 from {msh}, gmsh wrote {info['elements']}")
    return {"rodmesh": str(rodmesh), "nodes": conv["nodes"],
            "max_midside_offset_rel": conv["max_midside_offset_rel"]}


def cmd_mesh(args) -> dict:
    stl = pathlib.Path(args.stl)
    if not stl.is_file():
        raise SystemExit(f"mesh_rod: no such STL file: {stl}")
    if not (args.size > 0 and math.isfinite(args.size)):
        raise SystemExit(f"mesh_rod: --size must be a positive number of mm, got {args.size}")
    out_dir = pathlib.Path(args.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    name = args.name or stl.stem
    msh = out_dir / f"{name}.msh"
    rodmesh = out_dir / f"{name}.rodmesh"
    t0 = time.perf_counter()
    set_deadline(t0)
    size_field = pathlib.Path(args.size_field) if args.size_field else None
    if size_field is not None and not size_field.is_file():
        raise SystemExit(f"mesh_rod: no such size field file: {size_field}")
    geometry = pathlib.Path(args.geometry) if args.geometry else None
    meta = geometry.with_name(geometry.name + ".json") if geometry else None
    ladder = [tuple(rung) for rung in policy("ladder")]
    cached = None
    if geometry is not None and geometry.is_file() and meta.is_file():
        cached = json.loads(meta.read_text())
        # the classification that worked is kept: a failure with it goes to the fallbacks on that
        # classification, then back to the caller (which asks again with smaller sizes rather
        # than reclassifying six times)
        ladder = [(cached["classify_angle_deg"], cached["curve_angle_deg"])]
    failed = []
    info = None
    for rung, (angle, curve_angle) in enumerate(ladder):
        reuse = cached is not None and rung == 0
        log(f"{stl.name}: meshing at {args.size} mm (classification {angle:g} deg, curves {curve_angle:g} deg)"
            + (", size field" if size_field else "") + (", classified surface reused" if reuse else "")
            + (", curved attempt" if args.curved else ""))
        geo_in = geometry if reuse else None
        geo_out = None
        if not reuse:
            geo_out = (geometry.with_name(geometry.name + ".tmp.msh") if geometry is not None
                       else out_dir / f"{name}.classified.tmp.msh")
        curved = False
        if args.curved:
            info, why = run_attempt(stl, args.size, True, angle, curve_angle, msh, size_field, geo_in, geo_out,
                                    args.no_rodmesh)
            curved = info is not None and info["min_scaled_jacobian"] > 0.0
            if info is not None and not curved:
                log(f"curved mesh has min scaled Jacobian {info['min_scaled_jacobian']:.3g} <= 0: "
                    "falling back to straight-sided elements")
        if not curved:
            info, why = run_attempt(stl, args.size, False, angle, curve_angle, msh, size_field, geo_in, geo_out,
                                    args.no_rodmesh)
        if info is not None:
            info.update({"classify_angle_deg": angle, "curve_angle_deg": curve_angle, "curved": curved})
            if geometry is not None and geo_out is not None and geo_out.is_file():
                geo_out.replace(geometry)
                meta.write_text(json.dumps({"classify_angle_deg": angle, "curve_angle_deg": curve_angle}))
            elif geo_out is not None and geo_out.is_file():
                geo_out.unlink()
            break
        log(f"  failed: {why}")
        failed.append({"classify_angle_deg": angle, "curve_angle_deg": curve_angle, "error": why})
        if out_of_time():
            break
    if info is None:
        # the surface itself is meshed differently (the policy's fallbacks); the classification is the cached
        # one or the ladder's first
        angle, curve_angle = ladder[0]
        # shells that touch face to face are bonded first (their common faces removed)
        bonded = out_dir / f"{name}.bonded.stl"
        pairs = bond_shells(stl, bonded)
        if pairs:
            log(f"{stl.name}: {pairs} pairs of coincident opposite triangles (shells touching face to face) "
                "removed: the fallbacks mesh the bonded body")
        surface = bonded if pairs else stl
        for fallback in policy("fallbacks"):
            reuse = cached is not None and not pairs
            geo_out = None
            if fallback == "local refinement" and not reuse:
                geo_out = (geometry.with_name(geometry.name + ".tmp.msh") if geometry is not None
                           else out_dir / f"{name}.classified.tmp.msh")
            log(f"{stl.name}: every classification failed; fallback: {fallback}")
            info, why = run_fallback(fallback, surface, args.size, angle, curve_angle, msh, size_field,
                                     geometry if reuse else None, geo_out)
            if info is not None:
                if pairs:
                    info["fallback"] = f"shells bonded, {fallback}"
                    info["fallback_detail"]["coincident_triangle_pairs_removed"] = pairs
                info.update({"classify_angle_deg": angle if fallback == "local refinement" else 0.0,
                             "curve_angle_deg": curve_angle if fallback == "local refinement" else 0.0,
                             "curved": False})
                if geometry is not None and geo_out is not None and geo_out.is_file():
                    geo_out.replace(geometry)
                    meta.write_text(json.dumps({"classify_angle_deg": angle, "curve_angle_deg": curve_angle}))
            if geo_out is not None and geo_out.is_file():
                geo_out.unlink()
            if info is not None:
                break
            log(f"  failed: {why}")
            failed.append({"fallback": f"shells bonded, {fallback}" if pairs else fallback, "error": why})
        if bonded.is_file():
            bonded.unlink()
    if info is None:
        ladder_errors = [f["error"] for f in failed if "fallback" not in f]
        tried = [f"the classification ladder ({len(ladder_errors)} of {len(ladder)} settings tried, "
                 f"last error: {ladder_errors[-1] if ladder_errors else 'none'})"]
        tried += [f"{f['fallback']} ({'' if f['error'].startswith('not tried') else 'error: '}{f['error']})"
                  for f in failed if "fallback" in f]
        tried += [f"{fb} (not tried: the mesher's time limit)" for fb in policy("fallbacks")
                  if not any(f.get("fallback", "").endswith(fb) for f in failed)]
        raise SystemExit(f"mesh_rod: error: gmsh could not mesh {stl} at {args.size} mm; tried "
                         + "; ".join(tried) + f"; {policy('what_to_try')}")
    info.update({
        "stl": str(stl),
        "msh": str(msh),
        "size_mm": args.size,
        "failed_attempts": failed,
        "fallback": info.get("fallback"),
    })
    info.update(handed_off(msh, rodmesh, info, args.no_rodmesh))
    info["seconds_total"] = time.perf_counter() - t0
    log(f"{info['elements']} tet10, {info['nodes']} nodes, min SICN {info['min_sicn']:.3f}, "
        f"min SJ {info['min_scaled_jacobian']:.3f}, {info['seconds_total']:.1f} s")
    return info


def cmd_serve(args) -> None:
    """`serve`: one gmsh session for a whole adaptive sequence (see the module's doc). One JSON
    request per line on standard input, one JSON reply per line on standard output; the first
    error is replied and ends the session (the caller meshes the rest with `mesh`)."""
    import gmsh

    # the replies get their own copy of standard output; whatever gmsh's C++ side prints itself
    # (it does print some errors, Terminal 0 or not) goes to standard error with the log
    replies = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    stl = pathlib.Path(args.stl)
    geometry = pathlib.Path(args.geometry)
    if not stl.is_file():
        raise SystemExit(f"mesh_rod: no such STL file: {stl}")
    gmsh.initialize(["mesh_rod"], readConfigFiles=False, interruptible=False)
    gmsh.option.setNumber("General.Terminal", 0)
    state = {"prepared": None}
    # every mesh, and the model built for it ahead, in a thread of its own (`fixed_allocator`)
    worker = ArenaWorker(lambda: None)
    try:
        while True:
            line = sys.stdin.readline()
            if not line:
                return
            if not line.strip():
                continue
            try:
                request = json.loads(line)
                reply = worker.run(lambda: served_mesh(request, stl, geometry, state))
            except Exception as e:  # noqa: BLE001 - every failure is replied, then the session ends
                replies.write(json.dumps({"error": f"{type(e).__name__}: {e}"}) + "\n")
                replies.flush()
                return
            replies.write(json.dumps(reply, sort_keys=True) + "\n")
            replies.flush()
            worker = ArenaWorker(lambda: prepare_next(geometry, state))
    finally:
        gmsh.finalize()


def cached_classification(geometry: pathlib.Path) -> tuple[float, float] | None:
    """The classification setting cached beside `geometry` (`mesh --geometry`'s FILE.json)."""
    meta = geometry.with_name(geometry.name + ".json")
    if not (geometry.is_file() and meta.is_file()):
        return None
    cached = json.loads(meta.read_text())
    return cached["classify_angle_deg"], cached["curve_angle_deg"]


def prepare_next(geometry: pathlib.Path, state: dict) -> None:
    """Builds the next mesh's model from the cached classification while the caller works on the
    mesh just replied (its solve takes a second or more on the other core): a new model, read and
    reparametrised as a fresh process does it (0.3 s of each later mesh). The options are set
    again before meshing; those in force while the model is built do not change the mesh (design
    1's and design 5's size-field meshes compared file for file, and `tests/gmsh_session.rs`)."""
    import gmsh

    state["prepared"] = None
    classification = cached_classification(geometry)
    if classification is None:
        return
    try:
        gmsh.clear()
        patches = build_volume(pathlib.Path(), *classification, geometry, None)
    except Exception as e:  # noqa: BLE001 - the next request builds its model itself
        log(f"preparing the next model failed ({e}); the next request builds it")
        return
    state["prepared"] = (classification, patches)


def served_mesh(request: dict, stl: pathlib.Path, geometry: pathlib.Path, state: dict) -> dict:
    """One mesh of `serve`: the steps of `mesh`'s first attempt (HXT; the cached classification,
    else the ladder's first rung, which becomes the cache once it has made a mesh), in the running
    gmsh, on the model `prepare_next` built where it is that classification's."""
    import gmsh

    t0 = time.perf_counter()
    size = float(request["size"])
    if not (size > 0 and math.isfinite(size)):
        raise ValueError(f"size must be a positive number of mm, got {size}")
    size_field = pathlib.Path(request["size_field"]) if request.get("size_field") else None
    if size_field is not None and not size_field.is_file():
        raise ValueError(f"no such size field file: {size_field}")
    out_dir = pathlib.Path(request["out_dir"])
    out_dir.mkdir(parents=True, exist_ok=True)
    msh = out_dir / f"{request.get('name') or stl.stem}.msh"
    meta = geometry.with_name(geometry.name + ".json")
    cached = cached_classification(geometry)
    reused = cached is not None
    angle, curve_angle = cached if reused else tuple(policy("ladder")[0])
    geo_out = None if reused else geometry.with_name(geometry.name + ".tmp.msh")
    log(f"{stl.name}: meshing at {size} mm (classification {angle:g} deg, curves {curve_angle:g} deg)"
        + (", size field" if size_field else "") + (", classified surface reused" if reused else "")
        + ", gmsh session")
    prepared, state["prepared"] = state["prepared"], None
    if reused and prepared is not None and prepared[0] == (angle, curve_angle):
        patches = prepared[1]
        set_options(size, False, size_field is not None, False)
    else:
        # a new model, as a fresh process starts it (options, fields and views reset)
        gmsh.clear()
        set_options(size, False, size_field is not None, False)
        patches = build_volume(stl, angle, curve_angle, geometry if reused else None, geo_out)
    t1 = time.perf_counter()
    try:
        info = mesh_volume(msh, size_field, False, binary=True)
    except Exception as e:  # noqa: BLE001 - as `mesh`'s attempt: HXT's failures only
        if "HXT" not in str(e):
            raise
        # as `mesh` does it (`run_attempt`): Delaunay with Netgen's optimisation on a model
        # rebuilt from the classification just made or cached, in this session
        log(f"  HXT failed ({e}); Delaunay instead")
        gmsh.clear()
        set_options(size, False, size_field is not None, True)
        classified = geometry if reused else geo_out
        patches = build_volume(stl, angle, curve_angle, classified, None)
        t1 = time.perf_counter()
        info = mesh_volume(msh, size_field, True, binary=True)
    if geo_out is not None and geo_out.is_file():
        geo_out.replace(geometry)
        meta.write_text(json.dumps({"classify_angle_deg": angle, "curve_angle_deg": curve_angle}))
    info.update({
        "surface_patches": patches,
        "geometry_reused": reused,
        "seconds_geometry": t1 - t0,
        "classify_angle_deg": angle,
        "curve_angle_deg": curve_angle,
        "curved": False,
        "stl": str(stl),
        "msh": str(msh),
        "size_mm": size,
        "failed_attempts": [],
        "fallback": None,
        "rodmesh": None,
        "nodes": info["gmsh_nodes"],
    })
    info["seconds_total"] = time.perf_counter() - t0
    log(f"{info['elements']} tet10, {info['nodes']} nodes, min SICN {info['min_sicn']:.3f}, "
        f"min SJ {info['min_scaled_jacobian']:.3f}, {info['seconds_total']:.1f} s")
    return info


def gmsh_step_mesh(step: pathlib.Path, frame: list, scale: float, size_mm: float, msh_out: pathlib.Path,
                   size_field: pathlib.Path | None, delaunay: bool) -> dict:
    """One curved tet10 mesh of the STEP solid in the rod frame (see `mesh-step` above)."""
    import gmsh

    t0 = time.perf_counter()
    gmsh.initialize(["mesh_rod"], readConfigFiles=False, interruptible=False)
    try:
        for k, v in gmsh_options(size_mm, True, size_field is not None).items():
            gmsh.option.setNumber(k, v)
        # `Mesh.HighOrderOptimize` stays 0: gmsh's optimiser (1 or 2) visits the elements in the
        # order of their memory addresses, so the same STEP gave another mesh on every run, and it
        # took 2-26 s per mesh (the foreign fillet rod at 4 mm). The few poor curved elements are
        # made straight-sided instead (`straighten_poor_curved`), the same way on every run.
        gmsh.option.setNumber("Geometry.OCCScaling", 1.0)
        gmsh.option.setString("Geometry.OCCTargetUnit", "MM")
        if delaunay:
            gmsh.option.setNumber("Mesh.Algorithm3D", algorithm_code(True))
        gmsh.model.add("rod")
        occ = gmsh.model.occ
        ents = occ.importShapes(str(step))
        solids = [(d, t) for d, t in ents if d == 3]
        if not solids:
            raise RuntimeError(f"{step}: no closed solid in the file")
        if len(solids) > 1:
            out, _ = occ.fuse(solids[:1], solids[1:])
            solids = [(d, t) for d, t in out if d == 3]
        o = np.asarray(frame[:3], dtype=np.float64)
        r = np.asarray(frame[3:], dtype=np.float64).reshape(3, 3)
        a = np.hstack([scale * r, (-scale * r @ o).reshape(3, 1)])
        occ.affineTransform(solids, a.reshape(-1).tolist())
        occ.synchronize()
        size_field_tets = add_size_field(size_field)[0] if size_field is not None else 0
        t1 = time.perf_counter()
        gmsh.model.mesh.generate(3)
        t2 = time.perf_counter()
        straightened = straighten_poor_curved()
        tags10, min_sj, min_sicn = tet10_qualities()
        if min_sj.min() <= 0.0:
            raise RuntimeError(f"{step}: {int((min_sj <= 0).sum())} element(s) inverted even with straight sides "
                               f"(min scaled Jacobian {min_sj.min():.3g}): not solved on; try another element "
                               f"size, or repair the STEP where faces meet at a sliver")
        if delaunay is False and min_sicn.min() < policy("min_sicn"):
            raise RuntimeError(f"HXT left a sliver (min SICN {min_sicn.min():.2e} < {policy('min_sicn')})")
        return {
            **written_mesh((tags10, min_sj, min_sicn), msh_out),
            "solids": len(solids),
            **straightened,
            "size_field_tetrahedra": size_field_tets,
            "algorithm_3d": algorithm_name(algorithm_code(delaunay)),
            "seconds_geometry": t1 - t0,
            "seconds_mesh": t2 - t1,
            "gmsh_version": gmsh.option.getString("General.Version"),
        }
    finally:
        gmsh.finalize()


# gmsh's 10-node tetrahedron: midside node 4 + k on the edge GMSH_TET10_EDGES[k] (manual, "Node ordering")
GMSH_TET10_EDGES = ((0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1))


def straighten_poor_curved() -> dict:
    """Makes the curved 10-node tetrahedra whose minimum scaled Jacobian is below `threshold`
    straight-sided: each midside node of such an element goes back to the midpoint of its edge's
    corners (the neighbours sharing the edge share that straight edge), in rounds until no poor
    element has a curved edge left. A straight-sided element is as good as its corner tetrahedron,
    which the mesher made valid. Deterministic: the same mesh gives the same result on every run,
    where gmsh's high-order optimiser does not. Where the elements are too coarse for a fillet
    (an R1 fillet under 4 mm elements) the fillet is then meshed by its chords, as from an STL;
    the adaptive loop's smaller elements there are curved again. `threshold`: the policy's
    `curved_sj_min`. Returns the counts."""
    import gmsh

    threshold = policy("curved_sj_min")

    types, tags, conn = gmsh.model.mesh.getElements(3)
    if len(types) != 1 or types[0] != 11:
        raise RuntimeError(f"gmsh produced element types {list(types)}, expected only 10-node tets (11)")
    tags10 = np.asarray(tags[0])
    conn = np.asarray(conn[0], dtype=np.int64).reshape(-1, 10)
    node_tags, xyz, _ = gmsh.model.mesh.getNodes()
    row = np.zeros(int(np.max(node_tags)) + 1, dtype=np.int64)
    row[np.asarray(node_tags, dtype=np.int64)] = np.arange(len(node_tags))
    x = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
    moved: set[int] = set()
    elements: set[int] = set()
    while True:  # each round straightens at least one curved edge, so the rounds end
        sj = np.asarray(gmsh.model.mesh.getElementQualities(tags10, "minSJ"))
        corners = x[row[conn[:, :4]]]
        mids = np.stack([0.5 * (corners[:, a] + corners[:, b]) for a, b in GMSH_TET10_EDGES], axis=1)
        off = np.linalg.norm(x[row[conn[:, 4:]]] - mids, axis=2) > 0.0
        poor = np.flatnonzero((sj < threshold) & off.any(axis=1))
        if poor.size == 0:
            break
        for e in poor:
            elements.add(int(tags10[e]))
            for k in np.flatnonzero(off[e]):
                tag = int(conn[e, 4 + k])
                x[row[tag]] = mids[e, k]
                gmsh.model.mesh.setNode(tag, mids[e, k].tolist(), [])
                moved.add(tag)
    return {"curved_elements_straightened": len(elements), "midside_nodes_straightened": len(moved)}


def cmd_mesh_step(args) -> dict:
    step = pathlib.Path(args.step)
    if not step.is_file():
        raise SystemExit(f"mesh_rod: no such STEP file: {step}")
    if len(args.frame) != 12:
        raise SystemExit(f"mesh_rod: --frame takes 12 numbers, got {len(args.frame)}")
    if not (args.size > 0 and math.isfinite(args.size)):
        raise SystemExit(f"mesh_rod: --size must be a positive number of mm, got {args.size}")
    out_dir = pathlib.Path(args.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    name = args.name or step.stem
    msh, rodmesh = out_dir / f"{name}.msh", out_dir / f"{name}.rodmesh"
    size_field = pathlib.Path(args.size_field) if args.size_field else None
    t0 = time.perf_counter()
    log(f"{step.name}: curved tet10 at {args.size} mm on the exact geometry" + (", size field" if size_field else ""))
    failed = []
    info = None
    for delaunay in (False, True):
        try:
            info = gmsh_step_mesh(step, args.frame, args.scale, args.size, msh, size_field, delaunay)
            break
        except Exception as e:  # gmsh raises Exception with its last error
            failed.append({"algorithm_3d": algorithm_name(algorithm_code(delaunay)), "error": str(e)})
            log(f"  failed: {e}")
    if info is None:
        raise SystemExit(f"mesh_rod: gmsh could not mesh {step} at {args.size} mm: "
                         + "; ".join(f["error"] for f in failed))
    info.update({"stl": str(step), "msh": str(msh), "size_mm": args.size, "curved": True,
                 "classify_angle_deg": 0.0, "curve_angle_deg": 0.0, "failed_attempts": failed})
    info.update(handed_off(msh, rodmesh, info, args.no_rodmesh))
    info["seconds_total"] = time.perf_counter() - t0
    log(f"{info['elements']} curved tet10 ({info['curved_elements_straightened']} made straight-sided), "
        f"{info['nodes']} nodes, min SJ {info['min_scaled_jacobian']:.3f}, {info['seconds_total']:.1f} s")
    return info


def cmd_attempt(args) -> dict:
    """Internal: one gmsh run, writing the .msh; used by `mesh` in a child process."""
    path = lambda v: pathlib.Path(v) if v else None  # noqa: E731
    return gmsh_volume_mesh(pathlib.Path(args.stl), args.size, args.curved, args.angle, args.curve_angle,
                            pathlib.Path(args.msh), path(args.size_field), path(args.geometry_in),
                            path(args.geometry_out), args.delaunay, args.binary)


def cmd_fallback(args) -> dict:
    """Internal: one fallback of the policy's, writing the .msh; used by `mesh` in a child process."""
    path = lambda v: pathlib.Path(v) if v else None  # noqa: E731
    if args.strategy == "local refinement":
        return gmsh_local_refinement(pathlib.Path(args.stl), args.size, args.angle, args.curve_angle,
                                     pathlib.Path(args.msh), path(args.size_field), path(args.geometry_in),
                                     path(args.geometry_out))
    if args.strategy == "STL surface kept":
        return gmsh_surface_kept(pathlib.Path(args.stl), args.size, pathlib.Path(args.msh), path(args.size_field))
    raise SystemExit(f"mesh_rod: unknown fallback {args.strategy!r} (this script knows 'local refinement' "
                     "and 'STL surface kept')")


# ---------------------------------------------------------------------------------------------
# meshio conversion and the .rodmesh writer
# ---------------------------------------------------------------------------------------------

def promote_tetra4(points: np.ndarray, tets: np.ndarray):
    """Linear tets -> straight-sided tetra10 (VTK order): one new node per unique edge, at its midpoint."""
    edges = np.concatenate([tets[:, [a, b]] for a, b in TET10_EDGES], axis=0)
    edges.sort(axis=1)
    uniq, inverse = np.unique(edges, axis=0, return_inverse=True)
    mid = 0.5 * (points[uniq[:, 0]] + points[uniq[:, 1]])
    new_ids = len(points) + inverse.reshape(len(TET10_EDGES), len(tets)).T
    return np.vstack([points, mid]), np.hstack([tets, new_ids])


def convert(inp: pathlib.Path, out: pathlib.Path, units: str) -> dict:
    import meshio

    if units not in ("mm", "m"):
        raise SystemExit(f"mesh_rod: --units must be mm or m, got {units}")
    m = meshio.read(str(inp))
    points = np.asarray(m.points, dtype=np.float64)
    if points.shape[1] == 2:
        raise SystemExit(f"mesh_rod: {inp} is a 2D mesh")
    blocks10 = [np.asarray(c.data, dtype=np.int64) for c in m.cells if c.type == "tetra10"]
    blocks4 = [np.asarray(c.data, dtype=np.int64) for c in m.cells if c.type == "tetra"]
    kinds = sorted({c.type for c in m.cells})
    if blocks10 and blocks4:
        raise SystemExit(f"mesh_rod: {inp} mixes tetra and tetra10 cells; give one kind")
    if blocks10:
        tets = np.concatenate(blocks10)
    elif blocks4:
        log(f"{inp.name}: linear tetrahedra promoted to straight-sided tetra10")
        points, tets = promote_tetra4(points, np.concatenate(blocks4))
    else:
        raise SystemExit(f"mesh_rod: {inp} has no tetrahedra (cell types: {', '.join(kinds) or 'none'})")
    # Keep only the nodes the tets use, renumbered in their original order.
    used = np.unique(tets)
    remap = np.full(len(points), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    points = points[used]
    tets = remap[tets]
    # Midside nodes must sit near their edge midpoints (straight: exactly on them); a large offset
    # means a wrong node order. Report the worst one relative to the edge length.
    offs = []
    for k, (a, b) in enumerate(TET10_EDGES):
        pa, pb, pm = points[tets[:, a]], points[tets[:, b]], points[tets[:, 4 + k]]
        offs.append(np.linalg.norm(pm - 0.5 * (pa + pb), axis=1) / np.linalg.norm(pb - pa, axis=1))
    max_off = float(np.max(offs)) if len(tets) else 0.0
    write_rodmesh(out, points, tets, units, source=str(inp))
    return {"nodes": int(len(points)), "elements": int(len(tets)), "units": units,
            "max_midside_offset_rel": max_off, "input_cell_types": kinds,
            "rodmesh": str(out)}


def write_rodmesh(path: pathlib.Path, points: np.ndarray, tets: np.ndarray, units: str, source: str) -> None:
    lines = [FORMAT_HEADER, f"# from {pathlib.Path(source).name}", f"units {units}", f"nodes {len(points)}"]
    lines.extend(f"{x!r} {y!r} {z!r}" for x, y, z in points.tolist())
    lines.append(f"tet10 {len(tets)}")
    lines.extend(" ".join(map(str, row)) for row in tets.tolist())
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text("\n".join(lines) + "\n")
    tmp.replace(path)


def cmd_convert(args) -> dict:
    t0 = time.perf_counter()
    info = convert(pathlib.Path(args.input), pathlib.Path(args.output), args.units)
    info["seconds_total"] = time.perf_counter() - t0
    log(f"{args.input} -> {args.output}: {info['elements']} tetra10, {info['nodes']} nodes")
    return info


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    pm = sub.add_parser("mesh", help="STL -> tet10 volume mesh (.msh + .rodmesh)")
    pm.add_argument("stl")
    pm.add_argument("out_dir")
    pm.add_argument("--size", type=float, required=True, help="target element size, mm")
    pm.add_argument("--name", help="output base name (default: the STL's stem)")
    pm.add_argument("--curved", action="store_true",
                    help="try midside nodes on the surface; fall back to straight if any element inverts")
    pm.add_argument("--size-field", help="local size map: raw float64, 16 per tetrahedron (see above)")
    pm.add_argument("--geometry", help="cache of the classified surface (written once, then reused)")
    pm.add_argument("--no-rodmesh", action="store_true",
                    help="write no .rodmesh (the caller reads the .msh natively)")
    pa = sub.add_parser("_attempt", help=argparse.SUPPRESS)
    pa.add_argument("stl")
    pa.add_argument("msh")
    pa.add_argument("--size", type=float, required=True)
    pa.add_argument("--angle", type=float, required=True)
    pa.add_argument("--curve-angle", type=float, required=True)
    pa.add_argument("--curved", action="store_true")
    pa.add_argument("--size-field")
    pa.add_argument("--geometry-in")
    pa.add_argument("--geometry-out")
    pa.add_argument("--delaunay", action="store_true")
    pa.add_argument("--binary", action="store_true")
    pf = sub.add_parser("_fallback", help=argparse.SUPPRESS)
    pf.add_argument("strategy")
    pf.add_argument("stl")
    pf.add_argument("msh")
    pf.add_argument("--size", type=float, required=True)
    pf.add_argument("--angle", type=float, required=True)
    pf.add_argument("--curve-angle", type=float, required=True)
    pf.add_argument("--size-field")
    pf.add_argument("--geometry-in")
    pf.add_argument("--geometry-out")
    ps = sub.add_parser("mesh-step", help="STEP solid -> curved tet10 in the rod frame (.msh + .rodmesh)")
    ps.add_argument("step")
    ps.add_argument("out_dir")
    ps.add_argument("--frame", type=lambda v: [float(x) for x in v.split(",")], required=True,
                    help="origin (3) and the rod frame's x, y, z axes (3 each), file coordinates, "
                         "12 numbers separated by commas")
    ps.add_argument("--scale", type=float, required=True, help="millimetres per file unit")
    ps.add_argument("--size", type=float, required=True, help="target element size, mm")
    ps.add_argument("--name", help="output base name (default: the STEP's stem)")
    ps.add_argument("--size-field", help="local size map: raw float64, 16 per tetrahedron (see above)")
    ps.add_argument("--no-rodmesh", action="store_true",
                    help="write no .rodmesh (the caller reads the .msh natively)")
    pc = sub.add_parser("convert", help="any meshio volume mesh -> .rodmesh")
    pc.add_argument("input")
    pc.add_argument("output")
    pc.add_argument("--units", default="mm", help="units of the input coordinates: mm (default) or m")
    pv = sub.add_parser("serve", help="one gmsh session for an adaptive sequence: JSON requests on stdin")
    pv.add_argument("stl")
    pv.add_argument("--geometry", required=True, help="the classified-surface cache, as `mesh --geometry`")
    for p in (pm, pa, pf, ps, pv):
        p.add_argument("--policy", type=json.loads, required=True,
                       help="the meshing policy, JSON (rodstudy's src/mesher/policy.rs; "
                            "`rodstudy pipeline mesh_rod.py ...` adds it)")
    args = ap.parse_args(argv)
    if getattr(args, "policy", None) is not None:
        POLICY.update(args.policy)
    fixed_allocator()
    if args.cmd == "serve":
        cmd_serve(args)
        return 0
    command = {"mesh": cmd_mesh, "mesh-step": cmd_mesh_step, "convert": cmd_convert,
               "_attempt": cmd_attempt, "_fallback": cmd_fallback}[args.cmd]
    info = in_fresh_arena(command, args)
    print(json.dumps(info, sort_keys=True))
    return 0


if __name__ == "__main__":
    sys.exit(main())
