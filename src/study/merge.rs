//! `rodstudy merge SHARD_DIR... --out DIR`: the reports of a one-machine study from the shards of a
//! split one (`study --shard K/N`).
//!
//! Each shard's full record (`timings.json`: `results.json` with its wall times) is read back; the
//! shards must come from this program version with the same settings and stages, and together
//! hold every design of the folder exactly once (see [`super::shard::check_complete`]). The
//! per-design files (ParaView, pictures) are copied; the pin-force histories are recomputed
//! (closed form, milliseconds); then the reports are written as a study writes them.

use super::results::{DesignResult, FailedDesign, StudyResults};
use super::shard::{ShardRecord, check_complete};
use crate::config::StudyConfig;
use crate::geometry::design::DesignMass;
use crate::mechanism::{DrivenResult, Method};
use crate::report::atomic_write::write_atomic;
use crate::report::file_safe;
use crate::stages;
use crate::stages::records::{DesignCycle, DesignDynamics, DesignFem};
use anyhow::{Context, Result, bail};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// A shard's record as read back.
#[derive(Deserialize)]
struct ShardFile {
    program_version: String,
    config: StudyConfig,
    stages_run: Vec<String>,
    stages_skipped: Vec<String>,
    designs: Vec<ShardDesign>,
    failed: Vec<FailedDesign>,
    shard: Option<ShardRecord>,
}

#[derive(Deserialize)]
struct ShardDesign {
    mass: DesignMass,
    dynamics: DesignDynamics,
    fem: Option<DesignFem>,
    #[serde(default)]
    cycle: Option<DesignCycle>,
}

/// The pin-force history of a design (the driven scene, closed form).
pub fn history_of(mass: &DesignMass, config: &StudyConfig) -> Result<DrivenResult> {
    // as the study computed it: the configured engine (gas force over 720° with a trace)
    stages::dynamics::history(
        mass,
        &config.driven_scene(),
        config.driven.gravity,
        &config.engine,
        Method::ClosedForm,
    )
}

fn read_shard(dir: &Path) -> Result<ShardFile> {
    let path = dir.join("timings.json");
    let text = std::fs::read_to_string(&path).with_context(|| {
        format!(
            "{}: no shard record (timings.json): is this the --out of `study --shard K/N`?",
            dir.display()
        )
    })?;
    let shard: ShardFile = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a study record", path.display()))?;
    if shard.shard.is_none() {
        bail!(
            "{}: a whole study, not a shard (it was run without --shard)",
            dir.display()
        );
    }
    Ok(shard)
}

/// Copies every file of `from` into `to` (created), each atomically.
fn copy_files(from: &Path, to: &Path) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(from) else {
        return Ok(());
    };
    for e in entries {
        let e = e?;
        if e.file_type()?.is_file() {
            let bytes = std::fs::read(e.path())
                .with_context(|| format!("cannot read {}", e.path().display()))?;
            write_atomic(&to.join(e.file_name()), &bytes)?;
        }
    }
    Ok(())
}

/// Merges the shards in `dirs` into the results of the whole study and copies their per-design
/// files into `out` (the caller writes the reports).
pub fn merge_shards(dirs: &[PathBuf], out: &Path) -> Result<StudyResults> {
    if dirs.is_empty() {
        bail!("no shard folders given");
    }
    // the merged reports must not overwrite a shard's own record
    let canonical = |p: &Path| std::fs::canonicalize(p).ok();
    if let Some(o) = canonical(out)
        && let Some(d) = dirs.iter().find(|d| canonical(d).as_ref() == Some(&o))
    {
        bail!(
            "{}: --out is one of the shards; merge into another folder",
            d.display()
        );
    }
    let shards: Vec<(PathBuf, ShardFile)> = dirs
        .iter()
        .map(|d| read_shard(d).map(|s| (d.clone(), s)))
        .collect::<Result<_>>()?;
    let version = env!("CARGO_PKG_VERSION");
    let (first_dir, first) = &shards[0];
    for (dir, s) in &shards {
        if s.program_version != version {
            bail!(
                "{}: written by rodstudy {}, this is {version}: rerun the shard with this version",
                dir.display(),
                s.program_version
            );
        }
        if s.config != first.config {
            bail!(
                "{}: its settings differ from {}'s (compare `config` in their results.json)",
                dir.display(),
                first_dir.display()
            );
        }
        if s.stages_run != first.stages_run || s.stages_skipped != first.stages_skipped {
            bail!(
                "{}: ran stages [{}], {} ran [{}]",
                dir.display(),
                s.stages_run.join(", "),
                first_dir.display(),
                first.stages_run.join(", ")
            );
        }
    }
    let records: Vec<(PathBuf, ShardRecord)> = shards
        .iter()
        .map(|(d, s)| (d.clone(), s.shard.clone().expect("checked on reading")))
        .collect();
    check_complete(&records)?;
    // the shards of one study read one designs folder (sweeps name their rods alike)
    let (first_dir, first_record) = &records[0];
    if let Some((dir, r)) = records
        .iter()
        .find(|(_, r)| r.designs_folder != first_record.designs_folder)
    {
        bail!(
            "{} studied the designs in {}, {} those in {}: the shards of one study read one \
             designs folder",
            first_dir.display(),
            first_record.designs_folder,
            dir.display(),
            r.designs_folder
        );
    }
    let config = first.config;
    let mut results = StudyResults {
        program_version: version.into(),
        config,
        stages_run: first.stages_run.clone(),
        stages_skipped: first.stages_skipped.clone(),
        designs: Vec::new(),
        failed: Vec::new(),
        shard: None,
    };
    for (dir, s) in shards {
        for d in s.designs {
            copy_files(
                &dir.join(file_safe(&d.mass.id)),
                &out.join(file_safe(&d.mass.id)),
            )?;
            let history = history_of(&d.mass, &config)
                .with_context(|| format!("{}: pin-force history", d.mass.file))?;
            results.designs.push(DesignResult {
                mass: d.mass,
                dynamics: d.dynamics,
                fem: d.fem,
                cycle: d.cycle,
                history,
            });
        }
        for mut f in s.failed {
            // its folder (a failure.log, the stages that passed) whatever stage failed
            let id = file_safe(&f.id());
            copy_files(&dir.join(&id), &out.join(&id))?;
            if let Some(m) = &f.mass
                && f.dynamics.is_some()
            {
                f.history = history_of(m, &config).ok();
            }
            results.failed.push(f);
        }
    }
    // the order of a one-machine study: the designs folder's files, sorted
    results
        .designs
        .sort_by(|a, b| Path::new(&a.mass.file).cmp(Path::new(&b.mass.file)));
    results
        .failed
        .sort_by(|a, b| Path::new(&a.file).cmp(Path::new(&b.file)));
    Ok(results)
}
