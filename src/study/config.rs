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
//! mesh_size_mm = 5.0
//! youngs_modulus_pa = 210e9
//! poisson_ratio = 0.3
//!
//! [criterion]         # the ranking's stress criterion
//! yield_mpa = 355.0
//! safety_factor = 1.5
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
    pub mesh_size_mm: f64,
    pub youngs_modulus_pa: f64,
    pub poisson_ratio: f64,
}

impl Default for FemConfig {
    fn default() -> Self {
        FemConfig {
            mesh_size_mm: 5.0,
            youngs_modulus_pa: 210e9,
            poisson_ratio: 0.3,
        }
    }
}

/// The stress criterion of the ranking: σ_allowed = yield / safety factor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CriterionConfig {
    pub yield_mpa: f64,
    pub safety_factor: f64,
}

impl Default for CriterionConfig {
    fn default() -> Self {
        CriterionConfig {
            yield_mpa: 355.0,
            safety_factor: 1.5,
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
            ("fem.youngs_modulus_pa", self.fem.youngs_modulus_pa),
            ("criterion.yield_mpa", self.criterion.yield_mpa),
            ("criterion.safety_factor", self.criterion.safety_factor),
        ];
        for (key, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                bail!("`{key}` must be a positive number, got {v}");
            }
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
