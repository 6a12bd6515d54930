"""The usual route of `mesh`: the STL classified into patches, reparametrised, closed into one
volume and meshed with the policy's 3D algorithm (one attempt, in the process it is called in)."""

from __future__ import annotations

import math
import pathlib
import time

from .cap import cap_open_cut
from .policy import algorithm_name, policy, set_options
from .quality import meshing_phases, tet10_qualities, written_mesh
from .size_field import add_size_field


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
