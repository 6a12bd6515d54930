#!/usr/bin/env python3
"""Writes the example cylinder pressure trace `pipeline/examples/wiebe_gasoline.csv`.

A single-zone model of a spark-ignition (gasoline) engine at full load, after J. B. Heywood,
*Internal Combustion Engine Fundamentals*, McGraw-Hill 1988:

* cylinder volume over the crank angle θ (§2.2, the slider-crank geometry):
  V(θ) = V_c + (π B²/4) (r + l − r cos θ − √(l² − r² sin² θ)), V_c = V_d / (r_c − 1);
* mass fraction burned, the Wiebe function (§9.2.1):
  x_b(θ) = 1 − exp(−a ((θ − θ_0)/Δθ)^(m+1)), with Heywood's typical a = 5, m = 2;
* the first law for the closed cylinder with a constant ratio of specific heats γ (§9.2.2,
  the single-zone heat-release relation solved for the pressure):
  dp/dθ = (γ − 1)/V · Q_n dx_b/dθ − γ p/V · dV/dθ,
  integrated from inlet valve closing (taken at bottom dead centre, θ = −180°) to exhaust valve
  opening (taken at bottom dead centre, θ = +180°) with classical RK4 at 0.05°;
* gas exchange, crudely: blowdown from the pressure at exhaust opening towards the exhaust
  back-pressure with a 12° decay constant over the exhaust stroke, then the inlet pressure over
  the inlet stroke (joined linearly over the 20° after exhaust top dead centre).

The net heat release Q_n is the fuel's chemical energy (trapped air / stoichiometric air-fuel
ratio × lower heating value) times an assumed effective fraction of 0.80 that stands for
combustion inefficiency and the wall heat loss (Heywood §9.2.2: the net heat release is the gross
release less the heat transfer to the walls). With combustion from 20° before to 25° after top
dead centre (Δθ = 45°), this gives a peak of 64 bar gauge at 12° after firing top dead centre,
typical of a naturally aspirated gasoline engine at full load; the parameters are illustrative,
not a measured engine.

The engine: the thesis' crank radius r = 46 mm (stroke 92 mm), a bore B = 82 mm (an assumption:
a plausible bore for that stroke, bore/stroke 0.89; 486 cm³ per cylinder), l = 180 mm, compression
ratio 10. Crank angle 0 = firing top dead centre, the output covers 0–720° in steps of 1°; the
pressure is gauge (absolute − 1.01325 bar). Run: `python3 pipeline/wiebe_trace.py` (no packages
beyond the standard library); the output is committed.
"""

import math
import os

# engine
BORE = 0.082  # m (assumed, see above)
R = 0.046  # m, the thesis' crank radius
L = 0.180  # m, the thesis' centre distance
RC = 10.0  # compression ratio
# charge and fuel (full load)
P_INLET = 0.95e5  # Pa absolute, inlet manifold at wide-open throttle
T_INLET = 320.0  # K, charge temperature at inlet valve closing
ETA_V = 0.90  # volumetric efficiency
AFR = 14.7  # stoichiometric air/fuel ratio of gasoline
Q_LHV = 44.0e6  # J/kg, lower heating value of gasoline
EFFECTIVE = 0.80  # net heat release / fuel energy (assumed: combustion efficiency, wall loss)
GAMMA = 1.3  # ratio of specific heats, a typical constant value for heat-release analysis
# combustion (Wiebe)
THETA_0 = -20.0  # deg, start of combustion (spark timing plus ignition delay)
DURATION = 45.0  # deg, combustion duration Δθ
A_WIEBE = 5.0
M_WIEBE = 2.0
# gas exchange
P_EXHAUST = 1.10e5  # Pa absolute, exhaust back-pressure
BLOWDOWN_DEG = 12.0
ATM = 1.01325e5  # Pa, the gauge reference

AREA = math.pi * BORE**2 / 4.0
V_D = AREA * 2.0 * R
V_C = V_D / (RC - 1.0)


def volume(theta_deg):
    t = math.radians(theta_deg)
    s = R * math.cos(t) + math.sqrt(L * L - (R * math.sin(t)) ** 2)
    return V_C + AREA * (R + L - s)


def dvolume(theta_deg):
    t = math.radians(theta_deg)
    ds = -R * math.sin(t) - R * R * math.sin(t) * math.cos(t) / math.sqrt(L * L - (R * math.sin(t)) ** 2)
    return -AREA * ds * math.pi / 180.0  # per degree


def dxb(theta_deg):
    if theta_deg <= THETA_0:
        return 0.0
    u = (theta_deg - THETA_0) / DURATION
    return A_WIEBE * (M_WIEBE + 1.0) / DURATION * u**M_WIEBE * math.exp(-A_WIEBE * u ** (M_WIEBE + 1.0))


def closed_cycle(q_n, step=0.05):
    """p(θ) at whole degrees θ = −180 … 180 (Pa absolute)."""

    def rhs(theta, p):
        v = volume(theta)
        return (GAMMA - 1.0) / v * q_n * dxb(theta) - GAMMA * p / v * dvolume(theta)

    n_per_deg = round(1.0 / step)
    p = P_INLET
    out = {-180: p}
    theta = -180.0
    for deg in range(-180, 180):
        for _ in range(n_per_deg):
            k1 = rhs(theta, p)
            k2 = rhs(theta + step / 2, p + step / 2 * k1)
            k3 = rhs(theta + step / 2, p + step / 2 * k2)
            k4 = rhs(theta + step, p + step * k3)
            p += step / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
            theta += step
        out[deg + 1] = p
    return out


def trace():
    rho = P_INLET / (287.0 * T_INLET)
    m_air = ETA_V * rho * (V_D + V_C)
    q_n = EFFECTIVE * m_air / AFR * Q_LHV
    closed = closed_cycle(q_n)
    p_evo = closed[180]
    rows = []
    for c in range(0, 721):
        if c <= 180:
            p = closed[c]
        elif c >= 540:
            p = closed[c - 720]
        elif c <= 360:
            p = P_EXHAUST + (p_evo - P_EXHAUST) * math.exp(-(c - 180) / BLOWDOWN_DEG)
        elif c <= 380:
            w = (c - 360) / 20.0
            p = (1.0 - w) * P_EXHAUST + w * P_INLET
        else:
            p = P_INLET
        rows.append((c, (p - ATM) / 1e5))
    return rows, q_n, m_air


def main():
    rows, q_n, m_air = trace()
    peak = max(rows, key=lambda r: r[1])
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "examples", "wiebe_gasoline.csv")
    with open(path, "w", encoding="utf-8") as f:
        f.write("# Cylinder pressure of a gasoline engine at full load: single-zone Wiebe model\n")
        f.write("# (Heywood, Internal Combustion Engine Fundamentals, 1988, sections 2.2, 9.2.1, 9.2.2),\n")
        f.write("# written by pipeline/wiebe_trace.py (its docstring states every assumption).\n")
        f.write(
            f"# bore {BORE * 1e3:.0f} mm, crank radius {R * 1e3:.0f} mm, l {L * 1e3:.0f} mm, compression ratio {RC:g}, "
            f"gamma {GAMMA:g}\n"
        )
        f.write(
            f"# Wiebe a = {A_WIEBE:g}, m = {M_WIEBE:g}, start {THETA_0:g} deg, duration {DURATION:g} deg; "
            f"trapped air {m_air * 1e6:.1f} mg, net heat release {q_n:.0f} J\n"
        )
        f.write(f"# peak {peak[1]:.2f} bar gauge at {peak[0]} deg; 0 deg = firing top dead centre\n")
        f.write("crank_angle_deg,pressure_bar\n")
        for c, p in rows:
            f.write(f"{c},{p:.6f}\n")
    print(f"wrote {path}: peak {peak[1]:.2f} bar gauge at {peak[0]} deg, Q_n = {q_n:.0f} J")


if __name__ == "__main__":
    main()
