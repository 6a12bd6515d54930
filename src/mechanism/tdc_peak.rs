//! The peak pin force at constant crank speed: the closed formula at top dead
//! centre, the refined true maximum, and its inverse, the l₁ that reproduces a
//! given peak.
//!
//! At constant crank speed ω the peak of |F_A| is at top dead centre (φ = 0),
//! where θ̈ = 0 so that the rod's inertia drops out, and — without gravity and
//! transverse offset — it equals
//!
//! F_TDC = r ω² [m₄ (1 + r/l) + m₃ (1 + (r/l)(l₁/l))]
//!
//! (closed-form Newton–Euler of [`closed_form`](super::closed_form) at φ = 0).
//! Gravity adds a small vertical component (the rod's and piston's weight
//! share, ≈ 20 N) that changes |F_A| by ≈ W²/(2F) ≈ 0.02 N and shifts the peak
//! a few thousandths of a degree off TDC; the studies use the refined true
//! maximum ([`refine_peak`], [`peak_pin_force`]) so that such effects are
//! included.

use serde::Serialize;

use super::crank_slider::{CrankSlider, MechanismParams, RodInertia};
use super::error::{Result, positive};
use super::peak::{PeakRefinement, refine_peak};

/// F_TDC = r ω² [m₄ (1 + r/l) + m₃ (1 + (r/l)(l₁/l))] (no gravity, no offset).
pub fn tdc_peak_formula(params: &MechanismParams, rod: &RodInertia, omega_rad_s: f64) -> f64 {
    let (r, l) = (params.crank_radius_m, params.centre_distance_m);
    let lam = r / l;
    r * omega_rad_s
        * omega_rad_s
        * (params.piston_mass_kg * (1.0 + lam) + rod.mass_kg * (1.0 + lam * rod.l1_m / l))
}

/// True maximum of |F_A| at constant speed ω over one revolution (closed
/// form, refined; gravity as in `params`).
pub fn peak_pin_force(
    params: &MechanismParams,
    rod: &RodInertia,
    omega_rad_s: f64,
) -> Result<PeakRefinement> {
    let model = CrankSlider::new(params, rod)?;
    positive("omega_rad_s", omega_rad_s)?;
    refine_peak(
        &model,
        0.0,
        omega_rad_s,
        std::f64::consts::TAU / omega_rad_s,
    )
}

/// Outcome of [`l1_for_peak_force`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum L1Fit {
    /// The l₁ ∈ [0, l] whose peak equals the target.
    Reachable {
        /// l₁ (m).
        l1_m: f64,
        /// The peak at that l₁ (N).
        peak_n: f64,
    },
    /// Below the peak at l₁ = 0: no rod of this mass reaches it.
    BelowMinimum {
        /// Target (N).
        target_n: f64,
        /// Lower bound: the peak at l₁ = 0 (N).
        min_peak_n: f64,
    },
    /// Above the peak at l₁ = l (centroid on the piston pin).
    AboveMaximum {
        /// Target (N).
        target_n: f64,
        /// Upper bound: the peak at l₁ = l (N).
        max_peak_n: f64,
    },
}

impl L1Fit {
    /// l₁ if reachable.
    pub fn l1_m(&self) -> Option<f64> {
        match *self {
            L1Fit::Reachable { l1_m, .. } => Some(l1_m),
            _ => None,
        }
    }

    /// A sentence for reports.
    pub fn explanation(&self) -> String {
        match *self {
            L1Fit::Reachable { l1_m, peak_n } => {
                format!(
                    "l1 = {:.2} mm reproduces the peak ({peak_n:.1} N)",
                    l1_m * 1e3
                )
            }
            L1Fit::BelowMinimum {
                target_n,
                min_peak_n,
            } => format!(
                "physically unreachable: {target_n:.0} N is below {min_peak_n:.0} N, the peak for \
                 any l1 >= 0 with this rod mass"
            ),
            L1Fit::AboveMaximum {
                target_n,
                max_peak_n,
            } => format!(
                "unreachable: {target_n:.0} N is above {max_peak_n:.0} N, the peak with the \
                 centroid at the piston pin (l1 = l)"
            ),
        }
    }
}

/// The l₁ ∈ [0, l] at which the refined constant-speed peak equals
/// `target_peak_n` for a rod with the mass, offset and I_zz of `rod` (its
/// `l1_m` is ignored). The peak grows strictly with l₁ (slope
/// r ω² m₃ (r/l)/l), so the root is unique; it is found by Newton steps with
/// that slope, safeguarded by bisection, to 1e-11 relative.
pub fn l1_for_peak_force(
    params: &MechanismParams,
    rod: &RodInertia,
    target_peak_n: f64,
    omega_rad_s: f64,
) -> Result<L1Fit> {
    positive("target_peak_n", target_peak_n)?;
    let l = params.centre_distance_m;
    let peak = |l1: f64| -> Result<f64> {
        let r = RodInertia { l1_m: l1, ..*rod };
        Ok(peak_pin_force(params, &r, omega_rad_s)?.force_n)
    };
    let (f_lo, f_hi) = (peak(0.0)?, peak(l)?);
    if target_peak_n < f_lo {
        return Ok(L1Fit::BelowMinimum {
            target_n: target_peak_n,
            min_peak_n: f_lo,
        });
    }
    if target_peak_n > f_hi {
        return Ok(L1Fit::AboveMaximum {
            target_n: target_peak_n,
            max_peak_n: f_hi,
        });
    }
    let lam = params.crank_radius_m / l;
    let slope = params.crank_radius_m * omega_rad_s * omega_rad_s * rod.mass_kg * lam / l;
    let (mut a, mut b) = (0.0, l);
    // start from the gravity-free formula
    let base = tdc_peak_formula(params, &RodInertia { l1_m: 0.0, ..*rod }, omega_rad_s);
    let mut x = ((target_peak_n - base) / slope).clamp(0.0, l);
    for _ in 0..100 {
        let fx = peak(x)? - target_peak_n;
        if fx.abs() <= 1e-11 * target_peak_n {
            return Ok(L1Fit::Reachable {
                l1_m: x,
                peak_n: fx + target_peak_n,
            });
        }
        if fx < 0.0 {
            a = x;
        } else {
            b = x;
        }
        let newton = x - fx / slope;
        x = if newton > a && newton < b {
            newton
        } else {
            0.5 * (a + b)
        };
        if b - a < 1e-15 {
            break;
        }
    }
    Ok(L1Fit::Reachable {
        l1_m: x,
        peak_n: peak(x)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn explanations_read_well() {
        let e = L1Fit::BelowMinimum {
            target_n: 5244.0,
            min_peak_n: 7481.3,
        }
        .explanation();
        assert!(e.contains("unreachable") && e.contains("7481"), "{e}");
    }
}
