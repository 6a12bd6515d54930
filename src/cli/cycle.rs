//! `rodstudy cycle DESIGN [--mesh FILE] [--size MM | --target-error R] [--config FILE] [--json]
//! [--out DIR]`: stress over one crank revolution with inertia relief, and the fatigue safety
//! factor, on the mesh stage 3 ends on.

use super::mesh_args::MeshArgs;
use super::settings::DesignSettings;
use crate::mechanism::Method;
use crate::report::fields::{write_cycle_fields, write_fem_fields};
use crate::stages;
use crate::stages::records::DesignCycle;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct CycleArgs {
    /// The STL design (its sidecar gives units, pins, axis and density).
    design: PathBuf,
    /// The mesh of stage 3 the cycle runs on (the final one of adaptive refinement).
    #[command(flatten)]
    mesh: MeshArgs,
    /// Settings file (as for `study`).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
    /// Folder for cycle.vtu, von_mises_cycle.svg and the stage-3 files.
    #[arg(long, default_value = "reports/cycle")]
    out: PathBuf,
}

/// `cycle --json`: the cycle record with the static stage's time on the same mesh beside it.
#[derive(serde::Serialize)]
struct CycleJson<'a> {
    #[serde(flatten)]
    cycle: &'a DesignCycle,
    /// Elements and DOFs of the mesh.
    elements: usize,
    dofs: usize,
    /// Wall time of the static two-case analysis on this mesh (the last one of stage 3: assembly,
    /// factorisation, solves, stresses, recovery, estimate; no files), s.
    static_stage_s: f64,
}

pub fn run(args: CycleArgs) -> Result<i32> {
    let DesignSettings { config, mode, .. } =
        DesignSettings::resolve(args.config.as_deref(), &args.mesh, None)?;
    let design = stages::mass::load(&args.design)?;
    let mass = stages::mass::mass(&design)?;
    let (dynamics, _) = stages::dynamics::dynamics_with(
        &mass,
        &config.driven_scene(),
        config.driven.gravity,
        &config.engine,
        Method::ClosedForm,
    )?;
    let mut f = stages::fem::fem(
        &design,
        &stages::fem::FemLoads::from_records(&mass, &dynamics),
        &config,
        &args.out.join("mesh"),
        &mode,
    )?;
    write_fem_fields(
        &mut f.record.fem,
        &f.solution,
        &f.mesh.mesh,
        &args.out,
        "fem",
    )?;
    let fem = f.record;
    let mesh = f.mesh;
    let c = stages::cycle::cycle(&mass, &mesh, &config)?;
    let mut cycle = c.record;
    write_cycle_fields(
        &mut cycle, &mesh.mesh, &c.cycle, &c.units, &c.local, &args.out,
    )?;
    // the static two-case analysis of the final mesh (assembly, factorisation, solves, stresses,
    // recovery and estimate), for the cost ratio
    let t = &fem.fem.timings;
    let static_s = t.assembly_s + t.symbolic_s + t.factorisation_s + t.solve_s + t.stress_s;
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&CycleJson {
                cycle: &cycle,
                elements: mesh.mesh.n_elements(),
                dofs: mesh.mesh.n_dofs(),
                static_stage_s: static_s,
            })?
        );
    } else {
        outln!(
            "{}: {} instants over {} at {:.2} rad/s, mesh {} elements / {} DOFs",
            mass.design,
            cycle.instants,
            crate::report::design_files::load_span(cycle.cycle_span_deg.is_some()),
            cycle.omega_rad_s,
            mesh.mesh.n_elements(),
            mesh.mesh.n_dofs()
        );
        outln!(
            "max von Mises over the cycle (away from the fixed bore): {:.2} MPa at φ = {:.1}°, at ({:.1}, {:.1}, {:.1}) mm",
            cycle.max_von_mises_over_cycle_mpa,
            cycle.crank_angle_of_max_deg,
            cycle.location_of_max_mm[0],
            cycle.location_of_max_mm[1],
            cycle.location_of_max_mm[2]
        );
        outln!(
            "fatigue ({}, Se {:.0} / Sut {:.0} MPa): safety factor {:.2} at ({:.1}, {:.1}, {:.1}) mm, σa {:.2} MPa, σm {:.2} MPa",
            if cycle.mean_stress.is_goodman() {
                "Goodman"
            } else {
                "Gerber"
            },
            cycle.endurance_mpa,
            cycle.ultimate_mpa,
            cycle.fatigue_safety_factor,
            cycle.fatigue_location_mm[0],
            cycle.fatigue_location_mm[1],
            cycle.fatigue_location_mm[2],
            cycle.fatigue_alternating_mpa,
            cycle.fatigue_mean_mpa
        );
        if let Some(l) = &cycle.local_fatigue {
            outln!(
                "local fatigue (FKM, jD {:.2}): safety factor {:.2} at ({:.1}, {:.1}, {:.1}) mm, χ* {:.3}/mm, n {:.3}, σa {:.2} MPa, σm {:.2} MPa, σWK {:.1} MPa; Findley {:.2} at ({:.1}, {:.1}, {:.1}) mm ({} nodes; {:.2} at the FKM node); {:.2} s",
                l.j_d,
                l.safety_factor,
                l.at_mm[0],
                l.at_mm[1],
                l.at_mm[2],
                l.chi_star_per_mm,
                l.support_factor,
                l.sigma1.amplitude_mpa,
                l.sigma1.mean_mpa,
                l.sigma1.sigma_wk_mpa,
                l.findley.factor,
                l.findley.at_mm[0],
                l.findley.at_mm[1],
                l.findley.at_mm[2],
                l.findley.nodes_checked,
                l.findley.factor_at_local_node,
                l.seconds
            );
        }
        outln!(
            "reaction at B against the dynamics' F_B: largest difference {:.2e} of the peak pin force ({:.1} N); mesh mass {:.4} kg (STL {:.4} kg)",
            cycle.reaction_mismatch_rel,
            cycle.peak_pin_force_n,
            cycle.mesh_mass_kg,
            cycle.stl_mass_kg
        );
        outln!(
            "time: cycle analysis {:.2} s ({} unit solves, {} instants combined; {:.2} s the whole stage), static two-case analysis of the same mesh {:.2} s: ratio {:.2}",
            cycle.analysis_seconds,
            cycle.cosine_bore_load.as_ref().map_or(6, |c| c.unit_solves),
            cycle.instants,
            cycle.seconds,
            static_s,
            cycle.analysis_seconds / static_s
        );
        eprintln!(
            "wrote {} and {}",
            args.out.join("cycle.vtu").display(),
            args.out.join("von_mises_cycle.svg").display()
        );
    }
    Ok(0)
}
