//! The study: every stage that exists, run on every design of a folder, and the reports.
//!
//! Today the stages are: 1 mass properties (always). One broken design never stops the others:
//! it is listed in the report with its error, and the command's exit status says so.

pub mod atomic_write;
pub mod tables;

use crate::geometry::design::{DesignMass, find_stl_files, mass_of_design};
use anyhow::{Result, bail};
use atomic_write::write_atomic;
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The stages this version runs, in order, for the report's `stages_run`.
pub const STAGES_RUN: &[&str] = &["mass"];
/// Stages of the specification not built yet, so the report says what it did not do.
pub const STAGES_NOT_YET_AVAILABLE: &[&str] = &["dynamics", "fem"];

/// Everything the study found, as written to `results.json`.
#[derive(Debug, Clone, Serialize)]
pub struct StudyResults {
    pub program_version: String,
    pub stages_run: Vec<String>,
    pub stages_not_yet_available: Vec<String>,
    pub designs: Vec<DesignResult>,
    pub failed: Vec<FailedDesign>,
}

/// The figures of one design that went through every stage.
#[derive(Debug, Clone, Serialize)]
pub struct DesignResult {
    pub mass: DesignMass,
}

/// A design that could not be studied, and why.
#[derive(Debug, Clone, Serialize)]
pub struct FailedDesign {
    pub file: String,
    pub error: String,
}

/// Runs the stages on every `*.stl` of `designs` (in parallel).
pub fn run_study(designs: &Path) -> Result<StudyResults> {
    if !designs.is_dir() {
        bail!("{}: the designs folder does not exist", designs.display());
    }
    let files = find_stl_files(&[designs.to_path_buf()])?;
    let outcomes: Vec<(PathBuf, Result<DesignResult>)> = files
        .into_par_iter()
        .map(|f| {
            let r = mass_of_design(&f).map(|mass| DesignResult { mass });
            (f, r)
        })
        .collect();
    let mut results = StudyResults {
        program_version: env!("CARGO_PKG_VERSION").into(),
        stages_run: STAGES_RUN.iter().map(|s| s.to_string()).collect(),
        stages_not_yet_available: STAGES_NOT_YET_AVAILABLE
            .iter()
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

/// Writes `results.json`, `mass_properties.md` and `mass_properties.csv` into `out`
/// (each atomically) and returns their paths.
pub fn write_reports(results: &StudyResults, out: &Path) -> Result<Vec<PathBuf>> {
    let json = out.join("results.json");
    write_atomic(&json, serde_json::to_string_pretty(results)?.as_bytes())?;
    let md = out.join("mass_properties.md");
    write_atomic(&md, markdown(results).as_bytes())?;
    let csv_path = out.join("mass_properties.csv");
    write_atomic(&csv_path, &csv_table(results)?)?;
    Ok(vec![json, md, csv_path])
}

fn markdown(results: &StudyResults) -> String {
    let designs: Vec<&DesignMass> = results.designs.iter().map(|d| &d.mass).collect();
    let mut out = format!(
        "# Mass properties of the designs\n\nStages run: {}. Not yet available: {}.\nI_zz is about the pin axis through the centroid (the one the planar dynamics uses); I_xx is about the rod's long axis (what the thesis' Table 5.1 lists).\n\n",
        results.stages_run.join(", "),
        results.stages_not_yet_available.join(", ")
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

fn csv_table(results: &StudyResults) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "design",
        "file",
        "mass_kg",
        "volume_m3",
        "l1_m",
        "offset_m",
        "i_zz_kgm2",
        "i_xx_kgm2",
        "centroid_x_m",
        "centroid_y_m",
        "centroid_z_m",
        "status",
        "error",
    ])?;
    for d in &results.designs {
        let m = &d.mass;
        let num = |x: f64| format!("{x:.12e}");
        w.write_record([
            m.design.clone(),
            m.file.clone(),
            num(m.mass_kg),
            num(m.volume_m3),
            num(m.l1_m),
            num(m.offset_m),
            num(m.i_zz_kgm2),
            num(m.i_xx_kgm2),
            num(m.centroid_m[0]),
            num(m.centroid_m[1]),
            num(m.centroid_m[2]),
            "ok".into(),
            String::new(),
        ])?;
    }
    for f in &results.failed {
        let mut row = vec![String::new(), f.file.clone()];
        row.extend(std::iter::repeat_n(String::new(), 9));
        row.extend(["failed".into(), f.error.clone()]);
        w.write_record(row)?;
    }
    Ok(w.into_inner()?)
}
