//! A STEP design (`.step`, `.stp`; AP203/AP214) read through gmsh's OpenCASCADE kernel
//! (`pipeline/step_solid.py`, SPEC "Design files").
//!
//! The mass properties are the exact volume integrals of the B-rep (OpenCASCADE's
//! `BRepGProp::VolumeProperties`, through gmsh's `occ.getMass`, `getCenterOfMass`,
//! `getMatrixOfInertia`), not those of a triangulation; several solids in one file (rod, cap,
//! bolts) are fused into one bonded body first, and bodies that do not touch add by the parallel
//! axis theorem. A surface triangulation of the solid comes back with them (binary STL in file
//! units): what the bore check, the mechanism frame and the STL route of stage 3 use. A file with
//! no closed solid (an open or unsewn shell) or a degenerate solid is refused with a message that
//! names the file and the defect.

use super::mass_properties::MassProperties;
use anyhow::{Context, Result, bail};
use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;
use std::path::Path;
use std::process::Command;

/// The reader script in `pipeline/`.
pub const STEP_SCRIPT: &str = "step_solid.py";

/// Whether `path` names a STEP file (by extension, any case).
pub fn is_step(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("step") || e.eq_ignore_ascii_case("stp"))
}

/// What `step_solid.py read` reports (file units).
#[derive(Debug, Clone, Deserialize)]
pub struct StepReport {
    /// Solids in the file, and volumes after fusing them.
    pub solids_in_file: usize,
    pub volumes: usize,
    pub fused: bool,
    /// Exact volume (file units³), centre of volume (file units), second-moment tensor about it
    /// at unit density (file units⁵).
    pub volume: f64,
    pub centroid: [f64; 3],
    pub inertia: [[f64; 3]; 3],
    /// The surface triangulation written, and its triangles.
    pub stl: std::path::PathBuf,
    pub triangles: usize,
    pub gmsh_version: String,
}

impl StepReport {
    /// The exact mass properties in metres at `density` (kg/m³), the file's lengths being
    /// `to_metres` metres each.
    pub fn mass_properties(&self, to_metres: f64, density: f64) -> MassProperties {
        let s = to_metres;
        MassProperties::from_integrals(
            self.volume * s.powi(3),
            Vector3::from(self.centroid) * s,
            Matrix3::from_row_slice(&self.inertia.concat()) * s.powi(5),
            density,
        )
    }

    /// What the reports say about how the file was read.
    pub fn description(&self) -> String {
        match (self.solids_in_file, self.volumes) {
            (1, _) => "STEP: one solid, exact B-rep mass properties".into(),
            (n, 1) => {
                format!("STEP: {n} solids fused into one bonded body, exact B-rep mass properties")
            }
            (n, v) => format!(
                "STEP: {n} solids, {v} separate bodies after fusing those that touch (treated as one rigid part), exact B-rep mass properties"
            ),
        }
    }
}

/// An ISO 10303-21 file begins with `ISO-10303-21;` (after optional white space): an empty file
/// or another kind of file is named as such before OpenCASCADE's bare "Could not read file".
fn check_step_header(step: &Path) -> Result<()> {
    use std::io::Read;
    let mut head = Vec::with_capacity(64);
    std::fs::File::open(step)
        .and_then(|f| f.take(4096).read_to_end(&mut head))
        .with_context(|| format!("{}: cannot read", step.display()))?;
    let text = String::from_utf8_lossy(&head);
    let text = text.trim_start_matches('\u{feff}').trim_start();
    if text.is_empty() {
        bail!("{}: empty file (a STEP export has content)", step.display());
    }
    if !text.starts_with("ISO-10303-21;") {
        bail!(
            "{}: not a STEP file (an ISO 10303-21 file begins with `ISO-10303-21;`): export the \
             part again as STEP AP203/AP214/AP242",
            step.display()
        );
    }
    Ok(())
}

/// Reads `step` with `python` and the reader script, writing the surface triangulation to
/// `stl_out`.
pub fn read_step(python: &Path, script: &Path, step: &Path, stl_out: &Path) -> Result<StepReport> {
    check_step_header(step)?;
    let out = Command::new(python)
        .arg(script)
        .arg("read")
        .arg(step)
        .arg(stl_out)
        .output()
        .with_context(|| format!("{}: cannot run {}", step.display(), script.display()))?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        let msg = stderr
            .lines()
            .rev()
            .find(|l| l.starts_with("error: "))
            .map(|l| l.trim_start_matches("error: ").to_string())
            .unwrap_or_else(|| {
                format!(
                    "{}: the STEP reader failed ({}): {}",
                    step.display(),
                    out.status,
                    stderr.lines().last().unwrap_or_default()
                )
            });
        bail!("{msg}");
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout
        .lines()
        .rev()
        .find(|l| l.trim_start().starts_with('{'))
        .with_context(|| format!("{}: the STEP reader printed no report", step.display()))?;
    serde_json::from_str(line)
        .with_context(|| format!("{}: cannot parse the STEP reader's report", step.display()))
}
