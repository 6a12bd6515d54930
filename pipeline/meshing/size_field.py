"""A local element-size map (`--size-field FILE`: raw little-endian float64, 16 per tetrahedron:
x0..x3, y0..y3, z0..z3, s0..s3) read, checked and handed to gmsh as a `PostView` field."""

from __future__ import annotations

import pathlib

import numpy as np


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


def field_size_near(data: np.ndarray, p: np.ndarray) -> float:
    """The smallest size of the size-field tetrahedron whose centroid is nearest to `p`."""
    centroids = np.stack([data[:, 0:4].mean(axis=1), data[:, 4:8].mean(axis=1), data[:, 8:12].mean(axis=1)],
                         axis=1)
    k = int(np.argmin(((centroids - p) ** 2).sum(axis=1)))
    return float(data[k, 12:16].min())
