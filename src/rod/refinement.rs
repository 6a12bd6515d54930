//! Mesh refinement study: the rod analysed at several element sizes, to show which stress measure
//! converges (the maximum away from the fixed bore) and which does not (the peak at the fixed edge,
//! a singularity).

use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::bores::BoreSpec;
use super::records::LoadCaseResult;
use super::solve::{RodOptions, solve_rod};
use crate::fem::error::{FemError, Result};
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;
use crate::fem::statics::Timings;

/// The stress measures of one case at one size.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CaseMeasures {
    /// The case ([`super::cases`]).
    pub name: String,
    /// Max element-nodal von Mises, MPa.
    pub max_unaveraged_mpa: f64,
    /// Max nodally averaged von Mises, MPa.
    pub max_averaged_mpa: f64,
    /// Max nodally averaged von Mises outside the band around the fixed bore (and, with the
    /// options stage 3 passes, the bands along the sharp re-entrant edges): the judged stress, MPa.
    pub max_away_from_fixed_mpa: f64,
    /// Max displacement, mm.
    pub max_displacement_mm: f64,
    /// Estimated relative error of the "away" maximum.
    pub estimated_error_rel: f64,
    /// The recovery estimates on this mesh.
    pub error_estimate: crate::fem::estimate::EstimateSummary,
}

impl From<&LoadCaseResult> for CaseMeasures {
    fn from(c: &LoadCaseResult) -> Self {
        CaseMeasures {
            name: c.name.clone(),
            max_unaveraged_mpa: c.max_von_mises_unaveraged_mpa,
            max_averaged_mpa: c.max_von_mises_averaged_mpa,
            max_away_from_fixed_mpa: c.max_von_mises_away_from_fixed_mpa,
            max_displacement_mm: c.max_displacement_mm,
            estimated_error_rel: c.estimated_error_rel,
            error_estimate: c.error_estimate,
        }
    }
}

/// One size of a refinement study.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RefinementLevel {
    /// Target element size, mm.
    pub size_mm: f64,
    /// Mean element edge length of the mesh, mm.
    pub mean_edge_mm: f64,
    /// Nodes.
    pub nodes: usize,
    /// Elements.
    pub elements: usize,
    /// DOFs.
    pub dofs: usize,
    /// Stored entries of the Cholesky factor.
    pub nnz_l: usize,
    /// The load cases, in the order of [`super::cases::STATIC_CASES`].
    pub cases: Vec<CaseMeasures>,
    /// Meshing time, s (0 when the mesh was given).
    pub mesh_s: f64,
    /// Analysis times.
    pub timings: Timings,
    /// Analysis wall time, s.
    pub solve_total_s: f64,
}

impl RefinementLevel {
    /// The case named `name`.
    pub fn case(&self, name: &str) -> Option<&CaseMeasures> {
        self.cases.iter().find(|c| c.name == name)
    }
}

/// A refinement study.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RefinementStudy {
    /// Force magnitude, N.
    pub force_n: f64,
    /// Band around the fixed bore excluded from the "away" measure, the same at every size, mm.
    pub fixed_band_mm: f64,
    /// Levels, in the order of the sizes given.
    pub levels: Vec<RefinementLevel>,
}

/// Runs the rod analysis at each size with meshes from `mesher(size_mm) -> (mesh, seconds)`.
/// The band around the fixed bore is `options.fixed_band_m`, else the largest size, at every level.
pub fn refinement_study(
    sizes_mm: &[f64],
    mut mesher: impl FnMut(f64) -> Result<(TetMesh, f64)>,
    material: &Material,
    bores: &BoreSpec,
    force_n: f64,
    options: &RodOptions,
) -> Result<RefinementStudy> {
    if sizes_mm.is_empty() || sizes_mm.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(FemError::InvalidInput(format!(
            "refinement sizes must be > 0 mm, got {sizes_mm:?}"
        )));
    }
    let band = options
        .fixed_band_m
        .unwrap_or(sizes_mm.iter().copied().fold(0.0, f64::max) * 1e-3);
    let opts = RodOptions {
        fixed_band_m: Some(band),
        ..options.clone()
    };
    let mut levels = Vec::new();
    for &size in sizes_mm {
        let (mesh, mesh_s) = mesher(size)?;
        let t = Instant::now();
        let r = solve_rod(&mesh, material, bores, force_n, &opts)?;
        levels.push(RefinementLevel {
            size_mm: size,
            mean_edge_mm: r.mean_edge_mm,
            nodes: r.nodes,
            elements: r.elements,
            dofs: r.dofs,
            nnz_l: r.nnz_l,
            cases: r.cases.iter().map(CaseMeasures::from).collect(),
            mesh_s,
            timings: r.timings,
            solve_total_s: t.elapsed().as_secs_f64(),
        });
    }
    Ok(RefinementStudy {
        force_n,
        fixed_band_mm: band * 1e3,
        levels,
    })
}
