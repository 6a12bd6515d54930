//! Stage 1 for one design file: read, weld, validate, integrate, map to the mechanism frame,
//! check the bores, and the record that reports it.

use super::bore_check::RodSurface;
use super::mass_properties::MassProperties;
use super::mechanism_frame::{MechanismFrame, RodInFrame};
use super::sidecar::DesignSettings;
use super::stl_file::{StlFormat, read_stl_file};
use super::validate::validate;
use super::weld::{IndexedMesh, weld};
use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Plausible mass range of a connecting rod [kg]; outside it the units are probably wrong.
pub const PLAUSIBLE_MASS_KG: (f64, f64) = (0.01, 100.0);

/// A design loaded and validated: its settings, its surface in metres and its mass properties.
pub struct LoadedDesign {
    pub name: String,
    pub file: PathBuf,
    pub format: StlFormat,
    pub settings: DesignSettings,
    /// Validated, outward-oriented surface in metres.
    pub mesh: IndexedMesh,
    pub mass: MassProperties,
    pub frame: MechanismFrame,
    pub warnings: Vec<String>,
}

/// The mass-stage record of one design, as written to JSON (SI units; see README "mass").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DesignMass {
    /// Display name: the sidecar's `name`, else the file stem.
    pub design: String,
    /// The file stem: a stable identifier, used for per-design report folders.
    pub id: String,
    pub file: String,
    pub format: String,
    pub triangles: usize,
    pub vertices: usize,
    pub units: String,
    pub density_kg_m3: f64,
    pub volume_m3: f64,
    pub mass_kg: f64,
    pub centroid_m: [f64; 3],
    pub inertia_about_centroid_kgm2: [[f64; 3]; 3],
    pub principal_moments_kgm2: [f64; 3],
    /// Principal axes, one unit vector per row, in the order of `principal_moments_kgm2`.
    pub principal_axes: [[f64; 3]; 3],
    pub l1_m: f64,
    pub offset_m: f64,
    pub offset_z_m: f64,
    pub i_zz_kgm2: f64,
    pub i_xx_kgm2: f64,
    pub i_yy_kgm2: f64,
    pub centre_distance_m: f64,
    pub crank_bore_radius_m: f64,
    pub piston_bore_radius_m: f64,
    pub warnings: Vec<String>,
}

/// The design name: the sidecar's `name`, else the file stem.
fn design_name(stl: &Path, settings: &DesignSettings) -> String {
    settings.name.clone().unwrap_or_else(|| {
        stl.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| stl.display().to_string())
    })
}

/// Reads and validates a design and integrates its mass properties. Errors name the file.
pub fn load_design(stl: &Path) -> Result<LoadedDesign> {
    let settings = DesignSettings::for_stl(stl)?;
    let file = || stl.display().to_string();
    let (soup, format) = read_stl_file(stl).with_context(file)?;
    let valid = validate(weld(&soup)).with_context(file)?;
    let mut warnings = valid.warnings;
    let scale = settings.units.to_metres();
    let mesh = valid.mesh.scaled(scale);
    let mass = MassProperties::of_mesh(&mesh, settings.density);
    let frame = MechanismFrame::new(
        settings.crank_pin_m,
        settings.piston_pin_m,
        settings.pin_axis,
    )
    .with_context(file)?;
    let (lo, hi) = PLAUSIBLE_MASS_KG;
    if !(lo..=hi).contains(&mass.mass) {
        warnings.push(format!(
            "mass {:.4e} kg is implausible for a connecting rod ({lo}–{hi} kg): are the units right? (sidecar `units`, now {})",
            mass.mass,
            settings.units.symbol()
        ));
    }
    Ok(LoadedDesign {
        name: design_name(stl, &settings),
        file: stl.to_path_buf(),
        format,
        settings,
        mesh,
        mass,
        frame,
        warnings,
    })
}

/// Stage 1 for one file: [`load_design`], the bore check, and the report record. A solid whose
/// pins do not sit in bores is an error (the mechanism needs them).
pub fn mass_of_design(stl: &Path) -> Result<DesignMass> {
    let d = load_design(stl)?;
    rod_record(&d, stl)
}

/// Stage 1 for any closed solid (`rodstudy mass`): the mass properties always; the
/// mechanism-frame fields (l1, offsets, I_zz, I_xx, I_yy, centre distance, bore radii) are NaN,
/// written as JSON `null`, with a warning saying why, when the pins do not sit in bores.
/// File and surface defects are still errors.
pub fn mass_of_solid(stl: &Path) -> Result<DesignMass> {
    Ok(solid_mass(&load_design(stl)?))
}

/// Stage 1 of a loaded design: the bore check and the record ([`mass_of_design`]).
pub fn rod_mass(d: &LoadedDesign) -> Result<DesignMass> {
    rod_record(d, &d.file)
}

/// [`mass_of_solid`] of a loaded design.
pub fn solid_mass(d: &LoadedDesign) -> DesignMass {
    let stl = d.file.as_path();
    match rod_record(d, stl) {
        Ok(r) => r,
        Err(e) => {
            let mut r = record(d, stl, None);
            r.warnings.push(format!(
                "no mechanism-frame properties (l1, I_zz, I_xx, bores: null): {e:#}"
            ));
            r
        }
    }
}

/// The bore check and the mechanism frame of a loaded design.
fn rod_record(d: &LoadedDesign, stl: &Path) -> Result<DesignMass> {
    let surface = RodSurface::new(&d.mesh).with_context(|| stl.display().to_string())?;
    let scale = d.settings.units.to_metres();
    let units = d.settings.units.symbol();
    let bore = |pin: &str, centre| {
        surface
            .bore_radius(pin, centre, d.frame.z, scale, units)
            .with_context(|| stl.display().to_string())
    };
    let crank_bore = bore("crank pin (A)", d.settings.crank_pin_m)?;
    let piston_bore = bore("piston pin (B)", d.settings.piston_pin_m)?;
    let rod = RodInFrame::new(&d.frame, &d.mass);
    if !(rod.l1_m > 0.0 && rod.l1_m < rod.centre_distance_m) {
        bail!(
            "{}: the centroid lies outside the span between the pins (l1 = {:.4} m, A→B = {:.4} m): check the pin positions",
            stl.display(),
            rod.l1_m,
            rod.centre_distance_m
        );
    }
    Ok(record(d, stl, Some((rod, crank_bore, piston_bore))))
}

/// The record; the mechanism-frame fields NaN when `rod` is `None`.
fn record(d: &LoadedDesign, stl: &Path, rod: Option<(RodInFrame, f64, f64)>) -> DesignMass {
    let m = &d.mass;
    let nan = f64::NAN;
    let (rod, crank_bore, piston_bore) = match rod {
        Some((r, a, b)) => (Some(r), a, b),
        None => (None, nan, nan),
    };
    let pick = |f: fn(&RodInFrame) -> f64| rod.as_ref().map_or(nan, f);
    DesignMass {
        design: d.name.clone(),
        id: stl
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        file: stl.display().to_string(),
        format: format!("{:?}", d.format).to_lowercase(),
        triangles: d.mesh.triangles.len(),
        vertices: d.mesh.vertices.len(),
        units: d.settings.units.symbol().to_string(),
        density_kg_m3: d.settings.density,
        volume_m3: m.volume,
        mass_kg: m.mass,
        centroid_m: m.centroid.into(),
        inertia_about_centroid_kgm2: m.inertia.transpose().into(),
        principal_moments_kgm2: m.principal_moments.into(),
        principal_axes: m.principal_axes.into(),
        l1_m: pick(|r| r.l1_m),
        offset_m: pick(|r| r.offset_m),
        offset_z_m: pick(|r| r.offset_z_m),
        i_zz_kgm2: pick(|r| r.i_zz_kgm2),
        i_xx_kgm2: pick(|r| r.i_xx_kgm2),
        i_yy_kgm2: pick(|r| r.i_yy_kgm2),
        centre_distance_m: pick(|r| r.centre_distance_m),
        crank_bore_radius_m: crank_bore,
        piston_bore_radius_m: piston_bore,
        warnings: d.warnings.clone(),
    }
}

/// The STL files named by `paths`: files as given, folders searched (not recursively) for
/// `*.stl` (any case), sorted by name.
pub fn find_stl_files(paths: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for path in paths {
        if path.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(path)
                .with_context(|| format!("{}: cannot list the folder", path.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.is_file() && p.extension().is_some_and(|e| e.eq_ignore_ascii_case("stl"))
                })
                .collect();
            found.sort();
            if found.is_empty() {
                bail!("{}: no .stl files in this folder", path.display());
            }
            files.extend(found);
        } else if path.is_file() {
            files.push(path.clone());
        } else {
            bail!("{}: no such file or folder", path.display());
        }
    }
    Ok(files)
}
