//! `rodstudy study [--designs DIR] [--out DIR]`

use crate::study::atomic_write::write_atomic;
use crate::study::baseline::{Baseline, read_results};
use crate::study::tables::{dynamics_table, mass_table};
use crate::study::{run_study, write_reports};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct StudyArgs {
    /// Folder of designs (`*.stl`, each with an optional sidecar `.toml`).
    #[arg(long, default_value = "designs")]
    designs: PathBuf,
    /// Folder the reports are written to.
    #[arg(long, default_value = "reports")]
    out: PathBuf,
    /// Also write OUT/baseline.json from these results (on purpose: it is what CI checks against).
    #[arg(long)]
    update_baseline: bool,
}

pub fn run(args: StudyArgs) -> Result<i32> {
    let results = run_study(&args.designs)?;
    eprintln!(
        "study: ran {} on {} design(s) in {}; not yet available: {}",
        results.stages_run.join(", "),
        results.designs.len() + results.failed.len(),
        args.designs.display(),
        results.stages_not_yet_available.join(", ")
    );
    let designs: Vec<_> = results.designs.iter().map(|d| &d.mass).collect();
    print!("{}", mass_table(&designs));
    let dynamics: Vec<_> = results.designs.iter().map(|d| &d.dynamics).collect();
    println!();
    print!("{}", dynamics_table(&dynamics));
    for d in &designs {
        for w in &d.warnings {
            eprintln!("warning: {}: {w}", d.file);
        }
    }
    for f in &results.failed {
        eprintln!("FAILED {}", f.error);
    }
    let written = write_reports(&results, &args.out)?;
    for path in written {
        eprintln!("wrote {}", path.display());
    }
    if args.update_baseline {
        if !results.failed.is_empty() {
            anyhow::bail!(
                "not updating the baseline: {} design(s) failed",
                results.failed.len()
            );
        }
        let view = read_results(&args.out.join("results.json"))?;
        let path = args.out.join("baseline.json");
        write_atomic(
            &path,
            serde_json::to_string_pretty(&Baseline::from_results(&view))?.as_bytes(),
        )?;
        eprintln!(
            "wrote {} (the new baseline for `rodstudy check`)",
            path.display()
        );
    }
    Ok(i32::from(!results.failed.is_empty()))
}
