"""Mass properties of a closed triangle mesh (SPEC Stage 1 method), numpy."""

from __future__ import annotations

import numpy as np

from .definitions import DENSITY, KG_PER_MM3, KGM2_PER_KGMM2


def summarize(vol_mm3: float, centroid_mm, inertia_kgm2) -> dict:
    return {"volume": vol_mm3, "mass": vol_mm3 * KG_PER_MM3, "centroid": np.asarray(centroid_mm),
            "l1": float(centroid_mm[0]), "ixx": float(inertia_kgm2[0, 0]), "izz": float(inertia_kgm2[2, 2]),
            "inertia": np.asarray(inertia_kgm2)}


def mesh_mass_properties(vertices, triangles, density: float = DENSITY) -> dict:
    """Volume [mm^3], mass [kg], centroid [mm] and inertia tensor about the centroid [kg m^2] of a
    closed, outward-oriented triangle mesh in mm, by the divergence theorem over signed tetrahedra
    (reference point: bounding-box centre, so far-from-origin meshes lose no digits).
    For a tetrahedron (r, r+a, r+b, r+c): V = a.(b x c)/6, first moment V (a+b+c)/4, second moments
    int x_i x_j dV = V/20 (sum_k v_k,i v_k,j + s_i s_j) with s = a + b + c."""
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64)
    ref = 0.5 * (v.min(axis=0) + v.max(axis=0))
    a, b, c = v[t[:, 0]] - ref, v[t[:, 1]] - ref, v[t[:, 2]] - ref
    vol_t = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    volume = vol_t.sum()
    s = a + b + c
    first = (vol_t[:, None] * s).sum(axis=0) / 4.0
    d = first / volume  # centroid relative to ref
    second = (np.einsum("n,ni,nj->ij", vol_t, a, a) + np.einsum("n,ni,nj->ij", vol_t, b, b)
              + np.einsum("n,ni,nj->ij", vol_t, c, c) + np.einsum("n,ni,nj->ij", vol_t, s, s)) / 20.0
    second_c = second - volume * np.outer(d, d)  # parallel-axis shift to the centroid
    inertia = (np.trace(second_c) * np.eye(3) - second_c) * density * 1e-9 * KGM2_PER_KGMM2
    props = summarize(volume, ref + d, inertia)
    props["mass"] = volume * density * 1e-9
    return props
