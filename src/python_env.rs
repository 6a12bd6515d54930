//! The Python interpreter the `pipeline/` scripts run in (gmsh, meshio, numpy).
//!
//! By default a project-local virtual environment `.venv/` at the project root, created on first
//! use with `python3 -m venv` and filled with `pip install -r pipeline/requirements.txt`, with
//! pip's progress shown. A marker file records the requirements it was built from, so a change
//! of pins reinstalls and everything else reuses it. `RODSTUDY_PYTHON` names an existing
//! interpreter instead (checked to import the three packages). A file lock serialises concurrent
//! first uses (parallel tests, several studies).
//!
//! A pipeline script reading a malformed file can run for ever (OpenCASCADE on a STEP with an
//! absurd coordinate, meshio's Nastran reader on a truncated .bdf): [`output_within`] runs a
//! child under the time limit [`pipeline_timeout`], the one limit of the mesher and the STEP reader.

use anyhow::{Context, Result, bail};
use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Environment variable naming an existing Python interpreter to use instead of `.venv`.
pub const PYTHON_VAR: &str = "RODSTUDY_PYTHON";
/// Environment variable overriding the project root (where `pipeline/` and `.venv/` live).
pub const ROOT_VAR: &str = "RODSTUDY_ROOT";
/// Environment variable: the time limit of a pipeline script (meshing, reading a STEP) in
/// seconds (default 600).
pub const TIMEOUT_VAR: &str = "RODSTUDY_MESHER_TIMEOUT_S";
/// The modules every pipeline script needs.
const REQUIRED_MODULES: &str = "import gmsh, meshio, numpy";

/// The project root: `RODSTUDY_ROOT`, else the folder this crate was built from if it still has
/// `pipeline/`, else the current directory.
pub fn project_root() -> PathBuf {
    if let Some(root) = std::env::var_os(ROOT_VAR) {
        return PathBuf::from(root);
    }
    let built = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    if built.join("pipeline").is_dir() {
        return built;
    }
    std::env::current_dir().unwrap_or_else(|_| PathBuf::from("."))
}

/// Path of a script in the project's `pipeline/` folder.
pub fn pipeline_script(name: &str) -> PathBuf {
    project_root().join("pipeline").join(name)
}

/// A Python interpreter that can import gmsh, meshio and numpy, setting one up if needed.
pub fn python() -> Result<PathBuf> {
    if let Some(python) = std::env::var_os(PYTHON_VAR) {
        let python = PathBuf::from(python);
        return check_imports(&python).with_context(|| {
            format!(
                "{PYTHON_VAR}={} cannot be used: install pipeline/requirements.txt into it, or unset {PYTHON_VAR} to let rodstudy create .venv",
                python.display()
            )
        }).map(|()| python);
    }
    ensure_venv(&project_root())
}

fn venv_python(venv: &Path) -> PathBuf {
    if cfg!(windows) {
        venv.join("Scripts").join("python.exe")
    } else {
        venv.join("bin").join("python")
    }
}

/// Creates or refreshes `ROOT/.venv` from `ROOT/pipeline/requirements.txt`.
pub fn ensure_venv(root: &Path) -> Result<PathBuf> {
    let requirements = root.join("pipeline").join("requirements.txt");
    let pins = std::fs::read_to_string(&requirements).with_context(|| {
        format!(
            "{}: cannot read the Python requirements",
            requirements.display()
        )
    })?;
    let venv = root.join(".venv");
    let python = venv_python(&venv);
    let marker = venv.join("rodstudy-requirements.txt");
    let up_to_date =
        || python.exists() && std::fs::read_to_string(&marker).is_ok_and(|m| m == pins);
    if up_to_date() {
        return Ok(python);
    }
    let lock_path = root.join(".venv.lock");
    let lock = File::create(&lock_path)
        .with_context(|| format!("{}: cannot create the lock file", lock_path.display()))?;
    lock.lock().context("cannot lock .venv.lock")?;
    if up_to_date() {
        return Ok(python);
    }
    eprintln!(
        "rodstudy: setting up the Python environment for the pipeline in {} (first use: gmsh, meshio, numpy as pinned in {}); this takes a minute and is reused afterwards",
        venv.display(),
        requirements.display()
    );
    if !python.exists() {
        let system = system_python()?;
        eprintln!(
            "rodstudy: [1/3] creating the virtual environment with {}",
            system.display()
        );
        run(
            Command::new(&system).args(["-m", "venv"]).arg(&venv),
            "python3 -m venv",
        )?;
    }
    eprintln!("rodstudy: [2/3] installing the pinned packages with pip (progress below)");
    run(
        Command::new(&python)
            .args(["-m", "pip", "install", "--disable-pip-version-check", "-r"])
            .arg(&requirements)
            .stdout(stderr_as_stdout()),
        "pip install -r pipeline/requirements.txt",
    )?;
    eprintln!("rodstudy: [3/3] checking that gmsh, meshio and numpy import");
    check_imports(&python)?;
    std::fs::write(&marker, &pins)
        .with_context(|| format!("{}: cannot write", marker.display()))?;
    eprintln!("rodstudy: Python environment ready ({})", python.display());
    Ok(python)
}

/// `python3` (or `python` when it is Python 3) from the PATH, or a clear error.
fn system_python() -> Result<PathBuf> {
    for candidate in ["python3", "python"] {
        let ok = Command::new(candidate)
            .args(["-c", "import sys, venv; assert sys.version_info >= (3, 9)"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        if ok {
            return Ok(PathBuf::from(candidate));
        }
    }
    bail!(
        "python3 (3.9 or newer, with the venv module) was not found on the PATH: install Python 3, or set {PYTHON_VAR} to an interpreter that has the packages of pipeline/requirements.txt"
    )
}

fn check_imports(python: &Path) -> Result<()> {
    let output = Command::new(python)
        .args(["-c", REQUIRED_MODULES])
        .output()
        .with_context(|| format!("cannot run {}", python.display()))?;
    if !output.status.success() {
        bail!(
            "{} cannot import gmsh, meshio and numpy: {}",
            python.display(),
            String::from_utf8_lossy(&output.stderr).trim()
        );
    }
    Ok(())
}

fn run(command: &mut Command, what: &str) -> Result<()> {
    let status = command
        .status()
        .with_context(|| format!("cannot start {what}"))?;
    if !status.success() {
        bail!("{what} failed ({status}); see the messages above");
    }
    Ok(())
}

/// Our standard error, as a child's standard output: pip's progress must never mix with JSON
/// that a command prints on standard output.
fn stderr_as_stdout() -> Stdio {
    use std::os::fd::AsFd;
    std::io::stderr()
        .as_fd()
        .try_clone_to_owned()
        .map(Stdio::from)
        .unwrap_or_else(|_| Stdio::null())
}

/// The time limit of a pipeline script: `RODSTUDY_MESHER_TIMEOUT_S` seconds, else 600.
pub fn pipeline_timeout() -> Duration {
    let secs = std::env::var(TIMEOUT_VAR)
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|v| v.is_finite() && *v > 0.0)
        .unwrap_or(600.0);
    Duration::from_secs_f64(secs)
}

/// Runs `command` to completion like `Command::output`, but kills it after `limit` (an error of
/// kind `TimedOut` that says the limit and [`TIMEOUT_VAR`]). The output goes through temporary
/// files, so a chatty child never blocks on a full pipe.
pub fn output_within(
    command: &mut Command,
    limit: Duration,
) -> std::io::Result<std::process::Output> {
    let stdout = tempfile::tempfile()?;
    let stderr = tempfile::tempfile()?;
    let mut child = command
        .stdout(stdout.try_clone()?)
        .stderr(stderr.try_clone()?)
        .spawn()?;
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return Err(std::io::Error::new(
                std::io::ErrorKind::TimedOut,
                format!(
                    "stopped after {:.0} s (the limit; set {TIMEOUT_VAR} to change it)",
                    limit.as_secs_f64()
                ),
            ));
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let read = |mut f: File| -> std::io::Result<Vec<u8>> {
        use std::io::{Read, Seek};
        let mut bytes = Vec::new();
        f.seek(std::io::SeekFrom::Start(0))?;
        f.read_to_end(&mut bytes)?;
        Ok(bytes)
    };
    Ok(std::process::Output {
        status,
        stdout: read(stdout)?,
        stderr: read(stderr)?,
    })
}

#[cfg(test)]
mod timeout_tests {
    use super::*;

    #[test]
    fn a_hanging_child_is_stopped_with_a_clear_error() {
        // the TimedOut error is returned only after the child was killed and reaped (no wall
        // time is asserted: that belongs to benchmarks)
        let err =
            output_within(Command::new("sleep").arg("5"), Duration::from_millis(200)).unwrap_err();
        assert_eq!(err.kind(), std::io::ErrorKind::TimedOut);
        assert!(err.to_string().contains(TIMEOUT_VAR));
        let ok = output_within(Command::new("echo").arg("hi"), Duration::from_secs(5)).unwrap();
        assert_eq!(ok.stdout, b"hi\n");
    }
}
