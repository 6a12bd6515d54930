//! The settings of a command on one design (`fem`, `cycle`), resolved once: the flags as clap
//! parsed them (the low-level arguments: `--config`, [`MeshArgs`], `--force`) and the
//! configuration file become one value, each number checked once by the rule of the key it
//! overrides ([`crate::config::check_element_size`], [`crate::config::check_target_error`]),
//! which the command hands to the stages (the model: ripgrep's `LowArgs` → `HiArgs`).

use super::mesh_args::MeshArgs;
use crate::config::StudyConfig;
use crate::stages::fem::MeshMode;
use anyhow::{Result, bail};
use std::path::Path;

/// What a command on one design runs with.
pub struct DesignSettings {
    /// The configuration (`--config`, else `rodstudy.toml`, else the defaults) with the mesh
    /// flags folded in: `--target-error` is `fem.target_error`, `--size` is `fem.mesh_size_mm`
    /// with `fem.target_error` 0.
    pub config: StudyConfig,
    /// How stage 3 meshes: the user's mesh (`--mesh`), else the configuration's choice.
    pub mode: MeshMode,
    /// `--force` (N), checked positive; `None`: the design's peak pin force.
    pub force_n: Option<f64>,
}

impl DesignSettings {
    /// Reads the configuration and folds the flags into it, each checked once.
    pub fn resolve(
        config_file: Option<&Path>,
        mesh: &MeshArgs,
        force_n: Option<f64>,
    ) -> Result<Self> {
        let mut config = StudyConfig::load(config_file)?;
        let mode = mesh.fold_into(&mut config)?;
        if let Some(f) = force_n
            && !(f.is_finite() && f > 0.0)
        {
            bail!("--force must be a positive number of newtons, got {f}");
        }
        Ok(DesignSettings {
            config,
            mode,
            force_n,
        })
    }

    /// The target error of adaptive refinement: the configuration's (or `--target-error`), else
    /// the default's where the configuration asks for one fixed mesh (`fem --convergence`, which
    /// runs the adaptive sequence beside uniform meshes).
    pub fn target_error(&self) -> f64 {
        if self.config.fem.adaptive() {
            self.config.fem.target_error
        } else {
            crate::config::FemConfig::default().target_error
        }
    }
}
