//! `rodstudy dynamics driven DESIGN... [--config FILE] [--json] [--csv FILE]` and `rodstudy dynamics table-5-1`

use crate::config::StudyConfig;
use crate::free_run::{FreeRunOptions, Method as FreeMethod, run_free};
use crate::geometry::design::find_stl_files;
use crate::mechanism::{DrivenScene, MechanismParams, Method, table_5_1_check};
use crate::report::design_files::write_history_csv;
use crate::report::tables::dynamics_table;
use crate::stages;
use crate::stages::records::DesignDynamics;
use anyhow::Result;
use clap::{Args, Subcommand, ValueEnum};
use rayon::prelude::*;
use std::path::PathBuf;

#[derive(Subcommand)]
pub enum DynamicsCommand {
    /// The driven crank–slider (φ = ωt): crank–rod pin force history and its peak, per design.
    Driven(DrivenArgs),
    /// The free-running crank (thesis ch. 4): M = 1 N·m on the crank, F = 15 N on the piston,
    /// from rest; the reduction-method equation of motion integrated by the chosen method.
    Free(FreeArgs),
    /// The thesis' Table 5.1 reproduced: rods of the table's mass with the spec's l1.
    #[command(name = "table-5-1")]
    Table51 {
        #[arg(long)]
        json: bool,
        /// Switch gravity off.
        #[arg(long)]
        no_gravity: bool,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum MethodArg {
    /// Closed-form Newton–Euler (default; the cheapest exact model).
    ClosedForm,
    /// The planar multibody core (9 body coordinates, Lagrange multipliers).
    Multibody,
}

#[derive(Args)]
pub struct DrivenArgs {
    /// STL designs (files or folders); each design's sidecar is honoured.
    #[arg(required = true)]
    designs: Vec<PathBuf>,
    /// Print a JSON array of per-design summaries.
    #[arg(long)]
    json: bool,
    /// Write the pin-force histories of all designs to this CSV file.
    #[arg(long)]
    csv: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "closed-form")]
    method: MethodArg,
    /// Switch gravity off (on by default, g = 9.81 m/s² along −y).
    #[arg(long)]
    no_gravity: bool,
    /// Crank speed [rad/s] (default 40π).
    #[arg(long)]
    omega: Option<f64>,
    /// Duration [s] (default 5).
    #[arg(long)]
    duration: Option<f64>,
    /// Number of output steps (intervals; default 5000).
    #[arg(long)]
    steps: Option<usize>,
    /// Settings file (default: `rodstudy.toml` if present): its `[driven]` scene (which the
    /// flags above override) and its `[engine]`. With `[engine] pressure_trace` the scene covers
    /// the four-stroke cycle (720°, `--duration` is then replaced by 4π/ω) with the gas force,
    /// and the CSV gains a `gas_force_n` column.
    #[arg(long)]
    config: Option<PathBuf>,
}

#[derive(Args)]
pub struct FreeArgs {
    /// initial-acceleration, rk45, rk23, bdf, rosenbrock, trbdf2 (reduced model), dae-index1,
    /// dae-genalpha (the 9-coordinate multibody DAE; genalpha's step is --dt).
    #[arg(long, default_value = "rk45")]
    method: String,
    /// Relative tolerance (default 0: φ grows without bound, so control is absolute); the
    /// fixed-step methods refuse it.
    #[arg(long)]
    rtol: Option<f64>,
    /// Absolute tolerance on φ [rad] and φ̇ [rad/s] (default 1e-8); the fixed-step methods
    /// refuse it.
    #[arg(long)]
    atol: Option<f64>,
    /// Step of the fixed-step methods, initial-acceleration and dae-genalpha [s] (default
    /// 1e-5); the adaptive methods refuse it.
    #[arg(long)]
    dt: Option<f64>,
    /// End time [s] (default 1).
    #[arg(long)]
    t_end: Option<f64>,
    /// Cap on steps, in all (default: 1e6 per second of simulated time, at least 1e6); also
    /// raises the cap on right-hand-side evaluations to 20 per step if that is more.
    #[arg(long, value_parser = parse_count)]
    max_steps: Option<u64>,
    /// Print the result as JSON (without the trajectories).
    #[arg(long)]
    json: bool,
    /// Write t, φ, ω on the 1e-4 s output grid to this CSV file.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// rk45 only: after every step put φ̇ back onto the energy integral at the step's φ
    /// (projection onto the invariant; removes the method's energy drift over long runs).
    #[arg(long)]
    project_energy: bool,
}

/// What `dynamics free --json` prints: the run without its trajectories, and its error against
/// the exact energy-integral reference.
#[derive(serde::Serialize)]
struct FreeSummary<'a> {
    method: String,
    model: &'a str,
    t_end_s: f64,
    phi_rad: f64,
    omega_rad_s: f64,
    steps: u64,
    rejected_steps: u64,
    rhs_evals: u64,
    jac_evals: u64,
    lu_decompositions: u64,
    cpu_s: f64,
    energy_drift_max_j: Option<f64>,
    /// With `--project-energy`: the projections made and the largest change of φ̇ [rad/s].
    #[serde(skip_serializing_if = "Option::is_none")]
    energy_projection: Option<ProjectionSummary>,
    /// The DAE forms' largest constraint violation (max |Φ|, max |D ċ|) over the run.
    constraint_drift_max: Option<crate::mechanism::forward::ConstraintViolation>,
    max_err_phi_rad: Option<f64>,
    max_err_omega_rad_s: Option<f64>,
    warnings: &'a [String],
}

/// `energy_projection` of [`FreeSummary`].
#[derive(serde::Serialize)]
struct ProjectionSummary {
    projections: u64,
    max_change_rad_s: f64,
}

/// What a user can do about a run that stopped, by why it stopped and what the method reads.
fn what_to_try(method: FreeMethod, e: &crate::free_run::FreeRunError) -> &'static str {
    use crate::integrators::FailureKind as K;
    let crate::free_run::FreeRunError::Solver(se) = e else {
        return "";
    };
    match (&se.kind, method.is_fixed_step()) {
        (K::StepLimit { .. } | K::EvalLimit { .. }, true) => {
            ": raise --max-steps, or lengthen --dt"
        }
        (K::StepLimit { .. } | K::EvalLimit { .. }, false) => {
            ": raise --max-steps, or loosen --atol/--rtol (below the tolerance floor the step \
             control fights round-off)"
        }
        (K::StepSizeUnderflow { .. }, _) => {
            ": loosen --atol/--rtol (the step fell below what the time can resolve)"
        }
        (K::NoConvergence { .. } | K::NonFinite, true) => ": shorten --dt",
        (K::NoConvergence { .. } | K::NonFinite, false) => ": tighten --atol/--rtol",
        _ => "",
    }
}

/// A flag the chosen method would not read is refused rather than ignored: `--dt` belongs to
/// the fixed-step methods (initial-acceleration, dae-genalpha), `--atol`/`--rtol` to the
/// adaptive ones.
fn refuse_flags_the_method_ignores(method: FreeMethod, args: &FreeArgs) -> Result<()> {
    if method.is_fixed_step() {
        let given: Vec<&str> = [
            ("--atol", args.atol.is_some()),
            ("--rtol", args.rtol.is_some()),
        ]
        .into_iter()
        .filter_map(|(flag, set)| set.then_some(flag))
        .collect();
        if !given.is_empty() {
            anyhow::bail!(
                "{method} is a fixed-step method and does not read {}: its accuracy is set by \
                 --dt (default 1e-5 s); for error control choose an adaptive method (rk45, rk23, \
                 bdf, rosenbrock, trbdf2, dae-index1)",
                given.join(" or ")
            );
        }
    } else if args.dt.is_some() {
        anyhow::bail!(
            "{method} chooses its own steps from --atol/--rtol and does not read --dt: give \
             --atol/--rtol, or a fixed-step method (initial-acceleration, dae-genalpha) for --dt"
        );
    }
    Ok(())
}

/// A count given as an integer or in the help's own form (`1e6`).
fn parse_count(v: &str) -> std::result::Result<u64, String> {
    v.parse::<u64>().or_else(|_| match v.parse::<f64>() {
        Ok(x) if x >= 0.0 && x.fract() == 0.0 && x <= u64::MAX as f64 => Ok(x as u64),
        _ => Err(format!(
            "'{v}' is not a whole number ≥ 0 (e.g. 5000000 or 5e6)"
        )),
    })
}

fn free(args: FreeArgs) -> Result<i32> {
    let method: FreeMethod = args.method.parse().map_err(|e| anyhow::anyhow!("{e}"))?;
    refuse_flags_the_method_ignores(method, &args)?;
    let mut options = FreeRunOptions::default();
    if let Some(t_end) = args.t_end {
        options.scene.t_end = t_end;
    }
    options.rtol = args.rtol.unwrap_or(options.rtol);
    options.atol = args.atol.unwrap_or(options.atol);
    options.fixed_step = args.dt.unwrap_or(options.fixed_step);
    // the default caps grow with the simulated time; an explicit --max-steps is a total
    options = options.with_caps_for_duration();
    if let Some(n) = args.max_steps {
        options.max_steps = n;
        options.max_rhs_evals = options.max_rhs_evals.max(n.saturating_mul(20));
    }
    options.project_energy = args.project_energy;
    let mut run = run_free(method, &options).map_err(|e| {
        // the solver's own errors name the method already
        let text = e.to_string();
        let text = if text.starts_with(&format!("{method}:")) {
            text
        } else {
            format!("{method}: {text}")
        };
        anyhow::anyhow!("{text}{}", what_to_try(method, &e))
    })?;
    // the exact reference where the scene has one; warns when the error exceeds 10× the
    // tolerance
    let warnings_before = run.warnings.len();
    let mut reference_failed = None;
    let errors = match options.scene.reference() {
        Ok(reference) => Some(run.check_against_reference(&reference, &options)),
        Err(e) => {
            reference_failed = options.scene.loads.is_conservative().then(|| {
                format!(
                    "the exact reference could not be built ({e}), so the run is not compared \
                     with it (max_err_phi_rad and max_err_omega_rad_s are null)"
                )
            });
            None
        }
    };
    // RK45 drifts off the energy integral of a conservative scene over a long run, and the phase
    // error follows the drift: say what keeps it there (docs/free-run.md)
    let warned = run.warnings.len() > warnings_before;
    if warned
        && method == FreeMethod::Rk45
        && !options.project_energy
        && options.scene.loads.is_conservative()
    {
        run.warnings.push(
            "the scene conserves energy and rk45 drifts off it (energy_drift_max_j), which the \
             phase error follows: --project-energy keeps each step on the energy integral"
                .into(),
        );
    }
    run.warnings.extend(reference_failed);
    let summary = FreeSummary {
        method: run.method.to_string(),
        model: run.model,
        t_end_s: options.scene.t_end,
        phi_rad: run.phi_rad,
        omega_rad_s: run.omega_rad_s,
        steps: run.steps,
        rejected_steps: run.rejected_steps,
        rhs_evals: run.rhs_evals,
        jac_evals: run.jac_evals,
        lu_decompositions: run.lu_decompositions,
        cpu_s: run.cpu_s,
        energy_drift_max_j: run.energy_drift_max_j,
        energy_projection: options.project_energy.then_some(ProjectionSummary {
            projections: run.energy_projections,
            max_change_rad_s: run.energy_projection_max_change_rad_s,
        }),
        constraint_drift_max: run.constraint_drift_max,
        max_err_phi_rad: errors.map(|e| e.0),
        max_err_omega_rad_s: errors.map(|e| e.1),
        warnings: &run.warnings,
    };
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        outln!("scene free, method {} ({})", summary.method, summary.model);
        outln!(
            "t_end = {} s: φ = {:.12} rad, ω = {:.12} rad/s",
            summary.t_end_s,
            summary.phi_rad,
            summary.omega_rad_s
        );
        outln!(
            "steps {} (+{} rejected), RHS evaluations {}, Jacobians {}, LU {}, time {:.3} ms",
            summary.steps,
            summary.rejected_steps,
            summary.rhs_evals,
            summary.jac_evals,
            summary.lu_decompositions,
            summary.cpu_s * 1e3
        );
        if let (Some(p), Some(w)) = (summary.max_err_phi_rad, summary.max_err_omega_rad_s) {
            outln!(
                "against the exact energy-integral reference: max |Δφ| = {p:.3e} rad, max |Δω| = {w:.3e} rad/s"
            );
        }
        if let Some(e) = summary.energy_drift_max_j {
            outln!("energy drift: {e:.3e} J");
        }
        if let Some(p) = &summary.energy_projection {
            outln!(
                "energy projection: {} projections, largest change of φ̇ {:.3e} rad/s",
                p.projections,
                p.max_change_rad_s
            );
        }
        if let Some(c) = &summary.constraint_drift_max {
            outln!(
                "constraint drift: max |Φ| = {:.3e} (m, rad), max |D ċ| = {:.3e} (m/s, rad/s)",
                c.position,
                c.velocity
            );
        }
    }
    for w in summary.warnings {
        eprintln!("warning: {w}");
    }
    if let Some(path) = &args.csv {
        let mut w = csv::Writer::from_writer(Vec::new());
        w.write_record(["t_s", "phi_rad", "omega_rad_s"])?;
        for k in 0..run.t.len() {
            w.write_record([run.t[k], run.phi[k], run.omega[k]].map(|v| format!("{v:.15e}")))?;
        }
        crate::report::atomic_write::write_atomic(path, &w.into_inner()?)?;
    }
    Ok(0)
}

pub fn run(command: DynamicsCommand) -> Result<i32> {
    match command {
        DynamicsCommand::Driven(args) => driven(args),
        DynamicsCommand::Free(args) => free(args),
        DynamicsCommand::Table51 { json, no_gravity } => table51(json, !no_gravity),
    }
}

fn driven(args: DrivenArgs) -> Result<i32> {
    let config = StudyConfig::load(args.config.as_deref())?;
    let defaults = config.driven_scene();
    let gravity = config.driven.gravity && !args.no_gravity;
    let scene = DrivenScene {
        omega_rad_s: args.omega.unwrap_or(defaults.omega_rad_s),
        duration_s: args.duration.unwrap_or(defaults.duration_s),
        steps: args.steps.unwrap_or(defaults.steps),
        ..defaults
    };
    // the flags within the settings' ranges, checked once (not per design)
    if scene.omega_rad_s > crate::config::MAX_OMEGA_RAD_S {
        anyhow::bail!(
            "--omega {:e} is out of range: it must be at most {:e} rad/s (20 000 rpm is 2094 rad/s)",
            scene.omega_rad_s,
            crate::config::MAX_OMEGA_RAD_S
        );
    }
    scene.validate()?;
    let method = match args.method {
        MethodArg::ClosedForm => Method::ClosedForm,
        MethodArg::Multibody => Method::Multibody,
    };
    let files = find_stl_files(&args.designs)?;
    let outcomes: Vec<_> = files
        .par_iter()
        .map(|f| {
            stages::mass::load(f)
                .and_then(|d| stages::mass::mass(&d))
                .and_then(|m| {
                    stages::dynamics::dynamics_with(&m, &scene, gravity, &config.engine, method)
                })
        })
        .collect();
    let ok: Vec<&DesignDynamics> = outcomes
        .iter()
        .filter_map(|o| o.as_ref().ok().map(|(d, _)| d))
        .collect();
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&ok)?);
    } else {
        out!("{}", dynamics_table(&ok));
    }
    if let Some(path) = &args.csv {
        let mut w = csv::Writer::from_writer(Vec::new());
        for (summary, run) in outcomes.iter().filter_map(|o| o.as_ref().ok()) {
            write_history_csv(&mut w, &summary.design, run)?;
        }
        crate::report::atomic_write::write_atomic(path, &w.into_inner()?)?;
        eprintln!("wrote {}", path.display());
    }
    let failed: Vec<_> = outcomes.iter().filter_map(|o| o.as_ref().err()).collect();
    for e in &failed {
        eprintln!("error: {e:#}");
    }
    Ok(i32::from(!failed.is_empty()))
}

fn table51(json: bool, gravity: bool) -> Result<i32> {
    let params = MechanismParams::default().with_gravity(gravity);
    // The thesis gives no pin-axis inertia; the peak at top dead centre does not depend on it.
    let rows = table_5_1_check(&params, 0.02)?;
    if json {
        // each row says its scene (the table is at 40π rad/s; gravity as asked)
        #[derive(serde::Serialize)]
        struct Row<'a, T: serde::Serialize> {
            #[serde(flatten)]
            row: &'a T,
            omega_rad_s: f64,
            gravity: bool,
        }
        let v: Vec<_> = rows
            .iter()
            .map(|row| Row {
                row,
                omega_rad_s: crate::mechanism::table_5_1::THESIS_OMEGA_RAD_S,
                gravity,
            })
            .collect();
        outln!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(0);
    }
    outln!(
        "Table 5.1 of the thesis (ADAMS, GSTIFF) against ours: a rod of the table's mass with the spec's l1, ω = 40π rad/s, gravity {}\n",
        if gravity { "on" } else { "off" }
    );
    outln!(
        "| design | mass [kg] | l1 [mm] | thesis peak [N] | our peak [N] | difference | l1 that reproduces the thesis |\n|---|---|---|---|---|---|---|"
    );
    for r in &rows {
        outln!(
            "| {} | {:.10} | {:.2} | {:.0} | {:.2} | {} | {} |",
            r.design,
            r.mass_kg,
            r.l1_m * 1e3,
            r.thesis_peak_n,
            r.computed_peak_n,
            r.rel_error
                .map_or("—".into(), |e| format!("{:+.4} %", e * 100.0)),
            r.l1_fit.explanation()
        );
    }
    Ok(0)
}
