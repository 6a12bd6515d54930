"""The fallbacks: a new surface mesh where every classification of the policy's ladder fails
("local refinement", "STL surface kept"), and the bonding of shells that touch face to face."""

from __future__ import annotations

import math
import pathlib
import re
import time

import numpy as np

from .cap import cap_open_cut
from .policy import algorithm_code, gmsh_options, log, policy, set_options
from .quality import tet10_qualities, written_mesh
from .size_field import add_size_field, field_size_near, read_size_field
from .volume import build_volume


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
