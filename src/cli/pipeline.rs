//! `rodstudy setup` and `rodstudy pipeline SCRIPT [ARGS]...`

use crate::python_env::{pipeline_script, python};
use anyhow::{Context, Result, bail};
use clap::Args;
use std::process::Command;

#[derive(Args)]
pub struct PipelineArgs {
    /// Script name in `pipeline/`, e.g. `make_designs.py`.
    script: String,
    /// Arguments passed to the script unchanged.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    args: Vec<String>,
}

pub fn setup() -> Result<i32> {
    let python = python()?;
    outln!("Python environment ready: {}", python.display());
    Ok(0)
}

pub fn run(args: PipelineArgs) -> Result<i32> {
    // a script of the pipeline folder by its name, nothing elsewhere
    let plain = std::path::Path::new(&args.script)
        .file_name()
        .is_some_and(|n| n == args.script.as_str());
    if !plain || !args.script.ends_with(".py") {
        bail!(
            "{}: give the name of a Python script in pipeline/ (e.g. make_designs.py), not a path",
            args.script
        );
    }
    let script = pipeline_script(&args.script);
    if !script.is_file() {
        bail!("{}: no such pipeline script", script.display());
    }
    let python = python()?;
    let status = Command::new(&python)
        .arg(&script)
        .args(&args.args)
        .status()
        .with_context(|| format!("cannot run {}", python.display()))?;
    Ok(status.code().unwrap_or(2))
}
