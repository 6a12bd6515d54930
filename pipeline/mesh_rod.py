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

The code: this script parses the command line; the package `meshing/` beside it does the work, one
concept per module: `policy` (the policy received, gmsh's options, the log), `arena` (each mesh in
an allocator arena of its own), `size_field`, `quality` (what a mesh reports), `cap` (a half
model's cap), `volume` (the usual route: classify, reparametrise, mesh), `children` (the runs of
`mesh` in child processes, the time limit), `fallbacks`, `stl_mesh` (`mesh`), `serve`, `step`
(`mesh-step`) and `rodmesh` (`convert` and the hand-off file).
"""

from __future__ import annotations

import argparse
import json
import pathlib
import sys

from meshing.arena import fixed_allocator, in_fresh_arena
from meshing.fallbacks import gmsh_local_refinement, gmsh_surface_kept
from meshing.policy import POLICY
from meshing.rodmesh import cmd_convert
from meshing.serve import cmd_serve
from meshing.step import cmd_mesh_step
from meshing.stl_mesh import cmd_mesh
from meshing.volume import gmsh_volume_mesh


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
