//! Study settings: an optional `rodstudy.toml` at the project root (or `--config FILE`); every
//! setting has the spec's default, unknown keys are errors.
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
//! max_iterations = 5           # adaptive: most meshes
//! max_dofs = 400000            # adaptive: largest mesh
//! fixed_band_mm = 6.0          # band around the fixed bore left out of the judged peak
//! singular_band_mm = 3.0       # band around sharp re-entrant edges left out of it
//! youngs_modulus_pa = 210e9
//! poisson_ratio = 0.3
//!
//! [criterion]         # the ranking's stress criterion
//! yield_mpa = 355.0
//! safety_factor = 1.5
//! with_error = false  # judge the peak plus its estimated error instead of the peak
//! fatigue = true      # the criterion includes the cycle's fatigue safety factor …
//! fatigue_safety_factor = 1.5   # … which must be at least this
//!
//! [cycle]             # stress over one revolution (inertia relief, fatigue)
//! enabled = true
//! instants = 360      # equally spaced, the first at crank angle 0
//!
//! [material]          # fatigue strengths (S355: EN 10025-2 minimum tensile strength; Shigley's
//! ultimate_mpa = 470.0          # S'e = 0.5 Sut for steels, no Marin factors)
//! endurance_mpa = 235.0
//! ```

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
}

impl Default for FemConfig {
    fn default() -> Self {
        FemConfig {
            target_error: 0.03,
            mesh_size_mm: 5.0,
            initial_size_mm: 5.0,
            max_size_mm: 10.0,
            min_size_mm: 0.3,
            max_iterations: 5,
            max_dofs: 400_000,
            fixed_band_mm: 6.0,
            singular_band_mm: 3.0,
            youngs_modulus_pa: 210e9,
            poisson_ratio: 0.3,
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
    /// The smallest accepted Goodman safety factor.
    pub fatigue_safety_factor: f64,
}

impl Default for CriterionConfig {
    fn default() -> Self {
        CriterionConfig {
            yield_mpa: 355.0,
            safety_factor: 1.5,
            with_error: false,
            fatigue: true,
            fatigue_safety_factor: 1.5,
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

/// Fatigue strengths of the rod's material.
///
/// Defaults: S355 structural steel, minimum tensile strength 470 MPa (EN 10025-2, 3–100 mm);
/// endurance limit of the polished rotating-beam specimen S'e = 0.5 Sut (Budynas–Nisbett,
/// *Shigley's Mechanical Engineering Design*, 10th ed., eq. 6-8), without Marin factors (surface,
/// size, reliability: set `endurance_mpa` to the corrected value for a real part).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MaterialConfig {
    pub ultimate_mpa: f64,
    pub endurance_mpa: f64,
}

impl Default for MaterialConfig {
    fn default() -> Self {
        MaterialConfig {
            ultimate_mpa: 470.0,
            endurance_mpa: 235.0,
        }
    }
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
}

impl StudyConfig {
    /// Reads and checks a configuration file.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("{}: cannot read the configuration", path.display()))?;
        let config: StudyConfig = toml::from_str(&text)
            .with_context(|| format!("{}: invalid configuration", path.display()))?;
        config
            .check()
            .with_context(|| format!("{}: invalid configuration", path.display()))?;
        Ok(config)
    }

    /// `path` if given, else `rodstudy.toml` in the current folder if it exists, else defaults.
    pub fn load(path: Option<&Path>) -> Result<Self> {
        match path {
            Some(p) => Self::read(p),
            None if Path::new("rodstudy.toml").is_file() => Self::read(Path::new("rodstudy.toml")),
            None => Ok(Self::default()),
        }
    }

    fn check(&self) -> Result<()> {
        let positive = [
            ("driven.omega_rad_s", self.driven.omega_rad_s),
            ("driven.duration_s", self.driven.duration_s),
            ("fem.mesh_size_mm", self.fem.mesh_size_mm),
            ("fem.initial_size_mm", self.fem.initial_size_mm),
            ("fem.max_size_mm", self.fem.max_size_mm),
            ("fem.min_size_mm", self.fem.min_size_mm),
            ("fem.fixed_band_mm", self.fem.fixed_band_mm),
            ("fem.singular_band_mm", self.fem.singular_band_mm),
            ("fem.youngs_modulus_pa", self.fem.youngs_modulus_pa),
            ("criterion.yield_mpa", self.criterion.yield_mpa),
            ("criterion.safety_factor", self.criterion.safety_factor),
            (
                "criterion.fatigue_safety_factor",
                self.criterion.fatigue_safety_factor,
            ),
            ("material.ultimate_mpa", self.material.ultimate_mpa),
            ("material.endurance_mpa", self.material.endurance_mpa),
        ];
        for (key, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                bail!("`{key}` must be a positive number, got {v}");
            }
        }
        let t = self.fem.target_error;
        if !(t.is_finite() && (0.0..1.0).contains(&t)) {
            bail!("`fem.target_error` must lie in [0, 1) (0: one fixed mesh), got {t}");
        }
        if self.fem.max_iterations == 0 || self.fem.max_dofs < 1000 {
            bail!("`fem.max_iterations` must be at least 1 and `fem.max_dofs` at least 1000");
        }
        if self.cycle.instants < 360 {
            bail!(
                "`cycle.instants` must be at least 360, got {}",
                self.cycle.instants
            );
        }
        if self.material.endurance_mpa >= self.material.ultimate_mpa {
            bail!("`material.endurance_mpa` must be below `material.ultimate_mpa`");
        }
        if self.driven.steps == 0 {
            bail!("`driven.steps` must be at least 1");
        }
        let nu = self.fem.poisson_ratio;
        if !(nu.is_finite() && (-1.0..0.5).contains(&nu)) {
            bail!("`fem.poisson_ratio` must lie in [-1, 0.5), got {nu}");
        }
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
}
