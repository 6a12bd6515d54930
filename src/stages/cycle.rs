//! The cycle stage for one design: stress over one crank revolution on stage 3's mesh, with
//! inertia relief, and the fatigue safety factor (see [`crate::rod::cycle`]). With a cylinder
//! pressure trace (`[engine] pressure_trace`) the cycle is the engine's
//! four-stroke cycle: 720°, the gas force on the piston at each instant
//! ([`rod_frame_engine_cycle`]), so the worst instant and the fatigue factor come from the firing
//! loads and the inertia together.
//!
//! Loads and kinematics come from the configured engine's mechanism at the study's crank speed,
//! gravity on, evaluated with the **mesh's** mass properties (mass, centroid, I_zz from the tet10 mesh with
//! the design's density), so that the reaction at the fixed bore B equals the piston pin's force
//! F_B of the dynamics at every instant; the stage reports how far those properties are from the
//! STL's exact ones.

use super::records::{
    CosineBoreLoadCases, DesignCycle, DesignMass, FindleyCheck, LocalComponent, LocalFatigue,
    StageMesh,
};
use crate::config::StudyConfig;
use crate::fatigue::{ComponentAssessment, LocalSettings};
use crate::fem::QuadratureChoice;
use crate::fem::body_force::mesh_mass_properties;
use crate::fem::material::Material;
use crate::mechanism::{RodFrameInstant, rod_frame_engine_cycle};
use crate::rod::cycle::contact_fatigue::{ContactFatigue, contact_fatigue};
use crate::rod::cycle::contact_instants::{ContactInstant, contact_instants, instants_that_matter};
use crate::rod::cycle::{
    CycleOptions, CycleSolution, DEFAULT_DIRECTION_STEP_DEG, LocalFatigueSolution, PinBasis,
    UnitSolutions, combine, local_fatigue, rod_inertia_of, unit_solutions_for,
};
use crate::rod::fatigue::MeanStress;
use crate::rod::fatigue::signed_von_mises;
use anyhow::{Context, Result};
use std::time::Instant;

/// How the mean and alternating stresses are formed (reported as `method`), for the default
/// setting: one revolution, Goodman.
pub const FATIGUE_METHOD: &str = "signed von Mises (sign of the hydrostatic stress; Bishop & Sherratt, NAFEMS 2000) per node over one revolution: σa = (max − min)/2, σm = (max + min)/2; Goodman n = 1/(σa/Se + σm/Sut), compressive mean not credited (Shigley §6-12)";

/// The `method` text for a cycle over `span_deg` (360 or 720) with the `mean_stress` correction
/// ([`FATIGUE_METHOD`] for the default).
pub fn fatigue_method(span_deg: f64, mean_stress: MeanStress) -> String {
    if span_deg == 360.0 && mean_stress.is_goodman() {
        return FATIGUE_METHOD.into();
    }
    let cycle = if span_deg == 360.0 {
        "one revolution".to_string()
    } else {
        format!("the four-stroke cycle ({span_deg:.0}°, with the gas force)")
    };
    format!(
        "signed von Mises (sign of the hydrostatic stress; Bishop & Sherratt, NAFEMS 2000) per node over {cycle}: σa = (max − min)/2, σm = (max + min)/2; {}, compressive mean not credited (Shigley §6-12, Table 6-7)",
        mean_stress.formula()
    )
}

/// The cycle stage's record and the fields it was formed from (for the report's `cycle.vtu` and
/// picture).
pub struct CycleOutcome {
    pub record: DesignCycle,
    pub units: UnitSolutions,
    pub cycle: CycleSolution,
    /// The local (FKM) fatigue per surface node.
    pub local: LocalFatigueSolution,
}

/// The cycle's settings for `mass` on stage 3's `mesh`.
pub fn cycle_options(mass: &DesignMass, mesh: &StageMesh, config: &StudyConfig) -> CycleOptions {
    CycleOptions {
        density_kg_m3: mass.density_kg_m3,
        fixed_band_m: mesh.fixed_band_m,
        singular_edges_m: mesh.singular_edges_m.clone(),
        singular_band_m: mesh.singular_band_m,
        endurance_pa: config.material.endurance_mpa * 1e6,
        ultimate_pa: config.material.ultimate_mpa * 1e6,
        mean_stress: config.material.mean_stress,
        quadrature: QuadratureChoice::Auto,
        direction_step_deg: DEFAULT_DIRECTION_STEP_DEG,
        half_model: mesh.half_model.clone(),
    }
}

/// The instants of the cycle in the rod frame, from the mesh's own mass properties (those the
/// body forces integrate to), over one revolution or, with a pressure trace, 720°.
pub fn cycle_instants(
    mass: &DesignMass,
    mesh: &StageMesh,
    config: &StudyConfig,
) -> Result<Vec<RodFrameInstant>> {
    let context = || format!("{}: cycle", mass.file);
    let mesh_mass = mesh_mass_properties(&mesh.mesh, mass.density_kg_m3);
    let params = super::dynamics::engine_mechanism_for(mass, &config.engine, true);
    let gas = config.engine.gas_force().with_context(context)?;
    rod_frame_engine_cycle(
        &params,
        &rod_inertia_of(&mesh_mass),
        config.driven.omega_rad_s,
        config.cycle.instants,
        gas.as_deref(),
    )
    .with_context(context)
}

/// The cycle with contact at the instants that matter ([`instants_that_matter`]) and the fatigue
/// factor from them beside the linear cycle's at the same instants ([`contact_fatigue`]); the
/// instants that could not be solved are said (the third part), and the fatigue factor, which
/// needs the extremes of the cycle, is then left out.
fn contact_figures(
    mesh: &StageMesh,
    material: &Material,
    options: &CycleOptions,
    instants: &[RodFrameInstant],
    units: &UnitSolutions,
    cycle: &CycleSolution,
) -> crate::fem::error::Result<(Vec<ContactInstant>, Option<ContactFatigue>, Option<String>)> {
    let which = instants_that_matter(instants, cycle.max_instant);
    let solved = contact_instants(
        &mesh.mesh,
        material,
        &mesh.bores,
        options,
        instants,
        &cycle.history,
        &which,
    )?;
    if !solved.failed.is_empty() {
        let why = format!(
            "the cycle with contact: {} of {} instants not solved ({}); the fatigue factor with \
             contact needs them all",
            solved.failed.len(),
            which.len(),
            solved.failed.join("; ")
        );
        return Ok((solved.instants, None, Some(why)));
    }
    let linear = which
        .iter()
        .map(|(k, _)| {
            let t = units.terms(&instants[*k])?;
            Ok((0..mesh.mesh.n_nodes())
                .map(|n| signed_von_mises(&units.stress_at(n, &t)))
                .collect())
        })
        .collect::<crate::fem::error::Result<Vec<Vec<f64>>>>()?;
    let fatigue = contact_fatigue(
        &solved.signed_von_mises_pa,
        &linear,
        &units.judged,
        options,
        cycle.fatigue_safety_factor[cycle.fatigue_node],
        mesh.mesh.nodes(),
        which
            .iter()
            .map(|(k, _)| instants[*k].crank_angle_deg)
            .collect(),
    )?;
    Ok((solved.instants, Some(fatigue), None))
}

/// Runs the cycle stage on stage 3's mesh (writes nothing).
pub fn cycle(mass: &DesignMass, mesh: &StageMesh, config: &StudyConfig) -> Result<CycleOutcome> {
    let start = Instant::now();
    let context = || format!("{}: cycle", mass.file);
    let material = Material::from(&config.fem);
    let options = cycle_options(mass, mesh, config);
    let gas = config.engine.gas_force().with_context(context)?;
    let instants = cycle_instants(mass, mesh, config)?;
    let units = unit_solutions_for(&mesh.mesh, &material, &mesh.bores, &options, &instants)
        .with_context(context)?;
    let span_deg = if gas.is_some() { 720.0 } else { 360.0 };
    let cycle = combine(&units, &instants, &options).with_context(context)?;
    // the contact instants are figures beside the linear cycle: their failure is said, not fatal
    let (contact_instants, contact_fatigue, contact_instants_error) = if config.fem.load_model_error
    {
        match contact_figures(mesh, &material, &options, &instants, &units, &cycle) {
            Ok((v, f, failed)) => (v, f, failed),
            Err(e) => (Vec::new(), None, Some(format!("{e}"))),
        }
    } else {
        (Vec::new(), None, None)
    };
    let local_start = Instant::now();
    let terms = instants
        .iter()
        .map(|i| units.terms(i))
        .collect::<crate::fem::error::Result<Vec<_>>>()
        .with_context(context)?;
    let local_settings = config.material.local_settings();
    let local = local_fatigue(
        &mesh.mesh,
        &units,
        &terms,
        cycle.fatigue_node,
        &local_settings,
    )
    .with_context(context)?;
    let local_seconds = local_start.elapsed().as_secs_f64();
    let analysis_seconds = start.elapsed().as_secs_f64();
    let nodes = mesh.mesh.nodes();
    let mm = |n: usize| nodes[n].map(|v| v * 1e3);
    let k = cycle.max_instant;
    let f = cycle.fatigue_node;
    let mut record = DesignCycle {
        max_von_mises_over_cycle_mpa: cycle.history[k].max_von_mises_away_from_fixed_mpa,
        crank_angle_of_max_deg: cycle.history[k].crank_angle_deg,
        location_of_max_mm: mm(cycle.max_node),
        fatigue_safety_factor: cycle.fatigue_safety_factor[f],
        fatigue_location_mm: mm(f),
        fatigue_alternating_mpa: cycle.alternating_pa[f] * 1e-6,
        fatigue_mean_mpa: cycle.mean_pa[f] * 1e-6,
        method: fatigue_method(span_deg, config.material.mean_stress),
        endurance_mpa: config.material.endurance_mpa,
        ultimate_mpa: config.material.ultimate_mpa,
        instants: instants.len(),
        omega_rad_s: config.driven.omega_rad_s,
        mass_properties: "the mesh's (mass, centroid, I_zz of the tet10 mesh at the design's density), for the pin forces and the body forces alike, so that the reaction at B equals the dynamics' F_B".into(),
        mesh_mass_kg: units.mass.mass_kg,
        stl_mass_kg: mass.mass_kg,
        reaction_mismatch_rel: cycle.reaction_mismatch_rel,
        peak_pin_force_n: instants
            .iter()
            .map(|i| i.f_a_on_rod_n[0].hypot(i.f_a_on_rod_n[1]))
            .fold(0.0, f64::max),
        history: cycle.history.clone(),
        cycle_span_deg: gas.is_some().then_some(span_deg),
        peak_gas_force_n: gas
            .is_some()
            .then(|| instants.iter().map(|i| i.gas_force_n).fold(0.0, f64::max)),
        cosine_bore_load: match &units.pin {
            PinBasis::Linear => None,
            PinBasis::Directions { step_deg, case_of } => Some(CosineBoreLoadCases {
                direction_step_deg: *step_deg,
                directions: case_of.len(),
                directions_solved: case_of.iter().flatten().count(),
                unit_solves: units.stresses.len(),
            }),
        },
        mean_stress: config.material.mean_stress,
        contact_instants,
        contact_fatigue,
        contact_instants_error,
        local_fatigue_safety_factor: Some(local.critical().assessment.safety_factor),
        local_fatigue: Some(local_record(
            &local,
            &mesh.mesh,
            &instants,
            f,
            &local_settings,
            local_seconds,
        )),
        vtu: None,
        picture: None,
        analysis_seconds,
        seconds: 0.0,
    };
    record.seconds = start.elapsed().as_secs_f64();
    Ok(CycleOutcome {
        record,
        units,
        cycle,
        local,
    })
}

/// How the local factor is formed (the record's `method`).
pub const LOCAL_FATIGUE_METHOD: &str = "FKM guideline (6th ed. 2012), local stresses, at every surface node over the cycle: surface stress components σ1, σ2 (amplitude axes of the longest chord of the in-plane path); σW,zd = fW,σ Rm; χ* from the normal derivative of the recovered stress under the surface (cubic fit over two element lengths), support factor n(χ*), roughness KR (Rz), treatment KV, design factor KWK with K̃f = 2; mean-stress sensitivity Mσ on the Haigh diagram, overload case as configured; aBK = |σa| jD / σAK, von Mises combination; S = jD / aBK, the smallest over the judged surface nodes";

fn component(c: &ComponentAssessment, treatment_factor: f64) -> LocalComponent {
    let s = &c.strength;
    LocalComponent {
        direction: c.direction,
        amplitude_mpa: c.amplitude_pa * 1e-6,
        mean_mpa: c.mean_pa * 1e-6,
        chi_star_per_mm: s.chi_star_sigma_per_m * 1e-3,
        support_factor: s.n_sigma,
        roughness_factor: s.k_r_sigma,
        treatment_factor,
        design_factor: s.k_wk_sigma,
        sigma_w_zd_mpa: s.sigma_w_zd_pa * 1e-6,
        sigma_wk_mpa: s.sigma_wk_pa * 1e-6,
        mean_stress_sensitivity: c.mean_stress_sensitivity,
        mean_stress_factor: c.k_ak,
        sigma_ak_mpa: c.sigma_ak_pa * 1e-6,
        utilisation: c.utilisation,
    }
}

/// The record of the local assessment `local` on `mesh` over `instants`; `goodman_node` is the
/// node of the smallest Goodman factor.
fn local_record(
    local: &LocalFatigueSolution,
    mesh: &crate::fem::TetMesh,
    instants: &[RodFrameInstant],
    goodman_node: usize,
    settings: &LocalSettings,
    seconds: f64,
) -> LocalFatigue {
    let mm = |n: usize| mesh.nodes()[n].map(|v| v * 1e3);
    let c = local.critical();
    let a = &c.assessment;
    let worst = local.findley_worst().expect("at least the critical node");
    let at = |node: usize| {
        local
            .findley
            .iter()
            .find(|f| f.node == node)
            .map_or(f64::NAN, |f| f.result.factor)
    };
    let (p, q) = (mm(worst.node), mm(c.node));
    LocalFatigue {
        method: LOCAL_FATIGUE_METHOD.into(),
        node: c.node,
        at_mm: q,
        outward_normal: c.outward_normal,
        safety_factor: a.safety_factor,
        utilisation: a.utilisation,
        j_d: a.j_d,
        overload: settings.overload,
        turning_points_deg: a.turning_points.map(|i| instants[i].crank_angle_deg),
        chi_star_per_mm: a.sigma1.strength.chi_star_sigma_per_m * 1e-3,
        support_factor: a.sigma1.strength.n_sigma,
        gradient_found: c.has_gradient,
        sigma1: component(&a.sigma1, settings.surface.treatment_factor),
        sigma2: component(&a.sigma2, settings.surface.treatment_factor),
        surface_nodes: local.surface.len(),
        surface_nodes_without_gradient: local.surface.iter().filter(|s| !s.has_gradient).count(),
        at_goodman_node: local.safety_factor[goodman_node]
            .is_finite()
            .then_some(local.safety_factor[goodman_node]),
        findley: FindleyCheck {
            nodes_checked: local.findley.len(),
            k: worst.settings.k,
            node: worst.node,
            at_mm: p,
            factor: worst.result.factor,
            plane_normal: worst.result.normal,
            shear_amplitude_mpa: worst.result.shear_amplitude_pa * 1e-6,
            max_normal_stress_mpa: worst.result.max_normal_stress_pa * 1e-6,
            local_factor_there: worst.local_factor,
            factor_at_local_node: at(c.node),
            factor_at_goodman_node: at(goodman_node),
            same_node: worst.node == c.node,
            distance_from_local_mm: ((p[0] - q[0]).powi(2)
                + (p[1] - q[1]).powi(2)
                + (p[2] - q[2]).powi(2))
            .sqrt(),
        },
        map_picture: None,
        haigh_picture: None,
        seconds,
    }
}
