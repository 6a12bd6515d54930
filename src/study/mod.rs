//! The study: every stage that exists, run on every design of a folder, and the reports.
//!
//! Today the stages are: 1 mass properties, 2 the driven crank–slider (peak pin force, closed
//! form; no time integration, the mechanism has zero DOF). One broken design never stops the others:
//! it is listed in the report with its error, and the command's exit status says so.

pub mod atomic_write;
pub mod baseline;
pub mod cache;
pub mod config;
pub mod dynamics_stage;
pub mod fem_stage;
pub mod plots;
pub mod ranking;
pub mod tables;

use crate::geometry::design::{DesignMass, find_stl_files, mass_of_design};
use crate::mechanism::{DrivenResult, Method};
use anyhow::{Context, Result, bail};
use atomic_write::write_atomic;
use cache::{Cache, design_key};
use config::StudyConfig;
use dynamics_stage::{DesignDynamics, dynamics_of_design, write_history_csv};
use fem_stage::{DesignFem, MeshMode, fem_of_design};
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The stages a study runs, in order, for the report's `stages_run`.
pub const STAGES: &[&str] = &["mass", "dynamics driven", "fem"];

/// Everything the study found, as written to `results.json`.
#[derive(Debug, Clone, Serialize)]
pub struct StudyResults {
    pub program_version: String,
    /// The settings used (defaults, `rodstudy.toml` or `--config`).
    pub config: StudyConfig,
    pub stages_run: Vec<String>,
    /// Stages left out on purpose (e.g. `fem` with `--skip-fem`).
    pub stages_skipped: Vec<String>,
    pub designs: Vec<DesignResult>,
    pub failed: Vec<FailedDesign>,
}

/// The figures of one design that went through every stage.
#[derive(Debug, Clone, Serialize)]
pub struct DesignResult {
    pub mass: DesignMass,
    pub dynamics: DesignDynamics,
    /// Stage 3, unless skipped.
    pub fem: Option<DesignFem>,
    /// The pin-force history (written to its own CSV, not to `results.json`).
    #[serde(skip)]
    pub history: DrivenResult,
}

/// A design that could not be studied, and why.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct FailedDesign {
    pub file: String,
    pub error: String,
}

/// How a study runs: where, with which settings, how many designs at once.
pub struct StudyOptions<'a> {
    pub designs: &'a Path,
    pub out: &'a Path,
    pub config: StudyConfig,
    /// Designs studied at once (rayon threads); 0 = one per core.
    pub jobs: usize,
    /// Reuse cached per-design results whose content hash matches.
    pub use_cache: bool,
    /// Leave out the FEM stage (a force-only study needs no mesh).
    pub skip_fem: bool,
}

/// What happened to one design, reported as soon as it is done (for progress output).
pub struct Progress<'a> {
    pub file: &'a Path,
    pub cached: bool,
    pub outcome: std::result::Result<&'a DesignResult, String>,
}

/// The figures of one design that the cache keeps (the history is recomputed: it is cheap).
#[derive(Serialize, serde::Deserialize)]
struct CachedDesign {
    mass: DesignMass,
    dynamics: DesignDynamics,
    fem: Option<DesignFem>,
}

/// Runs the stages on every `*.stl` of `options.designs`, designs in parallel, calling
/// `on_done` as each one finishes.
pub fn run_study(
    options: &StudyOptions,
    on_done: &(dyn Fn(Progress) + Sync),
) -> Result<StudyResults> {
    let designs = options.designs;
    if !designs.is_dir() {
        bail!("{}: the designs folder does not exist", designs.display());
    }
    let files = find_stl_files(&[designs.to_path_buf()])?;
    let cache = Cache::new(options.out);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.jobs)
        .build()
        .context("cannot start the worker threads")?;
    let outcomes: Vec<(PathBuf, Result<DesignResult>)> = pool.install(|| {
        files
            .into_par_iter()
            .map(|f| {
                let (r, cached) = study_one(&f, options, options.use_cache.then_some(&cache));
                on_done(Progress {
                    file: &f,
                    cached,
                    outcome: r.as_ref().map_err(|e| format!("{e:#}")),
                });
                (f, r)
            })
            .collect()
    });
    let mut results = StudyResults {
        program_version: env!("CARGO_PKG_VERSION").into(),
        config: options.config,
        stages_run: STAGES
            .iter()
            .filter(|s| !(options.skip_fem && **s == "fem"))
            .map(|s| s.to_string())
            .collect(),
        stages_skipped: STAGES
            .iter()
            .filter(|s| options.skip_fem && **s == "fem")
            .map(|s| s.to_string())
            .collect(),
        designs: Vec::new(),
        failed: Vec::new(),
    };
    for (file, outcome) in outcomes {
        match outcome {
            Ok(d) => results.designs.push(d),
            Err(e) => results.failed.push(FailedDesign {
                file: file.display().to_string(),
                error: format!("{e:#}"),
            }),
        }
    }
    Ok(results)
}

/// The stages for one design, from the cache when its content hash matches; the flag says
/// whether the cache answered.
fn study_one(
    stl: &Path,
    options: &StudyOptions,
    cache: Option<&Cache>,
) -> (Result<DesignResult>, bool) {
    let config = &options.config;
    let id = stl
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let key = cache.and_then(|_| design_key(stl, config).ok()).map(|k| {
        if options.skip_fem {
            format!("{k}-without-fem")
        } else {
            k
        }
    });
    let scene = config.driven_scene();
    if let (Some(cache), Some(key)) = (cache, &key)
        && let Some(hit) = cache.get::<CachedDesign>(&id, key)
    {
        let params = dynamics_stage::mechanism_for(&hit.mass, config.driven.gravity);
        let rod = dynamics_stage::rod_inertia(&hit.mass);
        if let Ok(history) =
            crate::mechanism::driven_scene(&params, &rod, &scene, Method::ClosedForm)
        {
            let result = DesignResult {
                mass: hit.mass,
                dynamics: hit.dynamics,
                fem: hit.fem,
                history,
            };
            return (Ok(result), true);
        }
    }
    let computed = (|| {
        let mass = mass_of_design(stl)?;
        let (dynamics, history) =
            dynamics_of_design(&mass, &scene, config.driven.gravity, Method::ClosedForm)?;
        let fem = if options.skip_fem {
            None
        } else {
            let work = options.out.join(".cache").join("mesh").join(&id);
            let vtu = options.out.join(file_safe(&id));
            Some(fem_of_design(
                stl,
                dynamics.peak_pin_force_n,
                config,
                &work,
                &vtu,
                &MeshMode::from_config(config),
            )?)
        };
        Ok(DesignResult {
            mass,
            dynamics,
            fem,
            history,
        })
    })();
    if let (Ok(d), Some(cache), Some(key)) = (&computed, cache, &key) {
        let entry = CachedDesign {
            mass: d.mass.clone(),
            dynamics: d.dynamics.clone(),
            fem: d.fem.clone(),
        };
        // A cache that cannot be written only costs time on the next run.
        let _ = cache.put(&id, key, &entry);
    }
    (computed, false)
}

/// The keys of the stage-3 record that hold wall times or memory: they vary from run to run.
const WALL_TIME_KEYS: [&str; 4] = ["seconds", "total_s", "timings", "peak_memory_mb"];

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

/// Writes `results.json`, `mass_properties.md` and `mass_properties.csv` into `out`
/// (each atomically) and returns their paths.
pub fn write_reports(results: &StudyResults, out: &Path) -> Result<Vec<PathBuf>> {
    // results.json holds only what the computation decides (it is committed and must not change
    // from run to run); the same record with the wall times goes to timings.json (not committed)
    let full = serde_json::to_value(results)?;
    write_atomic(
        &out.join("timings.json"),
        serde_json::to_string_pretty(&full)?.as_bytes(),
    )?;
    let mut stable = full;
    if let Some(designs) = stable.get_mut("designs").and_then(|d| d.as_array_mut()) {
        for d in designs {
            if let Some(fem) = d.get_mut("fem") {
                strip_wall_times(fem);
            }
        }
    }
    let json = out.join("results.json");
    write_atomic(&json, serde_json::to_string_pretty(&stable)?.as_bytes())?;
    let md = out.join("mass_properties.md");
    write_atomic(&md, markdown(results).as_bytes())?;
    let csv_path = out.join("mass_properties.csv");
    write_atomic(&csv_path, &csv_table(results)?)?;
    let ranking = out.join("ranking.md");
    write_atomic(&ranking, ranking::markdown(results).as_bytes())?;
    let ranking_csv = out.join("ranking.csv");
    write_atomic(&ranking_csv, &ranking::csv(results)?)?;
    let mut written = vec![json, md, csv_path, ranking, ranking_csv];
    if !results.designs.is_empty() {
        let pin = out.join("pin_force.svg");
        write_atomic(&pin, pin_force_plot(results)?.as_bytes())?;
        let bars = out.join("peak_force.svg");
        let peaks: Vec<(String, f64)> = results
            .designs
            .iter()
            .map(|d| (d.mass.id.clone(), d.dynamics.peak_pin_force_n))
            .collect();
        write_atomic(
            &bars,
            plots::bar_chart(
                "Peak crank–rod pin force (φ = 40πt, gravity on)",
                "peak |F_A| [N]",
                &peaks,
            )?
            .as_bytes(),
        )?;
        let index = out.join("index.html");
        write_atomic(&index, index_html(results).as_bytes())?;
        written.extend([pin, bars, index]);
    }
    for d in &results.designs {
        let mut w = csv::Writer::from_writer(Vec::new());
        write_history_csv(&mut w, &d.mass.design, &d.history)?;
        let path = out.join(file_safe(&d.mass.id)).join("pin_force.csv");
        write_atomic(&path, &w.into_inner()?)?;
        written.push(path);
    }
    Ok(written)
}

/// |F_A| over the first crank revolution, all designs in one plot.
fn pin_force_plot(results: &StudyResults) -> Result<String> {
    let series: Vec<plots::Series> = results
        .designs
        .iter()
        .map(|d| {
            let h = &d.history;
            let turn = std::f64::consts::TAU;
            let points = (0..h.t_s.len())
                .take_while(|&k| h.phi_rad[k] - h.phi_rad[0] <= turn + 1e-9)
                .map(|k| ((h.phi_rad[k] - h.phi_rad[0]).to_degrees(), h.fa_abs_n[k]))
                .collect();
            plots::Series {
                name: d.mass.design.clone(),
                points,
            }
        })
        .collect();
    plots::line_chart(
        "Crank–rod pin force over one revolution (φ = 40πt, gravity on)",
        "crank angle φ [°] (0 = top dead centre)",
        "|F_A| [N]",
        &series,
        plots::Scale::Linear,
        plots::Scale::Linear,
    )
}

/// A page that shows the ranking and the plots in a browser.
fn index_html(results: &StudyResults) -> String {
    let escape = |s: &str| {
        s.replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;")
    };
    let mut ranked: Vec<&DesignResult> = results.designs.iter().collect();
    ranked.sort_by(|a, b| {
        a.dynamics
            .peak_pin_force_n
            .total_cmp(&b.dynamics.peak_pin_force_n)
    });
    let mut rows = String::new();
    for (k, d) in ranked.iter().enumerate() {
        rows.push_str(&format!(
            "<tr><td>{}</td><td>{}</td><td>{:.4}</td><td>{:.2}</td><td>{:.5}</td><td>{:.6}</td><td>{:.1}</td><td><a href=\"{}/pin_force.csv\">CSV</a></td></tr>\n",
            k + 1,
            escape(&d.mass.design),
            d.mass.mass_kg,
            d.mass.l1_m * 1e3,
            d.mass.i_zz_kgm2,
            d.mass.i_xx_kgm2,
            d.dynamics.peak_pin_force_n,
            file_safe(&d.mass.id)
        ));
    }
    let failed: String = results
        .failed
        .iter()
        .map(|f| {
            format!(
                "<li><code>{}</code>: {}</li>\n",
                escape(&f.file),
                escape(&f.error)
            )
        })
        .collect();
    format!(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>rodstudy report</title>\n<style>body{{font-family:sans-serif;max-width:1000px;margin:2em auto}}table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:4px 8px;text-align:right}}td:nth-child(2){{text-align:left}}img{{max-width:100%}}</style></head><body>\n<h1>Connecting-rod design study</h1>\n<p>Stages run: {}. Skipped: {}. Ranked by peak crank–rod pin force, lowest first.</p>\n<table><tr><th>rank</th><th>design</th><th>mass [kg]</th><th>l1 [mm]</th><th>I_zz [kg·m²]</th><th>I_xx [kg·m²]</th><th>peak pin force [N]</th><th>history</th></tr>\n{rows}</table>\n{}<h2>Pin force over one revolution</h2><img src=\"pin_force.svg\" alt=\"pin force\">\n<h2>Peak pin force</h2><img src=\"peak_force.svg\" alt=\"peak force\">\n<p>All figures: <a href=\"results.json\">results.json</a>, <a href=\"mass_properties.csv\">mass_properties.csv</a>.</p>\n</body></html>\n",
        results.stages_run.join(", "),
        results.stages_skipped.join(", "),
        if failed.is_empty() {
            String::new()
        } else {
            format!("<h2>Failed designs</h2><ul>{failed}</ul>\n")
        }
    )
}

/// A design name usable as a folder name.
fn file_safe(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

fn markdown(results: &StudyResults) -> String {
    let designs: Vec<&DesignMass> = results.designs.iter().map(|d| &d.mass).collect();
    let mut out = format!(
        "# Mass properties of the designs\n\nStages run: {}. Skipped: {}.\nI_zz is about the pin axis through the centroid (the one the planar dynamics uses); I_xx is about the rod's long axis (what the thesis' Table 5.1 lists).\n\n",
        results.stages_run.join(", "),
        results.stages_skipped.join(", ")
    );
    out.push_str(&tables::mass_table(&designs));
    if !results.failed.is_empty() {
        out.push_str("\n## Failed designs\n\n");
        for f in &results.failed {
            out.push_str(&format!("- `{}`: {}\n", f.file, f.error));
        }
    }
    out
}

/// One row of `mass_properties.csv` (SI units; empty figures for a failed design).
#[derive(Serialize, Default)]
struct CsvRow {
    design: String,
    file: String,
    mass_kg: Option<f64>,
    volume_m3: Option<f64>,
    l1_m: Option<f64>,
    offset_m: Option<f64>,
    i_zz_kgm2: Option<f64>,
    i_xx_kgm2: Option<f64>,
    centroid_x_m: Option<f64>,
    centroid_y_m: Option<f64>,
    centroid_z_m: Option<f64>,
    peak_pin_force_n: Option<f64>,
    status: &'static str,
    error: String,
}

fn csv_table(results: &StudyResults) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for d in &results.designs {
        let m = &d.mass;
        w.serialize(CsvRow {
            design: m.design.clone(),
            file: m.file.clone(),
            mass_kg: Some(m.mass_kg),
            volume_m3: Some(m.volume_m3),
            l1_m: Some(m.l1_m),
            offset_m: Some(m.offset_m),
            i_zz_kgm2: Some(m.i_zz_kgm2),
            i_xx_kgm2: Some(m.i_xx_kgm2),
            centroid_x_m: Some(m.centroid_m[0]),
            centroid_y_m: Some(m.centroid_m[1]),
            centroid_z_m: Some(m.centroid_m[2]),
            peak_pin_force_n: Some(d.dynamics.peak_pin_force_n),
            status: "ok",
            error: String::new(),
        })?;
    }
    for f in &results.failed {
        w.serialize(CsvRow {
            file: f.file.clone(),
            status: "failed",
            error: f.error.clone(),
            ..CsvRow::default()
        })?;
    }
    Ok(w.into_inner()?)
}
