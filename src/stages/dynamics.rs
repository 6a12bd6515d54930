//! Stage 2 for one design: its mass properties mapped onto the crank–slider, the `driven` scene,
//! the peak pin force and its sensitivities (SPEC "Stage 2").
//!
//! The planar dynamics needs only the rod's mass, l1, transverse offset and I_zz about the pin
//! axis through the centroid, plus the design's own centre distance A→B; the mesh plays no part
//! (model only what the scene needs).

use super::records::{DesignDynamics, DesignMass};
use crate::config::EngineConfig;
use crate::mechanism::{
    DrivenResult, DrivenScene, GasForce, MechanismParams, Method, RodInertia,
    driven_scene_with_gas, peak_sensitivity, tdc_peak_formula,
};
use anyhow::{Context, Result};

/// The rod as the planar mechanism sees it.
pub fn rod_inertia(mass: &DesignMass) -> RodInertia {
    RodInertia::new(mass.mass_kg, mass.l1_m, mass.i_zz_kgm2).with_offset(mass.offset_m)
}

/// The spec's mechanism (the thesis' rig, the default engine) with this design's centre
/// distance.
pub fn mechanism_for(mass: &DesignMass, gravity: bool) -> MechanismParams {
    MechanismParams {
        centre_distance_m: mass.centre_distance_m,
        ..MechanismParams::default()
    }
    .with_gravity(gravity)
}

/// The configured engine's mechanism with this design's centre distance (equal to
/// [`mechanism_for`] for the default engine).
pub fn engine_mechanism_for(
    mass: &DesignMass,
    engine: &EngineConfig,
    gravity: bool,
) -> MechanismParams {
    engine.mechanism(mass.centre_distance_m, gravity)
}

/// The scene stage 2 runs: `scene` as configured, or with a gas force its four-stroke cycle
/// ([`DrivenScene::four_stroke`]: 720° at the same speed and output steps per revolution).
pub fn scene_for(scene: &DrivenScene, gas: Option<&GasForce>) -> DrivenScene {
    match gas {
        Some(_) => scene.four_stroke(),
        None => *scene,
    }
}

/// The pin-force history alone (e.g. for a design whose figures come from the cache).
pub fn history(
    mass: &DesignMass,
    scene: &DrivenScene,
    gravity: bool,
    engine: &EngineConfig,
    method: Method,
) -> Result<DrivenResult> {
    let gas = engine.gas_force()?;
    let params = engine_mechanism_for(mass, engine, gravity);
    let scene = scene_for(scene, gas.as_deref());
    Ok(driven_scene_with_gas(
        &params,
        &rod_inertia(mass),
        gas,
        &scene,
        method,
    )?)
}

/// Runs the `driven` scene for a design on the thesis' rig (the default engine, no gas force)
/// and summarises it; returns the full history too.
pub fn dynamics(
    mass: &DesignMass,
    scene: &DrivenScene,
    gravity: bool,
    method: Method,
) -> Result<(DesignDynamics, DrivenResult)> {
    dynamics_with(mass, scene, gravity, &EngineConfig::default(), method)
}

/// [`dynamics`] on the configured engine.
///
/// With a pressure trace in `engine`, the scene covers the four-stroke cycle with the gas force
/// and the summary gains the rod's peak compression and tension (`peak_compression_n`, …);
/// `tdc_formula_n` and `sensitivity` stay those of the inertia loads alone (constant speed, no
/// gas force), as without a trace.
pub fn dynamics_with(
    mass: &DesignMass,
    scene: &DrivenScene,
    gravity: bool,
    engine: &EngineConfig,
    method: Method,
) -> Result<(DesignDynamics, DrivenResult)> {
    let context = || format!("{}: dynamics", mass.file);
    let gas = engine.gas_force().with_context(context)?;
    let with_gas = gas.is_some();
    let params = engine_mechanism_for(mass, engine, gravity);
    let rod = rod_inertia(mass);
    let scene = scene_for(scene, gas.as_deref());
    let run = driven_scene_with_gas(&params, &rod, gas, &scene, method).with_context(context)?;
    let sensitivity = peak_sensitivity(&params, &rod, scene.omega_rad_s).with_context(context)?;
    let axial = run.axial;
    let engine_field = |v: f64| with_gas.then_some(v);
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
        peak_compression_n: engine_field(axial.compression.force_n),
        peak_compression_crank_angle_deg: engine_field(axial.compression.crank_angle_deg),
        peak_compression_gas_force_n: engine_field(axial.compression_gas_force_n),
        peak_tension_n: engine_field(axial.tension.force_n),
        peak_tension_crank_angle_deg: engine_field(axial.tension.crank_angle_deg),
        peak_tension_gas_force_n: engine_field(axial.tension_gas_force_n),
        peak_transverse_n: None,
        peak_transverse_crank_angle_deg: None,
    };
    let mut summary = summary;
    if let Some(gas) = engine.gas_force().with_context(context)? {
        let (force, angle) =
            peak_transverse(&params, &rod, scene.omega_rad_s, &gas).with_context(context)?;
        summary.peak_transverse_n = Some(force);
        summary.peak_transverse_crank_angle_deg = Some(angle);
    }
    Ok((summary, run))
}

/// Samples per revolution of [`peak_transverse`]'s grid (0.1°).
pub const TRANSVERSE_SAMPLES_PER_REVOLUTION: usize = 3600;

/// The largest pin force across the rod over the four-stroke cycle with the gas force: max over
/// φ of |F_A · ŷ| (ŷ ⊥ A→B in the plane of motion; the rod-frame y component of the crank's force
/// on the rod, [`rod_frame_engine_cycle`]) and its crank angle in [0, 720). The closed form on a
/// 0.1° grid: near a smooth maximum the grid's value is within ½ (0.05°)² |f''/f| ≈ 4e-7 of the
/// true one, relative. The gas force acts along the cylinder and reaches the rod through the
/// piston pin, so this is the part of F_A that bends the rod: inertia and the slider's normal
/// force, far below the peak compression.
pub fn peak_transverse(
    params: &MechanismParams,
    rod: &RodInertia,
    omega_rad_s: f64,
    gas: &GasForce,
) -> Result<(f64, f64)> {
    let cycle = crate::mechanism::rod_frame_engine_cycle(
        params,
        rod,
        omega_rad_s,
        TRANSVERSE_SAMPLES_PER_REVOLUTION,
        Some(gas),
    )?;
    Ok(cycle.iter().fold((0.0, 0.0), |best, i| {
        let v = i.f_a_on_rod_n[1].abs();
        if v > best.0 {
            (v, i.crank_angle_deg)
        } else {
            best
        }
    }))
}
