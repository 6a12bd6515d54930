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
    /// The whole message when `error` had to be cut to one line (a subprocess's log): written by
    /// the report to `<id>/failure.log`, named in `error`.
    #[serde(skip)]
    pub log: Option<String>,
}

/// One line that says what failed, from a message that carries a subprocess's log (a failed
/// gmsh run: "… exited with …" and its standard error): the first line (which names the file and
/// the stage) and the log's last error line, and what to try for a mesher failure; from any
/// other message of several lines (a TOML error's excerpt of the file) its first and last lines;
/// `None` for a message of one line (kept whole).
pub fn one_line(message: &str, log_name: &str) -> Option<String> {
    if !message.contains(" exited with ") {
        let lines: Vec<&str> = message
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect();
        return match lines.as_slice() {
            [] | [_] => None,
            [first, .., last] => Some(format!(
                "{}: {last} (full message: {log_name})",
                first.trim_end_matches(':')
            )),
        };
    }
    let mut lines = message.lines().filter(|l| !l.trim().is_empty());
    let first = lines.next()?.trim_end_matches(':').to_string();
    let rest: Vec<&str> = lines.collect();
    if rest.is_empty() {
        return None;
    }
    let cause = rest
        .iter()
        .rev()
        .find(|l| l.contains("Error") || l.contains("error"))
        .unwrap_or(rest.last().expect("not empty"))
        .trim();
    // the mesher's own last line lists what it tried and what to try
    let hint = if cause.contains("try:") {
        ""
    } else if message.contains("mesh_rod.py") || message.contains("gmsh") {
        " — try: a fixed mesh (`fem.target_error = 0` or `--size`), a coarser or finer STL export, or a STEP export of the part"
    } else {
        ""
    };
    Some(format!("{first}: {cause}{hint} (full log: {log_name})"))
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

#[cfg(test)]
mod tests {
    use super::one_line;

    #[test]
    fn a_message_of_several_lines_becomes_its_first_and_last() {
        let msg = "designs/x.stl: designs/x.toml: TOML parse error at line 3, column 1\n  |\n3 | densty = 7850\n  | ^^^^^^\nunknown field `densty`, expected one of `units`, `density`\n";
        let line = one_line(msg, "x/failure.log").unwrap();
        assert_eq!(
            line,
            "designs/x.stl: designs/x.toml: TOML parse error at line 3, column 1: unknown field \
             `densty`, expected one of `units`, `density` (full message: x/failure.log)"
        );
        assert_eq!(one_line("designs/x.stl: one line", "x/failure.log"), None);
    }

    #[test]
    fn a_mesher_log_becomes_one_line_that_names_the_cause_and_the_log() {
        let msg = "designs/x.stl: FEM: .venv/bin/python pipeline/mesh_rod.py exited with exit status: 1:\nInfo : Meshing surface 12\nInfo : Done\nError : Wrong topology of boundary mesh for parametrization\nTraceback: gmsh exception";
        let line = one_line(msg, "x/failure.log").unwrap();
        assert!(!line.contains('\n'), "{line}");
        assert!(line.starts_with("designs/x.stl: FEM"), "{line}");
        assert!(
            line.contains("Wrong topology of boundary mesh for parametrization"),
            "{line}"
        );
        assert!(
            line.contains("try:") && line.contains("x/failure.log"),
            "{line}"
        );
        // the mesher's total failure says itself what to try: no second hint
        let msg = "designs/x.stl: FEM: .venv/bin/python pipeline/mesh_rod.py exited with exit status: 1:\nmesh_rod:   failed: Exception: PLC Error\nmesh_rod: error: gmsh could not mesh x.stl at 8 mm; tried A; B; try: a STEP export";
        let line = one_line(msg, "x/failure.log").unwrap();
        assert_eq!(line.matches("try:").count(), 1, "{line}");
        assert!(line.contains("tried A; B"), "{line}");
        // a one-line message stays as it is
        assert_eq!(one_line("x.stl: not an STL file", "x/failure.log"), None);
    }
}
