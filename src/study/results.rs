//! What a study found: the record of every design that went through the stages, of every design
//! that failed (with what the stages before the failure computed), as written to `results.json`.

use crate::config::StudyConfig;
use crate::mechanism::DrivenResult;
use crate::stages::records::{DesignCycle, DesignDynamics, DesignFem, DesignMass};
use serde::Serialize;
use std::path::Path;

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
    pub shard: Option<super::shard::ShardRecord>,
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
