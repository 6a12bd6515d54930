//! `rodstudy integrators [--json] [--out DIR] [--repeats N] [--t-end T]`: the work–precision
//! comparison of the free run (thesis ch. 4) against the exact energy-integral reference; with
//! `--t-end` other than 1 s, the long-horizon table.

use crate::free_run::{FreeScene, Method, SweepConfig, WorkPrecision, work_precision_sweep};
use crate::report::atomic_write::write_atomic;
use crate::report::plots::{Scale, Series, line_chart};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct IntegratorsArgs {
    /// Print the table rows as JSON instead of Markdown.
    #[arg(long)]
    json: bool,
    /// Folder for work_precision.{md,csv,json} and the plots work_precision_time.svg and
    /// work_precision_evals.svg.
    #[arg(long, default_value = "reports")]
    out: PathBuf,
    /// Repeats per run (at least 1); the median CPU time is reported.
    #[arg(long, default_value_t = 5, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..))]
    repeats: usize,
    /// End time [s]. Other than 1: the long-horizon table (scene `free` run to T, output
    /// every 1e-4·T s, the reduced-model methods and RK45 with the energy projection,
    /// tolerances 1e-6 … 1e-12, caps of 5e5 steps
    /// and 5e6 evaluations per simulated second; a method's tighter tolerances are skipped
    /// once it reaches the cap), written to work_precision_<T>s.* beside the 1 s files.
    #[arg(long, default_value_t = 1.0)]
    t_end: f64,
}

pub fn run(args: IntegratorsArgs) -> Result<i32> {
    let long = args.t_end != 1.0;
    let (scene, config, stem) = if long {
        let t = args.t_end;
        let scene = FreeScene::long_run(t, 1e-4 * t);
        let config = SweepConfig {
            methods: vec![
                Method::InitialAcceleration,
                Method::Rk45,
                Method::Rk23,
                Method::Bdf,
                Method::Rosenbrock,
                Method::TrBdf2,
            ],
            tolerances: vec![1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12],
            fixed_steps: vec![1e-4, 1e-5, 1e-6],
            repeats: args.repeats,
            max_steps: (5e5 * t.max(1.0)).ceil() as u64,
            max_rhs_evals: (5e6 * t.max(1.0)).ceil() as u64,
            projected_methods: vec![Method::Rk45],
            ..SweepConfig::default()
        };
        (scene, config, format!("work_precision_{t}s"))
    } else {
        let config = SweepConfig {
            repeats: args.repeats,
            ..SweepConfig::default()
        };
        (FreeScene::thesis(), config, "work_precision".to_string())
    };
    let wp = work_precision_sweep(&scene, &config).map_err(|e| anyhow::anyhow!("{e}"))?;
    let markdown = wp.to_markdown();
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&wp)?);
    } else {
        out!("{markdown}");
    }
    let file = |ext: &str| args.out.join(format!("{stem}{ext}"));
    write_atomic(&file(".md"), markdown.as_bytes())?;
    write_atomic(
        &file(".json"),
        serde_json::to_string_pretty(&wp)?.as_bytes(),
    )?;
    let mut w = csv::Writer::from_writer(Vec::new());
    for row in &wp.rows {
        w.serialize(CsvRow::from(row))?;
    }
    write_atomic(&file(".csv"), &w.into_inner()?)?;
    let time = plot(&wp, "CPU time [s]", |r| r.cpu_s)?;
    write_atomic(&file("_time.svg"), time.as_bytes())?;
    let evals = plot(&wp, "right-hand-side evaluations", |r| r.rhs_evals as f64)?;
    write_atomic(&file("_evals.svg"), evals.as_bytes())?;
    eprintln!(
        "wrote {stem}.md, .csv, .json, {stem}_time.svg, {stem}_evals.svg in {}",
        args.out.display()
    );
    let warned = wp.rows.iter().filter(|r| !r.warnings.is_empty()).count();
    if warned > 0 {
        eprintln!(
            "warning: {warned} runs carry warnings (error above 10× the tolerance, tolerance \
             floor, energy drift): see the `warnings` of {stem}.json"
        );
    }
    let non_monotone: Vec<String> = config
        .methods
        .iter()
        .filter(|m| !wp.is_monotone(**m))
        .map(|m| m.to_string())
        .chain(
            config
                .projected_methods
                .iter()
                .filter(|m| !wp.is_monotone_variant(**m, true))
                .map(|m| format!("{m} + energy projection")),
        )
        .collect();
    if !non_monotone.is_empty() {
        eprintln!(
            "warning: error not monotone in tolerance for {}",
            non_monotone.join(", ")
        );
    }
    Ok(0)
}

/// One flat row of `work_precision.csv` (the constraint drift split into its two columns).
#[derive(serde::Serialize)]
struct CsvRow {
    method: String,
    project_energy: bool,
    setting: &'static str,
    value: f64,
    failure: Option<String>,
    max_err_phi_rad: Option<f64>,
    max_err_omega_rad_s: Option<f64>,
    steps: u64,
    rhs_evals: u64,
    jac_evals: u64,
    lu_decompositions: u64,
    cpu_s: f64,
    energy_drift_max_j: Option<f64>,
    constraint_drift_position: Option<f64>,
    constraint_drift_velocity: Option<f64>,
}

impl From<&crate::free_run::SweepRow> for CsvRow {
    fn from(r: &crate::free_run::SweepRow) -> Self {
        CsvRow {
            method: r.method.to_string(),
            project_energy: r.project_energy,
            setting: r.setting,
            value: r.value,
            failure: r.failure.clone(),
            max_err_phi_rad: r.max_err_phi_rad,
            max_err_omega_rad_s: r.max_err_omega_rad_s,
            steps: r.steps,
            rhs_evals: r.rhs_evals,
            jac_evals: r.jac_evals,
            lu_decompositions: r.lu_decompositions,
            cpu_s: r.cpu_s,
            energy_drift_max_j: r.energy_drift_max_j,
            constraint_drift_position: r.constraint_drift_max.map(|c| c.position),
            constraint_drift_velocity: r.constraint_drift_max.map(|c| c.velocity),
        }
    }
}

/// Max |Δφ| against `cost`, log–log, one line per method (and per projected method).
fn plot(
    wp: &WorkPrecision,
    cost_label: &str,
    cost: impl Fn(&crate::free_run::SweepRow) -> f64,
) -> Result<String> {
    let series: Vec<Series> = [false, true]
        .into_iter()
        .flat_map(|p| Method::ALL.iter().map(move |m| (*m, p)))
        .map(|(m, projected)| Series {
            name: if projected {
                format!("{m} + energy projection")
            } else {
                m.to_string()
            },
            points: wp
                .rows_of_variant(m, projected)
                .into_iter()
                .filter_map(|r| r.max_err_phi_rad.map(|e| (cost(r), e)))
                .collect(),
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    line_chart(
        "Scene free (thesis ch. 4): error against the exact reference",
        cost_label,
        &format!("max |Δφ| over [0, {}] s [rad]", wp.scene.t_end),
        &series,
        Scale::Log,
        Scale::Log,
    )
}
