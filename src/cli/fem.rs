//! `rodstudy fem DESIGN [--mesh FILE] [--size MM] [--force N] [--json] [--no-pictures] [--out DIR]
//! [--refine 8,5,3.5]`

use super::mesh_args::MeshArgs;
use super::settings::DesignSettings;
use crate::config::StudyConfig;
use crate::stages;
use crate::stages::fem::FemLoads;
use crate::stages::records::{DesignFem, LoadedDesign};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct FemArgs {
    /// The STL design (its sidecar gives units, pins and axis).
    design: PathBuf,
    #[command(flatten)]
    mesh: MeshArgs,
    /// Load magnitude [N] of both cases (default: the design's peak pin force); with a pressure
    /// trace (`[engine]`) of the F_x case only, the F_y case carrying the largest pin force across
    /// the rod over the cycle.
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
    /// Write the VTU files only, not the von Mises pictures (von_mises_fx.svg, _fy.svg).
    #[arg(long)]
    no_pictures: bool,
    /// Leave out the linear buckling analysis (computed by default: `buckling_load_factor`),
    /// e.g. to time the static analysis alone against another solver's.
    #[arg(long)]
    no_buckling: bool,
    /// Refinement study over these element sizes [mm] instead of one analysis, e.g. 8,5,3.5.
    #[arg(long, value_delimiter = ',', conflicts_with_all = ["mesh", "size", "target_error", "no_pictures", "no_buckling"])]
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

/// The design's peak pin force (stage 2), the load of both cases unless `--force` gives one.
pub(crate) fn peak_force(design: &LoadedDesign, config: &StudyConfig) -> Result<f64> {
    Ok(FemLoads::of_design(design, config)?.force_n)
}

pub fn run(args: FemArgs) -> Result<i32> {
    let settings = DesignSettings::resolve(args.config.as_deref(), &args.mesh, args.force)?;
    let config = &settings.config;
    let design = stages::mass::load(&args.design)?;
    let design_loads = FemLoads::of_design(&design, config)?;
    let loads = match settings.force_n {
        Some(f) => design_loads.with_force(f),
        None => {
            eprintln!(
                "load: the design's peak pin force, {:.1} N",
                design_loads.force_n
            );
            design_loads
        }
    };
    let force = loads.force_n;
    if let Some(sizes) = &args.refine {
        return refine(&args, &design, &settings, &loads, sizes);
    }
    if args.convergence {
        let target = settings.target_error();
        let c = if args.replot {
            crate::bench::fem_convergence::replot(&args.out)?
        } else {
            crate::bench::fem_convergence::convergence(
                &args.design,
                &args.sizes,
                target,
                force,
                args.config.as_deref(),
                &args.out,
            )?
        };
        if args.json {
            outln!("{}", serde_json::to_string_pretty(&c)?);
        } else {
            out!("{}", crate::bench::fem_convergence::markdown(&c));
            eprintln!(
                "wrote {}/convergence.{{md,csv,json,svg}}",
                args.out.display()
            );
        }
        return Ok(0);
    }
    // buckling unless --no-buckling: under --force if given, else the peak compression (with a
    // pressure trace, where stage 3 computes and judges it itself) or the peak pin force (F_x);
    // stage 3 runs it beside its geometry check, on the factorised K of the final mesh (the same
    // supports)
    let buckling_n = match (args.no_buckling, settings.force_n) {
        (true, _) => None,
        (false, Some(f)) => Some(f),
        (false, None) if loads.engine => None,
        (false, None) => Some(loads.compression_n),
    };
    let mut outcome = stages::fem::fem_and_buckling(
        &design,
        &loads,
        config,
        &args.out.join("mesh"),
        &settings.mode,
        false,
        buckling_n,
    )?;
    let mut buckling_cost: Option<(f64, usize)> = None;
    if let Some(run) = outcome.buckling_run.take() {
        match run.result {
            Ok(b) => {
                buckling_cost = Some((b.static_s + b.geometric_s + b.iteration_s, b.iterations));
                stages::fem::apply_buckling(&mut outcome, run.compression_n, b, None);
            }
            Err(e) => {
                outcome.record.buckling_load_factor = None;
                outcome.solution.buckling = None;
                eprintln!("buckling: {e:#}");
            }
        }
    }
    outcome.solution.system = None;
    let buckling_load_n = outcome.solution.buckling.as_ref().map(|b| b.load_n);
    if args.no_pictures {
        crate::report::fields::write_fem_vtus(
            &mut outcome.record.fem,
            &outcome.solution,
            &outcome.mesh.mesh,
            &args.out,
            "fem",
        )?;
    } else {
        crate::report::fields::write_fem_fields(
            &mut outcome.record.fem,
            &outcome.solution,
            &outcome.mesh.mesh,
            &args.out,
            "fem",
        )?;
    }
    let result = outcome.record;
    if args.json {
        let mut json = FemJson::from(&result);
        json.buckling_load_n = buckling_load_n;
        json.buckling_s = buckling_cost.map(|c| c.0);
        json.buckling_iterations = buckling_cost.map(|c| c.1);
        outln!("{}", serde_json::to_string_pretty(&json)?);
    } else {
        print_result(&result);
        if let (Some(l), Some(load)) = (result.buckling_load_factor, buckling_load_n) {
            outln!(
                "buckling: load factor {l:.3} under {load:.1} N of compression on the big-end bore (small-end bore fixed): linear buckling load {:.0} N; mode in {}",
                l * load,
                args.out.join("buckling_mode.vtu").display()
            );
        }
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
    /// The load cases, one field per case named by it (`fx`, `fy`).
    #[serde(flatten)]
    cases: &'a crate::rod::LoadCases,
    mesh: &'a crate::stages::records::MeshSummary,
    criterion: &'a crate::stages::records::StressVerdict,
    fem: &'a crate::rod::FemResult,
    /// Linear buckling load factor λ₁ of the compressive F_x case (B fixed, the load on A
    /// towards B) under `buckling_load_n`; `null` when refused (message on stderr).
    buckling_load_factor: Option<f64>,
    /// The compression λ₁ refers to: `--force`, else the peak compression with a pressure
    /// trace, else the peak pin force [N].
    buckling_load_n: Option<f64>,
    /// Wall time of the buckling analysis on stage 3's factorised K (the pre-stress solve, K_σ,
    /// the subspace iteration), s; not part of `fem.total_s`. `null` when not computed.
    buckling_s: Option<f64>,
    /// Subspace iterations the buckling analysis made.
    buckling_iterations: Option<usize>,
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
            cases: &d.fem.cases,
            mesh: &d.mesh,
            criterion: &d.criterion,
            fem: &d.fem,
            buckling_load_factor: d.buckling_load_factor,
            buckling_load_n: None,
            buckling_s: None,
            buckling_iterations: None,
            peak_memory_mb: crate::bench::fem_rod::peak_memory_mb(),
        }
    }
}

fn print_result(d: &DesignFem) {
    let f = &d.fem;
    outln!(
        "mesh: {} ({} tet10, {} nodes, {} DOFs); load {:.1} N on the big-end bore (r = {:.2} mm), small-end bore fixed (r = {:.2} mm)",
        d.mesh.source,
        f.elements,
        f.nodes,
        f.dofs,
        d.force_n,
        f.loaded_bore.radius_mm,
        f.fixed_bore.radius_mm
    );
    if let Some(h) = &f.half_model {
        outln!(
            "half model: the rod is symmetric about z = {:.3} mm; its half ({} tet10, {} nodes) was solved with u_z = 0 on the plane ({} nodes) and mirrored: the DOFs are the half's, the elements, nodes and fields the whole's",
            h.plane_z_mm,
            h.elements,
            h.nodes,
            h.plane_nodes
        );
    }
    if let Some(fallback) = &d.mesh.fallback {
        outln!(
            "mesh fallback: {fallback} (gmsh could not mesh the reparametrised surface as classified)"
        );
    }
    outln!(
        "\n| case | max von Mises unaveraged [MPa] | averaged [MPa] | away from fixed bore [MPa] (judged) | max displacement [mm] | resultant error | reaction balance |\n|---|---|---|---|---|---|---|"
    );
    for c in f.cases.iter() {
        outln!(
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
        outln!(
            "\nadaptive refinement to an estimated error of {:.1} % ({:?} after {} meshes, {:.1} s meshing); the size floor is {} (median {:.2} mm)",
            100.0 * a.target_error_rel,
            a.stop,
            a.iterations,
            d.mesh.seconds,
            a.floor,
            a.facet_spacing_median_mm
        );
        outln!(
            "\n| case | iteration | elements | DOFs | peak [MPa] | size at peak [mm] | order | estimated error | wall [s] |\n|---|---|---|---|---|---|---|---|---|"
        );
        for c in f.cases.iter() {
            for s in &c.adaptive {
                outln!(
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
    outln!(
        "\ntimes [s]: assembly {:.2}, symbolic analysis {:.2}, factorisation {:.2}, solve (all cases) {:.2}, stress {:.2}; total {:.2}",
        t.assembly_s,
        t.symbolic_s,
        t.factorisation_s,
        t.solve_s,
        t.stress_s,
        f.total_s
    );
    let v = &d.criterion;
    outln!(
        "criterion: {:.1} MPa ({}) against {:.1} MPa allowed: safety factor {:.2}, {}",
        v.governing_mpa,
        v.governing_case,
        v.allowed_mpa,
        v.safety_factor,
        if v.pass { "pass" } else { "FAIL" }
    );
    for note in &v.model_validity {
        outln!("model validity: {note}");
    }
    for c in f.cases.iter() {
        if let Some(vtu) = &c.vtu {
            eprintln!("wrote {}", vtu.display());
        }
    }
}

fn refine(
    args: &FemArgs,
    design: &LoadedDesign,
    settings: &DesignSettings,
    loads: &FemLoads,
    sizes: &[f64],
) -> Result<i32> {
    let force = loads.force_n;
    let study = stages::fem::fem_refinement(
        design,
        loads,
        &settings.config,
        &args.out.join("refinement"),
        sizes,
    )?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&study)?);
        return Ok(0);
    }
    outln!(
        "refinement study of {} at {:.1} N{}; \"away\": the judged stress (bands at the fixed \
         bore and the sharp edges left out)\n",
        args.design.display(),
        force,
        if loads.engine {
            " (F_x; F_y carries the engine's largest pin force across the rod)"
        } else {
            " (both cases)"
        }
    );
    let labels: Vec<&str> = crate::rod::cases::STATIC_CASES
        .iter()
        .map(|c| c.label)
        .collect();
    let per_case: String = labels
        .iter()
        .map(|l| format!(" {l} unaveraged / averaged / away [MPa] |"))
        .collect();
    let all = labels.join(" / ");
    let columns = 9 + labels.len();
    outln!(
        "| size [mm] | elements | DOFs |{per_case} {all} max displ. [mm] | {all} recovered peak [MPa] | {all} est. error | {all} bound at peak | {all} energy error | mesh [s] | solve [s] |\n|{}",
        "---|".repeat(columns)
    );
    for l in &study.levels {
        let joined = |f: &dyn Fn(&crate::rod::refinement::CaseMeasures) -> String| {
            l.cases.iter().map(f).collect::<Vec<_>>().join(" / ")
        };
        let per_case: String = l
            .cases
            .iter()
            .map(|c| {
                format!(
                    " {:.1} / {:.1} / {:.1} |",
                    c.max_unaveraged_mpa, c.max_averaged_mpa, c.max_away_from_fixed_mpa
                )
            })
            .collect();
        outln!(
            "| {} | {} | {} |{per_case} {} | {} | {} | {} | {} | {:.1} | {:.2} |",
            l.size_mm,
            l.elements,
            l.dofs,
            joined(&|c| format!("{:.4}", c.max_displacement_mm)),
            joined(&|c| format!("{:.1}", c.error_estimate.recovered_peak_mpa)),
            joined(&|c| format!("{:.3}", c.estimated_error_rel)),
            joined(&|c| format!("{:.3}", c.error_estimate.peak_node_bound_rel)),
            joined(&|c| format!("{:.3}", c.error_estimate.energy_error_rel)),
            l.mesh_s,
            l.solve_total_s
        );
    }
    Ok(0)
}
