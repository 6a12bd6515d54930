//! Mechanism data and crank–slider kinematics (thesis ch. 2 and §3.4).

use serde::{Deserialize, Serialize};

/// Mass and geometry data of the crank–slider (SI units).
///
/// The rod's centroid lies on the line AB at `l1` from the crank pin A and `l2` from the
/// piston pin B; the centre distance is `l = l1 + l2`. For the thesis' ch. 3 rod this gives
/// `l = 0.17999999995 m` (not 0.18 m): that is how the thesis' `m_A`, `m_B` and `I_kor`
/// (eq. 3.41, 3.42, 3.44) come out. Rods with a given centre distance `l` use
/// [`CrankSliderData::with_rod`]. A transverse centroid offset is not part of the reduced
/// (two-mass) model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CrankSliderData {
    /// Crank radius `r` = |OA| \[m\].
    pub r: f64,
    /// Crank mass `m2` \[kg\] (used only for gravity).
    pub m2: f64,
    /// Crank moment of inertia about O, `I2` [kg·m²] (eq. 3.43, `I2 = I_S2 + m2 e²`; the thesis
    /// prints `I_S2 = 0.1619745319` with a misplaced decimal, 0.01619745319 is consistent).
    pub i2: f64,
    /// Crank centroid eccentricity `e` \[m\], signed, measured from O along OA (used only for
    /// gravity; the thesis gives |e| but not the direction: positive = towards the crank pin).
    pub crank_ecc: f64,
    /// Rod mass `m3` \[kg\].
    pub m3: f64,
    /// Rod moment of inertia about its centroid (pin axis), `I_S3` [kg·m²].
    pub i_s3: f64,
    /// Distance crank pin A → rod centroid, `l1` \[m\].
    pub l1: f64,
    /// Distance rod centroid → piston pin B, `l2` \[m\].
    pub l2: f64,
    /// Piston mass `m4` \[kg\].
    pub m4: f64,
}

impl CrankSliderData {
    /// The thesis' ch. 3 data (§3.4, eq. 3.41–3.44; SPEC "The mechanism").
    pub fn thesis_ch3() -> Self {
        Self {
            r: 0.046,
            m2: 8.9459574505,
            i2: 0.016438481547370,
            crank_ecc: 0.005190636979,
            m3: 4.3069062051,
            i_s3: 0.002520181413,
            l1: 0.07939460165,
            l2: 0.1006053983,
            m4: 5.2269229374,
        }
    }

    /// Replaces the rod: mass `m3`, centroidal inertia `i_s3`, centroid at `l1` from A, centre
    /// distance `l` (so `l2 = l − l1`).
    pub fn with_rod(self, m3: f64, i_s3: f64, l1: f64, l: f64) -> Self {
        Self {
            m3,
            i_s3,
            l1,
            l2: l - l1,
            ..self
        }
    }

    /// Same rod (mass, centroidal inertia, centroid fraction `l1/l`) with the centre distance
    /// scaled to `l = ratio · r` (for the near-toggle hard case `l/r → 1`).
    pub fn with_rod_ratio(self, ratio: f64) -> Self {
        let l = ratio * self.r;
        let frac = self.l1 / self.l();
        Self {
            l1: frac * l,
            l2: (1.0 - frac) * l,
            ..self
        }
    }

    /// Sets `I_S3` so that the two-mass correction inertia (eq. 3.14) is `i_kor`, for data
    /// given in the thesis' two-mass form.
    pub fn with_i_kor(self, i_kor: f64) -> Self {
        let l = self.l();
        let (m_a, m_b) = (self.m3 * self.l2 / l, self.m3 * self.l1 / l);
        Self {
            i_s3: i_kor + m_a * self.l1 * self.l1 + m_b * self.l2 * self.l2,
            ..self
        }
    }

    /// Centre distance `l = l1 + l2` \[m\].
    pub fn l(&self) -> f64 {
        self.l1 + self.l2
    }
}

/// Position-dependent kinematic quantities at one crank angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KinematicPoint {
    /// Piston travel from the top dead centre, `x(φ)` \[m\] (eq. 2.8).
    pub x: f64,
    /// `cos ψ = sqrt(1 − (r/l)² sin² φ)` (eq. 2.7).
    pub cos_psi: f64,
    /// `p42 = dx/dφ` \[m\] (eq. 2.11).
    pub p42: f64,
    /// `p32 = dψ/dφ` [–] (eq. 2.12).
    pub p32: f64,
    /// `dp42/dφ` \[m\].
    pub dp42: f64,
    /// `dp32/dφ`.
    pub dp32: f64,
    /// `d²p42/dφ²` \[m\].
    pub d2p42: f64,
    /// `d²p32/dφ²`.
    pub d2p32: f64,
}

/// Crank–slider kinematics for crank radius `r` and centre distance `l` (`l > r`).
///
/// With `λ = r/l`, `s = sin φ`, `c = cos φ`, `D = cos ψ = sqrt(1 − λ² s²)` (eq. 2.7):
/// - eq. 2.8:  `x = (r + l) − (r c + l D)`, evaluated without cancellation as
///   `x = 2 r sin²(φ/2) + (r²/l) s² / (1 + D)`;
/// - eq. 2.12: `p32 = λ c / D`, and `dp32/dφ = −λ (1 − λ²) s / D³`,
///   `d²p32/dφ² = −λ (1 − λ²) c (1 + 2 λ² s²) / D⁵`;
/// - eq. 2.11: `p42 = r s + r λ s c / D = r s (1 + p32)`, and
///   `dp42/dφ = r c (1 + p32) + r s p32'`, `d²p42/dφ² = −r s (1 + p32) + 2 r c p32' + r s p32''`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kinematics {
    /// Crank radius \[m\].
    pub r: f64,
    /// Centre distance \[m\].
    pub l: f64,
}

impl Kinematics {
    /// All kinematic quantities at crank angle `phi` \[rad\].
    pub fn at(&self, phi: f64) -> KinematicPoint {
        let (r, l) = (self.r, self.l);
        let lam = r / l;
        let (s, c) = phi.sin_cos();
        let d = (1.0 - lam * lam * s * s).sqrt();
        let half = (0.5 * phi).sin();
        let x = 2.0 * r * half * half + r * lam * s * s / (1.0 + d);
        let p32 = lam * c / d;
        let k = lam * (1.0 - lam * lam);
        let d3 = d * d * d;
        let dp32 = -k * s / d3;
        let d2p32 = -k * c * (1.0 + 2.0 * lam * lam * s * s) / (d3 * d * d);
        let p42 = r * s * (1.0 + p32);
        let dp42 = r * c * (1.0 + p32) + r * s * dp32;
        let d2p42 = -r * s * (1.0 + p32) + 2.0 * r * c * dp32 + r * s * d2p32;
        KinematicPoint {
            x,
            cos_psi: d,
            p42,
            p32,
            dp42,
            dp32,
            d2p42,
            d2p32,
        }
    }

    /// First-order quantities only, `(p42, p32, dp42/dφ, dp32/dφ)` (what the right-hand side
    /// of the equation of motion needs without a spring).
    pub fn transfer(&self, phi: f64) -> (f64, f64, f64, f64) {
        let lam = self.r / self.l;
        let (s, c) = phi.sin_cos();
        let d = (1.0 - lam * lam * s * s).sqrt();
        let p32 = lam * c / d;
        let dp32 = -lam * (1.0 - lam * lam) * s / (d * d * d);
        let p42 = self.r * s * (1.0 + p32);
        let dp42 = self.r * c * (1.0 + p32) + self.r * s * dp32;
        (p42, p32, dp42, dp32)
    }

    /// Piston travel `x(φ)` (eq. 2.8).
    pub fn x(&self, phi: f64) -> f64 {
        self.at(phi).x
    }

    /// `x(φ0 + Δ) − x(φ0)` without cancellation for small `Δ`:
    /// `r·2 sin(φ0 + Δ/2) sin(Δ/2) + l λ² sin Δ sin(2φ0 + Δ) / (D0 + D)`.
    pub fn x_increment(&self, phi0: f64, delta: f64) -> f64 {
        let lam = self.r / self.l;
        let phi = phi0 + delta;
        let d0 = (1.0 - (lam * phi0.sin()).powi(2)).sqrt();
        let d1 = (1.0 - (lam * phi.sin()).powi(2)).sqrt();
        2.0 * self.r * (phi0 + 0.5 * delta).sin() * (0.5 * delta).sin()
            + self.l * lam * lam * delta.sin() * (2.0 * phi0 + delta).sin() / (d0 + d1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kin() -> Kinematics {
        let d = CrankSliderData::thesis_ch3();
        Kinematics { r: d.r, l: d.l() }
    }

    #[test]
    fn travel_matches_eq_2_8() {
        let k = kin();
        for i in 0..50 {
            let phi = -3.0 + 0.37 * i as f64;
            let lam = k.r / k.l;
            let direct =
                (k.r + k.l) - (k.r * phi.cos() + k.l * (1.0 - (lam * phi.sin()).powi(2)).sqrt());
            assert!((k.x(phi) - direct).abs() < 1e-15, "φ = {phi}");
        }
        assert!((k.x(std::f64::consts::PI) - 2.0 * k.r).abs() < 1e-15);
    }

    #[test]
    fn transfer_functions_match_eq_2_11_2_12_and_finite_differences() {
        let k = kin();
        let h = 1e-5;
        for i in 0..40 {
            let phi = 0.1 + 0.31 * i as f64;
            let p = k.at(phi);
            let (s, c) = phi.sin_cos();
            let lam = k.r / k.l;
            let root = (1.0 - (lam * s).powi(2)).sqrt();
            // eq. 2.11 and 2.12 as printed
            let p42 = k.r * k.r * s * c / (k.l * root) + k.r * s;
            let p32 = k.r * c / (k.l * root);
            assert!((p.p42 - p42).abs() < 1e-16 && (p.p32 - p32).abs() < 1e-15);
            assert_eq!(k.transfer(phi), (p.p42, p.p32, p.dp42, p.dp32));
            let (a, b) = (k.at(phi + h), k.at(phi - h));
            assert!((p.p42 - (a.x - b.x) / (2.0 * h)).abs() < 1e-10);
            assert!((p.dp42 - (a.p42 - b.p42) / (2.0 * h)).abs() < 1e-10);
            assert!((p.dp32 - (a.p32 - b.p32) / (2.0 * h)).abs() < 1e-9);
            assert!((p.d2p42 - (a.dp42 - b.dp42) / (2.0 * h)).abs() < 1e-9);
            assert!((p.d2p32 - (a.dp32 - b.dp32) / (2.0 * h)).abs() < 1e-8);
            // ψ from sin ψ = λ sin φ: dψ/dφ
            let psi = |f: f64| (lam * f.sin()).asin();
            assert!((p.p32 - (psi(phi + h) - psi(phi - h)) / (2.0 * h)).abs() < 1e-9);
        }
    }

    #[test]
    fn travel_increment_has_no_cancellation() {
        let k = kin();
        for phi0 in [0.0, 0.7, 2.0, 100.0] {
            for delta in [1e-12, 1e-6, 0.3, 5.0] {
                let direct = k.x(phi0 + delta) - k.x(phi0);
                let inc = k.x_increment(phi0, delta);
                assert!(
                    (inc - direct).abs() <= 1e-15 + 1e-9 * direct.abs(),
                    "{phi0} {delta}"
                );
            }
        }
        // tiny increment from TDC: x ≈ (r + r²/l) Δ²/2 with full relative accuracy
        let d = 1e-9;
        let want = 0.5 * (k.r + k.r * k.r / k.l) * d * d;
        assert!((k.x_increment(0.0, d) / want - 1.0).abs() < 1e-12);
    }
}
