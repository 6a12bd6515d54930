//! Stage 1 (SPEC "Stage 1"): a design file read, welded and validated once ([`load`]); its mass
//! properties, the bore check and the mechanism frame ([`mass`]), or the mass properties of any
//! closed solid ([`mass_of_solid`], `rodstudy mass`). The mathematics is in [`crate::geometry`].

use super::records::{DesignMass, LoadedDesign};
use crate::geometry::design::{load_design, rod_mass, solid_mass};
use anyhow::Result;
use std::path::Path;

/// Reads and validates a design file and integrates its mass properties (errors name the file).
pub fn load(file: &Path) -> Result<LoadedDesign> {
    load_design(file)
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
