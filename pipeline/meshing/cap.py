"""The half model's cap: an open cut z = c closed with plane surfaces on the classified curves."""

from __future__ import annotations

from .policy import policy


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
