//! Design-study helpers: the peak pin force at constant speed, the thesis'
//! Table 5.1, the l₁ that reproduces a given peak, and the sensitivity of the
//! peak to the rod's mass properties.
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
//! a few thousandths of a degree off TDC; the studies below use the refined
//! true maximum ([`refine_peak`]) so that such effects are included.

use serde::Serialize;

use super::crank_slider::{CrankSlider, MechanismParams, RodInertia};
use super::error::{DynamicsError, Result, positive};
use super::peak::{PeakRefinement, refine_peak};

/// One row of the thesis' Table 5.1 (MSC.ADAMS, GSTIFF, ω = 40π rad/s).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Table51Row {
    /// Design number.
    pub design: u8,
    /// Rod mass (kg).
    pub mass_kg: f64,
    /// The thesis' "moment of inertia about the centroid" (kg·m²; per the
    /// spec consistent with the long axis, not with the pin axis).
    pub thesis_inertia_kgm2: f64,
    /// Thesis peak pin force (N).
    pub peak_force_n: f64,
    /// The l₁ that reproduces the peak (spec), `None` when unreachable.
    pub l1_m: Option<f64>,
}

/// Table 5.1 with the spec's l₁ column.
pub const TABLE_5_1: [Table51Row; 5] = [
    Table51Row {
        design: 1,
        mass_kg: 3.0420019180,
        thesis_inertia_kgm2: 0.0021344700938,
        peak_force_n: 7202.0,
        l1_m: Some(0.07176),
    },
    Table51Row {
        design: 2,
        mass_kg: 3.7363893102,
        thesis_inertia_kgm2: 0.0022836258632,
        peak_force_n: 5244.0,
        l1_m: None,
    },
    Table51Row {
        design: 3,
        mass_kg: 3.4571018109,
        thesis_inertia_kgm2: 0.0021168783226,
        peak_force_n: 7546.0,
        l1_m: Some(0.07505),
    },
    Table51Row {
        design: 4,
        mass_kg: 2.8775347239,
        thesis_inertia_kgm2: 0.0020569589380,
        peak_force_n: 7072.0,
        l1_m: Some(0.07231),
    },
    Table51Row {
        design: 5,
        mass_kg: 2.4794531840,
        thesis_inertia_kgm2: 0.0019245222142,
        peak_force_n: 6736.0,
        l1_m: Some(0.06561),
    },
];

/// l₁ of our design 2 (the spec's choice, the thesis' value is unreachable).
pub const DESIGN_2_L1_M: f64 = 0.072;

/// The thesis' crank speed in the driven scene, 40π rad/s.
pub const THESIS_OMEGA_RAD_S: f64 = 40.0 * std::f64::consts::PI;

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

/// Table 5.1 reproduced: one row per design.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Table51Check {
    /// Design number.
    pub design: u8,
    /// Rod mass (kg).
    pub mass_kg: f64,
    /// l₁ used (m): the spec's, or [`DESIGN_2_L1_M`] for design 2.
    pub l1_m: f64,
    /// Thesis peak (N).
    pub thesis_peak_n: f64,
    /// Our refined peak with that l₁ (N).
    pub computed_peak_n: f64,
    /// (computed − thesis) / thesis, `None` where the thesis value is unreachable.
    pub rel_error: Option<f64>,
    /// The l₁ that reproduces the thesis value, or why none does.
    pub l1_fit: L1Fit,
}

/// Reproduce Table 5.1 at 40π rad/s with rods of the table's mass, the
/// spec's l₁, no offset and the given I_zz (it does not affect the TDC peak).
pub fn table_5_1_check(params: &MechanismParams, i_zz_kgm2: f64) -> Result<Vec<Table51Check>> {
    TABLE_5_1
        .iter()
        .map(|row| {
            let l1 = row.l1_m.unwrap_or(DESIGN_2_L1_M);
            let rod = RodInertia::new(row.mass_kg, l1, i_zz_kgm2);
            let computed = peak_pin_force(params, &rod, THESIS_OMEGA_RAD_S)?.force_n;
            let fit = l1_for_peak_force(params, &rod, row.peak_force_n, THESIS_OMEGA_RAD_S)?;
            Ok(Table51Check {
                design: row.design,
                mass_kg: row.mass_kg,
                l1_m: l1,
                thesis_peak_n: row.peak_force_n,
                computed_peak_n: computed,
                rel_error: row
                    .l1_m
                    .map(|_| (computed - row.peak_force_n) / row.peak_force_n),
                l1_fit: fit,
            })
        })
        .collect()
}

/// Sensitivity of the refined constant-speed peak to the rod's mass
/// properties, by central finite differences, next to the derivatives of
/// [`tdc_peak_formula`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct PeakSensitivity {
    /// The peak (N).
    pub peak_n: f64,
    /// Crank angle of the peak (deg).
    pub peak_crank_angle_deg: f64,
    /// ∂F/∂m₃ (N/kg), central difference.
    pub d_mass_n_per_kg: f64,
    /// ∂F/∂l₁ (N/m), central difference.
    pub d_l1_n_per_m: f64,
    /// ∂F/∂I_zz (N/(kg·m²)), central difference; ≈ 0 (TDC peak).
    pub d_izz_n_per_kgm2: f64,
    /// Formula: r ω² (1 + (r/l)(l₁/l)).
    pub formula_d_mass_n_per_kg: f64,
    /// Formula: r ω² m₃ (r/l)/l.
    pub formula_d_l1_n_per_m: f64,
    /// Relative steps used: m₃ and I_zz by this fraction, l₁ by this fraction of l.
    pub relative_step: f64,
}

/// ∂F/∂m₃, ∂F/∂l₁, ∂F/∂I_zz of the refined peak at constant speed ω.
pub fn peak_sensitivity(
    params: &MechanismParams,
    rod: &RodInertia,
    omega_rad_s: f64,
) -> Result<PeakSensitivity> {
    let base = peak_pin_force(params, rod, omega_rad_s)?;
    let f = |r: RodInertia| -> Result<f64> { Ok(peak_pin_force(params, &r, omega_rad_s)?.force_n) };
    let rel = 1e-4;
    let hm = rel * rod.mass_kg;
    let hl = rel * params.centre_distance_m;
    let hi = rel * rod.i_zz_kgm2;
    let d_mass = (f(RodInertia {
        mass_kg: rod.mass_kg + hm,
        ..*rod
    })? - f(RodInertia {
        mass_kg: rod.mass_kg - hm,
        ..*rod
    })?) / (2.0 * hm);
    let d_l1 = (f(RodInertia {
        l1_m: rod.l1_m + hl,
        ..*rod
    })? - f(RodInertia {
        l1_m: rod.l1_m - hl,
        ..*rod
    })?) / (2.0 * hl);
    let d_izz = (f(RodInertia {
        i_zz_kgm2: rod.i_zz_kgm2 + hi,
        ..*rod
    })? - f(RodInertia {
        i_zz_kgm2: rod.i_zz_kgm2 - hi,
        ..*rod
    })?) / (2.0 * hi);
    let (r, l) = (params.crank_radius_m, params.centre_distance_m);
    let rw2 = r * omega_rad_s * omega_rad_s;
    let out = PeakSensitivity {
        peak_n: base.force_n,
        peak_crank_angle_deg: base.crank_angle_deg,
        d_mass_n_per_kg: d_mass,
        d_l1_n_per_m: d_l1,
        d_izz_n_per_kgm2: d_izz,
        formula_d_mass_n_per_kg: rw2 * (1.0 + r / l * rod.l1_m / l),
        formula_d_l1_n_per_m: rw2 * rod.mass_kg * (r / l) / l,
        relative_step: rel,
    };
    if [out.d_mass_n_per_kg, out.d_l1_n_per_m, out.d_izz_n_per_kgm2]
        .iter()
        .all(|v| v.is_finite())
    {
        Ok(out)
    } else {
        Err(DynamicsError::NonFinite {
            t_s: base.time_s,
            what: "peak sensitivity",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formula_matches_thesis_row_1() {
        let rod = RodInertia::new(3.0420019180, 0.07176, 0.02);
        let f = tdc_peak_formula(&MechanismParams::default(), &rod, THESIS_OMEGA_RAD_S);
        assert!((f - 7202.0).abs() < 0.5, "{f}");
    }

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
