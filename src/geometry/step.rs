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

/// The length unit a STEP file declares (ISO 10303-41: an `SI_UNIT` of `.METRE.` with an
/// optional prefix, or a `CONVERSION_BASED_UNIT` such as `'INCH'`), as its name and millimetres
/// per unit; `None` when the file declares none that is recognised. A conversion-based unit
/// wins over the SI unit it is defined by; else the first SI length unit of the file counts.
pub fn declared_length_unit(text: &str) -> Option<(String, f64)> {
    let upper = text.to_ascii_uppercase();
    let mut si = None;
    for entity in upper.split(';') {
        let compact: String = entity.chars().filter(|c| !c.is_whitespace()).collect();
        if !compact.contains("LENGTH_UNIT(") {
            continue;
        }
        if let Some(at) = compact.find("CONVERSION_BASED_UNIT('") {
            let name = compact[at + 23..].split('\'').next().unwrap_or_default();
            let mm = match name {
                "INCH" | "INCHES" => 25.4,
                "FOOT" | "FEET" => 304.8,
                "MILLIMETRE" | "MILLIMETER" | "MM" => 1.0,
                "METRE" | "METER" | "M" => 1000.0,
                _ => continue,
            };
            return Some((name.to_ascii_lowercase(), mm));
        }
        if let Some(at) = compact.find("SI_UNIT(") {
            let args = compact[at + 8..].split(')').next().unwrap_or_default();
            let mut parts = args.split(',');
            let (Some(prefix), Some(unit)) = (parts.next(), parts.next()) else {
                continue;
            };
            if unit != ".METRE." {
                continue;
            }
            let (name, mm) = match prefix {
                ".MILLI." => ("millimetre", 1.0),
                ".CENTI." => ("centimetre", 10.0),
                ".DECI." => ("decimetre", 100.0),
                "$" => ("metre", 1000.0),
                ".MICRO." => ("micrometre", 1e-3),
                ".KILO." => ("kilometre", 1e6),
                _ => continue,
            };
            si = si.or(Some((name.to_string(), mm)));
        }
    }
    si
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
    /// Metres per unit of the reported lengths (OpenCASCADE's millimetres, 1e-3), or, when the
    /// sidecar's `units` overrides the unit the file declares, the sidecar's unit over the
    /// declared one (a file that declares mm but holds metres: 1 m per 1 mm of OpenCASCADE's).
    #[serde(skip, default = "millimetre")]
    pub metres_per_unit: f64,
}

fn millimetre() -> f64 {
    1e-3
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
                "STEP: {n} solids, {v} separate bodies after fusing those that touch, exact B-rep mass properties (their sum)"
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

#[cfg(test)]
mod tests {
    use super::declared_length_unit;

    #[test]
    fn declared_units_are_read_as_written() {
        // as gmsh (OpenCASCADE) writes mm, as CAD systems write metres and inches
        let mm = "#1393 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );";
        assert_eq!(declared_length_unit(mm), Some(("millimetre".into(), 1.0)));
        let m = "#12=(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT($,.METRE.));\n#13=(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.));";
        assert_eq!(declared_length_unit(m), Some(("metre".into(), 1000.0)));
        let inch = "#7 = ( CONVERSION_BASED_UNIT('INCH',#8) LENGTH_UNIT() NAMED_UNIT(#9) );\n#8 = LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#10);";
        assert_eq!(declared_length_unit(inch), Some(("inch".into(), 25.4)));
        // angles only: none
        assert_eq!(
            declared_length_unit("#13=(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.));"),
            None
        );
    }
}
