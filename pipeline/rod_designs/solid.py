"""A design's exact solid with gmsh's OpenCASCADE kernel (eyes, bosses, shank, fillets, pockets or
slot, bores) and its exact volume properties."""

from __future__ import annotations

import math

import gmsh
import numpy as np

from .definitions import (BORE_A_R, BORE_B_R, CENTRE_DISTANCE, KG_PER_MM3, KGM2_PER_KGMM2, MESH_OPTIONS, Design,
                          shank_half_width)
from .mass import summarize


def gmsh_start() -> None:
    if not gmsh.isInitialized():
        gmsh.initialize(["rodstudy-make-designs"], readConfigFiles=False)
    for k, v in MESH_OPTIONS.items():
        gmsh.option.setNumber(k, v)


def occ_prism(points_xy, z0: float, height: float) -> int:
    """Extrude the closed polygon `points_xy` in the plane z = z0 by `height` along z; volume tag."""
    occ = gmsh.model.occ
    pts = [occ.addPoint(x, y, z0) for x, y in points_xy]
    lines = [occ.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
    surf = occ.addPlaneSurface([occ.addCurveLoop(lines)])
    return next(t for d, t in occ.extrude([(2, surf)], 0, 0, height) if d == 3)


def z_parallel_edges(volume: int):
    """Straight edges parallel to z of `volume`, with their (x, y); cylinder seams (y = 0) excluded."""
    occ = gmsh.model.occ
    occ.synchronize()
    faces = gmsh.model.getBoundary([(3, volume)], combined=False, oriented=False)
    curves = sorted({abs(c) for _, c in gmsh.model.getBoundary(faces, combined=False, oriented=False)})
    out = []
    for c in curves:
        x0, y0, _, x1, y1, _ = occ.getBoundingBox(1, c)
        if abs(x1 - x0) < 1e-5 and abs(y1 - y0) < 1e-5 and abs(y0 + y1) > 1e-3:
            out.append((c, x0, y0))
    return out


def shank_cutter(p: dict, z0: float, height: float) -> int:
    """A pocket (I-beam) or slot tool: the shank outline inset by the flange width, ending in arcs
    concentric with the eyes (at pocket_gap from their outlines), corners rounded."""
    occ = gmsh.model.occ
    L, f = CENTRE_DISTANCE, p["flange"]
    h_a, h_b = shank_half_width(p, 0.0), shank_half_width(p, L)
    inset = f / math.cos(math.atan2(h_a - h_b, L))  # perpendicular flange width f
    prism = occ_prism([(0.0, -(h_a - inset)), (L, -(h_b - inset)), (L, h_b - inset), (0.0, h_a - inset)],
                      z0, height)
    cyl_a = occ.addCylinder(0, 0, z0 - 1, 0, 0, height + 2, p["eye_a_r"] + p["pocket_gap"])
    cyl_b = occ.addCylinder(L, 0, z0 - 1, 0, 0, height + 2, p["eye_b_r"] + p["pocket_gap"])
    out, _ = occ.cut([(3, prism)], [(3, cyl_a), (3, cyl_b)])
    assert len(out) == 1, f"pocket tool is not one piece: {out}"
    tool = out[0][1]
    edges = [c for c, _, _ in z_parallel_edges(tool)]
    out = occ.fillet([tool], edges, [p["pocket_corner_r"]])
    assert len(out) == 1, "pocket corner fillet failed"
    return out[0][1]


def build_rod(d: Design, p: dict) -> int:
    """Build design `d` with parameters `p` in a fresh gmsh model; returns the volume tag."""
    occ = gmsh.model.occ
    gmsh.clear()
    gmsh.model.add(f"design{d.number}")
    L, T, Ts = CENTRE_DISTANCE, p["eye_t"], p["shank_t"]
    bx, wb = p["boss_half_len"], p["boss_half_span"]
    h_a, h_b = shank_half_width(p, 0.0), shank_half_width(p, L)

    # Outer body: eyes + bosses + shank, fused into one solid (symmetric about y = 0 and z = 0).
    eye_a = occ.addCylinder(0, 0, -T / 2, 0, 0, T, p["eye_a_r"])
    bosses = occ.addBox(-bx, -wb, -T / 2, 2 * bx, 2 * wb, T)
    eye_b = occ.addCylinder(L, 0, -T / 2, 0, 0, T, p["eye_b_r"])
    shank = occ_prism([(0.0, -h_a), (L, -h_b), (L, h_b), (0.0, h_a)], -Ts / 2, Ts)
    out, _ = occ.fuse([(3, eye_a)], [(3, bosses), (3, eye_b), (3, shank)])
    assert len(out) == 1, f"fuse gave {len(out)} solids"
    body = out[0][1]

    # Fillets on the z-parallel edges: convex boss corners small, concave junctions larger.
    edges, radii = [], []
    for c, x, y in z_parallel_edges(body):
        edges.append(c)
        corner = abs(abs(x) - bx) < 1e-6 and abs(abs(y) - wb) < 1e-6
        radii.append(p["boss_corner_r"] if corner else p["fillet_r"])
    expected = 12  # 4 boss corners, 4 boss/eye junctions, 2 + 2 shank/eye junctions
    assert len(edges) == expected, f"expected {expected} z-parallel edges, found {len(edges)}"
    out = occ.fillet([body], edges, radii)
    assert len(out) == 1, "junction fillet failed"
    body = out[0][1]

    # Lightening: I-beam pockets from both faces, or a slot through.
    tools = []
    if d.kind == "ibeam":
        depth = Ts / 2 - p["web"] / 2
        tools.append(shank_cutter(p, p["web"] / 2, depth + 1.0))
        tools.append(shank_cutter(p, -Ts / 2 - 1.0, depth + 1.0))
    elif d.kind == "slot":
        tools.append(shank_cutter(p, -Ts / 2 - 1.0, Ts + 2.0))

    # The two pin bores, through along z.
    bore_a = occ.addCylinder(0, 0, -T, 0, 0, 2 * T, BORE_A_R)
    bore_b = occ.addCylinder(L, 0, -T, 0, 0, 2 * T, BORE_B_R)
    out, _ = occ.cut([(3, body)], [(3, t) for t in tools] + [(3, bore_a), (3, bore_b)])
    assert len(out) == 1, f"the rod is not one solid after the cuts: {out}"
    occ.synchronize()
    return out[0][1]


def occ_properties(volume: int) -> dict:
    """Exact B-rep properties from OpenCASCADE (unit density, mm) converted to kg, mm, kg m^2.
    getMatrixOfInertia is about the centre of mass (checked in --selftest)."""
    occ = gmsh.model.occ
    vol = occ.getMass(3, volume)
    c = np.array(occ.getCenterOfMass(3, volume))
    inertia = np.array(occ.getMatrixOfInertia(3, volume)).reshape(3, 3) * KG_PER_MM3 * KGM2_PER_KGMM2
    return summarize(vol, c, inertia)
