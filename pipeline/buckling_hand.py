#!/usr/bin/env python3
"""Hand values of the buckling load of the five designs, beside the FEM's linear buckling factor.

For each rod of pipeline/make_designs.py this script
  1. takes the design's parameters from make_designs itself: its fixed values and the three
     calibrated ones, obtained by re-running its calibration (make_designs.generate, about 5 s per
     design); the regenerated STL is compared byte for byte with designs/designN.stl, so the
     parameters are those of the committed file;
  2. computes the shank cross-section (normal to the rod axis x) at these abscissae:
       min  the smallest plain section: I-beam and slot where the pockets / the slot end at the
            small eye (x = L - eye_b_r - pocket_gap); solid shanks where the junction fillet at the
            small eye leaves the tapered edge;
       mid  x = L/2;
       max  the largest plain section, the same at the big-end eye;
       neck (I-beam and slot only) the solid shank between the pocket end and the small-end fillet,
            where that fillet leaves the edge: narrower, so for design 3 its in-plane I is smaller;
     area A, second moments I_in (in-plane bending, about the pin axis z) and I_out (out-of-plane
     bending, about y, the in-plane axis normal to the rod axis), radii of gyration r. Shank outline:
     trapezoid of half-width h(x) (shank_h + shank_dh at A, shank_h - shank_dh at B), thickness
     shank_t along z. I-beam: the pockets from both faces leave flanges of y-width f / cos(taper)
     (make_designs' inset) over the full thickness and a web of thickness `web`; the slot is the
     same with no web (two rails). Rectangles and their differences (Roark's Formulas for Stress and
     Strain, 7th ed., Table A.1);
  3. slices the committed STL at the same abscissae (Green's theorem over the cut segments) and
     scans it between the two bores, as an independent check of the formulas, the parameters and the
     choice of the critical section (at the pocket ends the pockets' rounded corners add 2-20 % to
     the slice: the formula, for full-width pockets, is the slightly smaller section there; the
     scan's smallest slices lie within +3.3 % / -0.2 % of the formula's min section);
  4. treats the rod as the FEM model does (bore B fixed, compression on the free bore A): a
     fixed-free column, and computes per bending plane
       Euler    P_E = pi^2 E I / L_e^2, L_e = K L     (Timoshenko & Gere, Theory of Elastic
                                                      Stability, 2nd ed., §2.1; Budynas-Nisbett,
                                                      Shigley's Mechanical Engineering Design,
                                                      §4-12, end constant C = 1/K^2)
       Johnson  P_J = A [s_y - (s_y L_e / (2 pi r))^2 / E]  for L_e / r < sqrt(2 pi^2 E / s_y),
                i.e. P_J = A (s_y - s_y^2 / (4 s_E)) with s_E = P_E / A > s_y / 2
                                                     (Budynas-Nisbett §4-13, J. B. Johnson parabola)
     with rodstudy's defaults E = 210 GPa, s_y = 355 MPa (src/config.rs). The governing load is the
     smaller plane's, each plane by Johnson where it applies, else Euler;
  5. reads each design's peak compression from the program (`rodstudy dynamics driven DESIGN
     --config pipeline/examples/engine.toml --json`, field peak_compression_n) and divides.

Which section, which length (the shank tapers, the eyes are far stiffer than the shank):
  lower bound  K = 2 on the full centre distance L = 180 mm with the min section everywhere (the
               FEM's clamp is the bore B surface, 12.5 mm nearer A, and every section is stiffer);
               for I-beam and slot A and each plane's load are the smaller of the min and neck
               sections' (the formulas grow with A and with the elastic load, so this stays a bound);
  upper bound  the shank alone is flexible, between its plain-section ends x_max and x_min, with the
               max section; everything else rigid: clamped at x_min, a rigid arm c = x_max carries
               the load at A. E I v'' = P (d - v), v = d (1 - cos k s), d = v(l) + c v'(l) gives
               cos k l = k c sin k l (l = x_min - x_max), solved for k; L_e = pi / k.
The K = 2 values at the min, mid and max sections are also given (L_e = 360 mm), and pinned-pinned
values (K = 1, the engine's real in-plane support) for information. The FEM's lambda is a linear
elastic eigenvalue: compare it with the Euler (elastic) range; Johnson's value (lower where the column
is stocky) is the limit for a real, yielding part.
Slot (design 4): its two rails are joined only at the slot ends, so the slotted shank is
shear-flexible in plane (Vierendeel action) and a column of its composite I overestimates the in-plane
load (the FEM's mode of design 4 is in plane). Its in-plane elastic load solves Engesser's
1/P = 1/P_E + 1/S(P) (Timoshenko & Gere ch. 2, effect of shearing force on the critical load), S the
shear stiffness of the slot: the rails as fixed-guided beam-columns between rigid eyes, each carrying
P/2, S = 2 a k with the sway stiffness k = (E I_r / a^3) u^3 / (2 tan(u/2) - u), u = a sqrt(P / (2 E I_r))
(I_r one rail's in-plane second moment, a the slot length). Unloaded S = 24 E I_r / a^2 (the battened
column with rigid battens); it vanishes at the rails' sway load 2 pi^2 E I_r / a^2, the cap EN
1993-1-1 §6.4.3.1 puts on S_v. The neck and out-of-plane loads of the slot are plain Euler.

Usage
  python pipeline/buckling_hand.py                  markdown tables (needs target/release/rodstudy)
  python pipeline/buckling_hand.py --json out.json  also write the numbers as JSON
  python pipeline/buckling_hand.py --only 5         one design (repeatable)
  python pipeline/buckling_hand.py --self-test      section formulas, slicer and column formulas
                                                    against closed forms computed by hand
"""

from __future__ import annotations

import argparse
import json
import math
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import make_designs as md  # noqa: E402

REPO = md.REPO
L = md.CENTRE_DISTANCE  # mm, column length (centre distance A-B)
E = 210e3  # MPa, rodstudy default fem.youngs_modulus_pa = 210e9 (src/config.rs)
SIGMA_Y = 355.0  # MPa, rodstudy default criterion.yield_mpa (S355)
K_FEM = 2.0  # fixed-free: the FEM's supports (B fixed, A loaded and free)
K_PINNED = 1.0  # pinned-pinned: the engine's in-plane supports, for information
ENGINE = REPO / "pipeline" / "examples" / "engine.toml"


# ---------------------------------------------------------------------------------------------
# Sections
# ---------------------------------------------------------------------------------------------

def section_props(t: float, h: float, b: float = 0.0, web: float = 0.0) -> dict:
    """Rectangle 2h (along y) x t (along z) less a central opening 2b x (t - web), symmetric about
    y = 0 and z = 0: solid (b = 0), I-beam (web between pockets), slot (web = 0: two rails).
    I_in about z (in-plane bending), I_out about y (out-of-plane bending), mm units."""
    area = 2 * h * t - 2 * b * (t - web)
    i_in = (t * (2 * h) ** 3 - (t - web) * (2 * b) ** 3) / 12.0
    i_out = (2 * h * t**3 - 2 * b * (t**3 - web**3)) / 12.0
    return {"A": area, "I_in": i_in, "I_out": i_out,
            "r_in": math.sqrt(i_in / area), "r_out": math.sqrt(i_out / area)}


def shank_inner_half_width(p: dict, x: float) -> float:
    """Half-width of the pockets / slot at x: make_designs.shank_cutter insets the outline by
    f / cos(taper), so a flange (rail) is f wide normal to the tapered edge, f / cos(taper) along y."""
    taper = math.atan2(md.shank_half_width(p, 0.0) - md.shank_half_width(p, L), L)
    return md.shank_half_width(p, x) - p["flange"] / math.cos(taper)


def shank_section(kind: str, p: dict, x: float) -> dict:
    """The plain shank section of a make_designs rod at abscissa x (pockets / slot at full width)."""
    h = md.shank_half_width(p, x)
    if kind == "solid":
        sec = section_props(p["shank_t"], h)
    else:
        sec = section_props(p["shank_t"], h, shank_inner_half_width(p, x), p["web"] if kind == "ibeam" else 0.0)
    return {"kind": kind, "x": x, **sec}


def fillet_tangent_x(p: dict, eye_x: float, eye_r: float) -> float:
    """Abscissa where the junction fillet (radius fillet_r) between the shank's straight tapered edge
    and the eye circle (centre (eye_x, 0), radius eye_r) leaves the edge: the fillet's centre lies
    at fillet_r from the edge (outside the shank) and at eye_r + fillet_r from the eye's centre."""
    r = p["fillet_r"]
    h_a = md.shank_half_width(p, 0.0)
    s = (md.shank_half_width(p, L) - h_a) / L
    c = math.sqrt(1 + s * s)
    # centre (x + alpha, s x + beta) for the edge point (x, h(x))
    alpha, beta = -r * s / c - eye_x, h_a + r / c
    qa, qb, qc = 1 + s * s, 2 * (alpha + s * beta), alpha**2 + beta**2 - (eye_r + r) ** 2
    disc = math.sqrt(qb * qb - 4 * qa * qc)
    roots = ((-qb - disc) / (2 * qa), (-qb + disc) / (2 * qa))
    return min(roots) if eye_x > 0 else max(roots)  # the root on the shank's side of the eye


def critical_abscissae(kind: str, p: dict) -> dict:
    """Where the sections are taken: {name: {"x": abscissa, "kind": section kind}}."""
    neck_b, neck_a = fillet_tangent_x(p, L, p["eye_b_r"]), fillet_tangent_x(p, 0.0, p["eye_a_r"])
    if kind == "solid":
        return {"min": {"x": neck_b, "kind": kind}, "mid": {"x": L / 2, "kind": kind},
                "max": {"x": neck_a, "kind": kind}}
    # pockets / slot end on arcs pocket_gap outside the eye outlines; solid shank beyond them
    return {"min": {"x": L - p["eye_b_r"] - p["pocket_gap"], "kind": kind},
            "neck": {"x": neck_b, "kind": "solid"}, "mid": {"x": L / 2, "kind": kind},
            "max": {"x": p["eye_a_r"] + p["pocket_gap"], "kind": kind}}


# ---------------------------------------------------------------------------------------------
# STL slices (independent check of the formulas and of the parameters)
# ---------------------------------------------------------------------------------------------

def slice_section(verts: np.ndarray, tris: np.ndarray, x0: float) -> dict:
    """Section properties of the plane x = x0 through a closed, outward-oriented triangle mesh.
    Each crossing triangle gives one segment, oriented counter-clockwise in (y, z) (tangent
    (-n_z, n_y) for the outward normal n); A and the moments by Green's theorem summed over the
    segments: A = sum c/2, int y dA = sum c (y1 + y2)/6, int y^2 dA = sum c (y1^2 + y1 y2 + y2^2)/12,
    c = y1 z2 - y2 z1 (the polygon formulas, which need no ordering of the segments)."""
    v = np.asarray(verts, dtype=np.float64)
    d = v[:, 0] - x0
    up = d[tris] >= 0.0
    crossing_tri = (up.sum(axis=1) % 3) != 0
    t = tris[crossing_tri]
    up = up[crossing_tri]
    pts = np.empty((len(t), 3, 2))
    cross = np.empty((len(t), 3), dtype=bool)
    for k in range(3):
        i, j = t[:, k], t[:, (k + 1) % 3]
        cross[:, k] = up[:, k] != up[:, (k + 1) % 3]
        denom = np.where(cross[:, k], d[i] - d[j], 1.0)
        f = np.where(cross[:, k], d[i] / denom, 0.0)
        pts[:, k] = (v[i] + (v[j] - v[i]) * f[:, None])[:, 1:]
    first_two = np.argsort(~cross, axis=1, kind="stable")[:, :2]  # the two crossing edges
    rows = np.arange(len(t))
    p, q = pts[rows, first_two[:, 0]], pts[rows, first_two[:, 1]]
    n = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    flip = np.einsum("ij,ij->i", q - p, np.stack([-n[:, 2], n[:, 1]], axis=1)) < 0
    p[flip], q[flip] = q[flip].copy(), p[flip].copy()
    (y1, z1), (y2, z2) = p.T, q.T
    c = y1 * z2 - y2 * z1
    area = c.sum() / 2
    yc, zc = (c * (y1 + y2)).sum() / 6 / area, (c * (z1 + z2)).sum() / 6 / area
    i_in = (c * (y1 * y1 + y1 * y2 + y2 * y2)).sum() / 12 - area * yc**2
    i_out = (c * (z1 * z1 + z1 * z2 + z2 * z2)).sum() / 12 - area * zc**2
    return {"A": area, "I_in": i_in, "I_out": i_out, "y_c": yc, "z_c": zc}


def stl_scan(verts, tris, x_from: float, x_to: float, step: float = 0.25) -> dict:
    """Smallest A, I_in, I_out of the slices between x_from and x_to, and where."""
    xs = np.arange(x_from + step / 2, x_to, step)
    rows = [slice_section(verts, tris, x) for x in xs]
    out = {}
    for key in ("A", "I_in", "I_out"):
        vals = np.array([r[key] for r in rows])
        k = int(np.argmin(vals))
        out[key] = {"min": float(vals[k]), "x": float(xs[k])}
    return out


# ---------------------------------------------------------------------------------------------
# Columns
# ---------------------------------------------------------------------------------------------

TRANSITION = math.sqrt(2 * math.pi**2 * E / SIGMA_Y)  # slenderness where Johnson meets Euler


def euler(i: float, le: float) -> float:
    return math.pi**2 * E * i / le**2


def johnson(area: float, p_elastic: float) -> float | None:
    """Johnson's parabola written with the elastic critical stress s_E = P_E / A (for P_E = Euler's
    this is A [s_y - (s_y L_e / (2 pi r))^2 / E]); None where the column is elastic (s_E <= s_y / 2,
    i.e. slenderness >= TRANSITION)."""
    s_e = p_elastic / area
    return None if s_e <= SIGMA_Y / 2 else area * (SIGMA_Y - SIGMA_Y**2 / (4 * s_e))


def rigid_ends_length(flex: float, arm: float) -> float:
    """Effective length of a column clamped at one end of a flexible part of length `flex`, whose
    other end carries a rigid arm of length `arm` to the load: cos(u) = (arm / flex) u sin(u),
    u = k flex in (0, pi/2), by bisection; L_e = pi / k = pi flex / u."""
    lo, hi = 0.0, math.pi / 2
    for _ in range(200):
        u = 0.5 * (lo + hi)
        lo, hi = (u, hi) if math.cos(u) > arm / flex * u * math.sin(u) else (lo, u)
    return math.pi * flex / (0.5 * (lo + hi))


def rail_shear_stiffness(load: float, ei: float, a: float) -> float:
    """Shear stiffness S = 2 a k of a slot panel of length a whose two rails (bending stiffness ei
    each, fixed-guided between rigid ends) carry load / 2 each: k = (ei / a^3) u^3 / (2 tan(u/2) - u),
    u = a sqrt(load / (2 ei)), the sway stiffness of a fixed-guided beam-column (from
    v = C1 + C2 x + C3 cos(k x) + C4 sin(k x))."""
    u = a * math.sqrt(load / (2 * ei))
    if u < 1e-4:
        return 24 * ei / a**2
    return 2 * a * ei / a**3 * u**3 / (2 * math.tan(u / 2) - u)


def slot_in_plane(p_e: float, p: dict) -> float:
    """In-plane elastic load of the slotted shank: the root of 1/P = 1/P_E + 1/S(P) below the rails'
    sway load, by bisection."""
    x = critical_abscissae("slot", p)
    a = x["min"]["x"] - x["max"]["x"]
    w = md.shank_half_width(p, x["mid"]["x"]) - shank_inner_half_width(p, x["mid"]["x"])
    ei = E * p["shank_t"] * w**3 / 12
    lo, hi = 0.0, min(p_e, 2 * math.pi**2 * ei / a**2)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if 1 / mid > 1 / p_e + 1 / rail_shear_stiffness(mid, ei, a) else (lo, mid)
    return 0.5 * (lo + hi)


def elastic_loads(sec: dict, le: float, p: dict) -> dict:
    """Euler's load of both planes for the effective length le [mm]; slot: in plane with shear."""
    pe = {plane: euler(sec[f"I_{plane}"], le) for plane in ("in", "out")}
    if sec["kind"] == "slot":
        pe["in"] = slot_in_plane(pe["in"], p)
    return pe


def column(area: float, pe: dict, le: float) -> dict:
    """Both bending planes from their elastic loads pe (N): Johnson's load where it applies, the
    governing plane, and the equivalent slenderness pi sqrt(E A / P_E) (= L_e / r for Euler)."""
    planes = {}
    for plane in ("in", "out"):
        pj = johnson(area, pe[plane])
        planes[plane] = {"slenderness": math.pi * math.sqrt(E * area / pe[plane]), "euler_n": pe[plane],
                         "johnson_n": pj, "governing_n": pj if pj is not None else pe[plane],
                         "formula": "Johnson" if pj is not None else "Euler"}
    gov = min(planes, key=lambda pl: planes[pl]["governing_n"])
    ela = min(planes, key=lambda pl: planes[pl]["euler_n"])
    return {"L_e_mm": le, "planes": planes,
            "euler_n": planes[ela]["euler_n"], "euler_plane": ela,
            "governing_n": planes[gov]["governing_n"], "governing_plane": gov,
            "governing_formula": planes[gov]["formula"]}


# ---------------------------------------------------------------------------------------------
# Inputs from make_designs and from rodstudy
# ---------------------------------------------------------------------------------------------

def calibrated_params(n: int) -> tuple[dict, bool]:
    """make_designs' parameters of design n (its calibration rerun) and whether the regenerated STL
    is byte-identical to the committed designs/designN.stl."""
    res = md.generate(md.DESIGNS[n])
    with tempfile.TemporaryDirectory(prefix="rodstudy-buckling-") as tmp:
        path = md.write_design(res, pathlib.Path(tmp))
        same = path.read_bytes() == (md.DESIGNS_DIR / f"design{n}.stl").read_bytes()
    return res["params"], same


def peak_compression(n: int, exe: pathlib.Path) -> dict:
    if not exe.exists():
        sys.exit(f"{exe} is missing: run `cargo build --release` first (or pass --rodstudy)")
    cmd = [str(exe), "dynamics", "driven", str(md.DESIGNS_DIR / f"design{n}.stl"),
           "--config", str(ENGINE), "--json"]
    rec = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True, cwd=REPO).stdout)
    rec = rec[0] if isinstance(rec, list) else rec
    return {"peak_compression_n": rec["peak_compression_n"],
            "crank_angle_deg": rec["peak_compression_crank_angle_deg"]}


# ---------------------------------------------------------------------------------------------
# Driver
# ---------------------------------------------------------------------------------------------

def analyse(n: int, exe: pathlib.Path) -> dict:
    d = md.DESIGNS[n]
    p, same = calibrated_params(n)
    verts, tris = md.read_stl(md.DESIGNS_DIR / f"design{n}.stl")
    where = critical_abscissae(d.kind, p)
    le_upper = rigid_ends_length(where["min"]["x"] - where["max"]["x"], where["max"]["x"])
    sections = {}
    for name, at in where.items():
        sec = shank_section(at["kind"], p, at["x"])
        # slice a hair inside the plain region (the pockets / the fillets begin at x)
        stl = slice_section(verts, tris, at["x"] + {"max": 1e-3, "mid": 0.0}.get(name, -1e-3))
        sec["stl"] = {k: stl[k] for k in ("A", "I_in", "I_out")}
        for label, le in (("K2", K_FEM * L), ("K1", K_PINNED * L), ("rigid_ends", le_upper)):
            sec[label] = column(sec["A"], elastic_loads(sec, le, p), le)
        sections[name] = sec
    weak = [sections[k] for k in ("min", "neck") if k in sections]  # componentwise smallest

    def lower(label):
        return column(min(s["A"] for s in weak),
                      {pl: min(s[label]["planes"][pl]["euler_n"] for s in weak) for pl in ("in", "out")},
                      weak[0][label]["L_e_mm"])

    bounds = {"lower": lower("K2"), "upper": sections["max"]["rigid_ends"],
              "K1_lower": lower("K1"), "K1_upper": sections["max"]["K1"]}
    load = peak_compression(n, exe)
    f = load["peak_compression_n"]
    factors = {"elastic": [bounds[b]["euler_n"] / f for b in ("lower", "upper")],
               "governing": [bounds[b]["governing_n"] / f for b in ("lower", "upper")],
               "K1_governing": [bounds[b]["governing_n"] / f for b in ("K1_lower", "K1_upper")]}
    return {"design": n, "name": d.name, "kind": d.kind, "stl_regenerated_identical": same,
            "params": {k: p[k] for k in ("shank_t", "shank_h", "shank_dh", "flange", "web", "eye_a_r",
                                         "eye_b_r", "pocket_gap", "fillet_r") + d.free},
            "sections": sections, "bounds": bounds,
            "stl_scan_min": stl_scan(verts, tris, md.BORE_A_R, L - md.BORE_B_R),
            **load, "load_factor": factors}


def fmt_kn(v) -> str:
    return "—" if v is None else f"{v / 1e3:,.0f}"


def plane_name(c: dict, key: str) -> str:
    return "in-plane" if c[key] == "in" else "out-of-plane"


def tables(results: list) -> str:
    lines = [f"Sections; fixed-free column K = {K_FEM:.0f} on L = {L:.0f} mm (L_e = {K_FEM * L:.0f} mm), "
             f"E = {E / 1e3:.0f} GPa, σ_y = {SIGMA_Y:.0f} MPa, Johnson below L_e/r = {TRANSITION:.1f}. "
             "STL: the committed file sliced at the same x, relative difference of A, I_in, I_out.", "",
             "| design | section | x [mm] | A [mm²] | I in-plane [mm⁴] | I out-of-plane [mm⁴] "
             "| L_e/r in / out | Euler in / out [kN] | Johnson in / out [kN] | governs | STL slice |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        for name in ("min", "neck", "mid", "max"):
            if name not in r["sections"]:
                continue
            s = r["sections"][name]
            c = s["K2"]
            kind = s["kind"] + (" (in-plane: with rail shear)" if s["kind"] == "slot" else "")
            pin, pout = c["planes"]["in"], c["planes"]["out"]
            dev = " / ".join(f"{s['stl'][k] / s[k] - 1:+.2%}" for k in ("A", "I_in", "I_out"))
            lines.append(
                f"| {r['design']} | {name}, {kind} | {s['x']:.1f} | {s['A']:,.0f} | {s['I_in']:,.0f} "
                f"| {s['I_out']:,.0f} | {pin['slenderness']:.1f} / {pout['slenderness']:.1f} "
                f"| {fmt_kn(pin['euler_n'])} / {fmt_kn(pout['euler_n'])} "
                f"| {fmt_kn(pin['johnson_n'])} / {fmt_kn(pout['johnson_n'])} "
                f"| {c['governing_formula']}, {plane_name(c, 'governing_plane')} | {dev} |")
    lines += ["", "Buckling load and load factor under the peak compression of the engine cycle "
              "(`rodstudy dynamics driven … --config pipeline/examples/engine.toml`). Lower bound: K = 2 on "
              "L = 180 mm, min section; upper bound: the shank alone flexible (between its plain-section ends, "
              "max section), clamped at the small end, rigid arm to A. Elastic = Euler (slot in plane: with "
              "rail shear; compare with the FEM's λ), governing = Johnson where the column is stocky. K = 1: "
              "pinned–pinned on L = 180 mm, min (and neck) – max section.", "",
              "| design | peak compression [kN] (crank °) | L_e lower / upper [mm] | elastic P_cr [kN] (plane) "
              "| elastic factor | governing P_cr [kN] | governing factor | K = 1 governing [kN] "
              "| K = 1 factor |",
              "|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        lo, up = r["bounds"]["lower"], r["bounds"]["upper"]
        lf, k1 = r["load_factor"], (r["bounds"]["K1_lower"], r["bounds"]["K1_upper"])
        planes = plane_name(lo, "euler_plane")
        if up["euler_plane"] != lo["euler_plane"]:
            planes += " / " + plane_name(up, "euler_plane")
        formulas = lo["governing_formula"]
        if up["governing_formula"] != formulas:
            formulas += " / " + up["governing_formula"]
        lines.append(
            f"| {r['design']} | {r['peak_compression_n'] / 1e3:.2f} ({r['crank_angle_deg']:.0f}) "
            f"| {lo['L_e_mm']:.0f} / {up['L_e_mm']:.0f} "
            f"| {fmt_kn(lo['euler_n'])} – {fmt_kn(up['euler_n'])} ({planes}) "
            f"| {lf['elastic'][0]:.1f} – {lf['elastic'][1]:.1f} "
            f"| {fmt_kn(lo['governing_n'])} – {fmt_kn(up['governing_n'])} ({formulas}, "
            f"{plane_name(lo, 'governing_plane')}) "
            f"| {lf['governing'][0]:.1f} – {lf['governing'][1]:.1f} "
            f"| {fmt_kn(k1[0]['governing_n'])} – {fmt_kn(k1[1]['governing_n'])} ({k1[0]['governing_formula']}, "
            f"{plane_name(k1[0], 'governing_plane')}) "
            f"| {lf['K1_governing'][0]:.1f} – {lf['K1_governing'][1]:.1f} |")
    lines += ["", "Smallest slice of the committed STL between the bores (x from 25 to 167.5 mm, 0.25 mm "
              "steps), against the formula's min section (min and neck: the smaller):", "",
              "| design | A min [mm²] at x [mm] | I_in min [mm⁴] at x | I_out min [mm⁴] at x "
              "| regenerated STL identical |",
              "|---|---|---|---|---|"]
    for r in results:
        sc = r["stl_scan_min"]
        weak = {k: min(r["sections"][n][k] for n in ("min", "neck") if n in r["sections"])
                for k in ("A", "I_in", "I_out")}
        cells = " | ".join(f"{sc[k]['min']:,.0f} ({sc[k]['min'] / weak[k] - 1:+.1%}) at {sc[k]['x']:.1f}"
                           for k in ("A", "I_in", "I_out"))
        lines.append(f"| {r['design']} | {cells} | {'yes' if r['stl_regenerated_identical'] else 'NO'} |")
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------------
# Self-test: closed forms worked out by hand
# ---------------------------------------------------------------------------------------------

def self_test() -> int:
    failures = []

    def close(got, want, what, rel=1e-9):
        ok = abs(got - want) <= rel * abs(want)
        print(f"  {'ok  ' if ok else 'FAIL'} {what}: {got:.6g} (expected {want:.6g})")
        if not ok:
            failures.append(what)

    # Rectangle 2h = 50 (y) x t = 40 (z): A = 2000, b h^3/12 = 40*50^3/12, 50*40^3/12.
    s = section_props(40.0, 25.0)
    close(s["A"], 2000.0, "rectangle 40 x 50: A")
    close(s["I_in"], 416666.6666666667, "rectangle: I_in = 40 * 50^3 / 12")
    close(s["I_out"], 266666.6666666667, "rectangle: I_out = 50 * 40^3 / 12")
    # I-section 40 (y) x 30 (z), flanges 5 wide, web 10 thick. By parts (parallel axes):
    # A = 2 (5 * 30) + 30 * 10 = 600; I_in = 2 (30 * 5^3/12 + 150 * 17.5^2) + 10 * 30^3/12
    # = 2 (312.5 + 45937.5) + 22500 = 115000; I_out = 2 * 5 * 30^3/12 + 30 * 10^3/12 = 22500 + 2500.
    s = section_props(30.0, 20.0, 15.0, 10.0)
    close(s["A"], 600.0, "I-section: A")
    close(s["I_in"], 115000.0, "I-section: I_in by parallel axes")
    close(s["I_out"], 25000.0, "I-section: I_out")
    # Two rails 8 (y) x 40 (z), centres at y = +-14: I_in = 2 (40 * 8^3/12 + 320 * 14^2), I_out = 2 * 8 * 40^3/12.
    s = section_props(40.0, 18.0, 10.0, 0.0)
    close(s["A"], 640.0, "slot (two rails): A")
    close(s["I_in"], 2 * (40 * 8**3 / 12 + 320 * 14**2), "slot: I_in by parallel axes")
    close(s["I_out"], 2 * 8 * 40**3 / 12, "slot: I_out")

    # The STL slicer on meshes: a box, and an I-beam as three boxes (shared faces cancel), off-centre.
    box = md.box_mesh([-10.0, -25.0 + 3.0, -20.0 - 7.0], [10.0, 25.0 + 3.0, 20.0 - 7.0])
    s = slice_section(box[0], box[1], 0.37)
    close(s["A"], 2000.0, "slicer, box: A")
    close(s["I_in"], 416666.6666666667, "slicer, box: I_in about the centroid")
    close(s["I_out"], 266666.6666666667, "slicer, box: I_out about the centroid")
    parts = [md.box_mesh([0, -20, -15], [10, -15, 15]), md.box_mesh([0, 15, -15], [10, 20, 15]),
             md.box_mesh([0, -15, -5], [10, 15, 5])]
    verts = np.vstack([v for v, _ in parts])
    tris = np.vstack([t + 8 * k for k, (_, t) in enumerate(parts)])
    s = slice_section(verts, tris, 4.2)
    close(s["A"], 600.0, "slicer, I-beam of three boxes: A")
    close(s["I_in"], 115000.0, "slicer, I-beam: I_in")
    close(s["I_out"], 25000.0, "slicer, I-beam: I_out")

    # Columns. Euler fixed-free for docs/fem.md's test column 500 x 20 x 20 mm: pi^2 E I / (4 l^2),
    # I = 20^4 / 12, L_e = 2 * 500: 27 634.9 N.
    close(euler(20.0**4 / 12, 1000.0), 27634.9, "Euler fixed-free 500 x 20 x 20 mm column [N]", 2e-6)
    # pi sqrt(2 * 210000 / 355) = pi sqrt(1183.099) = pi * 34.39620 = 108.0589
    close(TRANSITION, 108.0589, "Johnson/Euler transition sqrt(2 pi^2 E / s_y) for S355", 1e-6)
    # Johnson, slenderness form: A = 1000, L_e / r = 60: 1000 (355 - (355 * 60 / (2 pi))^2 / 210000)
    # = 1000 (355 - 3390.00^2 / 210000) = 1000 (355 - 54.724) = 300 276 N
    area, r_g = 1000.0, 10.0
    close(johnson(area, euler(area * r_g**2, 600.0)), 300276.0, "Johnson at L_e/r = 60, A = 1000 mm^2 [N]", 2e-6)
    # At the transition Johnson meets Euler (A s_y / 2); a stub gives the squash load A s_y.
    le_t = TRANSITION * r_g * (1 - 1e-12)
    close(johnson(area, euler(area * r_g**2, le_t)), euler(area * r_g**2, le_t), "Johnson = Euler at the transition")
    close(johnson(area, euler(area * r_g**2, le_t)), area * SIGMA_Y / 2, "... = A s_y / 2 there")
    close(johnson(area, euler(area * r_g**2, 1e-6)), area * SIGMA_Y, "Johnson -> A s_y for a stub")
    elastic = johnson(area, euler(area * r_g**2, 1.01 * TRANSITION * r_g)) is None
    print(f"  {'ok  ' if elastic else 'FAIL'} Johnson not applied above the transition")
    if not elastic:
        failures.append("Johnson above the transition")
    # Rigid arm: no arm -> fixed-free Euler (L_e = 2 l); a long arm c -> P = E I / (l c) (the
    # cantilever's end rotational stiffness E I / l against the lever P c).
    close(rigid_ends_length(100.0, 1e-9), 200.0, "rigid arm 0: L_e = 2 l", 1e-6)
    close(euler(1.0, rigid_ends_length(100.0, 1e6)), E / (100.0 * 1e6), "rigid arm >> l: P = E I / (l c)", 1e-4)
    # Rail shear stiffness: unloaded 24 E I / a^2; zero at the rails' sway load 2 pi^2 E I / a^2.
    close(rail_shear_stiffness(1e-3, 5.0e8, 100.0), 24 * 5.0e8 / 100.0**2, "rail shear stiffness, unloaded", 1e-6)
    near_sway = rail_shear_stiffness(2 * math.pi**2 * 5.0e8 / 100.0**2 * (1 - 1e-9), 5.0e8, 100.0)
    ok = 0 <= near_sway < 1e-6 * 24 * 5.0e8 / 100.0**2
    print(f"  {'ok  ' if ok else 'FAIL'} rail shear stiffness vanishes at the sway load: {near_sway:.3g}")
    if not ok:
        failures.append("rail shear stiffness at the sway load")
    # Fillet tangent on an untapered shank (h = 10, fillet 8, eye radius 30): the fillet's centre is
    # at y = 18, 38 from the eye's centre: x = 180 - sqrt(38^2 - 18^2) = 180 - sqrt(1120) = 180 - 33.4664 = 146.5336.
    flat = {"shank_h": 10.0, "shank_dh": 0.0, "fillet_r": 8.0}
    close(fillet_tangent_x(flat, L, 30.0), 146.5336, "fillet tangent at the small eye (untapered)", 1e-6)
    close(fillet_tangent_x(flat, 0.0, 30.0), 33.4664, "fillet tangent at the big eye (untapered)", 1e-5)
    print("self-test " + ("passed" if not failures else f"FAILED ({len(failures)})"))
    return 0 if not failures else 1


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", type=int, choices=sorted(md.DESIGNS), action="append", help="one design (repeatable)")
    ap.add_argument("--json", type=pathlib.Path, help="write the numbers to this file")
    ap.add_argument("--rodstudy", type=pathlib.Path, default=REPO / "target" / "release" / "rodstudy",
                    help="the rodstudy binary (default target/release/rodstudy)")
    ap.add_argument("--self-test", action="store_true", help="check the formulas against hand-computed values")
    args = ap.parse_args(argv)
    if args.self_test:
        return self_test()
    numbers = sorted(set(args.only)) if args.only else sorted(md.DESIGNS)
    md.gmsh_start()
    try:
        results = [analyse(n, args.rodstudy) for n in numbers]
    finally:
        md.gmsh.finalize()
    print(tables(results))
    if args.json:
        args.json.write_text(json.dumps({
            "model": {"L_mm": L, "E_mpa": E, "yield_mpa": SIGMA_Y, "K_fem": K_FEM, "K_pinned": K_PINNED,
                      "johnson_transition_slenderness": TRANSITION, "engine_config": str(ENGINE.relative_to(REPO))},
            "designs": results}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
