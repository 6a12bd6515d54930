"""`mesh-step`: a STEP solid (the exact B-rep, through OpenCASCADE) in the rod frame to curved
tet10, the poor curved elements made straight-sided."""

from __future__ import annotations

import math
import pathlib
import time

import numpy as np

from .policy import algorithm_code, algorithm_name, gmsh_options, log, policy
from .quality import tet10_qualities, written_mesh
from .rodmesh import handed_off
from .size_field import add_size_field


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
