"""What every meshing route reports of its mesh: the 10-node tetrahedra's quality (gmsh's minSJ,
minSICN), the counts, the written file, and gmsh's own phase times from its log."""

from __future__ import annotations

import pathlib
import re

import numpy as np


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
