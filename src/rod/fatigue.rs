//! High-cycle fatigue of a stress history at a point: signed von Mises → alternating and mean
//! stress → Goodman safety factor.
//!
//! **Equivalent stress.** The multiaxial history is reduced to the *signed von Mises* stress
//! s(t) = sgn(tr σ(t)) · σ_vM(t): von Mises carries the magnitude, the sign of the hydrostatic
//! stress says whether the point is in tension or compression (N. W. M. Bishop, F. Sherratt,
//! *Finite Element Based Fatigue Calculations*, NAFEMS, 2000, §5; also nCode's "signed von Mises").
//! Over one revolution (one load cycle per revolution in the driven mechanism: the history repeats
//! exactly) σ_a = (s_max − s_min)/2 and σ_m = (s_max + s_min)/2. For a history that is nearly
//! proportional, as a rod's (axial force and bending from one plane), this is the usual engineering
//! reduction; a critical-plane method would be the next step for strongly non-proportional
//! histories.
//!
//! **Goodman.** n = 1 / (σ_a / S_e + σ_m / S_ut) for σ_m ≥ 0; for a compressive mean the mean stress
//! is taken as not helping, n = S_e / σ_a (R. G. Budynas, J. K. Nisbett, *Shigley's Mechanical
//! Engineering Design*, 10th ed., §6-12, eqs. 6-46 and the compressive-mean branch of Table 6-6).
//!
//! **Gerber** (`[material] mean_stress = "gerber"`): the parabola n σ_a/S_e + (n σ_m/S_ut)² = 1,
//! solved for the load line through (σ_m, σ_a):
//! n = ½ (S_ut/σ_m)² (σ_a/S_e) [−1 + √(1 + (2 σ_m S_e / (S_ut σ_a))²)] for σ_m > 0 (Shigley,
//! 10th ed., Table 6-7); compressive means as with Goodman. Gerber lies above the Goodman line
//! (n_Gerber ≥ n_Goodman) and fits ductile steels' test data better; Goodman is the conservative
//! default.

use serde::{Deserialize, Serialize};

use crate::fem::material::von_mises;

/// The mean-stress correction of the fatigue safety factor.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MeanStress {
    /// The Goodman line (the default).
    #[default]
    Goodman,
    /// The Gerber parabola.
    Gerber,
}

impl MeanStress {
    /// Whether this is the default (Goodman), e.g. to leave it out of written settings.
    pub fn is_goodman(&self) -> bool {
        *self == MeanStress::Goodman
    }

    /// The safety factor of alternating `sa` and mean `sm` against `se` and `sut`.
    pub fn safety_factor(self, sa: f64, sm: f64, se: f64, sut: f64) -> f64 {
        match self {
            MeanStress::Goodman => goodman_safety_factor(sa, sm, se, sut),
            MeanStress::Gerber => gerber_safety_factor(sa, sm, se, sut),
        }
    }

    /// The criterion's formula, for the reports.
    pub fn formula(self) -> &'static str {
        match self {
            MeanStress::Goodman => "Goodman n = 1/(σa/Se + σm/Sut)",
            MeanStress::Gerber => "Gerber n σa/Se + (n σm/Sut)² = 1",
        }
    }
}

/// The signed von Mises stress of a stress `[xx, yy, zz, xy, yz, zx]`: the von Mises stress with the
/// sign of the trace (Bishop & Sherratt); `+` for a zero trace.
pub fn signed_von_mises(s: &[f64; 6]) -> f64 {
    let vm = von_mises(s);
    if s[0] + s[1] + s[2] < 0.0 { -vm } else { vm }
}

/// Alternating and mean stress of a cycle with extremes `s_min` ≤ `s_max`.
pub fn amplitude_and_mean(s_min: f64, s_max: f64) -> (f64, f64) {
    (0.5 * (s_max - s_min), 0.5 * (s_max + s_min))
}

/// The Goodman safety factor of alternating stress `sa` and mean stress `sm` against endurance
/// limit `se` and ultimate strength `sut` (same units); infinite when `sa` and `sm` are both ≤ 0.
pub fn goodman_safety_factor(sa: f64, sm: f64, se: f64, sut: f64) -> f64 {
    let demand = if sm >= 0.0 {
        sa / se + sm / sut
    } else {
        sa / se
    };
    if demand > 0.0 {
        1.0 / demand
    } else {
        f64::INFINITY
    }
}

/// The Gerber safety factor (see the module documentation); for σ_m ≤ 0 as Goodman's.
pub fn gerber_safety_factor(sa: f64, sm: f64, se: f64, sut: f64) -> f64 {
    if sm <= 0.0 {
        return goodman_safety_factor(sa, sm, se, sut);
    }
    if sa <= 0.0 {
        // static tension: the parabola meets the σ_m axis at S_ut
        return sut / sm;
    }
    let q = 2.0 * sm * se / (sut * sa);
    // −1 + √(1 + q²) written without cancellation for small q: q² / (1 + √(1 + q²))
    let root = q * q / (1.0 + (1.0 + q * q).sqrt());
    0.5 * (sut / sm).powi(2) * (sa / se) * root
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signed_von_mises_takes_the_sign_of_the_trace() {
        // uniaxial tension and compression: ± the axial stress
        assert_eq!(signed_von_mises(&[100.0, 0.0, 0.0, 0.0, 0.0, 0.0]), 100.0);
        assert_eq!(signed_von_mises(&[-100.0, 0.0, 0.0, 0.0, 0.0, 0.0]), -100.0);
        // pure shear: trace 0, von Mises √3 τ
        let s = signed_von_mises(&[0.0, 0.0, 0.0, 10.0, 0.0, 0.0]);
        assert!((s - 10.0 * 3f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn goodman_line_and_its_limits() {
        let (se, sut) = (235.0, 470.0);
        // fully reversed: n = Se / σa
        assert!((goodman_safety_factor(117.5, 0.0, se, sut) - 2.0).abs() < 1e-12);
        // static tension at the ultimate: n = 1
        assert!((goodman_safety_factor(0.0, sut, se, sut) - 1.0).abs() < 1e-12);
        // a point on the Goodman line σa/Se + σm/Sut = 1 has n = 1
        let (sa, sm) = (0.5 * se, 0.5 * sut);
        assert!((goodman_safety_factor(sa, sm, se, sut) - 1.0).abs() < 1e-12);
        // compressive mean: the mean does not help
        assert!((goodman_safety_factor(117.5, -200.0, se, sut) - 2.0).abs() < 1e-12);
        assert_eq!(goodman_safety_factor(0.0, -10.0, se, sut), f64::INFINITY);
        // pulsating 0 → s: σa = σm = s/2
        let (sa, sm) = amplitude_and_mean(0.0, 200.0);
        assert_eq!((sa, sm), (100.0, 100.0));
        let n = goodman_safety_factor(sa, sm, se, sut);
        assert!((n - 1.0 / (100.0 / se + 100.0 / sut)).abs() < 1e-12);
    }

    #[test]
    fn gerber_parabola_and_its_limits() {
        let (se, sut) = (235.0, 470.0);
        // fully reversed and static: as Goodman
        assert!((gerber_safety_factor(117.5, 0.0, se, sut) - 2.0).abs() < 1e-12);
        assert!((gerber_safety_factor(0.0, 235.0, se, sut) - 2.0).abs() < 1e-12);
        // a point on the parabola σa/Se + (σm/Sut)² = 1 has n = 1, scaled loads scale n
        for sm in [10.0, 100.0, 300.0, 460.0] {
            let sa = se * (1.0 - (sm / sut) * (sm / sut));
            let n = gerber_safety_factor(sa, sm, se, sut);
            assert!((n - 1.0).abs() < 1e-12, "σm {sm}: n = {n}");
            let n2 = gerber_safety_factor(0.5 * sa, 0.5 * sm, se, sut);
            // n σa/Se + (n σm/Sut)² = 1 at half the load
            let g = n2 * 0.5 * sa / se + (n2 * 0.5 * sm / sut).powi(2);
            assert!((g - 1.0).abs() < 1e-12, "{g}");
            assert!(n2 > 2.0 * 0.999);
            // Gerber credits more than Goodman
            assert!(n2 >= goodman_safety_factor(0.5 * sa, 0.5 * sm, se, sut));
        }
        // compressive mean: as Goodman
        assert_eq!(
            gerber_safety_factor(117.5, -200.0, se, sut),
            goodman_safety_factor(117.5, -200.0, se, sut)
        );
        assert_eq!(
            MeanStress::Gerber.safety_factor(50.0, 80.0, se, sut),
            gerber_safety_factor(50.0, 80.0, se, sut)
        );
        assert_eq!(
            MeanStress::Goodman.safety_factor(50.0, 80.0, se, sut),
            goodman_safety_factor(50.0, 80.0, se, sut)
        );
    }
}
