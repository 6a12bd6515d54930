//! Stage 2 for one design: its mass properties mapped onto the crank–slider, the `driven` scene,
//! the peak pin force and its sensitivities (SPEC "Stage 2").
//!
//! The planar dynamics needs only the rod's mass, l1, transverse offset and I_zz about the pin
//! axis through the centroid, plus the design's own centre distance A→B; the mesh plays no part
//! (model only what the scene needs).

use super::records::{DesignDynamics, DesignMass};
use crate::mechanism::{
    DrivenResult, DrivenScene, MechanismParams, Method, RodInertia, driven_scene, peak_sensitivity,
    tdc_peak_formula,
};
use anyhow::{Context, Result};

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

/// Runs the `driven` scene for a design and summarises it; returns the full history too.
pub fn dynamics(
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
