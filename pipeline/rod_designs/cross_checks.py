"""Cross-checks for the report: the peak pin force in closed form and a beam-theory bending stress."""

from __future__ import annotations

from .definitions import CENTRE_DISTANCE, CRANK_R, OMEGA, PISTON_M4, ROD_L, Design, shank_half_width


def peak_pin_force(m3: float, l1_m: float) -> float:
    """SPEC Stage 2: peak crank-rod pin force at TDC, constant speed, no gravity."""
    r, l = CRANK_R, ROD_L
    return r * OMEGA**2 * (PISTON_M4 * (1 + r / l) + m3 * (1 + (r / l) * (l1_m / l)))


def beam_bending_stress(d: Design, p: dict, force: float) -> float:
    """Nominal bending stress [MPa] of the shank section where it meets the small-end eye, for an
    in-plane transverse force at A with B fixed (SPEC Stage 3 F_y case): sigma = F x / Z. A ranking
    aid only. For the slot, the rails also bend locally over the slot length (Vierendeel action:
    each rail carries half the shear, inflection point at mid-slot), which is added."""
    x = CENTRE_DISTANCE - p["eye_b_r"] - p["pocket_gap"]
    h, t = shank_half_width(p, x), p["shank_t"]
    full = t * (2 * h) ** 3 / 12.0
    if d.kind == "ibeam":
        second = full - (t - p["web"]) * (2 * h - 2 * p["flange"]) ** 3 / 12.0
    elif d.kind == "slot":
        second = full - t * (2 * h - 2 * p["flange"]) ** 3 / 12.0
    else:
        second = full
    sigma = force * x / (second / h)
    if d.kind == "slot":
        slot_len = x - (p["eye_a_r"] + p["pocket_gap"])
        sigma += (force / 2) * (slot_len / 2) / (t * p["flange"] ** 2 / 6.0)
    return sigma
