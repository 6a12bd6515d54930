//! Stage 2 for one design: its mass properties mapped onto the crank–slider, the `driven` scene,
//! the peak pin force and its sensitivities (SPEC "Stage 2").
//!
//! The planar dynamics needs only the rod's mass, l1, transverse offset and I_zz about the pin
//! axis through the centroid, plus the design's own centre distance A→B; the mesh plays no part
//! (model only what the scene needs).

use crate::geometry::design::DesignMass;
use crate::mechanism::{
    DrivenResult, DrivenScene, MechanismParams, Method, PeakSensitivity, RodInertia, driven_scene,
    peak_sensitivity, tdc_peak_formula,
};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

/// The rod as the planar mechanism sees it.
pub fn rod_inertia(mass: &DesignMass) -> RodInertia {
    RodInertia::new(mass.mass_kg, mass.l1_m, mass.i_zz_kgm2).with_offset(mass.offset_m)
}

/// The spec's mechanism with this design's centre distance.
pub fn mechanism_for(mass: &DesignMass, gravity: bool) -> MechanismParams {
    MechanismParams {
        centre_distance_m: mass.centre_distance_m,
        ..MechanismParams::default()
    }
    .with_gravity(gravity)
}

/// The stage-2 record of one design (SI units), as written to JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DesignDynamics {
    pub design: String,
    /// True maximum of |F_A| over the motion [N] (refined between samples).
    pub peak_pin_force_n: f64,
    /// Crank angle of the peak, in [0, 360) degrees (0 = top dead centre).
    pub peak_crank_angle_deg: f64,
    /// First time of the peak [s].
    pub peak_time_s: f64,
    /// Largest |F_A| on the output grid [N].
    pub grid_peak_pin_force_n: f64,
    pub gravity: bool,
    /// `closed_form` or `multibody`.
    pub method: Method,
    /// What the method computes (no time integration: the driven mechanism has zero DOF).
    pub model: String,
    pub omega_rad_s: f64,
    pub duration_s: f64,
    pub steps: usize,
    /// rω²[m4(1 + r/l) + m3(1 + (r/l)(l1/l))]: the top-dead-centre peak without gravity [N].
    pub tdc_formula_n: f64,
    /// ∂F/∂m3, ∂F/∂l1, ∂F/∂I_zz of the peak at constant speed.
    pub sensitivity: PeakSensitivity,
}

/// Runs the `driven` scene for a design and summarises it; returns the full history too.
pub fn dynamics_of_design(
    mass: &DesignMass,
    scene: &DrivenScene,
    gravity: bool,
    method: Method,
) -> Result<(DesignDynamics, DrivenResult)> {
    let context = || format!("{}: dynamics", mass.file);
    let params = mechanism_for(mass, gravity);
    let rod = rod_inertia(mass);
    let run = driven_scene(&params, &rod, scene, method).with_context(context)?;
    let sensitivity = peak_sensitivity(&params, &rod, scene.omega_rad_s).with_context(context)?;
    let summary = DesignDynamics {
        design: mass.design.clone(),
        peak_pin_force_n: run.peak_pin_force_n,
        peak_crank_angle_deg: run.peak_crank_angle_deg,
        peak_time_s: run.peak_time_s,
        grid_peak_pin_force_n: run.grid_peak_pin_force_n,
        gravity,
        method,
        model: method.description().to_string(),
        omega_rad_s: scene.omega_rad_s,
        duration_s: scene.duration_s,
        steps: scene.steps,
        tdc_formula_n: tdc_peak_formula(&params, &rod, scene.omega_rad_s),
        sensitivity,
    };
    Ok((summary, run))
}

/// The pin-force history as CSV rows (with a `design` column, so several designs share a file).
pub fn write_history_csv<W: std::io::Write>(
    w: &mut csv::Writer<W>,
    design: &str,
    run: &DrivenResult,
) -> Result<()> {
    for k in 0..run.t_s.len() {
        w.serialize(HistoryRow {
            design,
            t_s: run.t_s[k],
            phi_rad: run.phi_rad[k],
            fa_x_n: run.fa_x_n[k],
            fa_y_n: run.fa_y_n[k],
            fa_abs_n: run.fa_abs_n[k],
            fb_x_n: run.fb_x_n[k],
            fb_y_n: run.fb_y_n[k],
            fb_abs_n: run.fb_abs_n[k],
            crank_torque_nm: run.crank_torque_nm[k],
        })?;
    }
    Ok(())
}

#[derive(Serialize)]
struct HistoryRow<'a> {
    design: &'a str,
    t_s: f64,
    phi_rad: f64,
    fa_x_n: f64,
    fa_y_n: f64,
    fa_abs_n: f64,
    fb_x_n: f64,
    fb_y_n: f64,
    fb_abs_n: f64,
    crank_torque_nm: f64,
}
