//! `rodstudy study [--designs DIR] [--out DIR] [--config FILE] [--jobs N] [--no-cache]
//! [--update-baseline]`

use crate::config::StudyConfig;
use crate::report::atomic_write::write_atomic;
use crate::report::tables::{dynamics_table, mass_table};
use crate::report::write_reports;
use crate::study::baseline::{Baseline, read_results};
use crate::study::{Progress, StudyOptions, run_study};
use anyhow::Result;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

#[derive(Args)]
pub struct StudyArgs {
    /// Folder of designs (`*.stl`, each with an optional sidecar `.toml`).
    #[arg(long, default_value = "designs")]
    designs: PathBuf,
    /// Folder the reports are written to.
    #[arg(long, default_value = "reports")]
    out: PathBuf,
    /// Settings file (default: `rodstudy.toml` in the current folder if present, else the
    /// spec's defaults).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Designs studied at once (default: one per core; at most 256).
    #[arg(long, default_value_t = 0, value_parser = jobs)]
    jobs: usize,
    /// Leave out the FEM stage (mass and pin force only; no Python, no mesh).
    #[arg(long)]
    skip_fem: bool,
    /// Compute only shard K of N of the designs (a stable split by design id), for `merge`.
    #[arg(long, value_name = "K/N")]
    shard: Option<crate::study::shard::Shard>,
    /// Recompute every design even when its cached results are current.
    #[arg(long)]
    no_cache: bool,
    /// Also write OUT/baseline.json from these results (on purpose: it is what CI checks against;
    /// a whole study's, so not with `--shard`).
    #[arg(long, conflicts_with = "shard")]
    update_baseline: bool,
}

pub fn run(args: StudyArgs) -> Result<i32> {
    let config = StudyConfig::load(args.config.as_deref())?;
    let options = StudyOptions {
        designs: &args.designs,
        out: &args.out,
        config,
        jobs: args.jobs,
        use_cache: !args.no_cache,
        skip_fem: args.skip_fem,
        shard: args.shard,
    };
    let count = crate::geometry::design::find_stl_files(std::slice::from_ref(&args.designs))
        .map(|f| match args.shard {
            Some(sh) => crate::study::shard::share(&f, sh).len(),
            None => f.len(),
        })
        .unwrap_or(0);
    // A bar for people at a terminal; plain lines (kept in CI logs) otherwise.
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = ProgressBar::new(count as u64);
        bar.set_style(
            ProgressStyle::with_template("{bar:30} {pos}/{len} designs {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar
    });
    let done = AtomicUsize::new(0);
    let cached = AtomicUsize::new(0);
    let on_done = |p: Progress| {
        let k = done.fetch_add(1, Ordering::SeqCst) + 1;
        if p.cached {
            cached.fetch_add(1, Ordering::SeqCst);
        }
        let name = p
            .file
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        match &bar {
            Some(bar) => {
                bar.inc(1);
                bar.set_message(name);
            }
            None => match &p.outcome {
                Ok(d) => eprintln!(
                    "[{k}/{count}] {name}: peak pin force {:.1} N{}",
                    d.dynamics.peak_pin_force_n,
                    if p.cached { " (cached)" } else { "" }
                ),
                Err(_) => eprintln!("[{k}/{count}] {name}: FAILED"),
            },
        }
    };
    let results = run_study(&options, &on_done)?;
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    eprintln!(
        "study: ran {} on {} design(s) in {} ({} from the cache); skipped: {}",
        results.stages_run.join(", "),
        results.designs.len() + results.failed.len(),
        args.designs.display(),
        cached.load(Ordering::SeqCst),
        if results.stages_skipped.is_empty() {
            "none".to_string()
        } else {
            results.stages_skipped.join(", ")
        }
    );
    let designs: Vec<_> = results.designs.iter().map(|d| &d.mass).collect();
    out!("{}", mass_table(&designs));
    let dynamics: Vec<_> = results.designs.iter().map(|d| &d.dynamics).collect();
    outln!();
    out!("{}", dynamics_table(&dynamics));
    for d in &designs {
        for w in &d.warnings {
            eprintln!("warning: {}: {w}", d.file);
        }
    }
    for f in &results.failed {
        eprintln!("FAILED {}", f.error);
    }
    let written = write_reports(&results, &args.out)?;
    eprintln!("wrote {} files in {}", written.len(), args.out.display());
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

/// `--jobs`: 0 (one per core) to 256 designs at once.
fn jobs(v: &str) -> std::result::Result<usize, String> {
    match v.parse::<usize>() {
        Ok(n) if n <= 256 => Ok(n),
        _ => Err(format!(
            "'{v}' is not a number of designs at once from 0 (one per core) to 256"
        )),
    }
}
