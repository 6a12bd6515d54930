//! The reduction method for the crank–slider (thesis §3.1.2, eq. 3.11–3.24, 4.1).

use super::loads::{G, Loads};
use super::mechanism::{CrankSliderData, KinematicPoint, Kinematics};
use serde::Serialize;
use std::f64::consts::PI;

/// Why mechanism data are refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// `l ≤ r`: the crank cannot make a full turn (the rod would have to stretch).
    #[error(
        "rod too short: centre distance l = {l} m must exceed the crank radius r = {r} m \
         (l ≤ r: the crank cannot turn)"
    )]
    RodTooShort {
        /// Centre distance \[m\].
        l: f64,
        /// Crank radius \[m\].
        r: f64,
    },
    /// Missing, negative or non-finite data.
    #[error("invalid mechanism data: {0}")]
    InvalidData(String),
    /// The reduced moment of inertia is not positive somewhere (wrong input data).
    #[error(
        "reduced moment of inertia I_red = {i_red:.6e} kg·m² ≤ 0 at φ = {phi_deg:.3}° \
         ({phi_rad:.6} rad), I_kor = {i_kor:.6e} kg·m²: the rod inertia data are inconsistent \
         (a physical rod keeps I_red > 0); refusing to integrate"
    )]
    NonPositiveInertia {
        /// Crank angle of the minimum \[rad\].
        phi_rad: f64,
        /// The same in degrees.
        phi_deg: f64,
        /// `I_red` there [kg·m²].
        i_red: f64,
        /// The two-mass correction inertia of the data [kg·m²].
        i_kor: f64,
    },
}

/// The rod replaced by two point masses at the pins plus a correction inertia
/// (thesis Fig. 3.2, eq. 3.11–3.14):
/// `m_A + m_B = m3` (3.11), `m_A l1 = m_B l2` (3.12), `I_S3 = m_A l1² + m_B l2² + I_kor` (3.13),
/// so `m_A = m3 l2 / l`, `m_B = m3 l1 / l` (3.41–3.42) and `I_kor = I_S3 − m_A l1² − m_B l2²`
/// (3.14, 3.44), with `l = l1 + l2`. This replacement preserves mass, centroid and centroidal
/// inertia, so for a rod whose centroid lies on AB it is exact for planar motion. (The thesis
/// prints `m_B = 1,89969501440514 kg` in eq. 3.42, a digit short: `m_B = 1.899695014404514 kg`.)
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TwoMassRod {
    /// Point mass at the crank pin A \[kg\].
    pub m_a: f64,
    /// Point mass at the piston pin B \[kg\].
    pub m_b: f64,
    /// Correction moment of inertia [kg·m²] (negative for real rods).
    pub i_kor: f64,
}

impl TwoMassRod {
    /// Eq. 3.41, 3.42, 3.44.
    pub fn from_data(d: &CrankSliderData) -> Self {
        let l = d.l();
        let m_a = d.m3 * d.l2 / l;
        let m_b = d.m3 * d.l1 / l;
        let i_kor = d.i_s3 - m_a * d.l1 * d.l1 - m_b * d.l2 * d.l2;
        Self { m_a, m_b, i_kor }
    }
}

/// The crank as reduction member: `I_red(φ)`, `M_red(φ, φ̇)` and the equation of motion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReducedModel {
    /// Mechanism data.
    pub data: CrankSliderData,
    /// Two-mass rod.
    pub rod: TwoMassRod,
    /// Crank angle \[rad\] of the smallest `I_red` over a revolution.
    pub i_red_min_phi: f64,
    /// Smallest `I_red` over a revolution [kg·m²].
    pub i_red_min: f64,
    #[serde(skip)]
    kin: Kinematics,
}

impl ReducedModel {
    /// Builds the model and refuses data it cannot integrate: `l ≤ r`, non-finite data,
    /// negative masses, a centroid outside AB, or `I_red(φ) ≤ 0` anywhere on a revolution
    /// (found by a scan of 7200 points refined by golden-section search; the error names φ).
    /// Inertia inputs are not sign-checked one by one: wrong inertia data (e.g. a two-mass
    /// `I_kor` far below the thesis' −0.032 kg·m²) are caught by the `I_red` check.
    pub fn new(data: CrankSliderData) -> Result<Self, ModelError> {
        let d = &data;
        let fields = [d.r, d.m2, d.i2, d.crank_ecc, d.m3, d.i_s3, d.l1, d.l2, d.m4];
        if fields.iter().any(|v| !v.is_finite()) {
            return Err(ModelError::InvalidData(format!(
                "non-finite value in {d:?}"
            )));
        }
        if d.r <= 0.0 || d.m2 < 0.0 || d.m3 < 0.0 || d.m4 < 0.0 {
            return Err(ModelError::InvalidData(format!(
                "need r > 0 and non-negative masses, got {d:?}"
            )));
        }
        if d.l1 < 0.0 || d.l2 < 0.0 {
            return Err(ModelError::InvalidData(format!(
                "rod centroid must lie between the pins (l1 = {}, l2 = {})",
                d.l1, d.l2
            )));
        }
        if d.l() <= d.r {
            return Err(ModelError::RodTooShort { l: d.l(), r: d.r });
        }
        let kin = Kinematics { r: d.r, l: d.l() };
        let rod = TwoMassRod::from_data(d);
        let mut m = Self {
            data,
            rod,
            i_red_min_phi: 0.0,
            i_red_min: 0.0,
            kin,
        };
        let (phi, i) = m.scan_min_i_red();
        m.i_red_min_phi = phi;
        m.i_red_min = i;
        if i.is_nan() || i <= 0.0 {
            return Err(ModelError::NonPositiveInertia {
                phi_rad: phi,
                phi_deg: phi.to_degrees(),
                i_red: i,
                i_kor: rod.i_kor,
            });
        }
        Ok(m)
    }

    /// Kinematics of this mechanism.
    pub fn kinematics(&self) -> &Kinematics {
        &self.kin
    }

    fn scan_min_i_red(&self) -> (f64, f64) {
        const N: usize = 7200;
        let step = 2.0 * PI / N as f64;
        let (mut best_k, mut best) = (0usize, f64::INFINITY);
        for k in 0..N {
            let v = self.i_red(k as f64 * step);
            if v < best || v.is_nan() {
                best = v;
                best_k = k;
                if v.is_nan() {
                    return (k as f64 * step, v);
                }
            }
        }
        // golden-section refinement on the bracketing interval
        let (mut a, mut b) = ((best_k as f64 - 1.0) * step, (best_k as f64 + 1.0) * step);
        let gr = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..60 {
            let c = b - gr * (b - a);
            let e = a + gr * (b - a);
            if self.i_red(c) < self.i_red(e) {
                b = e
            } else {
                a = c
            }
        }
        let phi = 0.5 * (a + b);
        let v = self.i_red(phi);
        if v < best {
            // report in [0, 2π), with angles a hair below 2π shown as 0
            let p = phi.rem_euclid(2.0 * PI);
            (if 2.0 * PI - p < 1e-9 { 0.0 } else { p }, v)
        } else {
            (best_k as f64 * step, best)
        }
    }

    /// `I_red(φ) = I2 + m_A r² + m_B p42² + m4 p42² + I_kor p32²` (eq. 3.17).
    pub fn i_red(&self, phi: f64) -> f64 {
        self.i_red_at(&self.kin.at(phi))
    }

    /// Eq. 3.17 at a precomputed kinematic point.
    pub fn i_red_at(&self, k: &KinematicPoint) -> f64 {
        let d = &self.data;
        d.i2 + self.rod.m_a * d.r * d.r
            + (self.rod.m_b + d.m4) * k.p42 * k.p42
            + self.rod.i_kor * k.p32 * k.p32
    }

    /// `dI_red/dφ = 2 (m_B + m4) p42 p42' + 2 I_kor p32 p32'` (eq. 3.18–3.19; the thesis
    /// prints the last term as `2 I_kor dp32(φ) dp32/dφ`, a misprint for `p32(φ) dp32/dφ`).
    pub fn di_red(&self, phi: f64) -> f64 {
        self.di_red_at(&self.kin.at(phi))
    }

    /// Eq. 3.19 at a precomputed kinematic point.
    pub fn di_red_at(&self, k: &KinematicPoint) -> f64 {
        2.0 * (self.rod.m_b + self.data.m4) * k.p42 * k.dp42 + 2.0 * self.rod.i_kor * k.p32 * k.dp32
    }

    /// `d²I_red/dφ² = 2 (m_B + m4)(p42'² + p42 p42'') + 2 I_kor (p32'² + p32 p32'')`
    /// (derivative of eq. 3.19; used by the analytic Jacobian).
    pub fn d2i_red_at(&self, k: &KinematicPoint) -> f64 {
        2.0 * (self.rod.m_b + self.data.m4) * (k.dp42 * k.dp42 + k.p42 * k.d2p42)
            + 2.0 * self.rod.i_kor * (k.dp32 * k.dp32 + k.p32 * k.d2p32)
    }

    /// Gravity lever `K = m2 e + m_A r`: the potential is `V(φ) = g K sin φ` (the rod's
    /// centroid height `r sin φ · l2/l` equals that of `m_A` at A; `m_B` and the piston stay at
    /// `y = 0`).
    pub fn gravity_lever(&self) -> f64 {
        self.data.m2 * self.data.crank_ecc + self.rod.m_a * self.data.r
    }

    /// Potential energy of gravity and of the spring's elastic part, `V(φ)` \[J\].
    pub fn potential(&self, loads: &Loads, phi: f64, k: &KinematicPoint) -> f64 {
        let mut v = 0.0;
        if loads.gravity {
            v += G * self.gravity_lever() * phi.sin();
        }
        if let Some(s) = loads.spring {
            v += 0.5 * s.k * (k.x - s.x0).powi(2);
        }
        v
    }

    /// Reduced moment `M_red = M + F p42` (eq. 3.20–3.22), extended by gravity
    /// `−g K cos φ` and the spring's `(−k (x − x0) − c p42 φ̇) p42` when enabled.
    pub fn m_red_at(&self, loads: &Loads, phi: f64, omega: f64, k: &KinematicPoint) -> f64 {
        let mut f = loads.piston_force;
        if let Some(s) = loads.spring {
            f += -s.k * (k.x - s.x0) - s.c * k.p42 * omega;
        }
        let mut m = loads.torque + f * k.p42;
        if loads.gravity {
            m -= G * self.gravity_lever() * phi.cos();
        }
        m
    }

    /// `M_red(φ, φ̇)` (eq. 3.22 and extensions).
    pub fn m_red(&self, loads: &Loads, phi: f64, omega: f64) -> f64 {
        self.m_red_at(loads, phi, omega, &self.kin.at(phi))
    }

    /// Crank acceleration from the equation of motion (eq. 3.10, 3.24, solved as eq. 4.1):
    /// `φ̈ = M_red / I_red − ½ (dI_red/dφ) / I_red · φ̇²`.
    pub fn acceleration(&self, loads: &Loads, phi: f64, omega: f64) -> f64 {
        if loads.spring.is_none() {
            // fast path: no travel or second derivatives needed
            let (p42, p32, dp42, dp32) = self.kin.transfer(phi);
            let d = &self.data;
            let mb4 = self.rod.m_b + d.m4;
            let i = d.i2 + self.rod.m_a * d.r * d.r + mb4 * p42 * p42 + self.rod.i_kor * p32 * p32;
            let di = 2.0 * mb4 * p42 * dp42 + 2.0 * self.rod.i_kor * p32 * dp32;
            let mut m = loads.torque + loads.piston_force * p42;
            if loads.gravity {
                m -= G * self.gravity_lever() * phi.cos();
            }
            return (m - 0.5 * di * omega * omega) / i;
        }
        let k = self.kin.at(phi);
        (self.m_red_at(loads, phi, omega, &k) - 0.5 * self.di_red_at(&k) * omega * omega)
            / self.i_red_at(&k)
    }

    /// `(∂φ̈/∂φ, ∂φ̈/∂φ̇)`, analytic, for the implicit solvers' Jacobian.
    pub fn acceleration_partials(&self, loads: &Loads, phi: f64, omega: f64) -> (f64, f64) {
        let k = self.kin.at(phi);
        let i = self.i_red_at(&k);
        let di = self.di_red_at(&k);
        let d2i = self.d2i_red_at(&k);
        let mr = self.m_red_at(loads, phi, omega, &k);
        let a = (mr - 0.5 * di * omega * omega) / i;
        let mut f = loads.piston_force;
        let (mut dmr_dphi, mut dmr_dw) = (0.0, 0.0);
        if let Some(s) = loads.spring {
            f += -s.k * (k.x - s.x0) - s.c * k.p42 * omega;
            let df_dphi = -s.k * k.p42 - s.c * k.dp42 * omega;
            dmr_dphi += df_dphi * k.p42;
            dmr_dw += -s.c * k.p42 * k.p42;
        }
        dmr_dphi += f * k.dp42;
        if loads.gravity {
            dmr_dphi += G * self.gravity_lever() * phi.sin();
        }
        let da_dphi = (dmr_dphi - 0.5 * d2i * omega * omega - a * di) / i;
        let da_dw = (dmr_dw - di * omega) / i;
        (da_dphi, da_dw)
    }

    /// Energy invariant `E = ½ I_red φ̇² − M φ − F x + V(φ)` \[J\] (kinetic energy, eq. 3.16,
    /// minus the work of the constant loads plus the potentials). Constant along exact
    /// solutions when the loads are conservative.
    pub fn energy(&self, loads: &Loads, phi: f64, omega: f64) -> f64 {
        let k = self.kin.at(phi);
        0.5 * self.i_red_at(&k) * omega * omega - loads.torque * phi - loads.piston_force * k.x
            + self.potential(loads, phi, &k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::free_run::loads::GasSpring;

    fn model() -> ReducedModel {
        ReducedModel::new(CrankSliderData::thesis_ch3()).unwrap()
    }

    #[test]
    fn two_mass_rod_matches_thesis_numbers() {
        let r = model().rod;
        assert!((r.m_a - 2.407211190695486).abs() < 1e-13, "m_A {}", r.m_a); // eq. 3.41
        assert!((r.m_b - 1.899695014404514).abs() < 1e-13, "m_B {}", r.m_b); // eq. 3.42 (SPEC)
        assert!(
            (r.i_kor - -0.031881341820528).abs() < 1e-14,
            "I_kor {}",
            r.i_kor
        ); // eq. 3.44
        let d = CrankSliderData::thesis_ch3();
        // eq. 3.43: I2 = I_S2 + m2 e² with I_S2 = 0.01619745319 (printed 0.1619745319)
        assert!((0.01619745319 + d.m2 * d.crank_ecc.powi(2) - d.i2).abs() < 1e-11);
    }

    #[test]
    fn i_red_matches_eq_3_16_kinetic_energy() {
        // ½ I_red φ̇² must equal the kinetic energy of eq. 3.15 with ẋ = p42 φ̇, ψ̇ = p32 φ̇,
        // and the exact rigid-rod energy ½ m3 v_G² + ½ I_S3 ψ̇² (two-mass model is exact).
        let m = model();
        let d = m.data;
        let k = m.kinematics();
        let h = 1e-6;
        for i in 0..24 {
            let phi = 0.05 + 0.27 * i as f64;
            let w = 3.0;
            let p = k.at(phi);
            let xdot = p.p42 * w;
            let psidot = p.p32 * w;
            let e315 = 0.5 * d.i2 * w * w
                + 0.5 * m.rod.m_a * (d.r * w).powi(2)
                + 0.5 * (m.rod.m_b + d.m4) * xdot * xdot
                + 0.5 * m.rod.i_kor * psidot * psidot;
            assert!((0.5 * m.i_red(phi) * w * w - e315).abs() < 1e-14);
            // rigid rod: G = A + l1 (B − A)/l
            let g = |f: f64| {
                let (ax, ay) = (d.r * f.cos(), d.r * f.sin());
                let bx = d.r + d.l() - k.x(f); // B = (r cos φ + l cos ψ, 0)
                let t = d.l1 / d.l();
                (ax + t * (bx - ax), ay * (1.0 - t))
            };
            let (gp, gm) = (g(phi + h), g(phi - h));
            let vg2 = ((gp.0 - gm.0) / (2.0 * h)).powi(2) + ((gp.1 - gm.1) / (2.0 * h)).powi(2);
            let exact = 0.5 * d.i2 * w * w
                + 0.5 * d.m3 * vg2 * w * w
                + 0.5 * d.i_s3 * psidot * psidot
                + 0.5 * d.m4 * xdot * xdot;
            assert!((e315 - exact).abs() < 1e-8, "φ = {phi}: {e315} vs {exact}");
        }
    }

    #[test]
    fn di_red_against_finite_differences() {
        let m = model();
        let h = 1e-5;
        for i in 0..60 {
            let phi = -1.0 + 0.23 * i as f64;
            let fd = (m.i_red(phi + h) - m.i_red(phi - h)) / (2.0 * h);
            assert!((m.di_red(phi) - fd).abs() < 1e-11, "φ = {phi}");
            let k = m.kinematics();
            let fd2 = (m.di_red(phi + h) - m.di_red(phi - h)) / (2.0 * h);
            assert!((m.d2i_red_at(&k.at(phi)) - fd2).abs() < 1e-10, "φ = {phi}");
        }
    }

    #[test]
    fn acceleration_partials_against_finite_differences() {
        let m = model();
        let loads = Loads {
            gravity: true,
            spring: Some(GasSpring {
                k: 1e4,
                x0: 0.03,
                c: 5.0,
            }),
            ..Loads::thesis_ch4()
        };
        let h = 1e-6;
        for i in 0..30 {
            let (phi, w) = (0.1 + 0.21 * i as f64, 2.0 + i as f64);
            let (ap, aw) = m.acceleration_partials(&loads, phi, w);
            let fp = (m.acceleration(&loads, phi + h, w) - m.acceleration(&loads, phi - h, w))
                / (2.0 * h);
            let fw = (m.acceleration(&loads, phi, w + h) - m.acceleration(&loads, phi, w - h))
                / (2.0 * h);
            assert!(
                (ap - fp).abs() < 1e-6 * (1.0 + fp.abs()),
                "∂/∂φ at {phi}: {ap} vs {fp}"
            );
            assert!(
                (aw - fw).abs() < 1e-6 * (1.0 + fw.abs()),
                "∂/∂ω at {phi}: {aw} vs {fw}"
            );
        }
    }

    #[test]
    fn equation_of_motion_is_energy_balance() {
        // d/dt(½ I φ̇²) = M_red φ̇ (eq. 3.8–3.10) ⇔ φ̈ from eq. 4.1
        let m = model();
        let loads = Loads::thesis_ch4();
        let (phi, w) = (0.9, 7.0);
        let a = m.acceleration(&loads, phi, w);
        let lhs = 0.5 * m.di_red(phi) * w * w * w + m.i_red(phi) * w * a; // eq. 3.9
        let rhs = m.m_red(&loads, phi, w) * w;
        assert!((lhs - rhs).abs() < 1e-12);
        // the fast path (no spring) and the general path agree
        let spring0 = Loads {
            spring: Some(GasSpring {
                k: 0.0,
                x0: 0.0,
                c: 0.0,
            }),
            gravity: true,
            ..loads
        };
        let grav = Loads {
            gravity: true,
            ..loads
        };
        assert!((m.acceleration(&spring0, phi, w) - m.acceleration(&grav, phi, w)).abs() < 1e-12);
        // eq. 3.22 at TDC: p42 = 0, so M_red = M
        assert_eq!(m.m_red(&loads, 0.0, 0.0), 1.0);
    }

    #[test]
    fn min_i_red_is_positive_for_thesis_data() {
        let m = model();
        assert!(
            m.i_red_min > 0.019 && m.i_red_min < 0.0195,
            "{}",
            m.i_red_min
        );
        // minimum at a dead centre (p42 = 0, |p32| = r/l maximal)
        let s = m.i_red_min_phi.sin();
        assert!(s.abs() < 1e-6, "φ_min = {}", m.i_red_min_phi);
    }
}
