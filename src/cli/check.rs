//! `rodstudy check [--baseline FILE] [--results FILE] [--rtol R] [--rtol-mass R] [--json]`

use crate::study::baseline::{
    Baseline, DEFAULT_RTOL_FORCE, DEFAULT_RTOL_MASS, check, check_table, read_results,
};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct CheckArgs {
    /// The committed baseline.
    #[arg(long, default_value = "reports/baseline.json")]
    baseline: PathBuf,
    /// The latest study results.
    #[arg(long, default_value = "reports/results.json")]
    results: PathBuf,
    /// Relative tolerance on the peak pin force (a number ≥ 0).
    #[arg(long, default_value_t = DEFAULT_RTOL_FORCE, value_parser = tolerance)]
    rtol: f64,
    /// Relative tolerance on the mass (a number ≥ 0).
    #[arg(long, default_value_t = DEFAULT_RTOL_MASS, value_parser = tolerance)]
    rtol_mass: f64,
    /// Print the rows as JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(args: CheckArgs) -> Result<i32> {
    let results = read_results(&args.results)?;
    let baseline = Baseline::read(&args.baseline)?;
    let rows = check(&baseline, &results, args.rtol, args.rtol_mass);
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        out!("{}", check_table(&rows, args.rtol, args.rtol_mass));
    }
    let failing = rows.iter().filter(|r| !r.passed()).count();
    if failing > 0 {
        eprintln!(
            "check FAILED: {failing} design(s) regressed, missing or failed against {}",
            args.baseline.display()
        );
        return Ok(1);
    }
    eprintln!(
        "check passed: {} design(s) within tolerance of {}",
        rows.len(),
        args.baseline.display()
    );
    Ok(0)
}

/// A relative tolerance: a finite number ≥ 0.
fn tolerance(v: &str) -> std::result::Result<f64, String> {
    match v.parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        _ => Err(format!(
            "'{v}' is not a relative tolerance (a finite number ≥ 0, e.g. 0.005)"
        )),
    }
}
