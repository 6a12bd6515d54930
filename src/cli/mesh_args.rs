//! The mesh arguments `fem` and `cycle` share (`#[command(flatten)]`), resolved once into a
//! [`MeshMode`].

use crate::config::StudyConfig;
use crate::stages::fem::{AdaptiveMeshing, MeshMode};
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
    /// The mesh mode asked for (checked): the user's mesh, one fixed size, adaptive refinement to
    /// `--target-error`, else the configuration's choice.
    pub fn mode(&self, config: &StudyConfig) -> Result<MeshMode> {
        use crate::config::{MAX_LENGTH_MM, MIN_MESH_SIZE_MM};
        if let Some(size) = self.size
            && !(size.is_finite() && (MIN_MESH_SIZE_MM..=MAX_LENGTH_MM).contains(&size))
        {
            bail!(
                "--size must be a number of mm between {MIN_MESH_SIZE_MM} and {MAX_LENGTH_MM:e} \
                 (the settings' range of element sizes), got {size:e}"
            );
        }
        if let Some(t) = self.target_error
            && !(t.is_finite() && t > 0.0 && t < 1.0)
        {
            bail!("--target-error must lie in (0, 1), got {t}");
        }
        if let Some(file) = &self.mesh
            && !file.is_file()
        {
            bail!("{}: no such mesh file (--mesh)", file.display());
        }
        Ok(match (&self.mesh, self.size, self.target_error) {
            (Some(file), _, _) => MeshMode::User(file.clone()),
            (None, Some(size), _) => MeshMode::Fixed(size),
            (None, None, Some(t)) => MeshMode::Adaptive(AdaptiveMeshing::new(&config.fem, t)),
            (None, None, None) => MeshMode::from_config(config),
        })
    }
}
