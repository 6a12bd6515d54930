//! The rod analysis of SPEC Stage 3 / thesis §5.3: small-end bore B fixed (all DOFs), big-end bore A
//! loaded by a uniform traction with resultant F along A→B (case `fx`) and, separately, in the plane
//! of motion perpendicular to it (case `fy` = pin axis × A→B); both cases from one factorisation.
//!
//! Reported per case: max von Mises element-nodal unaveraged (as NX reports), nodally averaged, and
//! nodally averaged outside a band around the fixed bore (the convergent measure: the edge of a fully
//! fixed surface is a singularity whose peak grows under refinement), each with its location; max
//! displacement; the load resultant check and the reaction balance.

use std::path::PathBuf;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::bores::{BoreSpec, BoreSurface, find_bores};
use crate::fem::boundary::{boundary_faces, cross, norm};
use crate::fem::element::QuadratureChoice;
use crate::fem::error::{FemError, Result};
use crate::fem::estimate::{ErrorEstimate, EstimateSummary, estimate_error};
use crate::fem::load::SurfaceLoad;
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;
use crate::fem::recovery::recover_stress_cases;
use crate::fem::statics::{
    FactorisedSystem, StaticProblem, StaticSolution, Timings, solve_static, solve_static_reusing,
};
use crate::fem::stress::{
    StressField, displacement_magnitudes, nodes_away_from, nodes_away_from_segments, peak_nodal,
    peak_unaveraged, stress_field,
};
use crate::rod::pin_load::{BoreLoad, pin_load};
use std::sync::Arc;

/// The default band around the fixed bore excluded from the judged stress measure: 6 mm.
pub const DEFAULT_FIXED_BAND_M: f64 = 6e-3;

/// The default band around sharp re-entrant edges left out of the judged peak: 3 mm.
pub const DEFAULT_SINGULAR_BAND_M: f64 = 3e-3;

/// Options of [`solve_rod`].
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct RodOptions {
    /// Element quadrature (default: 4-point for straight, 14-point for curved elements).
    pub quadrature: QuadratureChoice,
    /// Width of the band around the fixed bore excluded from the "away from fixed" measure, m.
    /// `None`: [`DEFAULT_FIXED_BAND_M`], a fixed physical distance (not a number of elements, so
    /// that refinement does not move the band towards the singular edge).
    pub fixed_band_m: Option<f64>,
    /// Sharp re-entrant edges of the geometry (segments, m): stress singularities, left out of
    /// the judged peak like the fixed bore ([`super::facets::reentrant_edges`]).
    #[serde(default)]
    pub singular_edges_m: Vec<[[f64; 3]; 2]>,
    /// Band around the singular edges left out of the judged peak, m (`None`:
    /// [`DEFAULT_SINGULAR_BAND_M`]).
    #[serde(default)]
    pub singular_band_m: Option<f64>,
    /// The magnitude of the F_y case when it differs from the F_x case's (`None`: both are
    /// `force_n`, the thesis' setting). The engine study sets it to the largest pin force across
    /// the rod over the cycle.
    #[serde(default)]
    pub fy_force_n: Option<f64>,
    /// Keep the factorised K in [`RodSolution::system`] for the buckling case on the same mesh
    /// (its supports are stage 3's), which then neither assembles nor factorises K again.
    #[serde(skip)]
    pub keep_system: bool,
    /// Edges of the geometry at or above the feature angle taken for kinks of faceted small
    /// fillets (refined like any curved surface, not excluded; [`super::facets::SurfaceEdges`]),
    /// for the record.
    #[serde(default)]
    pub fillet_kink_edges: usize,
    /// The symbolic analysis of another solve of K's pattern (the same mesh with its boundary moved:
    /// the geometry check of [`super::smooth`]), reused where it fits.
    #[serde(skip)]
    pub reuse_symbolic: Option<crate::fem::solver::SymbolicFactor>,
    /// The mesh given to [`solve_rod_on`] is the half z ≥ c of a mirror-symmetric rod, with its
    /// face on the plane z = c (m, rod frame); `None`: the whole rod.
    #[serde(default)]
    pub mirror_plane_z_m: Option<f64>,
    /// The mesh is of an exact geometry (a STEP's B-rep): a sharp edge is sharp in the part, not
    /// a fillet an export cut into few facets (what the warnings of the edge band say).
    #[serde(default)]
    pub exact_geometry: bool,
}

/// The record of the geometry check ([`super::smooth::geometry_check`]): what was moved, and its cost.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct GeometryCheckRecord {
    /// Boundary nodes moved onto the smooth surface through the STL's vertices.
    pub moved_nodes: usize,
    /// Of those, moved only part of the way (an element would have been distorted).
    pub damped_nodes: usize,
    /// Boundary nodes with no facet within 2 mm (left where they were).
    pub unmatched_nodes: usize,
    /// The largest move, mm.
    pub max_move_mm: f64,
    /// Wall time of the check (curving, the second solve), s.
    pub seconds: f64,
}

/// Results of one load case. Stresses in MPa, lengths in mm, forces in N.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LoadCaseResult {
    /// "fx" or "fy".
    pub name: String,
    /// Unit direction of the resultant.
    pub direction: [f64; 3],
    /// Magnitude of the resultant, N.
    pub force_n: f64,
    /// Max element-nodal (unaveraged) von Mises.
    pub max_von_mises_unaveraged_mpa: f64,
    /// Where (node coordinates, mm).
    pub max_von_mises_unaveraged_at_mm: [f64; 3],
    /// In which element.
    pub max_von_mises_unaveraged_element: usize,
    /// Max nodally averaged von Mises.
    pub max_von_mises_averaged_mpa: f64,
    /// Where.
    pub max_von_mises_averaged_at_mm: [f64; 3],
    /// Max nodally averaged von Mises at nodes at least the band width from the fixed bore surface.
    pub max_von_mises_away_from_fixed_mpa: f64,
    /// Where.
    pub max_von_mises_away_from_fixed_at_mm: [f64; 3],
    /// The same for the unaveraged values.
    pub max_von_mises_unaveraged_away_from_fixed_mpa: f64,
    /// Max displacement magnitude.
    pub max_displacement_mm: f64,
    /// Where.
    pub max_displacement_at_mm: [f64; 3],
    /// Sum of the applied nodal forces, N.
    pub applied_resultant_n: [f64; 3],
    /// |applied − requested| / F.
    pub resultant_error_rel: f64,
    /// Sum of the reactions at the fixed bore (K u − f over its DOFs), N.
    pub reaction_n: [f64; 3],
    /// |reaction + applied| / F.
    pub reaction_balance_rel: f64,
    /// ‖K u − f‖ / ‖f‖ over the free DOFs.
    pub solve_residual_rel: f64,
    /// Estimated relative error of `max_von_mises_away_from_fixed_mpa` (the judged peak): the
    /// discretisation part plus the geometry part (a bound: the two are not independent random
    /// errors, and where both lower the peak they add).
    pub estimated_error_rel: f64,
    /// The discretisation part: the single-mesh bound on one mesh, the goal-oriented estimate over
    /// an adaptive sequence (see `error_estimate` and `adaptive`).
    #[serde(default)]
    pub estimated_discretisation_error_rel: f64,
    /// The geometry part: what the facets of an STL do to the judged peak, |P_smooth − P| / P with
    /// P_smooth the judged peak of the same mesh curved onto a smooth surface through the STL's
    /// vertices (`smooth_surface_peak_mpa`); 0 on the exact geometry of a STEP; `None` where it is
    /// not estimated (a user's mesh, whose geometry is its own).
    #[serde(default)]
    pub estimated_geometry_error_rel: Option<f64>,
    /// The judged peak of the same mesh curved onto the smooth surface through the STL's vertices
    /// (see `estimated_geometry_error_rel`), MPa.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub smooth_surface_peak_mpa: Option<f64>,
    /// The recovery-based (Zienkiewicz–Zhu) estimates on this mesh.
    pub error_estimate: EstimateSummary,
    /// The adaptive sequence that led to this mesh (empty for a fixed mesh).
    #[serde(default)]
    pub adaptive: Vec<AdaptiveStep>,
    /// ParaView file, if written.
    pub vtu: Option<PathBuf>,
    /// Picture of the von Mises field on the surface (SVG), if written.
    #[serde(default)]
    pub picture: Option<PathBuf>,
}

impl LoadCaseResult {
    /// The one writer of the judged peak's error bar: its discretisation part (the single-mesh
    /// bound, or the adaptive sequence's estimate), its geometry part (what an STL's facets do;
    /// `None` where not estimated) and their sum, ε = ε_disc + ε_geom (a bound: the two are not
    /// independent, and where both move the peak the same way they add).
    pub fn set_error_bar(&mut self, discretisation: f64, geometry: Option<f64>) {
        self.estimated_discretisation_error_rel = discretisation;
        self.estimated_geometry_error_rel = geometry;
        self.estimated_error_rel = discretisation + geometry.unwrap_or(0.0);
    }
}

/// One iteration of the adaptive loop, for one load case.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AdaptiveStep {
    /// 0 for the initial mesh.
    pub iteration: usize,
    /// Elements (of the half, for a half model: the mesh that was made and solved).
    pub elements: usize,
    /// DOFs of the system solved (of the half, for a half model).
    pub dofs: usize,
    /// The judged peak (max von Mises away from the fixed bore), MPa.
    pub peak_mpa: f64,
    /// Its estimated relative error at this iteration.
    pub estimated_error_rel: f64,
    /// Mean size of the elements at the peak, mm.
    #[serde(default)]
    pub size_at_peak_mm: f64,
    /// The convergence order the estimate used (Richardson), 0 where it used recovery alone.
    #[serde(default)]
    pub order: f64,
    /// The peak extrapolated with that order (Richardson), MPa; the peak itself where there is
    /// no extrapolation.
    #[serde(default)]
    pub extrapolated_mpa: f64,
    /// Wall time of this iteration (mesh, solve, estimate), s.
    pub seconds: f64,
    /// Where this iteration's time went (wall times, not in `results.json`).
    #[serde(default)]
    pub timings: StepTimings,
}

/// The phases of one adaptive iteration, s: the mesh (gmsh), the analysis (`analysis_s`, of which
/// the solver's phases and the stresses with their recovery and estimate) and the sizing of the
/// next mesh (`seconds` less the mesh and the analysis).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct StepTimings {
    pub mesh_s: f64,
    pub analysis_s: f64,
    #[serde(flatten)]
    pub analysis: Timings,
    /// The mesh's own phases, where the mesher reports them (gmsh: [`MeshPhases`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh_phases: Option<MeshPhases>,
}

/// Where one gmsh mesh's time went, s (gmsh's own wall times from its log, the rest measured
/// around the calls; `pipeline/mesh_rod.py`, `mesh_volume`). `model`: building the model before
/// meshing (on the first mesh of an STL the classification of its triangles; in the loop's gmsh
/// session the next model is built while the last mesh is solved, so later meshes show only the
/// options set); `hxt_optimise` is part of `mesh_3d`; `read`: reading the written mesh on the
/// Rust side. A phase the mesher did not report is absent (`None`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MeshPhases {
    pub model: Option<f64>,
    pub mesh_1d: Option<f64>,
    pub mesh_2d: Option<f64>,
    pub mesh_3d: Option<f64>,
    pub hxt_optimise: Option<f64>,
    pub order_2: Option<f64>,
    pub qualities: Option<f64>,
    pub write: Option<f64>,
    pub read: Option<f64>,
}

/// A bore as found.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BoreSummary {
    /// Radius found, mm.
    pub radius_mm: f64,
    /// Area of its faces, mm².
    pub area_mm2: f64,
    /// Axial length, mm.
    pub axial_length_mm: f64,
    /// area / (2π r × length).
    pub coverage: f64,
    /// Boundary faces.
    pub faces: usize,
    /// Nodes.
    pub nodes: usize,
}

impl From<&BoreSurface> for BoreSummary {
    fn from(b: &BoreSurface) -> Self {
        BoreSummary {
            radius_mm: b.radius_m * 1e3,
            area_mm2: b.area_m2 * 1e6,
            axial_length_mm: (b.axial_range_m[1] - b.axial_range_m[0]) * 1e3,
            coverage: b.coverage,
            faces: b.faces.len(),
            nodes: b.nodes.len(),
        }
    }
}

/// Results of [`solve_rod`].
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FemResult {
    /// Load along A→B.
    pub fx: LoadCaseResult,
    /// Load perpendicular, in the plane of motion.
    pub fy: LoadCaseResult,
    /// Nodes.
    pub nodes: usize,
    /// Elements (10-node tetrahedra).
    pub elements: usize,
    /// DOFs (3 per node).
    pub dofs: usize,
    /// Free DOFs (equations).
    pub equations: usize,
    /// Stored entries of K (upper triangle).
    pub nnz_k: usize,
    /// Stored entries of the Cholesky factor.
    pub nnz_l: usize,
    /// Curved elements.
    pub curved_elements: usize,
    /// Quadrature choice.
    pub quadrature: QuadratureChoice,
    /// Material.
    pub material: Material,
    /// Mean element edge length, mm.
    pub mean_edge_mm: f64,
    /// Band around the fixed bore excluded from the "away" measure, mm.
    pub fixed_band_mm: f64,
    /// Sharp re-entrant edges found in the geometry (singularities left out of the judged peak).
    #[serde(default)]
    pub singular_edges: usize,
    /// Band around them excluded from the judged peak, mm.
    #[serde(default)]
    pub singular_band_mm: f64,
    /// Edges at or above the feature angle taken for kinks of faceted small fillets (a chain of
    /// facets turning about a small radius): refined, not excluded.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub fillet_kink_edges: usize,
    /// What the figures need said beside them: a band around sharp edges that holds a stress
    /// above the judged peak (the exclusion decides the judged figure).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// The second solve of an STL design's geometry error: its mesh curved onto the smooth surface
    /// through the STL's vertices ([`super::smooth`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geometry_check: Option<GeometryCheckRecord>,
    /// Solved on the half model of a mirror-symmetric rod and mirrored ([`solve_rod_on`]): `nodes`
    /// and `elements` are the whole's, `dofs`, `equations`, `nnz_k`, `nnz_l` the half's system.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_model: Option<HalfModel>,
    /// How the pin force is spread over the loaded bore (absent: uniform; `cosine`: a cosine
    /// bearing pressure on the pressed half).
    #[serde(default, skip_serializing_if = "BoreLoad::is_uniform")]
    pub bore_load: BoreLoad,
    /// The loaded bore.
    pub loaded_bore: BoreSummary,
    /// The fixed bore.
    pub fixed_bore: BoreSummary,
    /// Times of the stages, s.
    pub timings: Timings,
    /// Total wall time of the analysis, s.
    pub total_s: f64,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// Full fields of a rod analysis (for post-processing beyond the figures).
#[derive(Clone, Debug)]
pub struct RodSolution {
    /// The figures.
    pub result: FemResult,
    /// Displacements (3 per node, m) for fx and fy.
    pub displacements: [Vec<f64>; 2],
    /// Stresses for fx and fy.
    pub stresses: [StressField; 2],
    /// Loaded bore A.
    pub loaded: BoreSurface,
    /// Fixed bore B.
    pub fixed: BoreSurface,
    /// Nodes outside the bands around the fixed bore and the singular edges (the judged nodes).
    pub away_from_fixed: Vec<bool>,
    /// Per node, the smallest element size adaptive refinement may ask for near a singularity
    /// (within twice the band of it: a third of the fixed bore's band, a sixth of a sharp edge's,
    /// so that six elements lie between the edge and the judged stress at the band's border;
    /// else 0), m.
    pub singularity_floor_m: Vec<f64>,
    /// Error estimates for fx and fy.
    pub estimates: [ErrorEstimate; 2],
    /// The buckling mode of the F_x case, when buckling was computed
    /// ([`super::buckling::rod_buckling`]; set by the caller, `None` from [`solve_rod_fields`]).
    pub buckling: Option<crate::fem::buckling::BucklingMode>,
    /// The factorised K of the static cases, when [`RodOptions::keep_system`] asked for it.
    pub system: Option<Arc<FactorisedSystem>>,
    /// A half model's solution ([`solve_rod_on`]): for each node of the whole, the node of the
    /// half it is or is the image of (the first `half_model.nodes` are the half's own).
    pub mirror_source: Option<Vec<usize>>,
}

/// Analyses a rod: see the module documentation. `force_n` > 0 is the magnitude of both cases
/// (of F_x only when [`RodOptions::fy_force_n`] is set).
pub fn solve_rod(
    mesh: &TetMesh,
    material: &Material,
    bores: &BoreSpec,
    force_n: f64,
    options: &RodOptions,
) -> Result<FemResult> {
    Ok(solve_rod_fields(mesh, material, bores, force_n, options)?.result)
}

/// [`solve_rod`] returning the fields too.
pub fn solve_rod_fields(
    mesh: &TetMesh,
    material: &Material,
    bores: &BoreSpec,
    force_n: f64,
    options: &RodOptions,
) -> Result<RodSolution> {
    rod_fields(
        solve_rod_static(mesh, material, bores, force_n, options)?,
        options,
    )
}

/// [`solve_rod_fields`] on `mesh`, or, when `options` names a symmetry plane
/// ([`RodOptions::mirror_plane_z_m`]), on the half model `mesh` is: solved with half the pin loads
/// and u_z = 0 on the plane, then mirrored into the whole ([`crate::fem::mesh::mirror`]), on which the
/// stresses, estimates and peaks are formed as for any mesh. Returns the mesh the solution is on
/// (the whole, for a half model).
pub fn solve_rod_on(
    mesh: TetMesh,
    material: &Material,
    bores: &BoreSpec,
    force_n: f64,
    options: &RodOptions,
) -> Result<(TetMesh, RodSolution)> {
    let Some(c) = options.mirror_plane_z_m else {
        let solution = solve_rod_fields(&mesh, material, bores, force_n, options)?;
        return Ok((mesh, solution));
    };
    let m = crate::fem::mesh::mirror::mirror(&mesh, c, mirror_plane_tolerance(&mesh))?;
    let held: Vec<usize> = m.plane_nodes.iter().map(|&n| 3 * n + 2).collect();
    let half = static_cases(&mesh, material, bores, force_n, options, 0.5, &held)?;
    let whole = mirrored_static(&m, half, bores)?;
    let mut solution = rod_fields(whole, options)?;
    solution.result.half_model = Some(HalfModel {
        plane_z_mm: c * 1e3,
        nodes: mesh.n_nodes(),
        elements: mesh.n_elements(),
        plane_nodes: m.plane_nodes.len(),
    });
    solution.mirror_source = Some(m.source);
    Ok((m.whole, solution))
}

/// Nodes of a half model within this fraction of its extent from the symmetry plane, on a face
/// there, are the plane's.
pub const MIRROR_PLANE_TOLERANCE_REL: f64 = 1e-7;

/// How far from the symmetry plane a node of the half model `mesh` may lie and still be on it:
/// [`MIRROR_PLANE_TOLERANCE_REL`] times the mesh's largest extent (m).
pub fn mirror_plane_tolerance(mesh: &TetMesh) -> f64 {
    let (lo, hi) = mesh.bounding_box();
    let extent = (0..3).map(|j| hi[j] - lo[j]).fold(0.0, f64::max);
    MIRROR_PLANE_TOLERANCE_REL * extent
}

/// The static solution of a half model (`half`, on the half of `m`) as the whole's: the
/// displacements mirrored, the loads and reactions of both halves, the bores found on the whole.
fn mirrored_static<'a>(
    m: &'a crate::fem::mesh::mirror::MirroredMesh,
    half: RodStatic<'_>,
    bores: &BoreSpec,
) -> Result<RodStatic<'a>> {
    let (loaded, fixed, _, _) = bores_and_direction(&m.whole, bores)?;
    let loads = half
        .loads
        .iter()
        .map(|l| {
            let forces = m.mirror_forces(&l.forces);
            let mut resultant_n = [0.0; 3];
            for (d, f) in forces.iter().enumerate() {
                resultant_n[d % 3] += f;
            }
            SurfaceLoad {
                forces,
                area_m2: 2.0 * l.area_m2,
                traction_pa: l.traction_pa,
                resultant_n,
                resultant_error_rel: l.resultant_error_rel,
            }
        })
        .collect();
    let sol = StaticSolution {
        displacements: half
            .sol
            .displacements
            .iter()
            .map(|u| m.mirror_vector(u))
            .collect(),
        reactions: half
            .sol
            .reactions
            .iter()
            .map(|r| m.mirror_forces(r))
            .collect(),
        ..half.sol
    };
    Ok(RodStatic {
        mesh: &m.whole,
        material: half.material,
        bores: half.bores,
        t_all: half.t_all,
        loaded,
        fixed,
        cases: half.cases,
        loads,
        sol,
        system: None,
    })
}

/// A solution made on a half model and mirrored ([`solve_rod_on`]): what was solved.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HalfModel {
    /// The symmetry plane z = c in the rod frame, mm.
    pub plane_z_mm: f64,
    /// Nodes of the half (the solved system has 3 per node, less the supports).
    pub nodes: usize,
    /// Elements of the half.
    pub elements: usize,
    /// Nodes on the symmetry plane (u_z = 0).
    pub plane_nodes: usize,
}

impl HalfModel {
    /// The symmetry plane's z in the rod frame, m.
    pub fn plane_z_m(&self) -> f64 {
        self.plane_z_mm * 1e-3
    }

    /// The half model that was solved, out of the mirrored `whole` [`solve_rod_on`] returned: its
    /// first nodes and elements ([`crate::fem::mesh::mirror::MirroredMesh::whole`] puts the images
    /// after them).
    pub fn half_of(&self, whole: &TetMesh) -> Result<TetMesh> {
        TetMesh::new(
            whole.nodes()[..self.nodes].to_vec(),
            whole.elements()[..self.elements].to_vec(),
        )
    }
}

/// The first half of [`solve_rod_fields`]: the bores, the two pin loads and the static solution
/// of both cases. What it does not read of `options` (the fixed band, the singular edges and their
/// band, the fillet-kink count) [`rod_fields`] reads, so that a caller can work those out while K
/// is factorised (on one thread, [`crate::fem::solver`]).
pub struct RodStatic<'a> {
    mesh: &'a TetMesh,
    material: Material,
    bores: BoreSpec,
    t_all: Instant,
    loaded: BoreSurface,
    fixed: BoreSurface,
    cases: [(&'static str, [f64; 3], f64); 2],
    loads: Vec<SurfaceLoad>,
    sol: StaticSolution,
    system: Option<Arc<FactorisedSystem>>,
}

/// The bores, loads and static solution of both cases ([`RodStatic`]).
pub fn solve_rod_static<'a>(
    mesh: &'a TetMesh,
    material: &Material,
    bores: &BoreSpec,
    force_n: f64,
    options: &RodOptions,
) -> Result<RodStatic<'a>> {
    static_cases(mesh, material, bores, force_n, options, 1.0, &[])
}

/// [`solve_rod_static`] with the pin loads scaled by `load_share` (½ on a half model) and the
/// DOFs `held` fixed besides bore B's (u_z on a half model's symmetry plane).
fn static_cases<'a>(
    mesh: &'a TetMesh,
    material: &Material,
    bores: &BoreSpec,
    force_n: f64,
    options: &RodOptions,
    load_share: f64,
    held: &[usize],
) -> Result<RodStatic<'a>> {
    let t_all = Instant::now();
    material.validate()?;
    let fy_force_n = options.fy_force_n.unwrap_or(force_n);
    for f in [force_n, fy_force_n] {
        if !(f.is_finite() && f > 0.0) {
            return Err(FemError::InvalidInput(format!(
                "force must be > 0 N, got {f}"
            )));
        }
    }
    let (loaded, fixed, axis, ex) = bores_and_direction(mesh, bores)?;
    check_one_piece(mesh, &fixed.nodes)?;
    // y = axis × x, in the plane of motion
    let ey = cross(axis, ex);
    let cases = [("fx", ex, force_n), ("fy", ey, fy_force_n)];
    let loads = cases
        .iter()
        .map(|(_, d, f)| {
            pin_load(
                mesh,
                &loaded.faces,
                bores.loaded_centre_m,
                axis,
                d.map(|v| v * f * load_share),
                bores.bore_load,
            )
        })
        .collect::<Result<Vec<_>>>()?;

    let mut prescribed: Vec<(usize, f64)> = fixed
        .nodes
        .iter()
        .flat_map(|&n| (0..3).map(move |j| (3 * n + j, 0.0)))
        .collect();
    let fixed_already: std::collections::HashSet<usize> =
        prescribed.iter().map(|(d, _)| *d).collect();
    prescribed.extend(
        held.iter()
            .filter(|d| !fixed_already.contains(d))
            .map(|&d| (d, 0.0)),
    );
    let problem = StaticProblem {
        mesh,
        material: *material,
        prescribed,
        loads: loads.iter().map(|l| l.forces.clone()).collect(),
        quadrature: options.quadrature,
    };
    let (sol, system) = if options.keep_system || options.reuse_symbolic.is_some() {
        let (sol, system) = solve_static_reusing(&problem, options.reuse_symbolic.as_ref())?;
        (sol, options.keep_system.then(|| Arc::new(system)))
    } else {
        (solve_static(&problem)?, None)
    };
    Ok(RodStatic {
        mesh,
        material: *material,
        bores: bores.clone(),
        t_all,
        loaded,
        fixed,
        cases,
        loads,
        sol,
        system,
    })
}

/// The second half of [`solve_rod_fields`]: stresses, recovery, error estimates and peaks of
/// both cases of `st`, the peaks judged away from the fixed bore and from the singular edges of
/// `options`.
pub fn rod_fields(st: RodStatic<'_>, options: &RodOptions) -> Result<RodSolution> {
    let RodStatic {
        mesh,
        material,
        bores,
        t_all,
        loaded,
        fixed,
        cases,
        loads,
        sol,
        system,
    } = st;
    let (material, bores) = (&material, &bores);
    let t_stress = Instant::now();
    let band = options.fixed_band_m.unwrap_or(DEFAULT_FIXED_BAND_M);
    let singular_band = options.singular_band_m.unwrap_or(DEFAULT_SINGULAR_BAND_M);
    let away_fixed = nodes_away_from(mesh, &fixed.faces, band);
    let away_edges = nodes_away_from_segments(mesh, &options.singular_edges_m, singular_band);
    let away: Vec<bool> = away_fixed
        .iter()
        .zip(&away_edges)
        .map(|(a, b)| *a && *b)
        .collect();
    // nodes close enough to a singularity that refinement would chase it: within twice a band
    let near_fixed = nodes_away_from(mesh, &fixed.faces, 2.0 * band);
    let near_edges = nodes_away_from_segments(mesh, &options.singular_edges_m, 2.0 * singular_band);
    let chase_floor: Vec<f64> = near_fixed
        .iter()
        .zip(&near_edges)
        .map(|(f, e)| match (f, e) {
            (true, true) => 0.0,
            (false, true) => band / 3.0,
            (true, false) => singular_band / 6.0,
            (false, false) => (band / 3.0).max(singular_band / 6.0),
        })
        .collect();
    // the nodes left out for a sharp edge alone (not for the fixed bore)
    let in_edge_band: Vec<bool> = away_fixed
        .iter()
        .zip(&away_edges)
        .map(|(f, e)| *f && !*e)
        .collect();
    let any_in_edge_band = in_edge_band.iter().any(|b| *b);
    let mut warnings = Vec::new();
    let mut results = Vec::new();
    let mut fields = Vec::new();
    let mut estimates = Vec::new();
    // both cases' recovery at once: the patches' normal matrices are factorised once
    let displacements: Vec<&[f64]> = sol.displacements.iter().map(|u| u.as_slice()).collect();
    let recovered = recover_stress_cases(mesh, material, &displacements)?;
    for (c, ((name, dir, force_n), load)) in cases.iter().zip(&loads).enumerate() {
        let u = &sol.displacements[c];
        let field = stress_field(mesh, material, u)?;
        let estimate = estimate_error(mesh, material, u, &field, &recovered[c], &away)?;
        let vm_avg = field.von_mises_averaged();
        let un = peak_unaveraged(mesh, &field, None);
        let av = peak_nodal(mesh, &vm_avg, None);
        let away_av = peak_nodal(mesh, &vm_avg, Some(&away));
        let away_un = peak_unaveraged(mesh, &field, Some(&away));
        let umag = displacement_magnitudes(u);
        let dmax = peak_nodal(mesh, &umag, None);
        let mut reaction = [0.0; 3];
        for (d, r) in sol.reactions[c].iter().enumerate() {
            reaction[d % 3] += r;
        }
        let bal = norm(std::array::from_fn(|j| reaction[j] + load.resultant_n[j])) / *force_n;
        if bal > 1e-6 {
            return Err(FemError::Check(format!(
                "case {name}: reactions {reaction:?} N do not balance the load {:?} N (relative {bal:.2e})",
                load.resultant_n
            )));
        }
        let mm = |p: [f64; 3]| p.map(|v| v * 1e3);
        if any_in_edge_band {
            let hidden = peak_nodal(mesh, &vm_avg, Some(&in_edge_band));
            if hidden.value > away_av.value {
                warnings.push(edge_band_warning(
                    name,
                    &hidden,
                    away_av.value,
                    &options.singular_edges_m,
                    singular_band,
                    options.exact_geometry,
                ));
            }
        }
        results.push(LoadCaseResult {
            name: name.to_string(),
            direction: *dir,
            force_n: *force_n,
            max_von_mises_unaveraged_mpa: un.value * 1e-6,
            max_von_mises_unaveraged_at_mm: mm(un.location_m),
            max_von_mises_unaveraged_element: un.element.unwrap_or(0),
            max_von_mises_averaged_mpa: av.value * 1e-6,
            max_von_mises_averaged_at_mm: mm(av.location_m),
            max_von_mises_away_from_fixed_mpa: away_av.value * 1e-6,
            max_von_mises_away_from_fixed_at_mm: mm(away_av.location_m),
            max_von_mises_unaveraged_away_from_fixed_mpa: away_un.value * 1e-6,
            max_displacement_mm: dmax.value * 1e3,
            max_displacement_at_mm: mm(dmax.location_m),
            applied_resultant_n: load.resultant_n,
            resultant_error_rel: load.resultant_error_rel,
            reaction_n: reaction,
            reaction_balance_rel: bal,
            solve_residual_rel: sol.residual_rel[c],
            estimated_error_rel: 0.0,
            estimated_discretisation_error_rel: 0.0,
            estimated_geometry_error_rel: None,
            smooth_surface_peak_mpa: None,
            error_estimate: estimate.summary,
            adaptive: Vec::new(),
            vtu: None,
            picture: None,
        });
        let case = results.last_mut().expect("pushed");
        case.set_error_bar(estimate.summary.single_mesh_estimate(), None);
        fields.push(field);
        estimates.push(estimate);
    }
    let mut timings = sol.timings;
    timings.stress_s = t_stress.elapsed().as_secs_f64();
    let fy = results.pop().expect("two cases");
    let fx = results.pop().expect("two cases");
    let result = FemResult {
        fx,
        fy,
        nodes: mesh.n_nodes(),
        elements: mesh.n_elements(),
        dofs: sol.stats.dofs,
        equations: sol.stats.equations,
        nnz_k: sol.stats.nnz_k,
        nnz_l: sol.stats.nnz_l,
        curved_elements: sol.stats.curved_elements,
        quadrature: options.quadrature,
        material: *material,
        mean_edge_mm: mesh.mean_edge_length() * 1e3,
        fixed_band_mm: band * 1e3,
        singular_edges: options.singular_edges_m.len(),
        singular_band_mm: singular_band * 1e3,
        fillet_kink_edges: options.fillet_kink_edges,
        warnings,
        geometry_check: None,
        half_model: None,
        bore_load: bores.bore_load,
        loaded_bore: (&loaded).into(),
        fixed_bore: (&fixed).into(),
        timings,
        total_s: t_all.elapsed().as_secs_f64(),
    };
    let [d0, d1]: [Vec<f64>; 2] = sol
        .displacements
        .try_into()
        .map_err(|_| FemError::Check("two cases".into()))?;
    let [s0, s1]: [StressField; 2] = fields
        .try_into()
        .map_err(|_| FemError::Check("two cases".into()))?;
    let [e0, e1]: [ErrorEstimate; 2] = estimates
        .try_into()
        .map_err(|_| FemError::Check("two cases".into()))?;
    let solution = RodSolution {
        result,
        displacements: [d0, d1],
        stresses: [s0, s1],
        loaded,
        fixed,
        away_from_fixed: away,
        singularity_floor_m: chase_floor,
        estimates: [e0, e1],
        buckling: None,
        system,
        mirror_source: None,
    };
    Ok(solution)
}

/// The warning of a band around sharp edges that holds the highest stress of its neighbourhood,
/// above the judged peak `judged_pa` of case `name`: where, how far from the nearest edge, by how
/// much.
fn edge_band_warning(
    name: &str,
    hidden: &crate::fem::stress::Peak,
    judged_pa: f64,
    edges: &[[[f64; 3]; 2]],
    band: f64,
    exact_geometry: bool,
) -> String {
    let d = edges
        .iter()
        .map(|s| crate::fem::stress::point_segment_distance(hidden.location_m, *s))
        .fold(f64::INFINITY, f64::min);
    let p = hidden.location_m.map(|v| v * 1e3);
    let advice = if exact_geometry {
        "the edge is sharp in the B-rep, where the stress has no finite peak; if the real part \
         rounds it, model the fillet in CAD and the peak is there"
    } else {
        "if that edge is rounded in the real part (a fillet the export cut into few facets), the \
         peak is there (a STEP export settles it)"
    };
    format!(
        "{}: the {:.1} mm band around the sharp re-entrant edges holds the highest stress of its neighbourhood, {:.1} MPa at ({:.1}, {:.1}, {:.1}) mm, {:.2} mm from the nearest edge, {:.0} % above the judged peak {:.1} MPa: left out as a singularity; {advice}",
        if name == "fx" { "F_x" } else { "F_y" },
        band * 1e3,
        hidden.value * 1e-6,
        p[0],
        p[1],
        p[2],
        d * 1e3,
        100.0 * (hidden.value / judged_pa - 1.0),
        judged_pa * 1e-6
    )
}

/// The F_x case of [`solve_rod`] as supports and nodal forces: bore B fixed (all DOFs of its
/// nodes), the pin load (uniform or cosine, [`BoreSpec::bore_load`]) of resultant `force_n` along
/// A→B (perpendicular to the pin axis)
/// on bore A. Pushing A towards the fixed B, this case compresses the rod.
#[derive(Clone, Debug)]
pub struct RodFxCase {
    /// Unit direction of the load, A→B.
    pub direction: [f64; 3],
    /// The fixed DOFs (3 · node + component).
    pub fixed_dofs: Vec<usize>,
    /// Nodal forces, 3 per node, N.
    pub load: Vec<f64>,
    /// Loaded bore A.
    pub loaded: BoreSurface,
    /// Fixed bore B.
    pub fixed: BoreSurface,
}

/// The bores of a rod mesh (loaded A, fixed B), the unit pin axis, and the F_x direction: along
/// A→B, perpendicular to the pin axis. Shared by the static cases and [`rod_fx_case`].
fn bores_and_direction(
    mesh: &TetMesh,
    bores: &BoreSpec,
) -> Result<(BoreSurface, BoreSurface, [f64; 3], [f64; 3])> {
    let axis = bores.unit_axis()?;
    let boundary = boundary_faces(mesh)?;
    let (loaded, fixed) = find_bores(mesh, &boundary, bores)?;
    let ab: [f64; 3] = std::array::from_fn(|j| bores.fixed_centre_m[j] - bores.loaded_centre_m[j]);
    let along = crate::fem::boundary::dot(ab, axis);
    let abp: [f64; 3] = std::array::from_fn(|j| ab[j] - along * axis[j]);
    let l = norm(abp);
    if l.is_nan() || l <= 0.0 {
        return Err(FemError::InvalidInput(
            "the pin centres lie on one pin axis".into(),
        ));
    }
    Ok((loaded, fixed, axis, abp.map(|v| v / l)))
}

/// The F_x case of [`solve_rod_fields`] (the same bores, direction and nodal forces), for an
/// analysis of that load other than the static one (buckling).
pub fn rod_fx_case(mesh: &TetMesh, bores: &BoreSpec, force_n: f64) -> Result<RodFxCase> {
    if !(force_n.is_finite() && force_n > 0.0) {
        return Err(FemError::InvalidInput(format!(
            "force must be > 0 N, got {force_n}"
        )));
    }
    let (loaded, fixed, axis, ex) = bores_and_direction(mesh, bores)?;
    let load = pin_load(
        mesh,
        &loaded.faces,
        bores.loaded_centre_m,
        axis,
        ex.map(|v| v * force_n),
        bores.bore_load,
    )?;
    let fixed_dofs = fixed
        .nodes
        .iter()
        .flat_map(|&n| (0..3).map(move |j| 3 * n + j))
        .collect();
    Ok(RodFxCase {
        direction: ex,
        fixed_dofs,
        load: load.forces,
        loaded,
        fixed,
    })
}

/// A rod's mesh must be one piece ([`crate::fem::mesh::pieces`]): a piece apart from the one that
/// holds the fixed bore has no support (K singular), so it is refused by where it is and how
/// large it is, not reported later as a failed pivot.
fn check_one_piece(mesh: &TetMesh, fixed_nodes: &[usize]) -> Result<()> {
    let (pieces, labels) = crate::fem::mesh::pieces::pieces(mesh);
    if pieces.len() < 2 {
        return Ok(());
    }
    let held = fixed_nodes.first().map_or(0, |&n| labels[n]);
    let stray: Vec<String> = pieces
        .iter()
        .enumerate()
        .filter(|(k, _)| *k != held)
        .take(3)
        .map(|(_, p)| {
            let c = p.centroid_m.map(|v| v * 1e3);
            format!(
                "{:.4e} mm³ ({} elements) around ({:.1}, {:.1}, {:.1}) mm",
                p.volume_m3 * 1e9,
                p.elements,
                c[0],
                c[1],
                c[2]
            )
        })
        .collect();
    Err(FemError::InvalidInput(format!(
        "the mesh is {} separate pieces, and only the one of {:.4e} mm³ holds the fixed bore: {} \
         {} not connected to it (a separate body in the file, or a part that only touches the \
         rod without sharing its surface) and would float; remove it, or join it to the rod",
        pieces.len(),
        pieces[held].volume_m3 * 1e9,
        stray.join("; "),
        if pieces.len() == 2 { "is" } else { "are" }
    )))
}

#[cfg(test)]
mod tests {

    /// The edge band's warning fits the geometry: on an STL a sharp edge may be a fillet cut into
    /// few facets (a STEP settles it); on a STEP the edge is sharp in the B-rep.
    #[test]
    fn the_edge_band_warning_fits_stl_and_step() {
        let hidden = crate::fem::stress::Peak {
            value: 120e6,
            node: 0,
            element: None,
            location_m: [0.01, 0.0, 0.0],
        };
        let edges = [[[0.0, 0.0, 0.0], [0.0, 0.0, 0.01]]];
        let stl = edge_band_warning("fx", &hidden, 100e6, &edges, 3e-3, false);
        assert!(stl.contains("(a STEP export settles it)"), "{stl}");
        assert!(stl.contains("10.00 mm from the nearest edge") && stl.contains("20 % above"));
        let step = edge_band_warning("fx", &hidden, 100e6, &edges, 3e-3, true);
        assert!(step.contains("sharp in the B-rep"), "{step}");
        assert!(
            !step.contains("STEP export") && !step.contains("facets"),
            "{step}"
        );
    }
    use super::{RodOptions, check_one_piece, edge_band_warning};
    use crate::fem::TetMesh;
    use crate::fem::mesh::structured::box_tet10;

    /// A half model solved with half the pin loads and u_z = 0 on its plane, mirrored, is the
    /// whole model's solution: against the direct solve of the mirrored mesh (the same mesh, the
    /// same loads) the displacements, peaks, reactions and estimates agree to round-off.
    #[test]
    fn a_half_model_mirrored_is_the_whole_model() {
        use crate::fem::Material;
        use crate::fem::mesh::structured::{TwoEyePlate, two_eye_plate};
        use crate::rod::BoreSpec;
        // the upper half of a 40 mm plate, z ∈ [0, 20] mm, two layers
        let p = TwoEyePlate {
            thickness: 0.02,
            n_z: 2,
            ..TwoEyePlate::default()
        };
        let half = two_eye_plate(&p)
            .unwrap()
            .map_nodes(|_, q| [q[0], q[1], q[2] + 0.01])
            .unwrap();
        let (material, bores) = (Material::STEEL, BoreSpec::default());
        let options = RodOptions {
            mirror_plane_z_m: Some(0.0),
            fy_force_n: Some(3000.0),
            ..RodOptions::default()
        };
        let (whole, mirrored) =
            super::solve_rod_on(half.clone(), &material, &bores, 10_000.0, &options).unwrap();
        let direct = super::solve_rod_fields(
            &whole,
            &material,
            &bores,
            10_000.0,
            &RodOptions {
                mirror_plane_z_m: None,
                ..options.clone()
            },
        )
        .unwrap();
        let (lo, hi) = whole.bounding_box();
        assert_eq!((lo[2], hi[2]), (-0.02, 0.02));
        let hm = mirrored.result.half_model.as_ref().unwrap();
        assert_eq!((hm.nodes, hm.elements), (half.n_nodes(), half.n_elements()));
        assert_eq!(whole.n_elements(), 2 * half.n_elements());
        assert_eq!(mirrored.result.dofs, 3 * half.n_nodes());
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1e-300);
        for c in 0..2 {
            let (a, b) = (&mirrored.displacements[c], &direct.displacements[c]);
            let umax = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = a
                .iter()
                .zip(b)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(diff < 1e-9 * umax, "case {c}: {diff:e} of {umax:e}");
        }
        for (m, d) in [
            (&mirrored.result.fx, &direct.result.fx),
            (&mirrored.result.fy, &direct.result.fy),
        ] {
            assert!(
                rel(
                    m.max_von_mises_away_from_fixed_mpa,
                    d.max_von_mises_away_from_fixed_mpa
                ) < 1e-9
            );
            assert!(
                rel(
                    m.max_von_mises_unaveraged_mpa,
                    d.max_von_mises_unaveraged_mpa
                ) < 1e-9
            );
            assert!(rel(m.max_displacement_mm, d.max_displacement_mm) < 1e-9);
            assert!(rel(m.estimated_error_rel, d.estimated_error_rel) < 1e-6);
            assert_eq!(m.force_n, d.force_n);
            for j in 0..3 {
                assert!(
                    (m.reaction_n[j] - d.reaction_n[j]).abs() < 1e-6 * d.force_n,
                    "{:?} {:?}",
                    m.reaction_n,
                    d.reaction_n
                );
                assert!(
                    (m.applied_resultant_n[j] - d.applied_resultant_n[j]).abs() < 1e-9 * d.force_n
                );
            }
            assert!(m.reaction_balance_rel < 1e-6);
        }
        assert_eq!(
            format!("{:?}", mirrored.result.loaded_bore),
            format!("{:?}", direct.result.loaded_bore)
        );
    }

    #[test]
    fn a_piece_apart_from_the_fixed_bores_is_refused_by_where_it_is() {
        let a = box_tet10(0.1, 0.02, 0.02, 4, 1, 1).unwrap();
        assert!(check_one_piece(&a, &[0]).is_ok());
        let b = box_tet10(0.01, 0.01, 0.01, 1, 1, 1).unwrap();
        let mut nodes = a.nodes().to_vec();
        let n0 = nodes.len();
        nodes.extend(b.nodes().iter().map(|p| [p[0] + 0.2, p[1], p[2]]));
        let mut elements = a.elements().to_vec();
        elements.extend(b.elements().iter().map(|el| el.map(|i| i + n0)));
        let two = TetMesh::new(nodes, elements).unwrap();
        let e = check_one_piece(&two, &[0]).unwrap_err().to_string();
        assert!(
            e.contains("2 separate pieces")
                && e.contains("4.0000e4 mm³")
                && e.contains("1.0000e3 mm³")
                && e.contains("around (205.0, 5.0, 5.0) mm"),
            "{e}"
        );
    }
}
