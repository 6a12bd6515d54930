//! The loop over the designs of a folder: every stage on every design, in parallel, one broken
//! design never stopping the others; cached per design by content hash; a shard of the designs
//! when the study is split. The stages compute ([`crate::stages`]); their field files (VTU,
//! pictures) are written by [`crate::report::fields`] as soon as a design's stage 3 is done, so
//! that its mesh and fields need not be held until the end.

use super::cache::{Cache, design_key};
use super::results::{DesignResult, FailedDesign, STAGES, StudyResults, one_line};
use super::shard;
use crate::config::StudyConfig;
use crate::geometry::design::find_stl_files;
use crate::mechanism::Method;
use crate::report::{fields, file_safe};
use crate::stages;
use crate::stages::criterion::judge_fatigue;
use crate::stages::fem::MeshMode;
use crate::stages::records::{DesignCycle, DesignDynamics, DesignFem, DesignMass};
use anyhow::{Context, Result, bail};
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;

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
    if designs.is_file() {
        bail!(
            "{}: --designs takes a folder of designs, not a file (`rodstudy fem`, `mass` and \
             `dynamics driven` take single files)",
            designs.display()
        );
    }
    if !designs.is_dir() {
        bail!("{}: the designs folder does not exist", designs.display());
    }
    // the reports' folder must take files before any design is computed
    std::fs::create_dir_all(options.out)
        .and_then(|()| tempfile::NamedTempFile::new_in(options.out).map(drop))
        .with_context(|| {
            format!(
                "{}: cannot write the reports there (--out)",
                options.out.display()
            )
        })?;
    let all_files = find_stl_files(&[designs.to_path_buf()])?;
    // designs whose reports would share a folder (the same file stem, or stems that differ only
    // in case or in characters a file name cannot keep) are refused, all of them, by name
    let clashes = clashing_ids(&all_files);
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
                designs_folder: options.designs.display().to_string(),
            };
            (mine, Some(record))
        }
    };
    let (files, refused): (Vec<_>, Vec<_>) = files
        .into_iter()
        .partition(|f| !clashes.iter().any(|c| c.contains(f)));
    let cache = if options.skip_fem {
        Cache::in_folder(&options.out.join(".cache").join("without-fem"))
    } else {
        Cache::new(options.out)
    };
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
    for f in refused {
        let others: Vec<String> = clashes
            .iter()
            .find(|c| c.contains(&f))
            .into_iter()
            .flatten()
            .filter(|o| **o != f)
            .map(|o| o.display().to_string())
            .collect();
        let failed = FailedDesign {
            file: f.display().to_string(),
            error: format!(
                "{}: its id `{}` names the same report folder as {} (ids are file stems, reports go \
                 to OUT/<id>/): rename one of them",
                f.display(),
                shard::id_of(&f),
                others.join(", ")
            ),
            stage: STAGES[0].into(),
            ..FailedDesign::default()
        };
        on_done(Progress {
            file: &f,
            cached: false,
            outcome: Err(failed.error.clone()),
        });
        results.failed.push(failed);
    }
    Ok(results)
}

/// The groups of design files whose ids would share a report folder or cache entry: the same
/// [`file_safe`] id up to case (a case-insensitive file system keeps one of them).
fn clashing_ids(files: &[std::path::PathBuf]) -> Vec<Vec<std::path::PathBuf>> {
    let mut by_key: std::collections::BTreeMap<String, Vec<std::path::PathBuf>> =
        std::collections::BTreeMap::new();
    for f in files {
        by_key
            .entry(file_safe(&shard::id_of(f)).to_lowercase())
            .or_default()
            .push(f.clone());
    }
    by_key.into_values().filter(|g| g.len() > 1).collect()
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
    // a study without stage 3 keeps its entries in a folder of their own (run_study), so that
    // it does not replace a whole study's
    let key = cache.and_then(|_| design_key(stl, config).ok());
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
            && (hit.cycle.is_none()
                || present(&[
                    "von_mises_cycle.svg",
                    "cycle.vtu",
                    "local_fatigue.svg",
                    "haigh.svg",
                ]))
    };
    if let (Some(cache), Some(key)) = (cache, &key)
        && let Some(hit) = cache.get::<CachedDesign>(&id, key)
        && files_present(&hit)
        && let Ok(history) = stages::dynamics::history(
            &hit.mass,
            &scene,
            config.driven.gravity,
            &config.engine,
            Method::ClosedForm,
        )
    {
        // the same content may have moved: the record names the file studied now
        let mut mass = hit.mass;
        mass.file = stl.display().to_string();
        let result = DesignResult {
            mass,
            dynamics: hit.dynamics,
            fem: hit.fem,
            cycle: hit.cycle,
            history,
        };
        return (Ok(result), true);
    }
    let mut failed = FailedDesign {
        file: stl.display().to_string(),
        ..FailedDesign::default()
    };
    let computed = (|| {
        failed.stage = STAGES[0].into();
        let design = stages::mass::load(stl)?;
        let mass = stages::mass::mass(&design)?;
        failed.mass = Some(mass.clone());
        failed.stage = STAGES[1].into();
        let (dynamics, history) = stages::dynamics::dynamics_with(
            &mass,
            &scene,
            config.driven.gravity,
            &config.engine,
            Method::ClosedForm,
        )?;
        failed.dynamics = Some(dynamics.clone());
        failed.history = Some(history.clone());
        failed.stage = STAGES[2].into();
        let (mut fem, mut cycle) = (None, None);
        if !options.skip_fem {
            let work = options.out.join(".cache").join("mesh").join(&id);
            let dir = options.out.join(file_safe(&id));
            let context = || format!("{}: FEM", stl.display());
            let mut f = stages::fem::fem(
                &design,
                &stages::fem::FemLoads::from_records(&mass, &dynamics),
                config,
                &work,
                &MeshMode::from_config(config),
            )?;
            fields::write_fem_fields(&mut f.record.fem, &f.solution, &f.mesh.mesh, &dir, "fem")
                .with_context(context)?;
            let contact = match &f.contact {
                Some((mesh, solution)) => Some((mesh, solution)),
                None => {
                    (!f.solution.contact_fields.is_empty()).then_some((&f.mesh.mesh, &f.solution))
                }
            };
            if let Some((mesh, solution)) = contact {
                crate::report::contact_files::write_contact_fields(solution, mesh, &dir)
                    .with_context(context)?;
            }
            drop(f.contact);
            drop(f.solution);
            let mut record = f.record;
            if config.cycle.enabled {
                failed.stage = STAGES[3].into();
                let c = stages::cycle::cycle(&mass, &f.mesh, config)?;
                let mut c_record = c.record;
                fields::write_cycle_fields(
                    &mut c_record,
                    &f.mesh.mesh,
                    &c.cycle,
                    &c.units,
                    &c.local,
                    &dir,
                )
                .with_context(|| format!("{}: cycle", mass.file))?;
                judge_fatigue(&mut record.criterion, &c_record, config);
                cycle = Some(c_record);
            }
            fem = Some(record);
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
        let full = format!("{e:#}");
        let log_name = format!("{}/failure.log", file_safe(&id));
        let (error, log) = match one_line(&full, &log_name) {
            Some(line) => (line, Some(full)),
            None => (full, None),
        };
        Box::new(FailedDesign {
            error,
            log,
            ..failed
        })
    });
    (outcome, false)
}
