//! `rodstudy dynamics driven DESIGN... [--json] [--csv FILE]` and `rodstudy dynamics table-5-1`

use crate::geometry::design::{find_stl_files, mass_of_design};
use crate::mechanism::{DrivenScene, MechanismParams, Method, table_5_1_check};
use crate::study::dynamics_stage::{DesignDynamics, dynamics_of_design, write_history_csv};
use crate::study::tables::dynamics_table;
use anyhow::Result;
use clap::{Args, Subcommand, ValueEnum};
use rayon::prelude::*;
use std::path::PathBuf;

#[derive(Subcommand)]
pub enum DynamicsCommand {
    /// The driven crank–slider (φ = ωt): crank–rod pin force history and its peak, per design.
    Driven(DrivenArgs),
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
}

pub fn run(command: DynamicsCommand) -> Result<i32> {
    match command {
        DynamicsCommand::Driven(args) => driven(args),
        DynamicsCommand::Table51 { json, no_gravity } => table51(json, !no_gravity),
    }
}

fn driven(args: DrivenArgs) -> Result<i32> {
    let defaults = DrivenScene::default();
    let scene = DrivenScene {
        omega_rad_s: args.omega.unwrap_or(defaults.omega_rad_s),
        duration_s: args.duration.unwrap_or(defaults.duration_s),
        steps: args.steps.unwrap_or(defaults.steps),
        ..defaults
    };
    let method = match args.method {
        MethodArg::ClosedForm => Method::ClosedForm,
        MethodArg::Multibody => Method::Multibody,
    };
    let files = find_stl_files(&args.designs)?;
    let outcomes: Vec<_> = files
        .par_iter()
        .map(|f| {
            mass_of_design(f).and_then(|m| dynamics_of_design(&m, &scene, !args.no_gravity, method))
        })
        .collect();
    let ok: Vec<&DesignDynamics> = outcomes
        .iter()
        .filter_map(|o| o.as_ref().ok().map(|(d, _)| d))
        .collect();
    if args.json {
        println!("{}", serde_json::to_string_pretty(&ok)?);
    } else {
        print!("{}", dynamics_table(&ok));
    }
    if let Some(path) = &args.csv {
        let mut w = csv::Writer::from_writer(Vec::new());
        for (summary, run) in outcomes.iter().filter_map(|o| o.as_ref().ok()) {
            write_history_csv(&mut w, &summary.design, run)?;
        }
        crate::study::atomic_write::write_atomic(path, &w.into_inner()?)?;
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
        println!("{}", serde_json::to_string_pretty(&rows)?);
        return Ok(0);
    }
    println!(
        "Table 5.1 of the thesis (ADAMS, GSTIFF) against ours: a rod of the table's mass with the spec's l1, ω = 40π rad/s, gravity {}\n",
        if gravity { "on" } else { "off" }
    );
    println!(
        "| design | mass [kg] | l1 [mm] | thesis peak [N] | our peak [N] | difference | l1 that reproduces the thesis |\n|---|---|---|---|---|---|---|"
    );
    for r in &rows {
        println!(
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
