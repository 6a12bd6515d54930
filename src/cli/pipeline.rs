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
    let mut command = Command::new(&python);
    command.arg(&script).args(&args.args);
    if needs_policy(&args.script, &args.args) {
        command.arg(crate::mesher::MeshPolicy::standard().arg());
    }
    let status = command
        .status()
        .with_context(|| format!("cannot run {}", python.display()))?;
    Ok(status.code().unwrap_or(2))
}

/// Whether a call of the mesher script makes meshes (`mesh`, `mesh-step`, `serve`) without a
/// policy of its own: it then gets rodstudy's ([`crate::mesher::policy`]), as a study's meshes do.
fn needs_policy(script: &str, args: &[String]) -> bool {
    script == crate::mesher::MESHER_SCRIPT
        && args
            .first()
            .is_some_and(|c| ["mesh", "mesh-step", "serve"].contains(&c.as_str()))
        && !args.iter().any(|a| a.starts_with("--policy"))
}
