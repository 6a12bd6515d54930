//! `rodstudy merge SHARD_DIR... --out DIR`: the reports of a one-machine study from the shards of
//! `study --shard K/N`.

use crate::report::write_reports;
use crate::study::merge::merge_shards;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct MergeArgs {
    /// The shards' output folders (each the --out of one `study --shard K/N`).
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// Folder the merged reports are written to.
    #[arg(long, default_value = "reports")]
    out: PathBuf,
}

pub fn run(args: MergeArgs) -> Result<i32> {
    let results = merge_shards(&args.shards, &args.out)?;
    for f in &results.failed {
        eprintln!("FAILED ({} stage) {}", f.stage, f.error);
    }
    let written = write_reports(&results, &args.out)?;
    eprintln!(
        "merge: {} shard(s), {} design(s) studied, {} failed; wrote {} files in {}",
        args.shards.len(),
        results.designs.len(),
        results.failed.len(),
        written.len(),
        args.out.display()
    );
    Ok(i32::from(!results.failed.is_empty()))
}
