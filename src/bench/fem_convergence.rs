//! `rodstudy fem DESIGN --convergence [--sizes 8,5,3.5,2.5] [--target-error R] [--force N]`:
//! speed against error for stage 3: uniform meshes at each size and the adaptive
//! sequence, per load case DOFs, peak, estimated error, error against the reference, wall time and
//! peak memory. Each analysis runs in its own process (`rodstudy fem … --json`), so its peak
//! memory (VmHWM) is its own and the wall times are comparable.
//!
//! The reference of each case is the adaptive sequence's last peak extrapolated (Richardson, as
//! `rod::adapt` estimates it): the best value the program has; its own estimated error is in the
//! table. Writes `convergence.md`, `convergence.csv`, `convergence.json` and `convergence.svg`
//! (error against wall time, log–log) into the output folder.

use crate::report::atomic_write::write_atomic;
use crate::report::plots::{Scale, Series, line_chart};
use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// One row: an analysis (uniform size) or an adaptive iteration, one load case.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ConvergenceRow {
    /// `uniform` or `adaptive`.
    pub method: String,
    /// Uniform size [mm], or the adaptive iteration number.
    pub level: String,
    /// `fx` or `fy`.
    pub case: String,
    pub elements: usize,
    pub dofs: usize,
    /// The judged peak (max von Mises away from the fixed bore and sharp edges) [MPa].
    pub peak_mpa: f64,
    /// Its estimated relative error (recovery on a uniform mesh, the adaptive estimate otherwise).
    pub estimated_error_rel: f64,
    /// |peak − reference| / reference.
    pub error_vs_reference_rel: f64,
    /// Wall time to this result [s]: the whole run for a uniform mesh, cumulative for adaptive.
    pub wall_s: f64,
    /// Peak resident memory of the run [MB].
    pub peak_memory_mb: Option<f64>,
}

/// The whole comparison.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Convergence {
    pub design: String,
    pub force_n: f64,
    pub target_error_rel: f64,
    /// Reference peak per case [MPa]: fx, fy.
    pub reference_mpa: [f64; 2],
    /// Estimated relative error of the reference, fx, fy.
    pub reference_error_rel: [f64; 2],
    pub rows: Vec<ConvergenceRow>,
    /// Sizes skipped and why (e.g. a run that failed or ran out of memory).
    pub skipped: Vec<String>,
}

fn run_child(exe: &Path, args: &[String]) -> Result<(serde_json::Value, f64)> {
    let start = Instant::now();
    let out = std::process::Command::new(exe)
        .args(args)
        .stderr(std::process::Stdio::inherit())
        .output()
        .with_context(|| format!("cannot run {}", exe.display()))?;
    let wall = start.elapsed().as_secs_f64();
    if !out.status.success() {
        bail!("`rodstudy {}` exited with {}", args.join(" "), out.status);
    }
    let v: serde_json::Value =
        serde_json::from_slice(&out.stdout).context("cannot parse the child's JSON")?;
    Ok((v, wall))
}

/// Runs the comparison for `design` and writes the files into `out`.
pub fn convergence(
    design: &Path,
    sizes: &[f64],
    target: f64,
    force_n: f64,
    config: Option<&Path>,
    out: &Path,
) -> Result<Convergence> {
    let exe = std::env::current_exe()?;
    std::fs::create_dir_all(out).with_context(|| format!("{}: cannot create", out.display()))?;
    // the runs' meshes and VTU files (large) go to a temporary folder; the tables to `out`
    let scratch = tempfile::tempdir()?;
    let common = |extra: Vec<String>, dir: PathBuf| {
        let mut a = vec![
            "fem".to_string(),
            design.display().to_string(),
            "--force".into(),
            format!("{force_n}"),
            "--json".into(),
            "--out".into(),
            dir.display().to_string(),
        ];
        if let Some(c) = config {
            a.extend(["--config".into(), c.display().to_string()]);
        }
        a.extend(extra);
        a
    };
    eprintln!("convergence: adaptive to {target}");
    let (adaptive, adaptive_wall) = run_child(
        &exe,
        &common(
            vec!["--target-error".into(), format!("{target}")],
            scratch.path().join("adaptive"),
        ),
    )?;
    let mut reference = [0.0; 2];
    let mut reference_error = [0.0; 2];
    for (c, name) in ["fx", "fy"].iter().enumerate() {
        let steps = adaptive[name]["adaptive"]
            .as_array()
            .context("adaptive steps missing")?;
        let last = steps.last().context("no adaptive step")?;
        reference[c] = last["extrapolated_mpa"].as_f64().unwrap_or(0.0);
        reference_error[c] = last["estimated_error_rel"].as_f64().unwrap_or(0.0);
    }
    let mut rows = Vec::new();
    let mut skipped = Vec::new();
    for &size in sizes {
        eprintln!("convergence: uniform {size} mm");
        match run_child(
            &exe,
            &common(
                vec!["--size".into(), format!("{size}")],
                scratch.path().join(format!("uniform-{size}")),
            ),
        ) {
            Ok((v, wall)) => {
                for (c, name) in ["fx", "fy"].iter().enumerate() {
                    let peak = v[name]["max_von_mises_away_from_fixed_mpa"]
                        .as_f64()
                        .unwrap_or(f64::NAN);
                    rows.push(ConvergenceRow {
                        method: "uniform".into(),
                        level: format!("{size} mm"),
                        case: name.to_string(),
                        elements: v["elements"].as_u64().unwrap_or(0) as usize,
                        dofs: v["dofs"].as_u64().unwrap_or(0) as usize,
                        peak_mpa: peak,
                        estimated_error_rel: v[name]["estimated_error_rel"]
                            .as_f64()
                            .unwrap_or(f64::NAN),
                        error_vs_reference_rel: (peak - reference[c]).abs() / reference[c],
                        wall_s: wall,
                        peak_memory_mb: v["peak_memory_mb"].as_f64(),
                    });
                }
            }
            Err(e) => skipped.push(format!("{size} mm: {e:#}")),
        }
    }
    let total_steps: f64 = adaptive["fx"]["adaptive"]
        .as_array()
        .map(|s| s.iter().filter_map(|x| x["seconds"].as_f64()).sum())
        .unwrap_or(0.0);
    // cumulative wall per iteration, scaled so that the last one is the child's wall time
    // (start-up, the first classification and the final VTU files are outside the steps)
    let scale = if total_steps > 0.0 {
        adaptive_wall / total_steps
    } else {
        1.0
    };
    for (c, name) in ["fx", "fy"].iter().enumerate() {
        let mut cumulative = 0.0;
        for s in adaptive[name]["adaptive"].as_array().into_iter().flatten() {
            cumulative += s["seconds"].as_f64().unwrap_or(0.0) * scale;
            let peak = s["peak_mpa"].as_f64().unwrap_or(f64::NAN);
            rows.push(ConvergenceRow {
                method: "adaptive".into(),
                level: format!("iteration {}", s["iteration"]),
                case: name.to_string(),
                elements: s["elements"].as_u64().unwrap_or(0) as usize,
                dofs: s["dofs"].as_u64().unwrap_or(0) as usize,
                peak_mpa: peak,
                estimated_error_rel: s["estimated_error_rel"].as_f64().unwrap_or(f64::NAN),
                error_vs_reference_rel: (peak - reference[c]).abs() / reference[c],
                wall_s: cumulative,
                peak_memory_mb: adaptive["peak_memory_mb"].as_f64(),
            });
        }
    }
    let result = Convergence {
        design: design.display().to_string(),
        force_n,
        target_error_rel: target,
        reference_mpa: reference,
        reference_error_rel: reference_error,
        rows,
        skipped,
    };
    write_files(&result, out)?;
    Ok(result)
}

/// Re-writes the table and the plot in `out` from the `convergence.json` a run left there (no
/// analysis is repeated).
pub fn replot(out: &Path) -> Result<Convergence> {
    let path = out.join("convergence.json");
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let result: Convergence = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a convergence record", path.display()))?;
    write_files(&result, out)?;
    Ok(result)
}

/// Writes convergence.json, .md, .csv and .svg of `result` into `out`.
fn write_files(result: &Convergence, out: &Path) -> Result<()> {
    let design = Path::new(&result.design);
    write_atomic(
        &out.join("convergence.json"),
        serde_json::to_string_pretty(result)?.as_bytes(),
    )?;
    write_atomic(&out.join("convergence.md"), markdown(result).as_bytes())?;
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in &result.rows {
        w.serialize(r)?;
    }
    write_atomic(&out.join("convergence.csv"), &w.into_inner()?)?;
    let mut series = Vec::new();
    for method in ["uniform", "adaptive"] {
        for case in ["fx", "fy"] {
            series.push(Series {
                name: format!("{method} {case}"),
                points: result
                    .rows
                    .iter()
                    .filter(|r| r.method == method && r.case == case)
                    .map(|r| (r.wall_s, r.error_vs_reference_rel.max(1e-5)))
                    .collect(),
            });
        }
    }
    let svg = line_chart(
        &format!(
            "{}: peak stress error against wall time",
            design
                .file_stem()
                .map(|s| s.to_string_lossy())
                .unwrap_or_default()
        ),
        "wall time [s]",
        "|peak − reference| / reference",
        &series,
        Scale::Log,
        Scale::Log,
    )?;
    write_atomic(&out.join("convergence.svg"), svg.as_bytes())?;
    Ok(())
}

/// The table as Markdown.
pub fn markdown(c: &Convergence) -> String {
    let mut s = format!(
        "# Stage 3 speed against error: {}\n\nLoad {:.1} N per case. Reference per case: the adaptive sequence's last peak extrapolated (Richardson): F_x {:.2} MPa (± {:.1} %), F_y {:.2} MPa (± {:.1} %). Adaptive target {:.1} %. Each uniform run and the adaptive run in its own process; wall times on this machine (2 cores), memory = the run's peak resident set.\n\n| method | level | case | elements | DOFs | peak [MPa] | estimated error | error vs reference | wall [s] | peak memory [MB] |\n|---|---|---|---|---|---|---|---|---|---|\n",
        c.design,
        c.force_n,
        c.reference_mpa[0],
        100.0 * c.reference_error_rel[0],
        c.reference_mpa[1],
        100.0 * c.reference_error_rel[1],
        100.0 * c.target_error_rel
    );
    for r in &c.rows {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {:.2} | {:.2} % | {:.2} % | {:.1} | {} |\n",
            r.method,
            r.level,
            r.case,
            r.elements,
            r.dofs,
            r.peak_mpa,
            100.0 * r.estimated_error_rel,
            100.0 * r.error_vs_reference_rel,
            r.wall_s,
            r.peak_memory_mb.map_or("—".into(), |m| format!("{m:.0}"))
        ));
    }
    for k in &c.skipped {
        s.push_str(&format!("\nskipped: {k}\n"));
    }
    s
}
