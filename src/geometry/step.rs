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
//!
//! Before OpenCASCADE sees the file, its DATA section is scanned ([`scan_step_numbers`]): a
//! non-finite number (`NaN`, `INF`, an overflowing `1.E400`) in any entity, or a
//! `CARTESIAN_POINT` coordinate beyond [`ABSURD_COORDINATE`] file units, is refused naming the
//! entity `#id` and its line (OpenCASCADE crashes on some of them and runs for minutes on
//! others). The reader runs under the pipeline's time limit
//! ([`crate::python_env::pipeline_timeout`]); a reader killed by a signal is reported as the
//! file making OpenCASCADE crash.

use super::mass_properties::MassProperties;
use crate::python_env::{output_within, pipeline_timeout};
use anyhow::{Context, Result, bail};
use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;
use std::path::Path;
use std::process::Command;

/// A `CARTESIAN_POINT` coordinate beyond this many file units (a million kilometres in
/// millimetres) is no part's: the file is malformed.
pub const ABSURD_COORDINATE: f64 = 1e12;

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

/// An ISO 10303-21 file begins with `ISO-10303-21;` (after optional white space and a UTF-8
/// byte-order mark): an empty file or another kind of file is named as such before OpenCASCADE's
/// bare "Could not read file".
fn check_step_header(step: &Path, text: &str) -> Result<()> {
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

/// A number of a STEP entity that no part has: the entity, its line and the text of the number.
#[derive(Debug, Clone, PartialEq)]
pub struct AbsurdNumber {
    pub entity: String,
    pub keyword: String,
    pub line: usize,
    pub number: String,
    pub non_finite: bool,
}

/// The first non-finite number in an entity of the DATA section of `text` (`NaN`, `INF`, a real
/// that overflows), or the first `CARTESIAN_POINT` coordinate beyond [`ABSURD_COORDINATE`].
/// Strings (`'…'`, quotes doubled inside) and comments (`/* … */`) are skipped; entities are
/// the text between `;` outside them.
pub fn scan_step_numbers(text: &str) -> Option<AbsurdNumber> {
    let data = text.find("DATA;").map_or(0, |i| i + "DATA;".len());
    let mut line = 1 + text[..data].matches('\n').count();
    let mut statement = String::new();
    let mut start_line = line;
    let (mut in_string, mut in_comment) = (false, false);
    let mut chars = text[data..].chars().peekable();
    while let Some(c) = chars.next() {
        if c == '\n' {
            line += 1;
        }
        if in_comment {
            if c == '*' && chars.peek() == Some(&'/') {
                chars.next();
                in_comment = false;
            }
            continue;
        }
        if in_string {
            if c == '\'' {
                in_string = false;
            }
            continue;
        }
        match c {
            '\'' => {
                in_string = true;
                // the string's place keeps the tokens apart
                statement.push(' ');
            }
            '/' if chars.peek() == Some(&'*') => {
                chars.next();
                in_comment = true;
            }
            ';' => {
                if let Some(found) = absurd_in_entity(&statement, start_line) {
                    return Some(found);
                }
                statement.clear();
            }
            _ => {
                if statement.trim().is_empty() && !c.is_whitespace() {
                    start_line = line;
                    statement.clear();
                }
                statement.push(c);
            }
        }
    }
    None
}

/// The absurd number of one entity `#id = KEYWORD(…)` (its text without strings), if any.
fn absurd_in_entity(statement: &str, line: usize) -> Option<AbsurdNumber> {
    let (entity, rest) = statement.trim().split_once('=')?;
    let entity = entity.trim();
    if !entity.starts_with('#') {
        return None;
    }
    let rest = rest.trim_start();
    let keyword: String = rest
        .chars()
        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
        .collect();
    let point = keyword.eq_ignore_ascii_case("CARTESIAN_POINT");
    for token in rest.split(|c: char| "(),".contains(c) || c.is_whitespace()) {
        let t = token.trim_start_matches(['+', '-']);
        let Some(first) = t.chars().next() else {
            continue;
        };
        let named_non_finite = ["NAN", "INF", "INFINITY"]
            .iter()
            .any(|w| t.eq_ignore_ascii_case(w));
        let value = if first.is_ascii_digit() || first == '.' {
            token.parse::<f64>().ok()
        } else {
            None
        };
        let non_finite = named_non_finite || value.is_some_and(|v| !v.is_finite());
        let absurd = point && value.is_some_and(|v| v.abs() > ABSURD_COORDINATE);
        if non_finite || absurd {
            return Some(AbsurdNumber {
                entity: entity.to_string(),
                keyword: keyword.to_ascii_uppercase(),
                line,
                number: token.to_string(),
                non_finite,
            });
        }
    }
    None
}

/// The file refused for an absurd number, naming the entity, its line and what to do.
fn refuse_absurd(step: &Path, a: &AbsurdNumber) -> anyhow::Error {
    let what = if a.non_finite {
        "is not a finite number".to_string()
    } else {
        format!("is beyond any part (|x| > {ABSURD_COORDINATE:e} file units)")
    };
    anyhow::anyhow!(
        "{}:{}: malformed STEP: entity {} ({}) holds `{}`, which {what}: export the part again \
         from CAD (or mend entity {})",
        step.display(),
        a.line,
        a.entity,
        a.keyword,
        a.number,
        a.entity
    )
}

/// Reads `step` with `python` and the reader script, writing the surface triangulation to
/// `stl_out`.
pub fn read_step(python: &Path, script: &Path, step: &Path, stl_out: &Path) -> Result<StepReport> {
    let bytes = std::fs::read(step).with_context(|| format!("{}: cannot read", step.display()))?;
    let text = String::from_utf8_lossy(&bytes);
    check_step_header(step, &text)?;
    if let Some(a) = scan_step_numbers(&text) {
        return Err(refuse_absurd(step, &a));
    }
    // OpenCASCADE cannot read a file that starts with a UTF-8 byte-order mark: it reads a copy
    // without it, and its messages name the file given
    let bom_free = match bytes.strip_prefix(b"\xef\xbb\xbf") {
        Some(rest) => {
            let dir = tempfile::tempdir().with_context(|| format!("{}", step.display()))?;
            let copy = dir
                .path()
                .join(step.file_name().unwrap_or("design.step".as_ref()));
            std::fs::write(&copy, rest).with_context(|| format!("{}", copy.display()))?;
            Some((dir, copy))
        }
        None => None,
    };
    let read_from = bom_free.as_ref().map_or(step, |(_, copy)| copy.as_path());
    let named = |message: &str| match &bom_free {
        Some((_, copy)) => {
            message.replace(&copy.display().to_string(), &step.display().to_string())
        }
        None => message.to_string(),
    };
    let limit = pipeline_timeout();
    let out = output_within(
        Command::new(python)
            .arg(script)
            .arg("read")
            .arg(read_from)
            .arg(stl_out),
        limit,
    )
    .map_err(|e| {
        if e.kind() == std::io::ErrorKind::TimedOut {
            anyhow::anyhow!(
                "{}: the STEP reader (OpenCASCADE) did not finish: {e}; the file is probably \
                 malformed: export the part again as STEP, or study its STL instead",
                step.display()
            )
        } else {
            anyhow::anyhow!("{}: cannot run {}: {e}", step.display(), script.display())
        }
    })?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        if let Some(line) = stderr.lines().rev().find(|l| l.starts_with("error: ")) {
            bail!("{}", named(line.trim_start_matches("error: ")));
        }
        use std::os::unix::process::ExitStatusExt;
        if let Some(signal) = out.status.signal() {
            bail!(
                "{}: OpenCASCADE crashed reading the file (signal {signal}): the file is \
                 probably malformed: open it in CAD and export the part again as STEP, or study \
                 its STL instead",
                step.display()
            );
        }
        bail!(
            "{}: the STEP reader failed ({}: {}): the file is probably malformed: export the part \
             again as STEP, or study its STL instead",
            step.display(),
            out.status,
            stderr.lines().last().unwrap_or_default()
        );
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
    use super::*;

    const BOX: &str = "ISO-10303-21;\nHEADER;\nFILE_NAME('a;b','2026-01-01T00:00:00',(''),(''),'','','');\nENDSEC;\nDATA;\n#1 = CARTESIAN_POINT('',(0.,0.,0.));\n#2 = DIRECTION('',(0.,0.,1.));\n#3 = CARTESIAN_POINT('it''s; NaN',(1.5E2,\n  -20.,3.));\nENDSEC;\nEND-ISO-10303-21;\n";

    #[test]
    fn absurd_numbers_are_found_with_their_entity_and_line() {
        // strings (with a doubled quote and a `;`) and the header are not numbers
        assert_eq!(scan_step_numbers(BOX), None);
        let huge = BOX.replace("-20.", "1.E300");
        let a = scan_step_numbers(&huge).unwrap();
        assert_eq!(
            (a.entity.as_str(), a.keyword.as_str(), a.line),
            ("#3", "CARTESIAN_POINT", 8)
        );
        assert_eq!((a.number.as_str(), a.non_finite), ("1.E300", false));
        let nan = BOX.replace("(0.,0.,1.)", "(0.,NaN,1.)");
        let a = scan_step_numbers(&nan).unwrap();
        assert_eq!((a.entity.as_str(), a.line, a.non_finite), ("#2", 7, true));
        let overflow = BOX.replace("(0.,0.,1.)", "(0.,0.,1.E400)");
        assert!(scan_step_numbers(&overflow).unwrap().non_finite);
        // a big number elsewhere than in a point (a B-spline weight, a tolerance) is left alone
        assert_eq!(
            scan_step_numbers(&BOX.replace("(0.,0.,1.)", "(0.,0.,1.E20)")),
            None
        );
        let e = refuse_absurd(Path::new("rod.step"), &scan_step_numbers(&huge).unwrap());
        let e = e.to_string();
        assert!(
            e.starts_with("rod.step:8: malformed STEP: entity #3"),
            "{e}"
        );
        assert!(e.contains("export the part again"), "{e}");
    }

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
