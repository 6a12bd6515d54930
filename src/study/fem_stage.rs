//! Stage 3 for one design: mesh the rod with gmsh (tet10, `pipeline/mesh_rod.py`), solve the two
//! load cases F_x and F_y of the design's peak pin force, refine adaptively until the estimated
//! error of the judged peak is at most the target (or keep one fixed mesh), judge the stress
//! criterion (SPEC "Stage 3", "Outputs").
//!
//! **Any units, any pose.** The validated surface (stage 1, metres in the file's axes) is written
//! as a binary STL in the rod frame, in millimetres: origin at the crank pin A, x̂ along A→B, ẑ the
//! pin axis (the mechanism frame of [`crate::geometry::mechanism_frame`]). gmsh's sizes and
//! tolerances are then always millimetres of a rod in one pose, whatever the CAD export's units
//! and placement, and the bores sit at (0, 0, 0) and (l, 0, 0). Locations in the results are rod
//! frame millimetres; the VTU files are in the same frame.
//!
//! The criterion is judged on the convergent measure, the maximum nodally averaged von Mises
//! stress outside a fixed physical band around the fixed bore (the fully fixed bore edge is a
//! singularity whose peak grows with refinement), optionally plus its estimated error; the raw
//! peak is reported beside it.

use super::config::StudyConfig;
use crate::fem::adapt::{AdaptOptions, MeshAsk, StopReason, adaptive_rod};
use crate::fem::facets::{FacetScale, reentrant_edges};
use crate::fem::mesh::gmsh::{MeshReport, MeshRequest, convert_mesh, mesh_stl_with};
use crate::fem::mesh::size_field::write_size_field;
use crate::fem::{BoreSpec, FemResult, Material, RodOptions, TetMesh};
use crate::geometry::design::load_design;
use crate::geometry::primitives::{binary_stl, to_soup};
use crate::geometry::simplify::simplify;
use crate::geometry::validate::validate;
use crate::python_env::{pipeline_script, python};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The mesher script in `pipeline/`.
pub const MESHER: &str = "mesh_rod.py";

/// The dihedral angle (degrees) of gmsh's first surface classification: edges sharper than this
/// are features, not facet kinks of a curved surface.
const FEATURE_ANGLE_DEG: f64 = 40.0;

/// How the mesh was made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeshSummary {
    /// `gmsh from the STL` or the user's mesh file.
    pub source: String,
    /// Uniform size of a fixed mesh, mm (`null` for adaptive and user meshes).
    pub size_mm: Option<f64>,
    pub elements: usize,
    pub nodes: usize,
    /// Smallest signed inverse condition number of gmsh's quality measures (1 = perfect).
    pub min_sicn: Option<f64>,
    pub min_scaled_jacobian: Option<f64>,
    /// Meshing time, s (all meshes of an adaptive sequence).
    pub seconds: f64,
    /// The frame of the mesh and of every location reported.
    #[serde(default)]
    pub frame: String,
    /// The adaptive sequence, when the mesh was refined adaptively.
    #[serde(default)]
    pub adaptive: Option<AdaptiveSummary>,
    /// Triangles of the STL export and of the surface given to gmsh after simplification.
    #[serde(default)]
    pub surface_triangles: [usize; 2],
}

/// How an adaptive sequence went.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AdaptiveSummary {
    /// Target estimated error of the judged peak.
    pub target_error_rel: f64,
    /// `converged`, `iteration_cap` or `dof_cap`.
    pub stop: StopReason,
    /// Meshes made.
    pub iterations: usize,
    /// Uniform size of the first mesh, mm.
    pub initial_size_mm: f64,
    /// Smallest size asked for, mm.
    pub min_size_mm: f64,
    /// How sizes are floored: the STL's facet spacing on curved surfaces.
    pub floor: String,
    /// Median facet spacing of the STL's curved surfaces, mm (the typical floor).
    pub facet_spacing_median_mm: f64,
    /// Whether each case's peak sequence changed monotonically (Richardson applies), fx and fy.
    pub monotone: [bool; 2],
}

/// The stress criterion applied to one design.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StressVerdict {
    /// yield / safety factor [MPa].
    pub allowed_mpa: f64,
    /// What is judged: the larger of the F_x and F_y convergent measures [MPa], plus its
    /// estimated error when `with_error`.
    pub governing_mpa: f64,
    /// `fx` or `fy`: the case that governs.
    pub governing_case: String,
    /// Estimated relative error of the governing case's peak.
    #[serde(default)]
    pub governing_error_rel: f64,
    /// Whether the peak plus its estimated error was judged.
    #[serde(default)]
    pub with_error: bool,
    /// The larger raw peak (element-nodal, unaveraged, at the fixed edge) [MPa], for reference.
    pub raw_peak_mpa: f64,
    /// yield / governing stress.
    pub safety_factor: f64,
    pub pass: bool,
    /// Where the linear, small-displacement model is out of its depth (peak above yield,
    /// displacement above 1 % of the centre distance); empty when it is not.
    #[serde(default)]
    pub model_validity: Vec<String>,
    /// The static verdict alone (`pass` also includes fatigue when it is judged).
    #[serde(default)]
    pub static_pass: bool,
    /// The cycle's Goodman safety factor and the smallest accepted, when fatigue is judged.
    #[serde(default)]
    pub fatigue_safety_factor: Option<f64>,
    #[serde(default)]
    pub fatigue_required: Option<f64>,
}

/// Adds the cycle's fatigue safety factor to the verdict when the configuration judges fatigue:
/// the design passes when it passes statically and its Goodman factor is at least
/// `criterion.fatigue_safety_factor`.
pub fn judge_fatigue(
    verdict: &mut StressVerdict,
    cycle: &super::cycle_stage::DesignCycle,
    config: &StudyConfig,
) {
    if !config.criterion.fatigue {
        return;
    }
    let required = config.criterion.fatigue_safety_factor;
    verdict.fatigue_safety_factor = Some(cycle.fatigue_safety_factor);
    verdict.fatigue_required = Some(required);
    verdict.pass = verdict.static_pass && cycle.fatigue_safety_factor >= required;
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

/// How stage 3 meshes: one fixed mesh, adaptive refinement, or the user's mesh.
#[derive(Debug, Clone, PartialEq)]
pub enum MeshMode {
    /// One gmsh mesh of this size, mm.
    Fixed(f64),
    /// Adaptive refinement with the settings of the configuration.
    Adaptive,
    /// The user's volume mesh (in the design's units and pose).
    User(PathBuf),
}

impl MeshMode {
    /// The configuration's choice: adaptive when `fem.target_error` > 0, else fixed.
    pub fn from_config(config: &StudyConfig) -> Self {
        if config.fem.adaptive() {
            MeshMode::Adaptive
        } else {
            MeshMode::Fixed(config.fem.mesh_size_mm)
        }
    }
}

/// The rod surface in the rod frame, mm, written as a binary STL for the mesher.
pub struct RodFrameSurface {
    /// The STL written.
    pub stl: PathBuf,
    /// Vertices (mm, rod frame) and triangles.
    pub vertices: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// Centre distance A→B in the plane of motion, mm.
    pub centre_distance_mm: f64,
    /// SHA-256 of the STL bytes (keys the classified-surface cache).
    pub digest: String,
    /// Rod frame (origin A, x̂, ŷ, ẑ) in the file's axes, metres, for meshes given by the user.
    pub frame: crate::geometry::mechanism_frame::MechanismFrame,
    /// File units → metres.
    pub to_metres: f64,
    /// Triangles of the export (the STL written has `triangles.len()`).
    pub triangles_export: usize,
    /// Largest distance of a kept vertex from the facets it absorbed, mm.
    pub simplify_max_error_mm: f64,
}

/// Tolerance of the simplification of the export before meshing, mm (5 µm: far below any element
/// size, above the float32 noise of a millimetre export).
pub const SIMPLIFY_TOLERANCE_MM: f64 = 0.005;

impl RodFrameSurface {
    /// The pin axes in the rod frame: A at the origin, B at (l, 0, 0), along z.
    pub fn bores(&self) -> BoreSpec {
        BoreSpec::from_mm(
            [0.0, 0.0, 0.0],
            [self.centre_distance_mm, 0.0, 0.0],
            [0.0, 0.0, 1.0],
        )
    }
}

/// Writes `work_dir/rod_frame.stl`: the validated surface of `stl` in the rod frame, mm.
pub fn rod_frame_surface(stl: &Path, work_dir: &Path) -> Result<RodFrameSurface> {
    use sha2::Digest;
    let d = load_design(stl)?;
    let f = &d.frame;
    let mut mesh = d.mesh.clone();
    for v in &mut mesh.vertices {
        let p = *v - f.origin;
        *v = nalgebra::Vector3::new(p.dot(&f.x), p.dot(&f.y), p.dot(&f.z)) * 1e3;
    }
    // what gmsh reads must not grow with the export's triangle count: flat facets cut into many
    // triangles merge back (zero error), curved ones stay within SIMPLIFY_TOLERANCE_MM
    let before = mesh.triangles.len();
    let (simplified, report) = simplify(&mesh, SIMPLIFY_TOLERANCE_MM);
    let mesh = match validate(simplified) {
        Ok(v) if v.warnings.is_empty() => v.mesh,
        _ => mesh,
    };
    let bytes = binary_stl(&to_soup(&mesh));
    std::fs::create_dir_all(work_dir)
        .with_context(|| format!("{}: cannot create", work_dir.display()))?;
    let path = work_dir.join("rod_frame.stl");
    super::atomic_write::write_atomic(&path, &bytes)?;
    Ok(RodFrameSurface {
        stl: path,
        vertices: mesh.vertices.iter().map(|v| [v.x, v.y, v.z]).collect(),
        triangles: mesh.triangles.clone(),
        centre_distance_mm: f.centre_distance * 1e3,
        digest: sha2::Sha256::digest(&bytes)
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect(),
        frame: *f,
        to_metres: d.settings.units.to_metres(),
        triangles_export: before,
        simplify_max_error_mm: report.max_error,
    })
}

/// Meshes (or reads the user's mesh) and solves one design; VTU files go to `vtu_dir`.
pub fn fem_of_design(
    stl: &Path,
    force_n: f64,
    config: &StudyConfig,
    work_dir: &Path,
    vtu_dir: &Path,
    mode: &MeshMode,
) -> Result<DesignFem> {
    Ok(fem_of_design_with_mesh(stl, force_n, config, work_dir, vtu_dir, mode)?.0)
}

/// The mesh stage 3 ended on, in the rod frame (m), with what a later stage on the same mesh
/// needs.
#[derive(Clone, Debug)]
pub struct StageMesh {
    pub mesh: TetMesh,
    pub bores: BoreSpec,
    /// Sharp re-entrant edges (m) and the bands left out of judged maxima (m).
    pub singular_edges_m: Vec<[[f64; 3]; 2]>,
    pub fixed_band_m: f64,
    pub singular_band_m: f64,
}

/// [`fem_of_design`], also returning the final mesh.
pub fn fem_of_design_with_mesh(
    stl: &Path,
    force_n: f64,
    config: &StudyConfig,
    work_dir: &Path,
    vtu_dir: &Path,
    mode: &MeshMode,
) -> Result<(DesignFem, StageMesh)> {
    let context = || format!("{}: FEM", stl.display());
    let python = python().with_context(context)?;
    let script = pipeline_script(MESHER);
    let surface = rod_frame_surface(stl, work_dir).with_context(context)?;
    let bores = surface.bores();
    let material = Material {
        youngs_modulus_pa: config.fem.youngs_modulus_pa,
        poisson_ratio: config.fem.poisson_ratio,
    };
    let singular_edges: Vec<[[f64; 3]; 2]> =
        reentrant_edges(&surface.vertices, &surface.triangles, FEATURE_ANGLE_DEG)
            .into_iter()
            .map(|s| s.map(|p| p.map(|v| v * 1e-3)))
            .collect();
    let rod = RodOptions {
        vtu_dir: Some(vtu_dir.to_path_buf()),
        vtu_stem: Some("fem".into()),
        fixed_band_m: Some(config.fem.fixed_band_mm * 1e-3),
        singular_edges_m: singular_edges.clone(),
        singular_band_m: Some(config.fem.singular_band_mm * 1e-3),
        ..RodOptions::default()
    };
    let frame =
        "rod frame, mm: origin at the crank pin A, x along A→B, z along the pin axis".into();
    let geometry = work_dir.join(format!("classified-{}.msh", &surface.digest[..16]));
    let request = |size_mm: f64, size_field: Option<&Path>, name: &str, dir: &Path| {
        mesh_stl_with(
            &python,
            &script,
            &surface.stl,
            &MeshRequest {
                size_mm,
                size_field,
                geometry: Some(&geometry),
                name: Some(name),
            },
            dir,
        )
    };
    let (fem, summary, mesh) = match mode {
        MeshMode::User(file) => {
            let start = std::time::Instant::now();
            let out = work_dir.join("user.rodmesh");
            let read = convert_mesh(&python, &script, file, &out, "mm")
                .with_context(|| format!("{}: cannot use this volume mesh", file.display()))?;
            // convert read the file's numbers as mm (×1e-3); the file is in the design's units
            let f = surface.frame;
            let s = surface.to_metres * 1e3;
            let mesh = read
                .map_nodes(|_, p| {
                    let q = nalgebra::Vector3::new(p[0], p[1], p[2]) * s - f.origin;
                    [q.dot(&f.x), q.dot(&f.y), q.dot(&f.z)]
                })
                .with_context(|| format!("{}: the mesh in the rod frame", file.display()))?;
            let fem = crate::fem::solve_rod(&mesh, &material, &bores, force_n, &rod)
                .with_context(context)?;
            let summary = MeshSummary {
                source: file.display().to_string(),
                size_mm: None,
                elements: mesh.n_elements(),
                nodes: mesh.n_nodes(),
                min_sicn: None,
                min_scaled_jacobian: None,
                seconds: start.elapsed().as_secs_f64(),
                frame,
                adaptive: None,
                surface_triangles: [surface.triangles_export, surface.triangles.len()],
            };
            (fem, summary, mesh)
        }
        MeshMode::Fixed(size_mm) => {
            let meshed =
                request(*size_mm, None, "rod", &work_dir.join("fixed")).with_context(context)?;
            let fem = crate::fem::solve_rod(&meshed.mesh, &material, &bores, force_n, &rod)
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
                frame,
                adaptive: None,
                surface_triangles: [surface.triangles_export, surface.triangles.len()],
            };
            (fem, summary, meshed.mesh)
        }
        MeshMode::Adaptive => {
            let facets = FacetScale::new(
                &surface.vertices,
                &surface.triangles,
                FEATURE_ANGLE_DEG,
                2.0,
            );
            let floor = |p: [f64; 3]| facets.at(p.map(|v| v * 1e3)) * 1e-3;
            let c = &config.fem;
            let opts = AdaptOptions {
                target_error_rel: c.target_error,
                initial_size_m: c.initial_size_mm * 1e-3,
                max_size_m: c.max_size_mm * 1e-3,
                min_size_m: c.min_size_mm * 1e-3,
                max_iterations: c.max_iterations,
                max_dofs: c.max_dofs,
                ..AdaptOptions::default()
            };
            let mut last_report: Option<MeshReport> = None;
            let mesher = |ask: &MeshAsk<'_>| -> crate::fem::Result<(TetMesh, f64)> {
                let dir = work_dir.join(format!("adapt{}", ask.iteration));
                std::fs::create_dir_all(&dir)
                    .map_err(|e| crate::fem::FemError::Mesher(format!("{}: {e}", dir.display())))?;
                let field_path = dir.join("size_field.bin");
                // gmsh can fail to remesh a faceted surface coarsely where thin features meet
                // ("overlapping facets"): a failed mesh is asked again with all sizes × 0.8
                let mut scale = 1.0;
                let mut tries = 0;
                let meshed = loop {
                    let field = match ask.size_map {
                        Some((m, s)) => {
                            let scaled: Vec<f64> = s.iter().map(|v| v * scale).collect();
                            write_size_field(&field_path, m, &scaled, 1e3)?;
                            Some(field_path.as_path())
                        }
                        None => None,
                    };
                    match request(ask.size_m * 1e3 * scale, field, "rod", &dir) {
                        Ok(m) => break m,
                        Err(e) if tries < 2 => {
                            eprintln!(
                                "{}: mesh {} failed, sizes × {:.2} next: {}",
                                stl.display(),
                                ask.iteration,
                                0.8 * scale,
                                e.to_string().lines().last().unwrap_or_default()
                            );
                            scale *= 0.8;
                            tries += 1;
                        }
                        Err(e) => return Err(e),
                    }
                };
                let secs = meshed.report.seconds_wall.max(meshed.report.seconds_total);
                last_report = Some(meshed.report);
                Ok((meshed.mesh, secs))
            };
            let out = adaptive_rod(mesher, &material, &bores, force_n, &rod, &opts, &floor)
                .with_context(context)?;
            let r = last_report.expect("at least one mesh");
            let iterations = out.solution.result.fx.adaptive.len();
            let summary = MeshSummary {
                source: "gmsh from the STL (straight-sided tet10), adaptive".into(),
                size_mm: None,
                elements: r.elements,
                nodes: r.nodes,
                min_sicn: Some(r.min_sicn),
                min_scaled_jacobian: Some(r.min_scaled_jacobian),
                seconds: out.mesh_s,
                frame,
                adaptive: Some(AdaptiveSummary {
                    target_error_rel: c.target_error,
                    stop: out.stop,
                    iterations,
                    initial_size_mm: c.initial_size_mm,
                    min_size_mm: c.min_size_mm,
                    floor: format!(
                        "the STL's local facet spacing on curved surfaces (kinks below {FEATURE_ANGLE_DEG}°), at least min_size_mm"
                    ),
                    facet_spacing_median_mm: facets.median_spacing(),
                    monotone: out.monotone,
                }),
                surface_triangles: [surface.triangles_export, surface.triangles.len()],
            };
            (out.solution.result, summary, out.mesh)
        }
    };
    let criterion = verdict(&fem, config, surface.centre_distance_mm);
    Ok((
        DesignFem {
            force_n,
            mesh: summary,
            fem,
            criterion,
        },
        StageMesh {
            mesh,
            bores,
            singular_edges_m: singular_edges,
            fixed_band_m: config.fem.fixed_band_mm * 1e-3,
            singular_band_m: config.fem.singular_band_mm * 1e-3,
        },
    ))
}

/// Displacements above this fraction of the centre distance are beyond small-displacement
/// theory (1 %: the rotation of the shank then changes the load path by more than the target
/// accuracy of the stress, 3 %, for a lever of about a third of the rod).
pub const LARGE_DISPLACEMENT_FRACTION: f64 = 0.01;

/// Judges the stress criterion on the convergent measure (plus its estimated error when the
/// configuration asks for it), and says where the linear, small-displacement model is out of its
/// depth: a peak above yield, a displacement above [`LARGE_DISPLACEMENT_FRACTION`] of the centre
/// distance `centre_distance_mm`.
pub fn verdict(fem: &FemResult, config: &StudyConfig, centre_distance_mm: f64) -> StressVerdict {
    let allowed = config.criterion.yield_mpa / config.criterion.safety_factor;
    let with_error = config.criterion.with_error;
    let judged = |c: &crate::fem::LoadCaseResult| {
        c.max_von_mises_away_from_fixed_mpa
            * if with_error {
                1.0 + c.estimated_error_rel
            } else {
                1.0
            }
    };
    let (fx, fy) = (judged(&fem.fx), judged(&fem.fy));
    let (governing, case, err) = if fy >= fx {
        (fy, "fy", fem.fy.estimated_error_rel)
    } else {
        (fx, "fx", fem.fx.estimated_error_rel)
    };
    let peak = fem
        .fx
        .max_von_mises_away_from_fixed_mpa
        .max(fem.fy.max_von_mises_away_from_fixed_mpa);
    let displacement = fem.fx.max_displacement_mm.max(fem.fy.max_displacement_mm);
    let mut model_validity = Vec::new();
    if peak > config.criterion.yield_mpa {
        model_validity.push(format!(
            "beyond yield: the peak, {peak:.0} MPa, exceeds the yield stress ({:.0} MPa); a linear-elastic model does not describe this load (the part would yield first)",
            config.criterion.yield_mpa
        ));
    }
    if displacement > LARGE_DISPLACEMENT_FRACTION * centre_distance_mm {
        model_validity.push(format!(
            "large displacement: {displacement:.2} mm is {:.2} % of the centre distance (above {:.0} %), beyond small-displacement theory",
            100.0 * displacement / centre_distance_mm,
            100.0 * LARGE_DISPLACEMENT_FRACTION
        ));
    }
    StressVerdict {
        model_validity,
        allowed_mpa: allowed,
        governing_mpa: governing,
        governing_case: case.into(),
        governing_error_rel: err,
        with_error,
        raw_peak_mpa: fem
            .fx
            .max_von_mises_unaveraged_mpa
            .max(fem.fy.max_von_mises_unaveraged_mpa),
        safety_factor: config.criterion.yield_mpa / governing,
        pass: governing <= allowed,
        static_pass: governing <= allowed,
        fatigue_safety_factor: None,
        fatigue_required: None,
    }
}
