"""`convert` and the `.rodmesh` hand-off file (format in `mesh_rod.py`'s doc): any volume mesh
meshio reads, linear tetrahedra promoted to straight-sided tetra10 (VTK's node order)."""

from __future__ import annotations

import pathlib
import time

import numpy as np

from .policy import log


FORMAT_HEADER = "rodmesh 1"


# VTK/meshio tetra10 edges, in the order of the midside nodes 4..9.
TET10_EDGES = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)]


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


def cmd_convert(args) -> dict:
    t0 = time.perf_counter()
    info = convert(pathlib.Path(args.input), pathlib.Path(args.output), args.units)
    info["seconds_total"] = time.perf_counter() - t0
    log(f"{args.input} -> {args.output}: {info['elements']} tetra10, {info['nodes']} nodes")
    return info
