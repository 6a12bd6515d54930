//! Sensitivity of the refined constant-speed peak pin force to the rod's mass
//! properties (m₃, l₁, I_zz), by central finite differences, next to the
//! derivatives of the TDC formula F_TDC = r ω² [m₄ (1 + r/l) + m₃ (1 + (r/l)(l₁/l))]
//! ([`tdc_peak_formula`](super::tdc_peak::tdc_peak_formula)).

use serde::Serialize;

use super::crank_slider::{MechanismParams, RodInertia};
use super::error::{DynamicsError, Result};
use super::tdc_peak::peak_pin_force;

/// Sensitivity of the refined constant-speed peak to the rod's mass
/// properties, by central finite differences, next to the derivatives of
/// [`tdc_peak_formula`](super::tdc_peak::tdc_peak_formula).
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
