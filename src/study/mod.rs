//! The study: every stage that exists, run on every design of a folder, and the reports.
//!
//! Today the stages are: 1 mass properties, 2 the driven crank–slider (peak pin force, closed
//! form; no time integration, the mechanism has zero DOF). One broken design never stops the others:
//! it is listed in the report with its error, and the command's exit status says so.

pub mod atomic_write;
pub mod baseline;
pub mod cache;
pub mod config;
pub mod cycle_stage;
pub mod dynamics_stage;
pub mod fem_stage;
pub mod index_page;
pub mod merge;
pub mod pareto;
pub mod plots;
pub mod ranking;
pub mod shard;
pub mod tables;

use crate::geometry::design::{DesignMass, find_stl_files, mass_of_design};
use crate::mechanism::{DrivenResult, Method};
use anyhow::{Context, Result, bail};
use atomic_write::write_atomic;
use cache::{Cache, design_key};
use config::StudyConfig;
use cycle_stage::{DesignCycle, cycle_of_design};
use dynamics_stage::{DesignDynamics, dynamics_of_design, write_history_csv};
use fem_stage::{DesignFem, MeshMode, fem_of_design_with_mesh};
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The stages a study runs, in order, for the report's `stages_run`.
pub const STAGES: &[&str] = &["mass", "dynamics driven", "fem", "cycle"];

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
    /// For a shard of a split study (`study --shard K/N`): which, and the designs of the folder;
    /// absent from a whole or merged study.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shard: Option<shard::ShardRecord>,
}

/// The figures of one design that went through every stage.
#[derive(Debug, Clone, Serialize)]
pub struct DesignResult {
    pub mass: DesignMass,
    pub dynamics: DesignDynamics,
    /// Stage 3, unless skipped.
    pub fem: Option<DesignFem>,
    /// The cycle stage (stress over one revolution, fatigue), unless skipped.
    #[serde(default)]
    pub cycle: Option<DesignCycle>,
    /// The pin-force history (written to its own CSV, not to `results.json`).
    #[serde(skip)]
    pub history: DrivenResult,
}

/// A design that could not be studied through every stage: the stage that failed, why, and
/// what the stages before it computed (kept in every report; such a design is not judged on the
/// criterion of the stage it did not pass).
#[derive(Debug, Clone, Default, Serialize, serde::Deserialize)]
pub struct FailedDesign {
    pub file: String,
    pub error: String,
    /// The stage that failed: one of [`STAGES`] (empty in files written before 0.3).
    #[serde(default)]
    pub stage: String,
    /// Stage 1's figures, when it passed.
    #[serde(default)]
    pub mass: Option<DesignMass>,
    /// Stage 2's figures, when it passed.
    #[serde(default)]
    pub dynamics: Option<DesignDynamics>,
    /// Stage 2's pin-force history (written to its own CSV, not to `results.json`).
    #[serde(skip)]
    pub history: Option<DrivenResult>,
}

impl FailedDesign {
    /// The design's id: its file stem (as [`DesignMass::id`]).
    pub fn id(&self) -> String {
        self.mass.as_ref().map_or_else(
            || {
                Path::new(&self.file)
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_else(|| self.file.clone())
            },
            |m| m.id.clone(),
        )
    }
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
    /// Compute only this share of the designs.
    pub shard: Option<shard::Shard>,
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
    cycle: Option<DesignCycle>,
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
    let all_files = find_stl_files(&[designs.to_path_buf()])?;
    let (files, shard_record) = match options.shard {
        None => (all_files, None),
        Some(sh) => {
            let mine = shard::share(&all_files, sh);
            let mut all: Vec<String> = all_files.iter().map(|f| shard::id_of(f)).collect();
            all.sort();
            let mut designs: Vec<String> = mine.iter().map(|f| shard::id_of(f)).collect();
            designs.sort();
            let record = shard::ShardRecord {
                shard: sh,
                all_designs: all,
                designs,
            };
            (mine, Some(record))
        }
    };
    let cache = Cache::new(options.out);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.jobs)
        .build()
        .context("cannot start the worker threads")?;
    let outcomes: Vec<std::result::Result<DesignResult, Box<FailedDesign>>> = pool.install(|| {
        files
            .into_par_iter()
            .map(|f| {
                let (r, cached) = study_one(&f, options, options.use_cache.then_some(&cache));
                on_done(Progress {
                    file: &f,
                    cached,
                    outcome: r.as_ref().map_err(|e| e.error.clone()),
                });
                r
            })
            .collect()
    });
    // the cycle runs on stage 3's mesh: skipped with it, or on its own by the configuration
    let skipped = |s: &str| {
        (options.skip_fem && (s == "fem" || s == "cycle"))
            || (s == "cycle" && !options.config.cycle.enabled)
    };
    let mut results = StudyResults {
        program_version: env!("CARGO_PKG_VERSION").into(),
        config: options.config,
        stages_run: STAGES
            .iter()
            .filter(|s| !skipped(s))
            .map(|s| s.to_string())
            .collect(),
        stages_skipped: STAGES
            .iter()
            .filter(|s| skipped(s))
            .map(|s| s.to_string())
            .collect(),
        designs: Vec::new(),
        failed: Vec::new(),
        shard: shard_record,
    };
    for outcome in outcomes {
        match outcome {
            Ok(d) => results.designs.push(d),
            Err(f) => results.failed.push(*f),
        }
    }
    Ok(results)
}

/// The stages for one design, from the cache when its content hash matches; the flag says
/// whether the cache answered. A failure keeps what the stages before it computed.
fn study_one(
    stl: &Path,
    options: &StudyOptions,
    cache: Option<&Cache>,
) -> (std::result::Result<DesignResult, Box<FailedDesign>>, bool) {
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
    // the per-design files stage 3 writes beside its figures: a cached entry without them is
    // recomputed
    let present = |files: &[&str]| {
        files
            .iter()
            .all(|f| options.out.join(file_safe(&id)).join(f).is_file())
    };
    let files_present = |hit: &CachedDesign| {
        (hit.fem.is_none()
            || present(&[
                "von_mises_fx.svg",
                "von_mises_fy.svg",
                "fem_fx.vtu",
                "fem_fy.vtu",
            ]))
            && (hit.cycle.is_none() || present(&["von_mises_cycle.svg", "cycle.vtu"]))
    };
    if let (Some(cache), Some(key)) = (cache, &key)
        && let Some(hit) = cache.get::<CachedDesign>(&id, key)
        && files_present(&hit)
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
                cycle: hit.cycle,
                history,
            };
            return (Ok(result), true);
        }
    }
    let mut failed = FailedDesign {
        file: stl.display().to_string(),
        ..FailedDesign::default()
    };
    let computed = (|| {
        failed.stage = STAGES[0].into();
        let mass = mass_of_design(stl)?;
        failed.mass = Some(mass.clone());
        failed.stage = STAGES[1].into();
        let (dynamics, history) =
            dynamics_of_design(&mass, &scene, config.driven.gravity, Method::ClosedForm)?;
        failed.dynamics = Some(dynamics.clone());
        failed.history = Some(history.clone());
        failed.stage = STAGES[2].into();
        let (mut fem, mut cycle) = (None, None);
        if !options.skip_fem {
            let work = options.out.join(".cache").join("mesh").join(&id);
            let dir = options.out.join(file_safe(&id));
            let (f, mesh) = fem_of_design_with_mesh(
                stl,
                dynamics.peak_pin_force_n,
                config,
                &work,
                &dir,
                &MeshMode::from_config(config),
            )?;
            let mut f = f;
            if config.cycle.enabled {
                failed.stage = STAGES[3].into();
                let (c, _, _) = cycle_of_design(&mass, &mesh, config, Some(&dir))?;
                fem_stage::judge_fatigue(&mut f.criterion, &c, config);
                cycle = Some(c);
            }
            fem = Some(f);
        }
        anyhow::Ok(DesignResult {
            mass,
            dynamics,
            fem,
            cycle,
            history,
        })
    })();
    if let (Ok(d), Some(cache), Some(key)) = (&computed, cache, &key) {
        let entry = CachedDesign {
            mass: d.mass.clone(),
            dynamics: d.dynamics.clone(),
            fem: d.fem.clone(),
            cycle: d.cycle.clone(),
        };
        // A cache that cannot be written only costs time on the next run.
        let _ = cache.put(&id, key, &entry);
    }
    let outcome = computed.map_err(|e| {
        Box::new(FailedDesign {
            error: format!("{e:#}"),
            ..failed
        })
    });
    (outcome, false)
}

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
            for stage in ["fem", "cycle"] {
                if let Some(v) = d.get_mut(stage) {
                    strip_wall_times(v);
                }
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
    let histories = histories(results);
    for (id, design, h) in &histories {
        let dir = out.join(file_safe(id));
        let mut w = csv::Writer::from_writer(Vec::new());
        write_history_csv(&mut w, design, h)?;
        let path = dir.join("pin_force.csv");
        write_atomic(&path, &w.into_inner()?)?;
        let plot = dir.join("pin_force.svg");
        write_atomic(&plot, design_pin_force_plot(design, h)?.as_bytes())?;
        written.extend([path, plot]);
    }
    for d in &results.designs {
        if let Some(c) = &d.cycle {
            let dir = out.join(file_safe(&d.mass.id));
            let mut w = csv::Writer::from_writer(Vec::new());
            w.write_record([
                "crank_angle_deg",
                "time_s",
                "max_von_mises_away_from_fixed_mpa",
                "reaction_b_x_n",
                "reaction_b_y_n",
                "reaction_b_z_n",
                "dynamics_f_b_x_n",
                "dynamics_f_b_y_n",
            ])?;
            for h in &c.history {
                w.write_record(
                    [
                        h.crank_angle_deg,
                        h.time_s,
                        h.max_von_mises_away_from_fixed_mpa,
                        h.reaction_b_n[0],
                        h.reaction_b_n[1],
                        h.reaction_b_n[2],
                        h.dynamics_f_b_n[0],
                        h.dynamics_f_b_n[1],
                    ]
                    .map(|v| format!("{v:e}")),
                )?;
            }
            let path = dir.join("cycle.csv");
            write_atomic(&path, &w.into_inner()?)?;
            let plot = dir.join("cycle.svg");
            let series = vec![plots::Series {
                name: "max von Mises".into(),
                points: c
                    .history
                    .iter()
                    .map(|h| (h.crank_angle_deg, h.max_von_mises_away_from_fixed_mpa))
                    .collect(),
            }];
            write_atomic(
                &plot,
                plots::line_chart(
                    &format!(
                        "{}: max von Mises over one revolution (inertia relief)",
                        d.mass.design
                    ),
                    "crank angle φ [°] (0 = top dead centre)",
                    "max von Mises away from the fixed bore [MPa]",
                    &series,
                    plots::Scale::Linear,
                    plots::Scale::Linear,
                )?
                .as_bytes(),
            )?;
            written.extend([path, plot]);
        }
    }
    if !histories.is_empty() {
        let pin = out.join("pin_force.svg");
        write_atomic(&pin, pin_force_plot(&histories)?.as_bytes())?;
        let bars = out.join("peak_force.svg");
        let peaks: Vec<(String, f64)> = ranking::ranking(results)
            .iter()
            .filter_map(|r| Some((r.mass.id.clone(), r.peak_force_n()?)))
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
        written.extend([pin, bars]);
    }
    if !results.designs.is_empty() {
        let md = out.join("pareto.md");
        write_atomic(&md, pareto::markdown(results).as_bytes())?;
        let csv_path = out.join("pareto.csv");
        write_atomic(&csv_path, &pareto::csv(results)?)?;
        let svg = out.join("pareto.svg");
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
    let index = out.join("index.html");
    write_atomic(&index, index_page::index_html(results, out).as_bytes())?;
    written.push(index);
    Ok(written)
}

/// (id, name, pin-force history) of every design that passed stage 2, in ranking order.
fn histories(results: &StudyResults) -> Vec<(String, String, &DrivenResult)> {
    ranking::ranking(results)
        .iter()
        .filter_map(|r| {
            let h = results
                .designs
                .iter()
                .find(|d| d.mass.id == r.mass.id)
                .map(|d| &d.history)
                .or_else(|| {
                    results
                        .failed
                        .iter()
                        .find(|f| f.mass.as_ref().is_some_and(|m| m.id == r.mass.id))
                        .and_then(|f| f.history.as_ref())
                })?;
            Some((r.mass.id.clone(), r.mass.design.clone(), h))
        })
        .collect()
}

/// The points of one history over its first crank revolution: (φ − φ₀ [°], value).
fn first_turn(h: &DrivenResult, value: impl Fn(usize) -> f64) -> Vec<(f64, f64)> {
    let turn = std::f64::consts::TAU;
    (0..h.t_s.len())
        .take_while(|&k| h.phi_rad[k] - h.phi_rad[0] <= turn + 1e-9)
        .map(|k| ((h.phi_rad[k] - h.phi_rad[0]).to_degrees(), value(k)))
        .collect()
}

/// One design's pin force over the first revolution: |F_A| and its components.
fn design_pin_force_plot(design: &str, h: &DrivenResult) -> Result<String> {
    let series = vec![
        plots::Series {
            name: "|F_A|".into(),
            points: first_turn(h, |k| h.fa_abs_n[k]),
        },
        plots::Series {
            name: "F_Ax".into(),
            points: first_turn(h, |k| h.fa_x_n[k]),
        },
        plots::Series {
            name: "F_Ay".into(),
            points: first_turn(h, |k| h.fa_y_n[k]),
        },
    ];
    plots::line_chart(
        &format!("{design}: crank–rod pin force (φ = 40πt, gravity on)"),
        "crank angle φ [°] (0 = top dead centre)",
        "force by the crank on the rod at A [N] (global frame)",
        &series,
        plots::Scale::Linear,
        plots::Scale::Linear,
    )
}

/// |F_A| over the first crank revolution, all designs in one plot.
fn pin_force_plot(histories: &[(String, String, &DrivenResult)]) -> Result<String> {
    let series: Vec<plots::Series> = histories
        .iter()
        .map(|(_, design, h)| plots::Series {
            name: design.clone(),
            points: first_turn(h, |k| h.fa_abs_n[k]),
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
    // every design that passed stage 1, those that failed later included
    let designs: Vec<&DesignMass> = results
        .designs
        .iter()
        .map(|d| &d.mass)
        .chain(results.failed.iter().filter_map(|f| f.mass.as_ref()))
        .collect();
    let mut out = format!(
        "# Mass properties of the designs\n\nStages run: {}. Skipped: {}.\nI_zz is about the pin axis through the centroid (the one the planar dynamics uses); I_xx is about the rod's long axis (what the thesis' Table 5.1 lists).\n\n",
        results.stages_run.join(", "),
        results.stages_skipped.join(", ")
    );
    out.push_str(&tables::mass_table(&designs));
    if !results.failed.is_empty() {
        out.push_str("\n## Failed designs\n\n");
        for f in &results.failed {
            out.push_str(&format!(
                "- `{}` ({} stage): {}\n",
                f.file, f.stage, f.error
            ));
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
    /// The stage that failed (empty when none did).
    stage: String,
    error: String,
}

fn csv_table(results: &StudyResults) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let rows = results
        .designs
        .iter()
        .map(|d| (&d.mass, Some(&d.dynamics), None))
        .chain(
            results
                .failed
                .iter()
                .filter_map(|f| f.mass.as_ref().map(|m| (m, f.dynamics.as_ref(), Some(f)))),
        );
    for (m, dynamics, failed) in rows {
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
            peak_pin_force_n: dynamics.map(|d| d.peak_pin_force_n),
            status: if failed.is_some() { "failed" } else { "ok" },
            stage: failed.map(|f| f.stage.clone()).unwrap_or_default(),
            error: failed.map(|f| f.error.clone()).unwrap_or_default(),
        })?;
    }
    for f in results.failed.iter().filter(|f| f.mass.is_none()) {
        w.serialize(CsvRow {
            file: f.file.clone(),
            status: "failed",
            stage: f.stage.clone(),
            error: f.error.clone(),
            ..CsvRow::default()
        })?;
    }
    Ok(w.into_inner()?)
}
