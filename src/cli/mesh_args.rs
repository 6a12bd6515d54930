//! The mesh arguments `fem` and `cycle` share (`#[command(flatten)]`), folded into the
//! configuration they override ([`super::settings::DesignSettings`]).

use crate::config::{StudyConfig, check_element_size, check_target_error};
use crate::stages::fem::MeshMode;
use anyhow::{Result, bail};
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct MeshArgs {
    /// Use this ready volume mesh (gmsh .msh, Abaqus/CalculiX .inp, VTU, Nastran .bdf; tet10)
    /// as it is, instead of meshing the STL.
    #[arg(long, conflicts_with_all = ["size", "target_error"])]
    pub mesh: Option<PathBuf>,
    /// One fixed mesh of this element size [mm] (the thesis' setting is 5), instead of adaptive
    /// refinement.
    #[arg(long, conflicts_with = "target_error")]
    pub size: Option<f64>,
    /// Refine adaptively until the estimated relative error of each case's judged peak is at
    /// most this (default: `fem.target_error` of the configuration, 0.03).
    #[arg(long)]
    pub target_error: Option<f64>,
}

impl MeshArgs {
    /// Folds the flags into `config`, each checked by the rule of the key it overrides:
    /// `--size` is `fem.mesh_size_mm` with `fem.target_error` 0 (one fixed mesh),
    /// `--target-error` is `fem.target_error`. Returns the mesh mode: the user's mesh
    /// (`--mesh`), else the (overridden) configuration's choice.
    pub(super) fn fold_into(&self, config: &mut StudyConfig) -> Result<MeshMode> {
        if let Some(size) = self.size {
            check_element_size("--size", size)?;
            config.fem.mesh_size_mm = size;
            config.fem.target_error = 0.0;
        }
        if let Some(t) = self.target_error {
            if t == 0.0 {
                bail!("--target-error must be above 0; for one fixed mesh give --size MM");
            }
            check_target_error("--target-error", t)?;
            config.fem.target_error = t;
        }
        Ok(match &self.mesh {
            Some(file) if !file.is_file() => {
                bail!("{}: no such mesh file (--mesh)", file.display())
            }
            Some(file) => MeshMode::User(file.clone()),
            None => MeshMode::from_config(config),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(size: Option<f64>, target_error: Option<f64>) -> MeshArgs {
        MeshArgs {
            mesh: None,
            size,
            target_error,
        }
    }

    /// The flags become the keys they override, and the mode is the overridden configuration's:
    /// `--size` one fixed mesh of that size, `--target-error` adaptive refinement to it.
    #[test]
    fn the_flags_are_the_keys_they_override() {
        let mut config = StudyConfig::default();
        let mode = args(Some(6.5), None).fold_into(&mut config).unwrap();
        assert_eq!(mode, MeshMode::Fixed(6.5));
        assert_eq!(
            (config.fem.mesh_size_mm, config.fem.target_error),
            (6.5, 0.0)
        );
        let mut config = StudyConfig::default();
        let mode = args(None, Some(0.05)).fold_into(&mut config).unwrap();
        assert_eq!(config.fem.target_error, 0.05);
        assert_eq!(mode, MeshMode::from_config(&config));
        let MeshMode::Adaptive(a) = mode else {
            panic!("adaptive")
        };
        assert_eq!(a.target_error, 0.05);
        let mut config = StudyConfig::default();
        assert_eq!(
            args(None, None).fold_into(&mut config).unwrap(),
            MeshMode::from_config(&StudyConfig::default())
        );
    }

    /// Out of range, a flag is refused by the rule of its key, named as the flag.
    #[test]
    fn a_flag_out_of_range_is_refused_by_name() {
        for (a, flag) in [
            (args(Some(1e-3), None), "--size"),
            (args(Some(f64::NAN), None), "--size"),
            (args(Some(2e4), None), "--size"),
            (args(None, Some(1.0)), "--target-error"),
            (args(None, Some(-0.1)), "--target-error"),
            (args(None, Some(0.0)), "--target-error"),
        ] {
            let e = a.fold_into(&mut StudyConfig::default()).unwrap_err();
            assert!(e.to_string().starts_with(flag), "{e}");
        }
    }
}
