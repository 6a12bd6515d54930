//! Stage 1 for one design file: read, weld, validate, integrate, place the pins (from the
//! sidecar, else found from the geometry), map to the mechanism frame, check the bores, and the
//! record that reports it.
//!
//! Pins: values in the sidecar always win. When it gives neither pin, [`find_pins`] looks for the
//! two pin bores (restricted to the sidecar's `pin_axis` if given). A rod without any cylindrical
//! bore (e.g. square bores) falls back to the spec's mechanism (A at the origin, B 180 mm along
//! x, axis z), which the bore check then has to accept; any other refusal of the finder (one
//! bore, three candidates, axes not parallel, equal radii) is an error of [`mass_of_design`] (and
//! a warning of [`mass_of_solid`]). A pin in a partial bore (an arc open on one side: a big end
//! modelled without its cap) is accepted when the finder measured that arc: the ray along the
//! pin axis must still be clear, the radius is the arc's fitted radius, and a warning says the
//! loads act on the existing arc. Sidecar pins whose in-plane rays leave the part get the same
//! treatment if a partial bore's axis passes through them. The arcs are reported in
//! [`PinsReport`]: 360 for a bore the in-plane rays find closed, the finder's measure otherwise.

use super::bore_check::RodSurface;
use super::bore_finder::{FoundPins, PinSearchError, find_pins};
use super::error::MeshError;
use super::mass_properties::MassProperties;
use super::mechanism_frame::{MechanismFrame, RodInFrame};
use super::pin_bores::{Pin, PinsView, axis_name, pin_bore};
use super::sidecar::DesignSettings;
use super::step::{STEP_SCRIPT, StepReport, is_step, read_step};
use super::stl_file::{StlFormat, read_stl_file};
use super::validate::{ValidMesh, validate};
use super::weld::{IndexedMesh, near_weld_tolerance, weld, weld_within};
use crate::python_env::{pipeline_script, python};
use anyhow::{Context, Result, bail};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Plausible mass range of a connecting rod [kg]; outside it the units are probably wrong.
pub const PLAUSIBLE_MASS_KG: (f64, f64) = (0.01, 100.0);

/// The mass range outside which a rod's stage 1 refuses the design [kg]: a millimetre file read
/// as metres weighs 1e9 times its mass (and a metre file read as mm 1e-9 times), so a rod from
/// a 10 g model to a 1000 kg marine rod lands outside it in the wrong units, and a scale model of
/// a few milligrams or a rod of tonnes inside it in the right ones.
pub const REFUSED_MASS_KG: (f64, f64) = (1e-6, 1e5);

/// Plausible distance between the pins of a connecting rod [m]: outside it the units are
/// probably wrong.
pub const PLAUSIBLE_CENTRE_DISTANCE_M: (f64, f64) = (0.005, 5.0);

/// What to do when a design's size says its units are wrong, fitted to the kind of file: an STL
/// has no unit of its own (the sidecar's `units` says it); a STEP declares one, which the
/// sidecar's `units` overrides.
fn units_advice(file: &Path, format: &DesignFormat, settings: &DesignSettings) -> String {
    let sidecar = super::sidecar::sidecar_path(file);
    let sidecar = sidecar.file_name().map_or_else(
        || sidecar.display().to_string(),
        |n| n.to_string_lossy().into(),
    );
    let now = settings.units.symbol();
    match format {
        DesignFormat::Stl(_) => format!(
            "an STL has no unit of its own: its numbers are read as {now} (`units` in \
             {sidecar}; mm, cm, m or in)"
        ),
        DesignFormat::Step(_) if settings.units_given => format!(
            "the sidecar's `units = \"{now}\"` overrides the unit the STEP declares: check it, \
             or remove it from {sidecar} to take the declared unit"
        ),
        DesignFormat::Step(_) => {
            let declared = std::fs::read(file)
                .ok()
                .and_then(|b| super::step::declared_length_unit(&String::from_utf8_lossy(&b)))
                .map_or_else(|| "no readable unit".into(), |(name, _)| plural(&name));
            format!(
                "the STEP declares {declared}; if its numbers are in another unit (an export \
                 that declares mm but writes metres), write `units = \"m\"` (or cm, in, mm) in \
                 {sidecar}: it overrides the declared unit"
            )
        }
    }
}

/// A unit's name in the plural, as the messages say it ("millimetres", "inches", "feet").
fn plural(name: &str) -> String {
    match name {
        "inch" => "inches".into(),
        "foot" => "feet".into(),
        _ => format!("{name}s"),
    }
}

/// A design loaded and validated: its settings, its surface in metres and its mass properties.
pub struct LoadedDesign {
    pub name: String,
    pub file: PathBuf,
    pub format: DesignFormat,
    pub settings: DesignSettings,
    /// Validated, outward-oriented surface in metres.
    pub mesh: IndexedMesh,
    pub mass: MassProperties,
    pub frame: MechanismFrame,
    /// Where the pins came from and where they are.
    pub pins: Pins,
    pub warnings: Vec<String>,
    /// Vertices merged by the tolerant weld (0 when equality by value closed the surface).
    pub vertices_merged: usize,
    /// Bodies that do not touch: the gap between the nearest two groups [m] (a lower bound).
    pub loose_gap_m: Option<f64>,
}

/// The kind of design file.
#[derive(Debug, Clone)]
pub enum DesignFormat {
    /// An STL (binary or ASCII): mass properties of the polyhedron.
    Stl(StlFormat),
    /// A STEP file read through gmsh's OpenCASCADE kernel: exact B-rep mass properties, and
    /// stage 3 on the exact geometry ([`super::step`]).
    Step(StepReport),
}

impl DesignFormat {
    /// `binary`, `ascii` or `step`, as the record's `format` says.
    pub fn name(&self) -> &'static str {
        match self {
            DesignFormat::Stl(StlFormat::Binary) => "binary",
            DesignFormat::Stl(StlFormat::Ascii) => "ascii",
            DesignFormat::Step(_) => "step",
        }
    }

    /// The STEP reader's report, for a STEP design.
    pub fn step(&self) -> Option<&StepReport> {
        match self {
            DesignFormat::Step(r) => Some(r),
            DesignFormat::Stl(_) => None,
        }
    }
}

/// Where a design's pin centres came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum PinsSource {
    /// Given in the sidecar.
    #[default]
    Sidecar,
    /// Found from the geometry by [`find_pins`].
    Found,
    /// No sidecar pins and no cylindrical bore to find: the spec's mechanism.
    Default,
}

/// The pins of a loaded design (metres).
#[derive(Debug, Clone, PartialEq)]
pub struct Pins {
    pub crank_m: Vector3<f64>,
    pub piston_m: Vector3<f64>,
    /// Unit pin axis.
    pub axis: Vector3<f64>,
    pub source: PinsSource,
    /// The bores, when found from the geometry.
    pub found: Option<FoundPins>,
    /// Why the finder gave no pins, when it was asked and refused.
    pub search_error: Option<PinSearchError>,
}

/// What the record says about the pins (see the module documentation). Serialized in the
/// mass record only when it says something the sidecar did not: pins found from the geometry
/// or taken from the spec's default, or a partial bore.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PinsReport {
    /// `sidecar`, `found` or `default`.
    pub pins_source: PinsSource,
    pub crank_pin_file_units: [f64; 3],
    pub piston_pin_file_units: [f64; 3],
    pub pin_axis: [f64; 3],
    /// Arc of the crank bore A [deg]: 360 for a full bore.
    pub crank_bore_arc_deg: f64,
    /// Arc of the piston bore B [deg].
    pub piston_bore_arc_deg: f64,
    /// The bores as the finder measured them (metres), when found.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub found: Option<FoundPins>,
}

impl Default for PinsReport {
    fn default() -> Self {
        PinsReport {
            pins_source: PinsSource::Sidecar,
            crank_pin_file_units: [f64::NAN; 3],
            piston_pin_file_units: [f64::NAN; 3],
            pin_axis: [f64::NAN; 3],
            crank_bore_arc_deg: 360.0,
            piston_bore_arc_deg: 360.0,
            found: None,
        }
    }
}

impl PinsReport {
    /// Pins from the sidecar sitting in full bores: nothing to add to the record's JSON.
    pub fn says_nothing_new(&self) -> bool {
        self.pins_source == PinsSource::Sidecar
            && self.crank_bore_arc_deg == 360.0
            && self.piston_bore_arc_deg == 360.0
    }
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
    /// Vertices merged because they lay within the welding tolerance of another (an export's
    /// rounding); in the JSON only when not 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub vertices_merged: usize,
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
    /// Where the pins came from; in the JSON only when found, defaulted or in a partial bore.
    #[serde(default, skip_serializing_if = "PinsReport::says_nothing_new")]
    pub pins: PinsReport,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
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
    let scale = settings.units.to_metres();
    let (soup, format, mut warnings) = if is_step(stl) {
        // the exact solid through gmsh/OpenCASCADE, and a triangulation of it for the bore
        // check, the frame and the stage-3 surface
        let python = python().with_context(file)?;
        let dir = tempfile::tempdir().with_context(file)?;
        let surface = dir.path().join("surface.stl");
        let mut report = read_step(&python, &pipeline_script(STEP_SCRIPT), stl, &surface)?;
        let (soup, _) = read_stl_file(&surface).with_context(file)?;
        let mut notes = Vec::new();
        if settings.units_given {
            let (metres_per_unit, note) = step_units_override(stl, &settings)?;
            report.metres_per_unit = metres_per_unit;
            notes.extend(note);
        }
        if report.solids_in_file > 1 {
            notes.push(report.description());
        }
        // a folder's NAME.stl beside NAME.step is not studied (find_stl_files): say so
        for ext in ["stl", "STL", "Stl"] {
            let beside = stl.with_extension(ext);
            if beside.is_file() {
                notes.push(format!(
                    "{} beside it: a study of the folder takes the STEP's exact geometry as the \
                     design and leaves the STL out",
                    beside.display()
                ));
                break;
            }
        }
        (soup, DesignFormat::Step(report), notes)
    } else {
        let (soup, format) = read_stl_file(stl).with_context(file)?;
        (soup, DesignFormat::Stl(format), Vec::new())
    };
    let (valid, vertices_merged) = validate_welded(weld(&soup), &format).with_context(file)?;
    warnings.extend(valid.warnings);
    let loose_gap = valid.loose_gap;
    let mesh_scale = format.step().map_or(scale, |r| r.metres_per_unit);
    let (mesh, mass) = match format.step() {
        Some(report) => (
            valid.mesh.scaled(report.metres_per_unit),
            report.mass_properties(report.metres_per_unit, settings.density),
        ),
        None => {
            let mesh = valid.mesh.scaled(scale);
            let mass = MassProperties::of_mesh(&mesh, settings.density);
            (mesh, mass)
        }
    };
    let pins = place_pins(&settings, &mesh);
    let frame = MechanismFrame::new(pins.crank_m, pins.piston_m, pins.axis).with_context(file)?;
    let (lo, hi) = PLAUSIBLE_MASS_KG;
    let advice = || units_advice(stl, &format, &settings);
    if !(lo..=hi).contains(&mass.mass) {
        warnings.push(format!(
            "mass {:.4e} kg is implausible for a connecting rod ({lo}–{hi} kg): are the units \
             right? {}",
            mass.mass,
            advice()
        ));
    }
    let (short, long) = PLAUSIBLE_CENTRE_DISTANCE_M;
    if pins.source != PinsSource::Default && !(short..=long).contains(&frame.centre_distance) {
        warnings.push(format!(
            "{:.4e} m between the pins is implausible for a connecting rod ({} mm – {} m): are \
             the units right? {}",
            frame.centre_distance,
            short * 1e3,
            long,
            advice()
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
        pins,
        warnings,
        vertices_merged,
        loose_gap_m: loose_gap.map(|g| g * mesh_scale),
    })
}

/// The sidecar's `units` for a STEP: its numbers are read in them, whatever unit the file
/// declares. OpenCASCADE hands over millimetres converted from the declared unit (d mm per
/// declared unit), so a number n of the file is n·d of its millimetres, and n sidecar units:
/// metres per OpenCASCADE millimetre = (metres per sidecar unit) / d. A warning names both units
/// when they differ.
fn step_units_override(step: &Path, settings: &DesignSettings) -> Result<(f64, Option<String>)> {
    let bytes = std::fs::read(step).with_context(|| format!("{}: cannot read", step.display()))?;
    let text = String::from_utf8_lossy(&bytes);
    let units = settings.units;
    let Some((declared, mm)) = super::step::declared_length_unit(&text) else {
        bail!(
            "{}: the sidecar's `units = \"{}\"` is to override the length unit the STEP file \
             declares, but the file declares none that can be read (no SI_UNIT of .METRE. nor \
             an inch or foot CONVERSION_BASED_UNIT): remove `units` to take OpenCASCADE's \
             reading, or export the STEP again with its unit",
            step.display(),
            units.symbol()
        );
    };
    let metres_per_unit = units.to_metres() / mm;
    let same = (units.to_metres() / (mm * 1e-3) - 1.0).abs() < 1e-12;
    let note = (!same).then(|| {
        format!(
            "the file declares its lengths in {}; the sidecar's `units = \"{}\"` \
             overrides that: its numbers are read as {} (pin centres in the sidecar too)",
            plural(&declared),
            units.symbol(),
            units.symbol()
        )
    });
    Ok((metres_per_unit, note))
}

/// [`validate`], and when the surface is open, once more after merging the vertices closer than
/// [`near_weld_tolerance`] (an export that wrote one vertex as `0.0` and as `6.9e-15`): the
/// validated mesh and how many vertices were merged. A surface that stays open is refused with
/// the error of the unmerged one, its holes measured.
fn validate_welded(
    mesh: IndexedMesh,
    format: &DesignFormat,
) -> Result<(ValidMesh, usize), MeshError> {
    let open = match validate(mesh.clone()) {
        Err(e @ MeshError::Open { .. }) => e,
        other => return other.map(|v| (v, 0)),
    };
    let (merged, near) = weld_within(&mesh, near_weld_tolerance(&mesh));
    if near.vertices_merged == 0 {
        return Err(open);
    }
    let mut valid = match validate(merged) {
        Ok(v) => v,
        Err(MeshError::Open { .. }) => return Err(open),
        Err(e) => return Err(e),
    };
    let what = match format {
        DesignFormat::Step(_) => "the STEP's triangulation",
        DesignFormat::Stl(_) => "the STL",
    };
    valid.warnings.push(format!(
        "{} vertices of {what} lay within {:.1e} file units of another (rounding in the export) \
         and were merged{}; the surface is closed",
        near.vertices_merged,
        near.tolerance,
        match near.triangles_dropped {
            0 => String::new(),
            n => format!(", dropping {n} sliver triangle(s) thinner than that"),
        }
    ));
    Ok((valid, near.vertices_merged))
}

/// The pins: the sidecar's, else found from the geometry, else (no cylindrical bore at all)
/// the spec's default.
fn place_pins(settings: &DesignSettings, mesh: &IndexedMesh) -> Pins {
    if let (Some(crank_m), Some(piston_m)) = (settings.crank_pin_m, settings.piston_pin_m) {
        return Pins {
            crank_m,
            piston_m,
            axis: settings.pin_axis.unwrap_or_else(Vector3::z),
            source: PinsSource::Sidecar,
            found: None,
            search_error: None,
        };
    }
    match find_pins(mesh, settings.pin_axis, settings.units) {
        Ok(f) => Pins {
            crank_m: f.crank.centre_v(),
            piston_m: f.piston.centre_v(),
            axis: Vector3::from(f.axis),
            source: PinsSource::Found,
            found: Some(f),
            search_error: None,
        },
        Err(e) => {
            let (crank_m, piston_m, axis) = settings.default_pins();
            Pins {
                crank_m,
                piston_m,
                axis,
                source: PinsSource::Default,
                found: None,
                search_error: Some(e),
            }
        }
    }
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
    let file = || stl.display().to_string();
    let (lo, hi) = REFUSED_MASS_KG;
    if !(lo..=hi).contains(&d.mass.mass) {
        bail!(
            "{}: mass {:.4e} kg cannot be a connecting rod's ({lo:e}–{hi:e} kg): the units or \
             the density are wrong (a part read in units 1000 times too small or too large weighs \
             1e-9 or 1e9 times its mass; {}; `density`, now {} kg/m³: steel is 7850)",
            stl.display(),
            d.mass.mass,
            units_advice(stl, &d.format, &d.settings),
            d.settings.density
        );
    }
    if let Some(e) = &d.pins.search_error
        && !matches!(e, PinSearchError::NoBore(_))
    {
        bail!(
            "{}: the pins cannot be found from the geometry: {e}",
            stl.display()
        );
    }
    let surface = RodSurface::new(&d.mesh).with_context(file)?;
    let mut warnings = Vec::new();
    // the bores the geometry shows, once, for sidecar pins to be checked against
    let bores = std::sync::OnceLock::new();
    let view = PinsView {
        mesh: &d.mesh,
        units: d.settings.units,
        axis: d.frame.z,
        crank: d.pins.crank_m,
        piston: d.pins.piston_m,
        from_sidecar: d.pins.source == PinsSource::Sidecar,
        axis_given: d.settings.pin_axis.is_some(),
        found: d.pins.found.as_ref(),
    };
    // the two pins side by side, their warnings in order (the crank's first)
    let bore_of = |pin| {
        let mut warnings = Vec::new();
        let r = pin_bore(&view, &surface, pin, &bores, &mut warnings).with_context(file);
        (r, warnings)
    };
    let ((crank, crank_warnings), (piston, piston_warnings)) =
        rayon::join(|| bore_of(Pin::Crank), || bore_of(Pin::Piston));
    let crank = match (crank, &d.pins.search_error) {
        (Err(e), Some(why)) => {
            return Err(e.context(format!(
                "{}: the sidecar gives no pins and none were found from the geometry ({why}); the spec's default pins (A at the origin, B 180 mm along x, axis {}) do not sit in bores either",
                stl.display(),
                axis_name(d.pins.axis)
            )));
        }
        (r, _) => r?,
    };
    warnings.extend(crank_warnings);
    let piston = piston?;
    warnings.extend(piston_warnings);
    if d.pins.source == PinsSource::Sidecar && crank.radius < 0.95 * piston.radius {
        let mm = 1.0 / d.settings.units.to_metres();
        let u = d.settings.units.symbol();
        warnings.push(format!(
            "the sidecar's crank pin (A) sits in the smaller bore (radius {:.3} {u}) and its \
             piston pin (B) in the larger ({:.3} {u}): a rod's big end is at the crank; if the \
             pins are swapped, exchange `crank_pin` and `piston_pin` (l1 is measured from A)",
            crank.radius * mm,
            piston.radius * mm
        ));
    }
    let rod = RodInFrame::new(&d.frame, &d.mass);
    if !(rod.l1_m > 0.0 && rod.l1_m < rod.centre_distance_m) {
        bail!(
            "{}: the centroid lies outside the span between the pins (l1 = {:.4} m, A→B = {:.4} m): check the pin positions",
            stl.display(),
            rod.l1_m,
            rod.centre_distance_m
        );
    }
    let mut r = record(d, stl, Some((rod, crank.radius, piston.radius)));
    r.pins.crank_bore_arc_deg = crank.arc_deg;
    r.pins.piston_bore_arc_deg = piston.arc_deg;
    r.warnings.extend(warnings);
    Ok(r)
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
    let scale = d.settings.units.to_metres();
    let in_file = |p: Vector3<f64>| (p / scale).into();
    DesignMass {
        design: d.name.clone(),
        id: stl
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        file: stl.display().to_string(),
        format: d.format.name().to_string(),
        triangles: d.mesh.triangles.len(),
        vertices: d.mesh.vertices.len(),
        vertices_merged: d.vertices_merged,
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
        pins: PinsReport {
            pins_source: d.pins.source,
            crank_pin_file_units: in_file(d.pins.crank_m),
            piston_pin_file_units: in_file(d.pins.piston_m),
            pin_axis: d.pins.axis.into(),
            crank_bore_arc_deg: d.pins.found.as_ref().map_or(360.0, |f| f.crank.arc_deg),
            piston_bore_arc_deg: d.pins.found.as_ref().map_or(360.0, |f| f.piston.arc_deg),
            found: d.pins.found.clone(),
        },
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
                    p.is_file()
                        && (p.extension().is_some_and(|e| e.eq_ignore_ascii_case("stl"))
                            || is_step(p))
                })
                .collect();
            found.sort();
            // NAME.step beside NAME.stl: the exact geometry is the design, the STL is not a second
            // one (it is the design when the STEP cannot be read: stages::mass::load)
            let stems_with_step: std::collections::HashSet<PathBuf> = found
                .iter()
                .filter(|p| is_step(p))
                .map(|p| p.with_extension(""))
                .collect();
            found.retain(|p| is_step(p) || !stems_with_step.contains(&p.with_extension("")));
            if found.is_empty() {
                bail!(
                    "{}: no .stl files in this folder (nor .step/.stp)",
                    path.display()
                );
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
