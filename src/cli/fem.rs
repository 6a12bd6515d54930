//! `rodstudy fem DESIGN [--mesh FILE] [--size MM] [--force N] [--json] [--out DIR]
//! [--refine 8,5,3.5]`

use crate::fem::study::refinement_study_stl;
use crate::fem::{Material, RodOptions};
use crate::geometry::design::mass_of_design;
use crate::mechanism::Method;
use crate::python_env::{pipeline_script, python};
use crate::study::config::StudyConfig;
use crate::study::dynamics_stage::dynamics_of_design;
use crate::study::fem_stage::{DesignFem, MESHER, MeshMode, fem_of_design, rod_frame_surface};
use anyhow::{Result, bail};
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct FemArgs {
    /// The STL design (its sidecar gives units, pins and axis).
    design: PathBuf,
    /// Use this ready volume mesh (gmsh .msh, Abaqus/CalculiX .inp, VTU, Nastran .bdf; tet10)
    /// as it is, instead of meshing the STL.
    #[arg(long)]
    mesh: Option<PathBuf>,
    /// One fixed mesh of this element size [mm] (the thesis' setting is 5), instead of adaptive
    /// refinement.
    #[arg(long, conflicts_with = "target_error")]
    size: Option<f64>,
    /// Refine adaptively until the estimated relative error of each case's judged peak is at
    /// most this (default: `fem.target_error` of the configuration, 0.03).
    #[arg(long)]
    target_error: Option<f64>,
    /// Load magnitude [N] of both cases (default: the design's peak pin force).
    #[arg(long)]
    force: Option<f64>,
    /// Settings file (as for `study`).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Folder for the VTU files and the mesh.
    #[arg(long, default_value = "reports/fem")]
    out: PathBuf,
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
    /// Refinement study over these element sizes [mm] instead of one analysis, e.g. 8,5,3.5.
    #[arg(long, value_delimiter = ',')]
    refine: Option<Vec<f64>>,
    /// Speed against error: uniform meshes of `--sizes` and the adaptive sequence, each in its
    /// own process; writes convergence.md/.csv/.json/.svg into `--out`.
    #[arg(long, conflicts_with_all = ["refine", "mesh", "size"])]
    convergence: bool,
    /// With `--convergence`: re-write the table and the plot from the convergence.json in
    /// `--out`, without running the analyses again.
    #[arg(long, requires = "convergence")]
    replot: bool,
    /// Uniform sizes of `--convergence` [mm].
    #[arg(long, value_delimiter = ',', default_value = "8,5,3.5,2.5")]
    sizes: Vec<f64>,
}

/// The mesh mode of `--mesh`, `--size` and `--target-error` (checked), and the configuration
/// updated with them: shared by `fem` and `cycle`.
pub(crate) fn mesh_mode(
    config: &mut StudyConfig,
    mesh: Option<&PathBuf>,
    size: Option<f64>,
    target_error: Option<f64>,
) -> Result<MeshMode> {
    if let Some(size) = size {
        if !(size.is_finite() && size > 0.0) {
            bail!("--size must be a positive number of mm, got {size}");
        }
        config.fem.mesh_size_mm = size;
    }
    if let Some(t) = target_error {
        if !(t.is_finite() && t > 0.0 && t < 1.0) {
            bail!("--target-error must lie in (0, 1), got {t}");
        }
        config.fem.target_error = t;
    }
    Ok(match (mesh, size) {
        (Some(file), _) => MeshMode::User(file.clone()),
        (None, Some(size)) => MeshMode::Fixed(size),
        (None, None) => MeshMode::from_config(config),
    })
}

pub fn run(args: FemArgs) -> Result<i32> {
    let mut config = StudyConfig::load(args.config.as_deref())?;
    let mode = mesh_mode(
        &mut config,
        args.mesh.as_ref(),
        args.size,
        args.target_error,
    )?;
    let force = match args.force {
        Some(f) if f.is_finite() && f > 0.0 => f,
        Some(f) => bail!("--force must be a positive number of newtons, got {f}"),
        None => {
            let mass = mass_of_design(&args.design)?;
            let (dynamics, _) = dynamics_of_design(
                &mass,
                &config.driven_scene(),
                config.driven.gravity,
                Method::ClosedForm,
            )?;
            eprintln!(
                "load: the design's peak pin force, {:.1} N",
                dynamics.peak_pin_force_n
            );
            dynamics.peak_pin_force_n
        }
    };
    if let Some(sizes) = &args.refine {
        return refine(&args, &config, force, sizes);
    }
    if args.convergence {
        let c = if args.replot {
            crate::bench::fem_convergence::replot(&args.out)?
        } else {
            crate::bench::fem_convergence::convergence(
                &args.design,
                &args.sizes,
                if config.fem.adaptive() {
                    config.fem.target_error
                } else {
                    0.03
                },
                force,
                args.config.as_deref(),
                &args.out,
            )?
        };
        if args.json {
            println!("{}", serde_json::to_string_pretty(&c)?);
        } else {
            print!("{}", crate::bench::fem_convergence::markdown(&c));
            eprintln!(
                "wrote {}/convergence.{{md,csv,json,svg}}",
                args.out.display()
            );
        }
        return Ok(0);
    }
    let result = fem_of_design(
        &args.design,
        force,
        &config,
        &args.out.join("mesh"),
        &args.out,
        &mode,
    )?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&FemJson::from(&result))?);
    } else {
        print_result(&result);
    }
    Ok(0)
}

/// `fem --json`: the stage-3 record with `dofs` and `elements` at the top level.
#[derive(serde::Serialize)]
struct FemJson<'a> {
    dofs: usize,
    elements: usize,
    nodes: usize,
    force_n: f64,
    fx: &'a crate::fem::LoadCaseResult,
    fy: &'a crate::fem::LoadCaseResult,
    mesh: &'a crate::study::fem_stage::MeshSummary,
    criterion: &'a crate::study::fem_stage::StressVerdict,
    fem: &'a crate::fem::FemResult,
    /// Peak resident memory of this process so far (VmHWM) [MB].
    peak_memory_mb: Option<f64>,
}

impl<'a> From<&'a DesignFem> for FemJson<'a> {
    fn from(d: &'a DesignFem) -> Self {
        FemJson {
            dofs: d.fem.dofs,
            elements: d.fem.elements,
            nodes: d.fem.nodes,
            force_n: d.force_n,
            fx: &d.fem.fx,
            fy: &d.fem.fy,
            mesh: &d.mesh,
            criterion: &d.criterion,
            fem: &d.fem,
            peak_memory_mb: crate::fem::bench::peak_memory_mb(),
        }
    }
}

fn print_result(d: &DesignFem) {
    let f = &d.fem;
    println!(
        "mesh: {} ({} tet10, {} nodes, {} DOFs); load {:.1} N on the big-end bore (r = {:.2} mm), small-end bore fixed (r = {:.2} mm)",
        d.mesh.source,
        f.elements,
        f.nodes,
        f.dofs,
        d.force_n,
        f.loaded_bore.radius_mm,
        f.fixed_bore.radius_mm
    );
    println!(
        "\n| case | max von Mises unaveraged [MPa] | averaged [MPa] | away from fixed bore [MPa] (judged) | max displacement [mm] | resultant error | reaction balance |\n|---|---|---|---|---|---|---|"
    );
    for c in [&f.fx, &f.fy] {
        println!(
            "| {} | {:.2} | {:.2} | {:.2} ± {:.1} % | {:.4} | {:.1e} | {:.1e} |",
            c.name,
            c.max_von_mises_unaveraged_mpa,
            c.max_von_mises_averaged_mpa,
            c.max_von_mises_away_from_fixed_mpa,
            100.0 * c.estimated_error_rel,
            c.max_displacement_mm,
            c.resultant_error_rel,
            c.reaction_balance_rel
        );
    }
    if let Some(a) = &d.mesh.adaptive {
        println!(
            "\nadaptive refinement to an estimated error of {:.1} % ({:?} after {} meshes, {:.1} s meshing); the size floor is {} (median {:.2} mm)",
            100.0 * a.target_error_rel,
            a.stop,
            a.iterations,
            d.mesh.seconds,
            a.floor,
            a.facet_spacing_median_mm
        );
        println!(
            "\n| case | iteration | elements | DOFs | peak [MPa] | size at peak [mm] | order | estimated error | wall [s] |\n|---|---|---|---|---|---|---|---|---|"
        );
        for c in [&f.fx, &f.fy] {
            for s in &c.adaptive {
                println!(
                    "| {} | {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} % | {:.1} |",
                    c.name,
                    s.iteration,
                    s.elements,
                    s.dofs,
                    s.peak_mpa,
                    s.size_at_peak_mm,
                    s.order,
                    100.0 * s.estimated_error_rel,
                    s.seconds
                );
            }
        }
    }
    let t = &f.timings;
    println!(
        "\ntimes [s]: assembly {:.2}, symbolic analysis {:.2}, factorisation {:.2}, solve (both cases) {:.2}, stress {:.2}; total {:.2}",
        t.assembly_s, t.symbolic_s, t.factorisation_s, t.solve_s, t.stress_s, f.total_s
    );
    let v = &d.criterion;
    println!(
        "criterion: {:.1} MPa ({}) against {:.1} MPa allowed: safety factor {:.2}, {}",
        v.governing_mpa,
        v.governing_case,
        v.allowed_mpa,
        v.safety_factor,
        if v.pass { "pass" } else { "FAIL" }
    );
    for c in [&f.fx, &f.fy] {
        if let Some(vtu) = &c.vtu {
            eprintln!("wrote {}", vtu.display());
        }
    }
}

fn refine(args: &FemArgs, config: &StudyConfig, force: f64, sizes: &[f64]) -> Result<i32> {
    // meshed in the rod frame, mm, as stage 3 meshes (any units and pose)
    let surface = rod_frame_surface(&args.design, &args.out.join("refinement"))?;
    let bores = surface.bores();
    let material = Material {
        youngs_modulus_pa: config.fem.youngs_modulus_pa,
        poisson_ratio: config.fem.poisson_ratio,
    };
    let study = refinement_study_stl(
        &python()?,
        &pipeline_script(MESHER),
        &surface.stl,
        sizes,
        &args.out.join("refinement"),
        &material,
        &bores,
        force,
        &RodOptions {
            fixed_band_m: Some(config.fem.fixed_band_mm * 1e-3),
            ..RodOptions::default()
        },
    )?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&study)?);
        return Ok(0);
    }
    println!(
        "refinement study of {} at {:.1} N\n",
        args.design.display(),
        force
    );
    println!(
        "| size [mm] | elements | DOFs | F_x unaveraged / averaged / away [MPa] | F_y unaveraged / averaged / away [MPa] | F_y max displ. [mm] | F_x / F_y recovered peak [MPa] | F_x / F_y est. error | F_x / F_y bound at peak | F_x / F_y energy error | mesh [s] | solve [s] |\n|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for l in &study.levels {
        println!(
            "| {} | {} | {} | {:.1} / {:.1} / {:.1} | {:.1} / {:.1} / {:.1} | {:.4} | {:.1} / {:.1} | {:.3} / {:.3} | {:.3} / {:.3} | {:.3} / {:.3} | {:.1} | {:.2} |",
            l.size_mm,
            l.elements,
            l.dofs,
            l.fx.max_unaveraged_mpa,
            l.fx.max_averaged_mpa,
            l.fx.max_away_from_fixed_mpa,
            l.fy.max_unaveraged_mpa,
            l.fy.max_averaged_mpa,
            l.fy.max_away_from_fixed_mpa,
            l.fy.max_displacement_mm,
            l.fx.error_estimate.recovered_peak_mpa,
            l.fy.error_estimate.recovered_peak_mpa,
            l.fx.estimated_error_rel,
            l.fy.estimated_error_rel,
            l.fx.error_estimate.peak_node_bound_rel,
            l.fy.error_estimate.peak_node_bound_rel,
            l.fx.error_estimate.energy_error_rel,
            l.fy.error_estimate.energy_error_rel,
            l.mesh_s,
            l.solve_total_s
        );
    }
    Ok(0)
}
