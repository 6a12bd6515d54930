"""The tessellated surface: triangles from gmsh welded by float32 value, oriented consistently and
outward, validated (closed, 2-manifold, one shell, no degenerate triangle), pin axes clear."""

from __future__ import annotations

import collections

import gmsh
import numpy as np


def surface_triangles():
    """Surface triangles of the current gmsh model: float32 vertices (welded by value) and indices."""
    gmsh.model.mesh.clear()
    gmsh.model.mesh.generate(2)
    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    _, tri_nodes = gmsh.model.mesh.getElementsByType(2)
    xyz = np.asarray(coords, dtype=np.float64).reshape(-1, 3)
    index = np.zeros(int(node_tags.max()) + 1, dtype=np.int64)
    index[node_tags.astype(np.int64)] = np.arange(len(node_tags))
    tris = index[np.asarray(tri_nodes, dtype=np.int64).reshape(-1, 3)]
    # Weld by float32 value (-0.0 == 0.0), exactly as the stored file will be read.
    xyz32 = xyz.astype(np.float32) + np.float32(0.0)
    uniq, inverse = np.unique(xyz32, axis=0, return_inverse=True)
    return uniq, inverse.reshape(-1)[tris]


def edge_pairs(tris: np.ndarray):
    """For every undirected edge the two triangles sharing it; raises unless each edge has exactly 2.
    Returns (tri_i, tri_j, same_direction) arrays, one entry per edge."""
    n = len(tris)
    a = tris.reshape(-1)
    b = tris[:, [1, 2, 0]].reshape(-1)
    owner = np.repeat(np.arange(n), 3)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    forward = a < hi  # direction of this half-edge relative to (lo -> hi)
    key = lo.astype(np.int64) * (int(a.max()) + 1) + hi
    order = np.argsort(key, kind="stable")
    key_s = key[order]
    _, counts = np.unique(key_s, return_counts=True)
    if np.any(counts != 2):
        bad = np.count_nonzero(counts != 2)
        raise ValueError(f"mesh not closed/2-manifold: {bad} edges not shared by exactly two triangles")
    i, j = order[0::2], order[1::2]
    return owner[i], owner[j], forward[i] == forward[j]


def orient_outward(tris: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """Consistent winding by breadth-first search over edge adjacency (each shared edge traversed in
    opposite directions by its two triangles), then outward (positive signed volume)."""
    n = len(tris)
    ti, tj, same = edge_pairs(tris)
    # adjacency in CSR form: for each triangle its neighbours and whether the pair needs a relative flip
    src = np.concatenate([ti, tj])
    dst = np.concatenate([tj, ti])
    rel = np.concatenate([same, same])
    order = np.argsort(src, kind="stable")
    dst, rel = dst[order], rel[order]
    start = np.searchsorted(src[order], np.arange(n + 1))
    flip = np.full(n, -1, dtype=np.int8)
    flip[0] = 0
    queue = collections.deque([0])
    while queue:
        t = queue.popleft()
        for k in range(start[t], start[t + 1]):
            u, want = dst[k], flip[t] ^ int(rel[k])
            if flip[u] < 0:
                flip[u] = want
                queue.append(u)
            elif flip[u] != want:
                raise ValueError("mesh is not orientable")
    if np.any(flip < 0):
        raise ValueError(f"mesh has more than one shell ({np.count_nonzero(flip < 0)} triangles unreached)")
    out = tris.copy()
    out[flip == 1] = out[flip == 1][:, ::-1]
    if signed_volume(vertices, out) < 0:
        out = out[:, ::-1].copy()
    return out


def signed_volume(vertices, tris) -> float:
    v = np.asarray(vertices, dtype=np.float64)
    ref = 0.5 * (v.min(axis=0) + v.max(axis=0))
    a, b, c = v[tris[:, 0]] - ref, v[tris[:, 1]] - ref, v[tris[:, 2]] - ref
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def validate_mesh(vertices, tris, label: str) -> None:
    """Closed, consistently oriented, one shell, no degenerate triangle, positive volume."""
    v = np.asarray(vertices, dtype=np.float64)
    problems = []
    if np.any((tris[:, 0] == tris[:, 1]) | (tris[:, 1] == tris[:, 2]) | (tris[:, 2] == tris[:, 0])):
        problems.append("triangle with a repeated vertex")
    p0, p1, p2 = v[tris[:, 0]], v[tris[:, 1]], v[tris[:, 2]]
    cross = np.linalg.norm(np.cross(p1 - p0, p2 - p0), axis=1)
    longest2 = np.max([np.sum((p1 - p0) ** 2, 1), np.sum((p2 - p1) ** 2, 1), np.sum((p0 - p2) ** 2, 1)], axis=0)
    degenerate = cross <= 1e-9 * longest2  # (near-)collinear corners
    if np.any(degenerate):
        problems.append(f"{np.count_nonzero(degenerate)} degenerate triangles")
    try:
        _, _, same = edge_pairs(tris)
        if np.any(same):
            problems.append(f"{np.count_nonzero(same)} edges traversed in the same direction (inconsistent winding)")
        # one connected shell: orienting again must reach every triangle
        orient_outward(tris, v)
    except ValueError as e:
        problems.append(str(e))
    if signed_volume(v, tris) <= 0:
        problems.append("non-positive volume (inward normals)")
    if problems:
        raise ValueError(f"{label}: invalid mesh: " + "; ".join(problems))


def pin_axes_clear(vertices, tris, centres_xy) -> list:
    """Lines along z through each centre that hit a triangle (should be none: the bores are through)."""
    v = np.asarray(vertices, dtype=np.float64)
    hits = []
    for cx, cy in centres_xy:
        p0, p1, p2 = v[tris[:, 0], :2], v[tris[:, 1], :2], v[tris[:, 2], :2]
        d1 = (p1[:, 0] - p0[:, 0]) * (cy - p0[:, 1]) - (p1[:, 1] - p0[:, 1]) * (cx - p0[:, 0])
        d2 = (p2[:, 0] - p1[:, 0]) * (cy - p1[:, 1]) - (p2[:, 1] - p1[:, 1]) * (cx - p1[:, 0])
        d3 = (p0[:, 0] - p2[:, 0]) * (cy - p2[:, 1]) - (p0[:, 1] - p2[:, 1]) * (cx - p2[:, 0])
        inside = ((d1 >= 0) & (d2 >= 0) & (d3 >= 0)) | ((d1 <= 0) & (d2 <= 0) & (d3 <= 0))
        if np.any(inside):
            hits.append((cx, cy))
    return hits
