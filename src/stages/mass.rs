//! Stage 1 (SPEC "Stage 1"): a design file read, welded and validated once ([`load`]); its mass
//! properties, the bore check and the mechanism frame ([`mass`]), or the mass properties of any
//! closed solid ([`mass_of_solid`], `rodstudy mass`). The mathematics is in [`crate::geometry`].
//!
//! A STEP that cannot be read (empty, malformed, the reader's time limit) with an STL of the same
//! name beside it falls back to that STL: the STL is the design, and its warnings say why.

use super::records::{DesignMass, LoadedDesign};
use crate::geometry::design::{load_design, rod_mass, solid_mass};
use crate::geometry::step::is_step;
use anyhow::Result;
use std::path::{Path, PathBuf};

/// Reads and validates a design file and integrates its mass properties (errors name the file).
/// A STEP that fails to load with `NAME.stl` beside it is that STL's design, with a warning
/// naming the STEP's error; when the STL fails too, both errors are reported.
pub fn load(file: &Path) -> Result<LoadedDesign> {
    let step_error = match load_design(file) {
        Ok(d) => return Ok(d),
        Err(e) => e,
    };
    let Some(stl) = stl_beside(file) else {
        return Err(step_error);
    };
    match load_design(&stl) {
        Ok(mut d) => {
            d.warnings.insert(
                0,
                format!(
                    "{} beside it could not be read ({}): this design is the STL; mend or remove \
                     the STEP",
                    file.display(),
                    without_file(&one_line(&step_error), file)
                ),
            );
            Ok(d)
        }
        Err(stl_error) => Err(anyhow::anyhow!(
            "{}; the STL beside it fails too: {}",
            one_line(&step_error),
            one_line(&stl_error)
        )),
    }
}

/// `NAME.stl` (any case of the extension) beside a STEP file `NAME.step`.
fn stl_beside(file: &Path) -> Option<PathBuf> {
    if !is_step(file) {
        return None;
    }
    ["stl", "STL", "Stl"]
        .iter()
        .map(|ext| file.with_extension(ext))
        .find(|p| p.is_file())
}

/// `message` without the `FILE: ` it begins with (the warning names the file already); a
/// `FILE:LINE:` stays whole.
fn without_file(message: &str, file: &Path) -> String {
    let name = file.display().to_string();
    message
        .strip_prefix(&name)
        .and_then(|rest| rest.strip_prefix(": "))
        .unwrap_or(message)
        .to_string()
}

fn one_line(e: &anyhow::Error) -> String {
    format!("{e:#}").replace('\n', " ")
}

/// The stage-1 record of a rod: an error when its pins do not sit in bores (the mechanism needs
/// them).
pub fn mass(design: &LoadedDesign) -> Result<DesignMass> {
    rod_mass(design)
}

/// The stage-1 record of any closed solid: the mechanism-frame fields null, with a warning, when
/// the pins do not sit in bores.
pub fn mass_of_solid(design: &LoadedDesign) -> DesignMass {
    solid_mass(design)
}
