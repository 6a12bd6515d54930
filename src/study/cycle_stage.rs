//! The cycle stage for one design: stress over one crank revolution on stage 3's mesh, with
//! inertia relief, and the Goodman fatigue safety factor (see [`crate::fem::cycle`]).
//!
//! Loads and kinematics come from the driven scene's mechanism at the study's crank speed, gravity
//! on, evaluated with the **mesh's** mass properties (mass, centroid, I_zz from the tet10 mesh with
//! the design's density), so that the reaction at the fixed bore B equals the piston pin's force
//! F_B of the dynamics at every instant; the stage reports how far those properties are from the
//! STL's exact ones.

use super::config::StudyConfig;
use super::fem_stage::StageMesh;
use crate::fem::QuadratureChoice;
use crate::fem::cycle::{
    CycleInstant, CycleOptions, CycleSolution, UnitSolutions, combine, rod_inertia_of,
    unit_solutions,
};
use crate::fem::material::Material;
use crate::fem::vtu::{VtuField, write_vtu};
use crate::geometry::design::DesignMass;
use crate::mechanism::rod_frame_cycle;
use crate::report::picture::{PictureOptions, render_tet10_field};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// How the mean and alternating stresses are formed (reported as `method`).
pub const FATIGUE_METHOD: &str = "signed von Mises (sign of the hydrostatic stress; Bishop & Sherratt, NAFEMS 2000) per node over one revolution: σa = (max − min)/2, σm = (max + min)/2; Goodman n = 1/(σa/Se + σm/Sut), compressive mean not credited (Shigley §6-12)";

/// The cycle record of one design (JSON fields named by the issue that asked for them).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DesignCycle {
    /// Per instant: crank angle, time, judged max von Mises, the fixed bore's reaction and the
    /// dynamics' F_B (both on the rod at B, rod frame, N).
    pub history: Vec<CycleInstant>,
    pub max_von_mises_over_cycle_mpa: f64,
    pub crank_angle_of_max_deg: f64,
    /// Rod frame, mm (A at the origin, x towards B, z the pin axis).
    pub location_of_max_mm: [f64; 3],
    /// Smallest Goodman safety factor over the judged nodes.
    pub fatigue_safety_factor: f64,
    pub fatigue_location_mm: [f64; 3],
    /// Alternating and mean signed von Mises at that node, MPa.
    pub fatigue_alternating_mpa: f64,
    pub fatigue_mean_mpa: f64,
    /// How mean and alternating stress were formed.
    pub method: String,
    pub endurance_mpa: f64,
    pub ultimate_mpa: f64,
    /// Instants over the revolution.
    pub instants: usize,
    /// Crank speed, rad/s.
    pub omega_rad_s: f64,
    /// Which mass properties the loads use, and the mesh's against the STL's.
    pub mass_properties: String,
    pub mesh_mass_kg: f64,
    pub stl_mass_kg: f64,
    /// Largest |reaction at B − F_B| over the instants, relative to the peak |F_A|.
    pub reaction_mismatch_rel: f64,
    /// Largest |F_A| over the cycle with the mesh's mass properties, N.
    pub peak_pin_force_n: f64,
    /// ParaView file (max-over-cycle von Mises, fatigue factor) and the picture.
    pub vtu: Option<PathBuf>,
    pub picture: Option<PathBuf>,
    /// Wall time of the analysis (six unit solves with one factorisation, the combination), s.
    pub analysis_seconds: f64,
    /// Wall time of the stage with its files, s.
    pub seconds: f64,
}

/// Runs the cycle stage on stage 3's mesh; writes `cycle.vtu` and `von_mises_cycle.svg` into
/// `out_dir` when given.
pub fn cycle_of_design(
    mass: &DesignMass,
    mesh: &StageMesh,
    config: &StudyConfig,
    out_dir: Option<&Path>,
) -> Result<(DesignCycle, UnitSolutions, CycleSolution)> {
    let start = Instant::now();
    let context = || format!("{}: cycle", mass.file);
    let material = Material {
        youngs_modulus_pa: config.fem.youngs_modulus_pa,
        poisson_ratio: config.fem.poisson_ratio,
    };
    let options = CycleOptions {
        density_kg_m3: mass.density_kg_m3,
        fixed_band_m: mesh.fixed_band_m,
        singular_edges_m: mesh.singular_edges_m.clone(),
        singular_band_m: mesh.singular_band_m,
        endurance_pa: config.material.endurance_mpa * 1e6,
        ultimate_pa: config.material.ultimate_mpa * 1e6,
        quadrature: QuadratureChoice::Auto,
    };
    let units =
        unit_solutions(&mesh.mesh, &material, &mesh.bores, &options).with_context(context)?;
    let params = super::dynamics_stage::mechanism_for(mass, true);
    let instants = rod_frame_cycle(
        &params,
        &rod_inertia_of(&units.mass),
        config.driven.omega_rad_s,
        config.cycle.instants,
    )
    .with_context(context)?;
    let cycle = combine(&units, &instants, &options).with_context(context)?;
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
        method: FATIGUE_METHOD.into(),
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
        vtu: None,
        picture: None,
        analysis_seconds,
        seconds: 0.0,
    };
    if let Some(dir) = out_dir {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let vtu = dir.join("cycle.vtu");
        write_cycle_vtu(&vtu, &mesh.mesh, &cycle, &units).with_context(context)?;
        let picture = dir.join("von_mises_cycle.svg");
        write_cycle_picture(&picture, &mesh.mesh, &cycle, &record).with_context(context)?;
        record.vtu = Some(vtu);
        record.picture = Some(picture);
    }
    record.seconds = start.elapsed().as_secs_f64();
    Ok((record, units, cycle))
}

fn write_cycle_vtu(
    path: &Path,
    mesh: &crate::fem::TetMesh,
    cycle: &CycleSolution,
    units: &UnitSolutions,
) -> Result<()> {
    let mpa = |v: &[f64]| v.iter().map(|x| x * 1e-6).collect::<Vec<_>>();
    // ∞ (an unloaded node) is written as a large finite number: ParaView reads no "inf"
    let factor: Vec<f64> = cycle
        .fatigue_safety_factor
        .iter()
        .map(|v| v.min(1e6))
        .collect();
    let judged: Vec<f64> = units
        .judged
        .iter()
        .map(|j| if *j { 1.0 } else { 0.0 })
        .collect();
    write_vtu(
        path,
        mesh,
        &[
            VtuField {
                name: "von_mises_max_over_cycle_MPa",
                components: 1,
                data: &mpa(&cycle.max_von_mises_pa),
            },
            VtuField {
                name: "fatigue_safety_factor_goodman",
                components: 1,
                data: &factor,
            },
            VtuField {
                name: "signed_von_mises_alternating_MPa",
                components: 1,
                data: &mpa(&cycle.alternating_pa),
            },
            VtuField {
                name: "signed_von_mises_mean_MPa",
                components: 1,
                data: &mpa(&cycle.mean_pa),
            },
            VtuField {
                name: "judged_node",
                components: 1,
                data: &judged,
            },
        ],
        &[],
    )?;
    Ok(())
}

fn write_cycle_picture(
    path: &Path,
    mesh: &crate::fem::TetMesh,
    cycle: &CycleSolution,
    record: &DesignCycle,
) -> Result<()> {
    let values: Vec<f64> = cycle.max_von_mises_pa.iter().map(|v| v * 1e-6).collect();
    let peak = record.max_von_mises_over_cycle_mpa;
    let svg = render_tet10_field(
        mesh,
        &values,
        &PictureOptions {
            title: format!(
                "max von Mises over one revolution [MPa] (inertia relief, {:.0} rad/s)",
                record.omega_rad_s
            ),
            unit: "MPa".into(),
            range: [0.0, if peak > 0.0 { peak } else { 1.0 }],
            marker_mm: Some(record.location_of_max_mm),
            marker_label: format!(
                "max {peak:.1} MPa at φ = {:.0}°",
                record.crank_angle_of_max_deg
            ),
            width_px: 960,
        },
    )?;
    super::atomic_write::write_atomic(path, svg.as_bytes())?;
    Ok(())
}
