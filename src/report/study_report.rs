//! The study's report files: `results.json` (and the uncommitted `timings.json`), the mass
//! properties and ranking tables, per-design pin-force and cycle CSV files and plots, the
//! all-design plots, the Pareto front and `index.html`, each written atomically.

use super::atomic_write::write_atomic;
use super::{design_files, file_safe, index_page, mass_properties, pareto, plots, ranking};
use crate::study::results::StudyResults;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// The keys of the stage-3 record that hold wall times or memory: they vary from run to run.
const WALL_TIME_KEYS: [&str; 5] = [
    "seconds",
    "analysis_seconds",
    "total_s",
    "timings",
    "peak_memory_mb",
];

/// Removes the wall-time keys from a JSON value, at every depth.
fn strip_wall_times(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Object(map) => {
            for k in WALL_TIME_KEYS {
                map.remove(k);
            }
            for x in map.values_mut() {
                strip_wall_times(x);
            }
        }
        serde_json::Value::Array(a) => a.iter_mut().for_each(strip_wall_times),
        _ => {}
    }
}

/// Writes the study's reports into `out` (see the module documentation) and returns their
/// paths; removes the stage files a design's folder keeps from an earlier study.
pub fn write_reports(results: &StudyResults, out: &Path) -> Result<Vec<PathBuf>> {
    // every file is made in a staging folder first and moved into place only when all of them
    // are made, so that a failure part-way (a folder in the way, a full disk) leaves the last
    // complete set of reports, not a mix of two
    std::fs::create_dir_all(out).with_context(|| format!("{}: cannot create", out.display()))?;
    // a staging folder an interrupted run left behind
    for entry in std::fs::read_dir(out)?.flatten() {
        if entry.file_name().to_string_lossy().starts_with(".reports-") {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
    let staging = tempfile::Builder::new()
        .prefix(".reports-")
        .tempdir_in(out)
        .with_context(|| format!("{}: cannot write the reports there", out.display()))?;
    let made = write_report_files(results, staging.path())?;
    // every file made (timings.json too, which the list of reports leaves out) goes in: first
    // checked that nothing is in the way, then the designs' folders, the top-level files last
    let mut moves: Vec<(PathBuf, PathBuf)> = files_under(staging.path())?
        .into_iter()
        .map(|f| {
            let target = out.join(f.strip_prefix(staging.path())?);
            Ok((f, target))
        })
        .collect::<Result<_>>()?;
    for (_, target) in &moves {
        if target.is_dir() {
            anyhow::bail!("{}: a folder is in the way of a report", target.display());
        }
        let mut folder = target.parent();
        while let Some(f) = folder.filter(|f| *f != out) {
            if f.exists() && !f.is_dir() {
                anyhow::bail!("{}: a file is in the way of a design's folder", f.display());
            }
            folder = f.parent();
        }
    }
    remove_stale_stage_files(results, out)?;
    moves.sort_by_key(|(_, target)| std::cmp::Reverse(target.components().count()));
    for (file, target) in moves {
        if let Some(folder) = target.parent() {
            std::fs::create_dir_all(folder)
                .with_context(|| format!("{}: cannot create", folder.display()))?;
        }
        std::fs::rename(&file, &target)
            .with_context(|| format!("{}: cannot write", target.display()))?;
    }
    let mut written: Vec<PathBuf> = made
        .iter()
        .map(|f| f.strip_prefix(staging.path()).map(|r| out.join(r)))
        .collect::<std::result::Result<_, _>>()?;
    // last, on the files in place: the page links what exists
    let index = out.join("index.html");
    write_atomic(&index, index_page::index_html(results, out).as_bytes())?;
    written.push(index);
    Ok(written)
}

/// The files under `folder`, at any depth.
fn files_under(folder: &Path) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let mut todo = vec![folder.to_path_buf()];
    while let Some(dir) = todo.pop() {
        for entry in std::fs::read_dir(&dir)? {
            let path = entry?.path();
            if path.is_dir() {
                todo.push(path);
            } else {
                files.push(path);
            }
        }
    }
    Ok(files)
}

/// The report files of [`write_reports`] but the index page, written under `dest`.
fn write_report_files(results: &StudyResults, dest: &Path) -> Result<Vec<PathBuf>> {
    // results.json holds only what the computation decides (it is committed and must not change
    // from run to run); the same record with the wall times goes to timings.json (not committed)
    let full = serde_json::to_value(results)?;
    write_atomic(
        &dest.join("timings.json"),
        serde_json::to_string_pretty(&full)?.as_bytes(),
    )?;
    let mut stable = full;
    if let Some(designs) = stable.get_mut("designs").and_then(|d| d.as_array_mut()) {
        for d in designs {
            for stage in ["fem", "cycle"] {
                if let Some(v) = d.get_mut(stage) {
                    strip_wall_times(v);
                }
            }
        }
    }
    let json = dest.join("results.json");
    write_atomic(&json, serde_json::to_string_pretty(&stable)?.as_bytes())?;
    let md = dest.join("mass_properties.md");
    write_atomic(&md, mass_properties::markdown(results).as_bytes())?;
    let csv_path = dest.join("mass_properties.csv");
    write_atomic(&csv_path, &mass_properties::csv_table(results)?)?;
    let ranking = dest.join("ranking.md");
    write_atomic(&ranking, ranking::markdown(results).as_bytes())?;
    let ranking_csv = dest.join("ranking.csv");
    write_atomic(&ranking_csv, &ranking::csv(results)?)?;
    let mut written = vec![json, md, csv_path, ranking, ranking_csv];
    // a failure whose message was cut to one line keeps its whole log beside the reports
    for f in &results.failed {
        if let Some(log) = &f.log {
            let path = dest.join(file_safe(&f.id())).join("failure.log");
            write_atomic(&path, log.as_bytes())?;
            written.push(path);
        }
    }
    let histories = design_files::histories(results);
    let scene = design_files::scene_label(&results.config);
    for (id, design, h) in &histories {
        let dir = dest.join(file_safe(id));
        let path = dir.join("pin_force.csv");
        write_atomic(&path, &design_files::pin_force_csv(design, h)?)?;
        let plot = dir.join("pin_force.svg");
        write_atomic(
            &plot,
            design_files::design_pin_force_plot(design, h, &scene)?.as_bytes(),
        )?;
        written.extend([path, plot]);
    }
    for d in &results.designs {
        if let Some(c) = &d.cycle {
            let dir = dest.join(file_safe(&d.mass.id));
            let path = dir.join("cycle.csv");
            write_atomic(&path, &design_files::cycle_csv(c)?)?;
            let plot = dir.join("cycle.svg");
            write_atomic(
                &plot,
                design_files::cycle_plot(&d.mass.design, c)?.as_bytes(),
            )?;
            written.extend([path, plot]);
        }
    }
    if !histories.is_empty() {
        let pin = dest.join("pin_force.svg");
        write_atomic(
            &pin,
            design_files::pin_force_plot(&histories, &scene)?.as_bytes(),
        )?;
        let bars = dest.join("peak_force.svg");
        let peaks: Vec<(String, f64)> = ranking::ranking(results)
            .iter()
            .filter_map(|r| Some((r.mass.id.clone(), r.peak_force_n()?)))
            .collect();
        write_atomic(
            &bars,
            plots::bar_chart(
                &format!("Peak crank–rod pin force ({scene})"),
                "peak |F_A| [N]",
                &peaks,
            )?
            .as_bytes(),
        )?;
        written.extend([pin, bars]);
    }
    if !results.designs.is_empty() {
        let md = dest.join("pareto.md");
        write_atomic(&md, pareto::markdown(results).as_bytes())?;
        let csv_path = dest.join("pareto.csv");
        write_atomic(&csv_path, &pareto::csv(results)?)?;
        let svg = dest.join("pareto.svg");
        let points: Vec<plots::LabelledPoint> = pareto::pareto(results)
            .into_iter()
            .map(|r| plots::LabelledPoint {
                label: format!(
                    " {}{}",
                    r.id,
                    r.safety_factor
                        .map_or(String::new(), |s| format!(" (SF {s:.2})"))
                ),
                x: r.mass_kg,
                y: r.peak_pin_force_n,
                highlight: r.on_front,
            })
            .collect();
        write_atomic(
            &svg,
            plots::scatter_chart(
                "Pareto front: mass, peak pin force, safety factor",
                "mass [kg]",
                "peak crank–rod pin force [N]",
                &points,
                "on the Pareto front",
            )?
            .as_bytes(),
        )?;
        written.extend([md, csv_path, svg]);
    }
    Ok(written)
}

/// The files stage 3 and the cycle write into a design's folder (`fields`, and the cycle's table
/// and plot above).
const STAGE_FILES: [&str; 11] = [
    "fem_fx.vtu",
    "fem_fy.vtu",
    "von_mises_fx.svg",
    "von_mises_fy.svg",
    "buckling_mode.vtu",
    "cycle.vtu",
    "von_mises_cycle.svg",
    "cycle.csv",
    "cycle.svg",
    "local_fatigue.svg",
    "haigh.svg",
];

/// Removes what an earlier study left in a design's folder that now disagrees with
/// `results.json`: a failed design's stage files (its stages did not finish) and a studied
/// design's old `failure.log`. A stage this study skipped (`--skip-fem`, the cycle switched off)
/// keeps its files, which the cache of a study that runs it needs; the index page does not link
/// them.
fn remove_stale_stage_files(results: &StudyResults, out: &Path) -> Result<()> {
    let studied = results
        .designs
        .iter()
        .map(|d| (d.mass.id.clone(), &["failure.log"][..]));
    let failed = results.failed.iter().map(|f| (f.id(), &STAGE_FILES[..]));
    for (id, stale) in studied.chain(failed) {
        let dir = out.join(file_safe(&id));
        for name in stale {
            match std::fs::remove_file(dir.join(name)) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(anyhow::Error::new(e).context(format!(
                        "{}: cannot remove a stale file",
                        dir.join(name).display()
                    )));
                }
                _ => {}
            }
        }
    }
    Ok(())
}
