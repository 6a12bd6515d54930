//! `rodstudy integrators [--json] [--out DIR] [--repeats N]`: the work–precision comparison of
//! the free run (thesis ch. 4) against the exact energy-integral reference.

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
    /// Repeats per run; the median CPU time is reported.
    #[arg(long, default_value_t = 5)]
    repeats: usize,
}

pub fn run(args: IntegratorsArgs) -> Result<i32> {
    let config = SweepConfig {
        repeats: args.repeats,
        ..SweepConfig::default()
    };
    let wp =
        work_precision_sweep(&FreeScene::thesis(), &config).map_err(|e| anyhow::anyhow!("{e}"))?;
    let markdown = wp.to_markdown();
    if args.json {
        println!("{}", serde_json::to_string_pretty(&wp)?);
    } else {
        print!("{markdown}");
    }
    write_atomic(&args.out.join("work_precision.md"), markdown.as_bytes())?;
    write_atomic(
        &args.out.join("work_precision.json"),
        serde_json::to_string_pretty(&wp)?.as_bytes(),
    )?;
    let mut w = csv::Writer::from_writer(Vec::new());
    for row in &wp.rows {
        w.serialize(CsvRow::from(row))?;
    }
    write_atomic(&args.out.join("work_precision.csv"), &w.into_inner()?)?;
    let time = plot(&wp, "CPU time [s]", |r| r.cpu_s)?;
    write_atomic(&args.out.join("work_precision_time.svg"), time.as_bytes())?;
    let evals = plot(&wp, "right-hand-side evaluations", |r| r.rhs_evals as f64)?;
    write_atomic(&args.out.join("work_precision_evals.svg"), evals.as_bytes())?;
    eprintln!(
        "wrote work_precision.md, .csv, .json, work_precision_time.svg, work_precision_evals.svg in {}",
        args.out.display()
    );
    let non_monotone: Vec<String> = config
        .methods
        .iter()
        .filter(|m| !wp.is_monotone(**m))
        .map(|m| m.to_string())
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

/// Max |Δφ| against `cost`, log–log, one line per method.
fn plot(
    wp: &WorkPrecision,
    cost_label: &str,
    cost: impl Fn(&crate::free_run::SweepRow) -> f64,
) -> Result<String> {
    let series: Vec<Series> = Method::ALL
        .iter()
        .map(|m| Series {
            name: m.to_string(),
            points: wp
                .rows_of(*m)
                .into_iter()
                .filter_map(|r| r.max_err_phi_rad.map(|e| (cost(r), e)))
                .collect(),
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    line_chart(
        "Scene free (thesis ch. 4): error against the exact reference",
        cost_label,
        "max |Δφ| over [0, 1] s [rad]",
        &series,
        Scale::Log,
        Scale::Log,
    )
}
