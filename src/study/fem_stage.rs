//! Stage 3 for one design: mesh the STL with gmsh (tet10, `pipeline/mesh_rod.py`), solve the two
//! load cases F_x and F_y of the design's peak pin force, judge the stress criterion (SPEC
//! "Stage 3", "Outputs").
//!
//! The criterion is judged on the convergent measure, the maximum nodally averaged von Mises
//! stress at least one element size away from the fixed bore (the fully fixed bore edge is a
//! singularity whose peak grows with refinement); the raw peak is reported beside it.

use super::config::StudyConfig;
use crate::fem::mesh::gmsh::{MeshReport, convert_mesh, mesh_stl};
use crate::fem::{BoreSpec, FemResult, Material, RodOptions, solve_rod};
use crate::geometry::sidecar::DesignSettings;
use crate::python_env::{pipeline_script, python};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The mesher script in `pipeline/`.
pub const MESHER: &str = "mesh_rod.py";

/// How the mesh was made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeshSummary {
    /// `gmsh from the STL` or the user's mesh file.
    pub source: String,
    pub size_mm: Option<f64>,
    pub elements: usize,
    pub nodes: usize,
    /// Smallest signed inverse condition number of gmsh's quality measures (1 = perfect).
    pub min_sicn: Option<f64>,
    pub min_scaled_jacobian: Option<f64>,
    pub seconds: f64,
}

/// The stress criterion applied to one design.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StressVerdict {
    /// yield / safety factor [MPa].
    pub allowed_mpa: f64,
    /// The larger of the F_x and F_y convergent measures [MPa]: what is judged.
    pub governing_mpa: f64,
    /// `fx` or `fy`: the case that governs.
    pub governing_case: String,
    /// The larger raw 5 mm peak (element-nodal, unaveraged, at the fixed edge) [MPa], for reference.
    pub raw_peak_mpa: f64,
    /// yield / governing stress.
    pub safety_factor: f64,
    pub pass: bool,
}

/// The stage-3 record of one design.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DesignFem {
    /// Load magnitude of both cases: the design's peak pin force [N].
    pub force_n: f64,
    pub mesh: MeshSummary,
    pub fem: FemResult,
    pub criterion: StressVerdict,
}

/// Meshes (or reads `user_mesh`) and solves one design; VTU files go to `vtu_dir`.
pub fn fem_of_design(
    stl: &Path,
    force_n: f64,
    config: &StudyConfig,
    work_dir: &Path,
    vtu_dir: &Path,
    user_mesh: Option<&Path>,
) -> Result<DesignFem> {
    let context = || format!("{}: FEM", stl.display());
    let settings = DesignSettings::for_stl(stl)?;
    let python = python().with_context(context)?;
    let script = pipeline_script(MESHER);
    std::fs::create_dir_all(work_dir)
        .with_context(|| format!("{}: cannot create", work_dir.display()))?;
    let (mesh, summary) = match user_mesh {
        Some(file) => {
            let start = std::time::Instant::now();
            let out = work_dir.join("user.rodmesh");
            let mesh = convert_mesh(&python, &script, file, &out, settings.units.symbol())
                .with_context(|| format!("{}: cannot use this volume mesh", file.display()))?;
            let summary = MeshSummary {
                source: file.display().to_string(),
                size_mm: None,
                elements: mesh.n_elements(),
                nodes: mesh.n_nodes(),
                min_sicn: None,
                min_scaled_jacobian: None,
                seconds: start.elapsed().as_secs_f64(),
            };
            (mesh, summary)
        }
        None => {
            let meshed = mesh_stl(&python, &script, stl, config.fem.mesh_size_mm, work_dir)
                .with_context(context)?;
            let r: &MeshReport = &meshed.report;
            let summary = MeshSummary {
                source: "gmsh from the STL (straight-sided tet10)".into(),
                size_mm: Some(r.size_mm),
                elements: r.elements,
                nodes: r.nodes,
                min_sicn: Some(r.min_sicn),
                min_scaled_jacobian: Some(r.min_scaled_jacobian),
                seconds: r.seconds_wall.max(r.seconds_total),
            };
            (meshed.mesh, summary)
        }
    };
    let mm = |v: nalgebra::Vector3<f64>| [v.x * 1e3, v.y * 1e3, v.z * 1e3];
    let axis = settings.pin_axis;
    let bores = BoreSpec::from_mm(
        mm(settings.crank_pin_m),
        mm(settings.piston_pin_m),
        [axis.x, axis.y, axis.z],
    );
    let material = Material {
        youngs_modulus_pa: config.fem.youngs_modulus_pa,
        poisson_ratio: config.fem.poisson_ratio,
    };
    let options = RodOptions {
        vtu_dir: Some(vtu_dir.to_path_buf()),
        vtu_stem: Some("fem".into()),
        ..RodOptions::default()
    };
    let fem = solve_rod(&mesh, &material, &bores, force_n, &options).with_context(context)?;
    let criterion = verdict(&fem, config);
    Ok(DesignFem {
        force_n,
        mesh: summary,
        fem,
        criterion,
    })
}

/// Judges the stress criterion on the convergent measure.
pub fn verdict(fem: &FemResult, config: &StudyConfig) -> StressVerdict {
    let allowed = config.criterion.yield_mpa / config.criterion.safety_factor;
    let (fx, fy) = (
        fem.fx.max_von_mises_away_from_fixed_mpa,
        fem.fy.max_von_mises_away_from_fixed_mpa,
    );
    let (governing, case) = if fy >= fx { (fy, "fy") } else { (fx, "fx") };
    StressVerdict {
        allowed_mpa: allowed,
        governing_mpa: governing,
        governing_case: case.into(),
        raw_peak_mpa: fem
            .fx
            .max_von_mises_unaveraged_mpa
            .max(fem.fy.max_von_mises_unaveraged_mpa),
        safety_factor: config.criterion.yield_mpa / governing,
        pass: governing <= allowed,
    }
}
