"""`serve`: one gmsh session for a whole adaptive sequence of meshes of one STL."""

from __future__ import annotations

import json
import math
import os
import pathlib
import sys
import time

from .arena import ArenaWorker
from .policy import log, policy, set_options
from .volume import build_volume, mesh_volume


def cmd_serve(args) -> None:
    """`serve`: one gmsh session for a whole adaptive sequence (see the module's doc). One JSON
    request per line on standard input, one JSON reply per line on standard output; the first
    error is replied and ends the session (the caller meshes the rest with `mesh`)."""
    import gmsh

    # the replies get their own copy of standard output; whatever gmsh's C++ side prints itself
    # (it does print some errors, Terminal 0 or not) goes to standard error with the log
    replies = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    stl = pathlib.Path(args.stl)
    geometry = pathlib.Path(args.geometry)
    if not stl.is_file():
        raise SystemExit(f"mesh_rod: no such STL file: {stl}")
    gmsh.initialize(["mesh_rod"], readConfigFiles=False, interruptible=False)
    gmsh.option.setNumber("General.Terminal", 0)
    state = {"prepared": None}
    # every mesh, and the model built for it ahead, in a thread of its own (`fixed_allocator`)
    worker = ArenaWorker(lambda: None)
    try:
        while True:
            line = sys.stdin.readline()
            if not line:
                return
            if not line.strip():
                continue
            try:
                request = json.loads(line)
                reply = worker.run(lambda: served_mesh(request, stl, geometry, state))
            except Exception as e:  # noqa: BLE001 - every failure is replied, then the session ends
                replies.write(json.dumps({"error": f"{type(e).__name__}: {e}"}) + "\n")
                replies.flush()
                return
            replies.write(json.dumps(reply, sort_keys=True) + "\n")
            replies.flush()
            worker = ArenaWorker(lambda: prepare_next(geometry, state))
    finally:
        gmsh.finalize()


def cached_classification(geometry: pathlib.Path) -> tuple[float, float] | None:
    """The classification setting cached beside `geometry` (`mesh --geometry`'s FILE.json)."""
    meta = geometry.with_name(geometry.name + ".json")
    if not (geometry.is_file() and meta.is_file()):
        return None
    cached = json.loads(meta.read_text())
    return cached["classify_angle_deg"], cached["curve_angle_deg"]


def prepare_next(geometry: pathlib.Path, state: dict) -> None:
    """Builds the next mesh's model from the cached classification while the caller works on the
    mesh just replied (its solve takes a second or more on the other core): a new model, read and
    reparametrised as a fresh process does it (0.3 s of each later mesh). The options are set
    again before meshing; those in force while the model is built do not change the mesh (design
    1's and design 5's size-field meshes compared file for file, and `tests/gmsh_session.rs`)."""
    import gmsh

    state["prepared"] = None
    classification = cached_classification(geometry)
    if classification is None:
        return
    try:
        gmsh.clear()
        patches = build_volume(pathlib.Path(), *classification, geometry, None)
    except Exception as e:  # noqa: BLE001 - the next request builds its model itself
        log(f"preparing the next model failed ({e}); the next request builds it")
        return
    state["prepared"] = (classification, patches)


def served_mesh(request: dict, stl: pathlib.Path, geometry: pathlib.Path, state: dict) -> dict:
    """One mesh of `serve`: the steps of `mesh`'s first attempt (HXT; the cached classification,
    else the ladder's first rung, which becomes the cache once it has made a mesh), in the running
    gmsh, on the model `prepare_next` built where it is that classification's."""
    import gmsh

    t0 = time.perf_counter()
    size = float(request["size"])
    if not (size > 0 and math.isfinite(size)):
        raise ValueError(f"size must be a positive number of mm, got {size}")
    size_field = pathlib.Path(request["size_field"]) if request.get("size_field") else None
    if size_field is not None and not size_field.is_file():
        raise ValueError(f"no such size field file: {size_field}")
    out_dir = pathlib.Path(request["out_dir"])
    out_dir.mkdir(parents=True, exist_ok=True)
    msh = out_dir / f"{request.get('name') or stl.stem}.msh"
    meta = geometry.with_name(geometry.name + ".json")
    cached = cached_classification(geometry)
    reused = cached is not None
    angle, curve_angle = cached if reused else tuple(policy("ladder")[0])
    geo_out = None if reused else geometry.with_name(geometry.name + ".tmp.msh")
    log(f"{stl.name}: meshing at {size} mm (classification {angle:g} deg, curves {curve_angle:g} deg)"
        + (", size field" if size_field else "") + (", classified surface reused" if reused else "")
        + ", gmsh session")
    prepared, state["prepared"] = state["prepared"], None
    if reused and prepared is not None and prepared[0] == (angle, curve_angle):
        patches = prepared[1]
        set_options(size, False, size_field is not None, False)
    else:
        # a new model, as a fresh process starts it (options, fields and views reset)
        gmsh.clear()
        set_options(size, False, size_field is not None, False)
        patches = build_volume(stl, angle, curve_angle, geometry if reused else None, geo_out)
    t1 = time.perf_counter()
    try:
        info = mesh_volume(msh, size_field, False, binary=True)
    except Exception as e:  # noqa: BLE001 - as `mesh`'s attempt: HXT's failures only
        if "HXT" not in str(e):
            raise
        # as `mesh` does it (`run_attempt`): Delaunay with Netgen's optimisation on a model
        # rebuilt from the classification just made or cached, in this session
        log(f"  HXT failed ({e}); Delaunay instead")
        gmsh.clear()
        set_options(size, False, size_field is not None, True)
        classified = geometry if reused else geo_out
        patches = build_volume(stl, angle, curve_angle, classified, None)
        t1 = time.perf_counter()
        info = mesh_volume(msh, size_field, True, binary=True)
    if geo_out is not None and geo_out.is_file():
        geo_out.replace(geometry)
        meta.write_text(json.dumps({"classify_angle_deg": angle, "curve_angle_deg": curve_angle}))
    info.update({
        "surface_patches": patches,
        "geometry_reused": reused,
        "seconds_geometry": t1 - t0,
        "classify_angle_deg": angle,
        "curve_angle_deg": curve_angle,
        "curved": False,
        "stl": str(stl),
        "msh": str(msh),
        "size_mm": size,
        "failed_attempts": [],
        "fallback": None,
        "rodmesh": None,
        "nodes": info["gmsh_nodes"],
    })
    info["seconds_total"] = time.perf_counter() - t0
    log(f"{info['elements']} tet10, {info['nodes']} nodes, min SICN {info['min_sicn']:.3f}, "
        f"min SJ {info['min_scaled_jacobian']:.3f}, {info['seconds_total']:.1f} s")
    return info
