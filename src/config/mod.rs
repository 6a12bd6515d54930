//! Study settings: an optional `rodstudy.toml` at the project root (or `--config FILE`); every
//! setting has the spec's default, unknown keys are errors, and a value out of its range (below
//! the physical floor, above the bounds [`MAX_OMEGA_RAD_S`], [`MAX_LENGTH_MM`], [`MAX_INSTANTS`]
//! …) is refused naming its key when the file is read, before any design is computed. A UTF-8
//! byte-order mark is skipped.
//!
//! ```toml
//! [driven]            # scene `driven` (SPEC Stage 2)
//! omega_rad_s = 125.66370614359172   # 40π
//! duration_s = 5.0
//! steps = 5000
//! gravity = true
//!
//! [fem]               # SPEC Stage 3
//! target_error = 0.03          # adaptive refinement to this estimated error of the peak; 0: one
//!                              # fixed mesh of mesh_size_mm
//! mesh_size_mm = 5.0           # the fixed mesh's size (the thesis' 5 mm)
//! initial_size_mm = 5.0        # adaptive: first mesh (uniform)
//! max_size_mm = 10.0           # adaptive: largest size, where the stress is low
//! min_size_mm = 0.3            # adaptive: smallest size (the STL's facet spacing floors it too)
//! step_min_size_mm = 0.1       # adaptive on a STEP's exact geometry: smallest size (an R1
//!                              # fillet needs elements of about R/8 to reach 3 %)
//! max_iterations = 5           # adaptive: most meshes
//! max_dofs = 400000            # adaptive: largest mesh
//! fixed_band_mm = 6.0          # band around the fixed bore left out of the judged peak
//! singular_band_mm = 3.0       # band around sharp re-entrant edges left out of it
//! youngs_modulus_pa = 210e9
//! poisson_ratio = 0.3
//! bore_load = "uniform"        # or "cosine": a cosine bearing pressure on the pressed half;
//!                              # or "contact": frictionless contact with rigid pins
//! clearance_a_mm = 0.0175      # contact: radial clearance of the crank pin in bore A
//!                              # (negative: interference); default 0.35 ‰ of the bore diameter
//! clearance_b_mm = 0.00875     # contact: the piston pin's in bore B; same default
//! pins = "rigid"               # contact: or "elastic" (pins of the rod's material around a
//!                              # rigid core) or "elastic-ends" (held at the bore's faces)
//! pin_inner_ratio = 0.2        # elastic pins: the core's (or the pin's bore's) radius over the bore's
//! load_model_error = true      # solve the other load models on the final mesh (the error bar's
//!                              # load-model part)
//!
//! [criterion]         # the ranking's stress criterion
//! yield_mpa = 355.0
//! safety_factor = 1.5
//! with_error = false  # judge the peak plus its estimated error instead of the peak
//! fatigue = true      # the criterion includes the cycle's local (FKM) fatigue factor …
//! fatigue_safety_factor = 1.5   # … which must be at least this
//! buckling_factor = 3.0         # the smallest accepted linear buckling load factor, judged
//!                               # when buckling is computed (in the study: with a pressure trace)
//!
//! [cycle]             # stress over one revolution (inertia relief, fatigue); with a pressure
//! enabled = true      # trace over the four-stroke cycle (720°, the gas force on the piston)
//! instants = 360      # per revolution, equally spaced, the first at crank angle 0
//!
//! [material]          # fatigue strengths (S355, EN 10025-2; material.rs gives the sources)
//! ultimate_mpa = 470.0          # R_m (S_ut)
//! yield_mpa = 355.0             # R_p
//! material_group = "steel"      # FKM material group (its constants)
//! # fatigue_limit_mpa = 211.5   # a tested σ_W,zd; absent: FKM's f_W,σ · R_m
//! surface_roughness_um = 200.0  # R_z: forged skin (machined 100, ground 12.5, polished 0)
//! surface_treatment = "none"    # or "shot_peened", "cold_rolled", "nitrided", …
//! overload = "constant_ratio"   # FKM F2 (or "constant_mean", F1)
//! j_s = 1.0                     # FKM safety factors: loads,
//! j_f = 1.5                     # fatigue strength,
//! j_g = 1.0                     # castings
//! endurance_mpa = 235.0         # the Goodman factor's S_e (Shigley's S'e = 0.5 Sut)
//! mean_stress = "goodman"       # or "gerber": the Goodman factor's mean-stress correction
//!
//! [engine]            # the mechanism around the rod (defaults: the thesis' test rig)
//! crank_radius_mm = 46.0
//! piston_mass_kg = 5.2269229374        # piston + pin + rings
//! crank_mass_kg = 8.9459574505
//! crank_inertia_kgm2 = 0.016438481547370   # about the main bearing O
//! crank_eccentricity_mm = 5.190636979      # crank centroid on OA, from O towards A
//! cylinder_bore_mm = 82.0              # piston area π D²/4, used only with a trace
//! # pressure_trace = "trace.csv"       # crank_angle_deg (0–720, 0 = firing TDC), pressure_bar
//! #                                    # (gauge); relative to this file's folder. None: no gas force
//! ```

mod engine;
mod material;

pub use engine::{EngineConfig, TracePath};
pub use material::MaterialConfig;

use crate::rod::pin_load::BoreLoad;
use crate::rod::pin_model::PinModel;
use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The `driven` scene as configured.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DrivenConfig {
    pub omega_rad_s: f64,
    pub duration_s: f64,
    pub steps: usize,
    pub gravity: bool,
}

impl Default for DrivenConfig {
    fn default() -> Self {
        DrivenConfig {
            omega_rad_s: 40.0 * std::f64::consts::PI,
            duration_s: 5.0,
            steps: 5000,
            gravity: true,
        }
    }
}

/// Mesh and material of the FEM stage.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FemConfig {
    /// Target estimated relative error of the judged peak (adaptive refinement); 0 = one fixed
    /// mesh of `mesh_size_mm`.
    pub target_error: f64,
    /// Element size of the fixed mesh, mm.
    pub mesh_size_mm: f64,
    /// Adaptive: uniform size of the first mesh, mm.
    pub initial_size_mm: f64,
    /// Adaptive: largest size (where the stress is low), mm.
    pub max_size_mm: f64,
    /// Adaptive: smallest size, mm.
    pub min_size_mm: f64,
    /// Adaptive on a STEP (the exact geometry, no facet floor): smallest size, mm. Below an STL's
    /// 0.3 mm, since a small fillet of the exact geometry is worth resolving (an R1 fillet
    /// needs about 0.12 mm elements); the default is not written into `results.json`.
    #[serde(skip_serializing_if = "FemConfig::is_default_step_min_size")]
    pub step_min_size_mm: f64,
    /// Adaptive: most meshes in the sequence.
    pub max_iterations: usize,
    /// Adaptive: most DOFs of a mesh.
    pub max_dofs: usize,
    /// Band around the fixed bore excluded from the judged peak, mm.
    pub fixed_band_mm: f64,
    /// Band around sharp re-entrant edges (singularities) excluded from the judged peak, mm.
    pub singular_band_mm: f64,
    pub youngs_modulus_pa: f64,
    pub poisson_ratio: f64,
    /// How a pin's force is spread over its bore: `"uniform"` (default, the thesis' setting) or
    /// `"cosine"` (a cosine bearing pressure on the half the pin presses on); the default is not
    /// written into `results.json`.
    #[serde(skip_serializing_if = "BoreLoad::is_uniform")]
    pub bore_load: BoreLoad,
    /// With `bore_load = "contact"` and for the load-model comparison: the radial clearance of the
    /// crank pin in bore A, mm (negative: an interference); absent: 0.35 ‰ of the bore's
    /// diameter ([`crate::rod::bores::default_clearance_m`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearance_a_mm: Option<f64>,
    /// The same for the piston pin in bore B, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearance_b_mm: Option<f64>,
    /// With contact: `"rigid"` pins (default, not written into `results.json`), `"elastic"` (of
    /// the rod's material, held at a rigid core) or `"elastic-ends"` (held at the bore's faces)
    /// ([`crate::rod::pin_model::PinModel`]).
    #[serde(skip_serializing_if = "PinModel::is_rigid")]
    pub pins: PinModel,
    /// Elastic pins: the core's (or the pin's bore's) radius over the bore's, in (0, 1); absent:
    /// 0.2.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pin_inner_ratio: Option<f64>,
    /// Solve the judged cases on the final mesh under the other load models too (uniform, cosine
    /// and contact): the load-model part of each case's error bar
    /// (`estimated_load_model_error_rel`). The default is not written into `results.json`.
    #[serde(skip_serializing_if = "is_true")]
    pub load_model_error: bool,
    /// `"auto"` (default): an STL rod symmetric about its mid-plane across the pin axis (within
    /// [`crate::stages::fem::MIRROR_TOLERANCE_MM`]) is meshed and solved as its half with
    /// u_z = 0 on the plane, then mirrored (the same answer on the same mesh, from half the
    /// DOFs; docs/fem.md); `"off"`: always the whole rod. The default is not written into `results.json`.
    #[serde(skip_serializing_if = "Symmetry::is_default")]
    pub symmetry: Symmetry,
}

/// Whether stage 3 uses a rod's mirror symmetry ([`FemConfig::symmetry`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Symmetry {
    /// Always the whole rod.
    Off,
    /// The half model where the surface is symmetric.
    #[default]
    Auto,
}

impl Symmetry {
    fn is_default(&self) -> bool {
        *self == Symmetry::default()
    }

    /// `self`, or what [`HALF_MODEL_VAR`] says: `1` as `"auto"`, `0` as `"off"`.
    pub fn overridden(self) -> Result<Self> {
        match std::env::var(HALF_MODEL_VAR).as_deref() {
            Ok("1") => Ok(Symmetry::Auto),
            Ok("0") => Ok(Symmetry::Off),
            Ok(other) => anyhow::bail!(
                "{HALF_MODEL_VAR} must be 1 (the half model of a symmetric rod, as [fem] symmetry = \"auto\") or 0 (the whole rod), got {other:?}"
            ),
            Err(_) => Ok(self),
        }
    }
}

/// Environment variable overriding `[fem] symmetry` (for comparing the two routes, e.g. in
/// `bench fem --adaptive`): `1` as `"auto"`, `0` as `"off"`.
pub const HALF_MODEL_VAR: &str = "RODSTUDY_HALF_MODEL";

fn is_true(v: &bool) -> bool {
    *v
}

impl FemConfig {
    /// The default of `step_min_size_mm`.
    pub const STEP_MIN_SIZE_MM: f64 = 0.1;

    fn is_default_step_min_size(v: &f64) -> bool {
        *v == Self::STEP_MIN_SIZE_MM
    }
}

impl Default for FemConfig {
    fn default() -> Self {
        FemConfig {
            target_error: 0.03,
            mesh_size_mm: 5.0,
            initial_size_mm: 5.0,
            max_size_mm: 10.0,
            min_size_mm: 0.3,
            step_min_size_mm: FemConfig::STEP_MIN_SIZE_MM,
            max_iterations: 5,
            max_dofs: 400_000,
            fixed_band_mm: 6.0,
            singular_band_mm: 3.0,
            youngs_modulus_pa: 210e9,
            poisson_ratio: 0.3,
            bore_load: BoreLoad::Uniform,
            clearance_a_mm: None,
            clearance_b_mm: None,
            pins: PinModel::Rigid,
            pin_inner_ratio: None,
            load_model_error: true,
            symmetry: Symmetry::Auto,
        }
    }
}

impl FemConfig {
    /// True when stage 3 refines adaptively.
    pub fn adaptive(&self) -> bool {
        self.target_error > 0.0
    }
}

/// The stress criterion of the ranking: σ_allowed = yield / safety factor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CriterionConfig {
    pub yield_mpa: f64,
    pub safety_factor: f64,
    /// Judge the peak plus its estimated error (the upper end of the error bar) instead of the peak.
    pub with_error: bool,
    /// Include the cycle stage's fatigue safety factor in the criterion (when the stage runs).
    pub fatigue: bool,
    /// The smallest accepted local (FKM) fatigue safety factor.
    pub fatigue_safety_factor: f64,
    /// The smallest accepted linear buckling load factor λ₁ (buckling load / peak compression),
    /// judged where buckling is computed (the study: with `[engine] pressure_trace`). Written
    /// only when not the default, so default results keep their bytes.
    #[serde(skip_serializing_if = "CriterionConfig::is_default_buckling_factor")]
    pub buckling_factor: f64,
}

impl CriterionConfig {
    /// The default smallest accepted buckling load factor.
    pub const DEFAULT_BUCKLING_FACTOR: f64 = 3.0;

    fn is_default_buckling_factor(v: &f64) -> bool {
        *v == Self::DEFAULT_BUCKLING_FACTOR
    }
}

impl Default for CriterionConfig {
    fn default() -> Self {
        CriterionConfig {
            yield_mpa: 355.0,
            safety_factor: 1.5,
            with_error: false,
            fatigue: true,
            fatigue_safety_factor: 1.5,
            buckling_factor: CriterionConfig::DEFAULT_BUCKLING_FACTOR,
        }
    }
}

/// The cycle stage: stress over one revolution.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CycleConfig {
    /// Run the stage in the study.
    pub enabled: bool,
    /// Instants over the revolution (≥ 360), the first at crank angle 0.
    pub instants: usize,
}

impl Default for CycleConfig {
    fn default() -> Self {
        CycleConfig {
            enabled: true,
            instants: 360,
        }
    }
}

/// Upper bounds of the settings: beyond them a value is a typo or a unit slip, and the stages
/// would overflow or run for days. The fastest crank of any engine turns below 1e4 rad/s (95 000
/// rpm); no rod, bore or mesh size reaches 10 m; no structural metal is 100 GPa strong.
pub const MAX_OMEGA_RAD_S: f64 = 1e4;
/// Largest length setting, mm (10 m).
pub const MAX_LENGTH_MM: f64 = 1e4;
/// Largest strength setting, MPa.
pub const MAX_STRENGTH_MPA: f64 = 1e5;
/// Largest safety or load factor.
pub const MAX_FACTOR: f64 = 1e3;
/// Largest mass (kg) or inertia (kg·m²) of the engine's parts.
pub const MAX_MASS_KG: f64 = 1e6;
/// Smallest element size setting, mm (10 µm).
pub const MIN_MESH_SIZE_MM: f64 = 0.01;
/// Most cycle instants (0.01° apart over a revolution).
pub const MAX_INSTANTS: usize = 36_000;

/// An element size setting, mm: a number between [`MIN_MESH_SIZE_MM`] and [`MAX_LENGTH_MM`]; the
/// one rule of `[fem]`'s sizes and of `--size`, whose `name` the message gives.
pub fn check_element_size(name: &str, v: f64) -> Result<()> {
    if !(v.is_finite() && (MIN_MESH_SIZE_MM..=MAX_LENGTH_MM).contains(&v)) {
        bail!(
            "{name} = {v:e} is out of range: it must be a number of mm between {MIN_MESH_SIZE_MM} \
             and {MAX_LENGTH_MM:e} (finer elements resolve nothing of a rod and take gmsh beyond \
             its time limit)"
        );
    }
    Ok(())
}

/// The target estimated relative error of adaptive refinement: in [0, 1), 0 for one fixed mesh;
/// the one rule of `fem.target_error` and of `--target-error`, whose `name` the message gives.
pub fn check_target_error(name: &str, t: f64) -> Result<()> {
    if !(t.is_finite() && (0.0..1.0).contains(&t)) {
        bail!("{name} must lie in [0, 1) (0: one fixed mesh), got {t}");
    }
    Ok(())
}

/// Refuses the first `(key, value, max, unit)` whose value exceeds its max, naming the key.
fn check_upper_bounds(bounds: &[(&str, f64, f64, &str)]) -> Result<()> {
    for &(key, v, max, unit) in bounds {
        if v > max {
            let unit = if unit.is_empty() {
                String::new()
            } else {
                format!(" {unit}")
            };
            bail!("`{key}` = {v:e} is out of range: it must be at most {max:e}{unit}");
        }
    }
    Ok(())
}

/// Everything a study can be configured with.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StudyConfig {
    pub driven: DrivenConfig,
    pub fem: FemConfig,
    pub criterion: CriterionConfig,
    pub cycle: CycleConfig,
    pub material: MaterialConfig,
    /// Not written when it is the default (the thesis' rig, no trace): default results stay as
    /// they were before the section existed.
    #[serde(skip_serializing_if = "EngineConfig::is_default")]
    pub engine: EngineConfig,
}

impl StudyConfig {
    /// Reads and checks a configuration file.
    pub fn read(path: &Path) -> Result<Self> {
        // bytes that are not UTF-8 (a Latin-1 comment) are read as U+FFFD: in a comment they do
        // not matter, elsewhere TOML refuses them with their line
        let bytes = std::fs::read(path)
            .with_context(|| format!("{}: cannot read the configuration", path.display()))?;
        let text = String::from_utf8_lossy(&bytes);
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let mut config: StudyConfig = toml::from_str(text)
            .with_context(|| format!("{}: invalid configuration", path.display()))?;
        config.engine.resolve(path);
        config
            .check()
            .with_context(|| format!("{}: invalid configuration", path.display()))?;
        Ok(config)
    }

    /// `path` if given, else `rodstudy.toml` in the current folder if it exists, else defaults;
    /// `[fem] symmetry` as [`HALF_MODEL_VAR`] overrides it (so that what was run is what the
    /// configuration records, and what keys the study's cache).
    pub fn load(path: Option<&Path>) -> Result<Self> {
        let mut config = match path {
            Some(p) => Self::read(p)?,
            None if Path::new("rodstudy.toml").is_file() => Self::read(Path::new("rodstudy.toml"))?,
            None => Self::default(),
        };
        config.fem.symmetry = config.fem.symmetry.overridden()?;
        Ok(config)
    }

    fn check(&self) -> Result<()> {
        let positive = [
            ("driven.omega_rad_s", self.driven.omega_rad_s),
            ("driven.duration_s", self.driven.duration_s),
            ("fem.mesh_size_mm", self.fem.mesh_size_mm),
            ("fem.initial_size_mm", self.fem.initial_size_mm),
            ("fem.max_size_mm", self.fem.max_size_mm),
            ("fem.min_size_mm", self.fem.min_size_mm),
            ("fem.step_min_size_mm", self.fem.step_min_size_mm),
            ("fem.fixed_band_mm", self.fem.fixed_band_mm),
            ("fem.singular_band_mm", self.fem.singular_band_mm),
            ("fem.youngs_modulus_pa", self.fem.youngs_modulus_pa),
            ("criterion.yield_mpa", self.criterion.yield_mpa),
            ("criterion.safety_factor", self.criterion.safety_factor),
            (
                "criterion.fatigue_safety_factor",
                self.criterion.fatigue_safety_factor,
            ),
            ("criterion.buckling_factor", self.criterion.buckling_factor),
        ];
        for (key, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                bail!("`{key}` must be a positive number, got {v}");
            }
        }
        for (key, c) in [
            ("fem.clearance_a_mm", self.fem.clearance_a_mm),
            ("fem.clearance_b_mm", self.fem.clearance_b_mm),
        ] {
            if let Some(c) = c
                && !(c.is_finite() && c.abs() < 1.0)
            {
                bail!(
                    "`{key}` must be a radial clearance under 1 mm (negative: an interference), got {c} mm"
                );
            }
        }
        if let Some(r) = self.fem.pin_inner_ratio
            && !(r > 0.0 && r < 1.0)
        {
            bail!("`fem.pin_inner_ratio` must lie between 0 and 1 (exclusive), got {r}");
        }
        check_upper_bounds(&[
            (
                "driven.omega_rad_s",
                self.driven.omega_rad_s,
                MAX_OMEGA_RAD_S,
                "rad/s (20 000 rpm is 2094 rad/s)",
            ),
            ("driven.duration_s", self.driven.duration_s, 3600.0, "s"),
            (
                "fem.mesh_size_mm",
                self.fem.mesh_size_mm,
                MAX_LENGTH_MM,
                "mm",
            ),
            (
                "fem.initial_size_mm",
                self.fem.initial_size_mm,
                MAX_LENGTH_MM,
                "mm",
            ),
            ("fem.max_size_mm", self.fem.max_size_mm, MAX_LENGTH_MM, "mm"),
            (
                "fem.fixed_band_mm",
                self.fem.fixed_band_mm,
                MAX_LENGTH_MM,
                "mm",
            ),
            (
                "fem.singular_band_mm",
                self.fem.singular_band_mm,
                MAX_LENGTH_MM,
                "mm",
            ),
            (
                "criterion.yield_mpa",
                self.criterion.yield_mpa,
                MAX_STRENGTH_MPA,
                "MPa",
            ),
            (
                "criterion.safety_factor",
                self.criterion.safety_factor,
                MAX_FACTOR,
                "",
            ),
            (
                "criterion.fatigue_safety_factor",
                self.criterion.fatigue_safety_factor,
                MAX_FACTOR,
                "",
            ),
            (
                "criterion.buckling_factor",
                self.criterion.buckling_factor,
                MAX_FACTOR,
                "",
            ),
        ])?;
        for (key, v) in [
            ("fem.mesh_size_mm", self.fem.mesh_size_mm),
            ("fem.initial_size_mm", self.fem.initial_size_mm),
            ("fem.max_size_mm", self.fem.max_size_mm),
            ("fem.min_size_mm", self.fem.min_size_mm),
            ("fem.step_min_size_mm", self.fem.step_min_size_mm),
        ] {
            check_element_size(&format!("`{key}`"), v)?;
        }
        let e = self.fem.youngs_modulus_pa;
        if !(1e9..=1e12).contains(&e) {
            bail!(
                "`fem.youngs_modulus_pa` is in Pa and must lie between 1e9 and 1e12 (aluminium 7e10, \
                 titanium 1.1e11, steel 2.1e11), got {e}{}",
                if (1e3..1e6).contains(&e) {
                    format!(": that looks like MPa, i.e. {:e} Pa", e * 1e6)
                } else {
                    String::new()
                }
            );
        }
        check_target_error("`fem.target_error`", self.fem.target_error)?;
        if self.fem.max_iterations == 0 || self.fem.max_dofs < 1000 {
            bail!("`fem.max_iterations` must be at least 1 and `fem.max_dofs` at least 1000");
        }
        if !(360..=MAX_INSTANTS).contains(&self.cycle.instants) {
            bail!(
                "`cycle.instants` must lie between 360 and {MAX_INSTANTS} (0.01° apart; each \
                 instant costs a pass over the mesh), got {}",
                self.cycle.instants
            );
        }
        if self.fem.max_iterations > 100 {
            bail!(
                "`fem.max_iterations` must be at most 100, got {}",
                self.fem.max_iterations
            );
        }
        self.material.check()?;
        let max_steps = crate::mechanism::scene::MAX_STEPS;
        if self.driven.steps == 0 || self.driven.steps > max_steps {
            bail!(
                "`driven.steps` must be between 1 and {max_steps}, got {}",
                self.driven.steps
            );
        }
        let f = &self.fem;
        if !(f.min_size_mm <= f.max_size_mm
            && f.step_min_size_mm <= f.max_size_mm
            && f.initial_size_mm <= f.max_size_mm
            && f.min_size_mm <= f.initial_size_mm)
        {
            bail!(
                "the mesh sizes must be ordered `fem.min_size_mm` ({}) ≤ `fem.initial_size_mm` ({}) \
                 ≤ `fem.max_size_mm` ({}), and `fem.step_min_size_mm` ({}) ≤ `fem.max_size_mm`",
                f.min_size_mm,
                f.initial_size_mm,
                f.max_size_mm,
                f.step_min_size_mm
            );
        }
        let nu = self.fem.poisson_ratio;
        if !(nu.is_finite() && (-1.0..0.5).contains(&nu)) {
            bail!("`fem.poisson_ratio` must lie in [-1, 0.5), got {nu}");
        }
        self.engine.check()?;
        Ok(())
    }

    /// The `driven` scene these settings describe.
    pub fn driven_scene(&self) -> crate::mechanism::DrivenScene {
        crate::mechanism::DrivenScene {
            omega_rad_s: self.driven.omega_rad_s,
            duration_s: self.driven.duration_s,
            steps: self.driven.steps,
            ..Default::default()
        }
    }
}

impl From<&FemConfig> for crate::fem::Material {
    /// The elastic constants of stage 3 and the cycle.
    fn from(c: &FemConfig) -> Self {
        crate::fem::Material {
            youngs_modulus_pa: c.youngs_modulus_pa,
            poisson_ratio: c.poisson_ratio,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partial_files_keep_the_other_defaults_and_typos_are_refused() {
        let c: StudyConfig = toml::from_str("[driven]\ngravity = false\n").unwrap();
        assert!(!c.driven.gravity);
        assert_eq!(c.driven.steps, 5000);
        assert_eq!(c.fem, FemConfig::default());
        let e = toml::from_str::<StudyConfig>("[driven]\nspeed = 3.0\n").unwrap_err();
        assert!(e.to_string().contains("unknown field `speed`"), "{e}");
        let bad: StudyConfig = toml::from_str("[fem]\npoisson_ratio = 0.5\n").unwrap();
        assert!(bad.check().is_err());
    }

    #[test]
    fn the_pins_are_rigid_unless_said_and_an_inner_ratio_lies_in_0_1() {
        assert_eq!(FemConfig::default().pins, PinModel::Rigid);
        let c: StudyConfig =
            toml::from_str("[fem]\npins = \"elastic-ends\"\npin_inner_ratio = 0.5\n").unwrap();
        assert_eq!(c.fem.pins, PinModel::ElasticEnds);
        c.check().unwrap();
        let e = toml::from_str::<StudyConfig>("[fem]\npins = \"soft\"\n").unwrap_err();
        assert!(e.to_string().contains("unknown variant"), "{e}");
        let bad: StudyConfig = toml::from_str("[fem]\npin_inner_ratio = 1.0\n").unwrap();
        let e = bad.check().unwrap_err().to_string();
        assert!(e.contains("pin_inner_ratio"), "{e}");
    }
}
