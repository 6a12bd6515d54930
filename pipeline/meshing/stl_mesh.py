"""`mesh`: an STL to a tet10 volume mesh: the policy's classification ladder, then its fallbacks,
each run in a child process; a total failure ends in one message naming everything tried."""

from __future__ import annotations

import json
import math
import pathlib
import time

from .children import out_of_time, run_attempt, run_fallback, set_deadline
from .fallbacks import bond_shells
from .policy import log, policy
from .rodmesh import handed_off


def cmd_mesh(args) -> dict:
    stl = pathlib.Path(args.stl)
    if not stl.is_file():
        raise SystemExit(f"mesh_rod: no such STL file: {stl}")
    if not (args.size > 0 and math.isfinite(args.size)):
        raise SystemExit(f"mesh_rod: --size must be a positive number of mm, got {args.size}")
    out_dir = pathlib.Path(args.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    name = args.name or stl.stem
    msh = out_dir / f"{name}.msh"
    rodmesh = out_dir / f"{name}.rodmesh"
    t0 = time.perf_counter()
    set_deadline(t0)
    size_field = pathlib.Path(args.size_field) if args.size_field else None
    if size_field is not None and not size_field.is_file():
        raise SystemExit(f"mesh_rod: no such size field file: {size_field}")
    geometry = pathlib.Path(args.geometry) if args.geometry else None
    meta = geometry.with_name(geometry.name + ".json") if geometry else None
    ladder = [tuple(rung) for rung in policy("ladder")]
    cached = None
    if geometry is not None and geometry.is_file() and meta.is_file():
        cached = json.loads(meta.read_text())
        # the classification that worked is kept: a failure with it goes to the fallbacks on that
        # classification, then back to the caller (which asks again with smaller sizes rather
        # than reclassifying six times)
        ladder = [(cached["classify_angle_deg"], cached["curve_angle_deg"])]
    failed = []
    info = None
    for rung, (angle, curve_angle) in enumerate(ladder):
        reuse = cached is not None and rung == 0
        log(f"{stl.name}: meshing at {args.size} mm (classification {angle:g} deg, curves {curve_angle:g} deg)"
            + (", size field" if size_field else "") + (", classified surface reused" if reuse else "")
            + (", curved attempt" if args.curved else ""))
        geo_in = geometry if reuse else None
        geo_out = None
        if not reuse:
            geo_out = (geometry.with_name(geometry.name + ".tmp.msh") if geometry is not None
                       else out_dir / f"{name}.classified.tmp.msh")
        curved = False
        if args.curved:
            info, why = run_attempt(stl, args.size, True, angle, curve_angle, msh, size_field, geo_in, geo_out,
                                    args.no_rodmesh)
            curved = info is not None and info["min_scaled_jacobian"] > 0.0
            if info is not None and not curved:
                log(f"curved mesh has min scaled Jacobian {info['min_scaled_jacobian']:.3g} <= 0: "
                    "falling back to straight-sided elements")
        if not curved:
            info, why = run_attempt(stl, args.size, False, angle, curve_angle, msh, size_field, geo_in, geo_out,
                                    args.no_rodmesh)
        if info is not None:
            info.update({"classify_angle_deg": angle, "curve_angle_deg": curve_angle, "curved": curved})
            if geometry is not None and geo_out is not None and geo_out.is_file():
                geo_out.replace(geometry)
                meta.write_text(json.dumps({"classify_angle_deg": angle, "curve_angle_deg": curve_angle}))
            elif geo_out is not None and geo_out.is_file():
                geo_out.unlink()
            break
        log(f"  failed: {why}")
        failed.append({"classify_angle_deg": angle, "curve_angle_deg": curve_angle, "error": why})
        if out_of_time():
            break
    if info is None:
        # the surface itself is meshed differently (the policy's fallbacks); the classification is the cached
        # one or the ladder's first
        angle, curve_angle = ladder[0]
        # shells that touch face to face are bonded first (their common faces removed)
        bonded = out_dir / f"{name}.bonded.stl"
        pairs = bond_shells(stl, bonded)
        if pairs:
            log(f"{stl.name}: {pairs} pairs of coincident opposite triangles (shells touching face to face) "
                "removed: the fallbacks mesh the bonded body")
        surface = bonded if pairs else stl
        for fallback in policy("fallbacks"):
            reuse = cached is not None and not pairs
            geo_out = None
            if fallback == "local refinement" and not reuse:
                geo_out = (geometry.with_name(geometry.name + ".tmp.msh") if geometry is not None
                           else out_dir / f"{name}.classified.tmp.msh")
            log(f"{stl.name}: every classification failed; fallback: {fallback}")
            info, why = run_fallback(fallback, surface, args.size, angle, curve_angle, msh, size_field,
                                     geometry if reuse else None, geo_out)
            if info is not None:
                if pairs:
                    info["fallback"] = f"shells bonded, {fallback}"
                    info["fallback_detail"]["coincident_triangle_pairs_removed"] = pairs
                info.update({"classify_angle_deg": angle if fallback == "local refinement" else 0.0,
                             "curve_angle_deg": curve_angle if fallback == "local refinement" else 0.0,
                             "curved": False})
                if geometry is not None and geo_out is not None and geo_out.is_file():
                    geo_out.replace(geometry)
                    meta.write_text(json.dumps({"classify_angle_deg": angle, "curve_angle_deg": curve_angle}))
            if geo_out is not None and geo_out.is_file():
                geo_out.unlink()
            if info is not None:
                break
            log(f"  failed: {why}")
            failed.append({"fallback": f"shells bonded, {fallback}" if pairs else fallback, "error": why})
        if bonded.is_file():
            bonded.unlink()
    if info is None:
        ladder_errors = [f["error"] for f in failed if "fallback" not in f]
        tried = [f"the classification ladder ({len(ladder_errors)} of {len(ladder)} settings tried, "
                 f"last error: {ladder_errors[-1] if ladder_errors else 'none'})"]
        tried += [f"{f['fallback']} ({'' if f['error'].startswith('not tried') else 'error: '}{f['error']})"
                  for f in failed if "fallback" in f]
        tried += [f"{fb} (not tried: the mesher's time limit)" for fb in policy("fallbacks")
                  if not any(f.get("fallback", "").endswith(fb) for f in failed)]
        raise SystemExit(f"mesh_rod: error: gmsh could not mesh {stl} at {args.size} mm; tried "
                         + "; ".join(tried) + f"; {policy('what_to_try')}")
    info.update({
        "stl": str(stl),
        "msh": str(msh),
        "size_mm": args.size,
        "failed_attempts": failed,
        "fallback": info.get("fallback"),
    })
    info.update(handed_off(msh, rodmesh, info, args.no_rodmesh))
    info["seconds_total"] = time.perf_counter() - t0
    log(f"{info['elements']} tet10, {info['nodes']} nodes, min SICN {info['min_sicn']:.3f}, "
        f"min SJ {info['min_scaled_jacobian']:.3f}, {info['seconds_total']:.1f} s")
    return info
