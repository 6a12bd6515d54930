//! `rodstudy sweep generate --count N --seed S --out DIR [--bounds FILE]`
//!
//! Runs `pipeline/sweep_designs.py` with the project's Python environment (created on first use):
//! a Latin-hypercube sample of `make_designs.py`'s shape parameters, one STL and sidecar per rod
//! plus `DIR/sweep.json`. The sampler, the bounds, the replacement of invalid parameter sets and
//! the bounds-file format are documented in the script's docstring. Exit status: the script's
//! (0 all rods written, 1 a rod could not be made, 2 usage error).

use crate::python_env::{pipeline_script, python};
use anyhow::{Context, Result, bail};
use clap::Subcommand;
use std::path::PathBuf;
use std::process::Command;

/// The script that generates the sweep.
const SCRIPT: &str = "sweep_designs.py";

#[derive(Subcommand)]
pub enum SweepCommand {
    /// N rods from a Latin-hypercube sample of the design parameters (shank kind, eye radii and
    /// thickness, boss span, shank thickness/width/taper, flange/rail, web), each an STL with its
    /// sidecar, and DIR/sweep.json; the same seed gives byte-identical files.
    Generate {
        /// Number of rods (ids rod0001, rod0002, ...).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
        count: u32,
        /// Seed of numpy's PCG64 generator.
        #[arg(long)]
        seed: u64,
        /// Output folder (created; must not hold other files).
        #[arg(long)]
        out: PathBuf,
        /// TOML (.toml) or JSON file overriding min/max per parameter (format: see
        /// pipeline/sweep_designs.py).
        #[arg(long)]
        bounds: Option<PathBuf>,
    },
}

pub fn run(command: SweepCommand) -> Result<i32> {
    match command {
        SweepCommand::Generate {
            count,
            seed,
            out,
            bounds,
        } => {
            let script = pipeline_script(SCRIPT);
            if !script.is_file() {
                bail!("{}: no such pipeline script", script.display());
            }
            let python = python()?;
            let mut cmd = Command::new(&python);
            cmd.arg(&script)
                .arg("--count")
                .arg(count.to_string())
                .arg("--seed")
                .arg(seed.to_string())
                .arg("--out")
                .arg(&out);
            if let Some(bounds) = &bounds {
                cmd.arg("--bounds").arg(bounds);
            }
            let status = cmd
                .status()
                .with_context(|| format!("cannot run {}", python.display()))?;
            Ok(status.code().unwrap_or(2))
        }
    }
}
