//! The records the stages return, one per stage, as written to JSON (SI units; millimetres and
//! MPa where a field's name says so), and the loaded design every stage starts from. A stage is a
//! function from a loaded design (read and validated once) and settings to one of these; it writes
//! no file ([`crate::report`] does).

use crate::fem::TetMesh;
use crate::mechanism::{Method, PeakSensitivity};
use crate::rod::adapt::StopReason;
use crate::rod::cycle::CycleInstant;
use crate::rod::fatigue::MeanStress;
use crate::rod::{BoreSpec, FemResult};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Stage 1's record and the loaded design (file read, surface validated, mass properties, frame).
pub use crate::geometry::design::{DesignMass, LoadedDesign};

/// The stage-2 record of one design (SI units), as written to JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DesignDynamics {
    pub design: String,
    /// True maximum of |F_A| over the motion [N] (refined between samples).
    pub peak_pin_force_n: f64,
    /// Crank angle of the peak, in [0, 360) degrees (0 = top dead centre).
    pub peak_crank_angle_deg: f64,
    /// First time of the peak [s].
    pub peak_time_s: f64,
    /// Largest |F_A| on the output grid [N].
    pub grid_peak_pin_force_n: f64,
    pub gravity: bool,
    /// `closed_form` or `multibody`.
    pub method: Method,
    /// What the method computes (no time integration: the driven mechanism has zero DOF).
    pub model: String,
    pub omega_rad_s: f64,
    pub duration_s: f64,
    pub steps: usize,
    /// rω²[m4(1 + r/l) + m3(1 + (r/l)(l1/l))]: the top-dead-centre peak without gravity [N].
    pub tdc_formula_n: f64,
    /// ∂F/∂m3, ∂F/∂l1, ∂F/∂I_zz of the peak at constant speed.
    pub sensitivity: PeakSensitivity,
    /// With a pressure trace (`[engine] pressure_trace`) only: the largest compression along
    /// the rod axis A→B at the crank pin, max (F_A · u) over the four-stroke cycle [N, magnitude].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_compression_n: Option<f64>,
    /// Its crank angle in [0, 720) degrees (0 = firing top dead centre).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_compression_crank_angle_deg: Option<f64>,
    /// The gas force p·A on the piston there [N].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_compression_gas_force_n: Option<f64>,
    /// With a pressure trace only: the largest tension along the rod axis, max (−F_A · u)
    /// [N, magnitude].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_tension_n: Option<f64>,
    /// Its crank angle in [0, 720) degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_tension_crank_angle_deg: Option<f64>,
    /// The gas force p·A on the piston there [N].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_tension_gas_force_n: Option<f64>,
    /// With a pressure trace only: the largest pin force across the rod, max |F_A · ŷ| over the
    /// cycle [N] (the F_y case's magnitude in the engine study), and its crank angle in [0, 720).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_transverse_n: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_transverse_crank_angle_deg: Option<f64>,
}

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
    /// The mesher's fallback, where every classification of the surface failed (`local
    /// refinement`, `STL surface kept`; adaptive: `mesh <iteration>: …` per mesh that needed
    /// one, joined by "; "); absent for the usual mesh.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback: Option<String>,
    /// A STEP's curved mesh (the last one of an adaptive sequence): the elements made
    /// straight-sided because their scaled Jacobian was below 0.1 (a fillet far smaller than the
    /// elements); absent for an STL's or a user's mesh.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curved_elements_straightened: Option<usize>,
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
    pub monotone: Vec<bool>,
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
    /// The fatigue factor the criterion judges and the smallest accepted, when fatigue is judged:
    /// the cycle's local (FKM) factor, or its Goodman factor where no local one was formed
    /// ([`crate::stages::criterion::judge_fatigue`]).
    #[serde(default)]
    pub fatigue_safety_factor: Option<f64>,
    #[serde(default)]
    pub fatigue_required: Option<f64>,
}

/// The stage-3 record of one design.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DesignFem {
    /// Load magnitude of both cases: the design's peak pin force [N].
    pub force_n: f64,
    pub mesh: MeshSummary,
    pub fem: FemResult,
    pub criterion: StressVerdict,
    /// Linear buckling load factor λ₁ of the rod under its peak compression (the F_x case: B
    /// fixed, the compression on A towards B; [`crate::fem::buckling`]): computed in the study
    /// only with a pressure trace (`[engine] pressure_trace`), absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub buckling_load_factor: Option<f64>,
    /// λ₁ of the same case with the compression entering bore A through contact (a rigid pin at
    /// its clearance, bore B clamped; [`crate::rod::buckling::rod_buckling_contact`]): computed
    /// beside `buckling_load_factor` when `[fem] load_model_error` is on; the verdict stays on
    /// `buckling_load_factor`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub buckling_load_factor_contact: Option<f64>,
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
    /// The half model `mesh` was mirrored from (`None`: the whole was solved).
    pub half_model: Option<crate::rod::records::HalfModel>,
}

/// The cycle record of one design (JSON fields named by the issue that asked for them).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DesignCycle {
    /// Per instant: crank angle, time, judged max von Mises, the fixed bore's reaction and the
    /// dynamics' F_B (both on the rod at B, rod frame, N).
    pub history: Vec<CycleInstant>,
    pub max_von_mises_over_cycle_mpa: f64,
    pub crank_angle_of_max_deg: f64,
    /// Rod frame, mm (A at the origin, x towards B, z the pin axis).
    pub location_of_max_mm: [f64; 3],
    /// Smallest Goodman (or Gerber) safety factor over the judged nodes: the textbook factor of
    /// the signed von Mises cycle against S_e and S_ut, kept as an interface beside
    /// `local_fatigue_safety_factor` (the ranking's fatigue factor).
    pub fatigue_safety_factor: f64,
    pub fatigue_location_mm: [f64; 3],
    /// Alternating and mean signed von Mises at that node, MPa.
    pub fatigue_alternating_mpa: f64,
    pub fatigue_mean_mpa: f64,
    /// How mean and alternating stress were formed.
    pub method: String,
    pub endurance_mpa: f64,
    pub ultimate_mpa: f64,
    /// Instants over the revolution.
    pub instants: usize,
    /// Crank speed, rad/s.
    pub omega_rad_s: f64,
    /// Which mass properties the loads use, and the mesh's against the STL's.
    pub mass_properties: String,
    pub mesh_mass_kg: f64,
    pub stl_mass_kg: f64,
    /// Largest |reaction at B − F_B| over the instants, relative to the peak |F_A|.
    pub reaction_mismatch_rel: f64,
    /// Largest |F_A| over the cycle with the mesh's mass properties, N.
    pub peak_pin_force_n: f64,
    /// With a pressure trace: the cycle's span (720°, the four-stroke cycle) and the largest gas
    /// force on the piston over it, N (absent without a trace: one revolution, no gas force).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cycle_span_deg: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_gas_force_n: Option<f64>,
    /// With a cosine bore load (`[fem] bore_load = "cosine"`): the pin's unit directions (absent:
    /// a uniform bore load, two pin cases).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cosine_bore_load: Option<CosineBoreLoadCases>,
    /// The cycle with the pins in contact at the instants that matter (peak compression, tension,
    /// transverse force, the linear cycle's worst), beside the linear cycle's judged peak there
    /// ([`crate::rod::cycle::contact_instants`]); empty where not solved
    /// (`[fem] load_model_error = false`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contact_instants: Vec<crate::rod::cycle::contact_instants::ContactInstant>,
    /// The fatigue factor from the contact instants beside the linear cycle's at the same
    /// instants ([`crate::rod::cycle::contact_fatigue`]); absent where the instants are.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_fatigue: Option<crate::rod::cycle::contact_fatigue::ContactFatigue>,
    /// Why the contact instants are missing where they were asked for and could not be solved.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_instants_error: Option<String>,
    /// The mean-stress correction of the fatigue factor (absent: Goodman).
    #[serde(default, skip_serializing_if = "MeanStress::is_goodman")]
    pub mean_stress: MeanStress,
    /// The local fatigue safety factor after the FKM guideline's local-stress procedure: the
    /// smallest over the judged surface nodes (docs/fatigue.md); the ranking's fatigue factor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub local_fatigue_safety_factor: Option<f64>,
    /// Where it is and how it was formed: the factor chain, the Findley check.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub local_fatigue: Option<LocalFatigue>,
    /// ParaView file (max-over-cycle von Mises, fatigue factors, χ*) and the picture.
    pub vtu: Option<PathBuf>,
    pub picture: Option<PathBuf>,
    /// Wall time of the analysis (six unit solves with one factorisation, the combination), s.
    pub analysis_seconds: f64,
    /// Wall time of the stage (its files, written by the report, not included), s.
    pub seconds: f64,
}

/// How the cycle superposes a cosine bore load ([`crate::rod::cycle`]): one unit case per pin
/// direction, `direction_step_deg` apart, of which `directions_solved` (those next to a force
/// direction of the cycle) were solved; `unit_solves` counts them with the four body forces, all
/// from one factorisation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CosineBoreLoadCases {
    pub direction_step_deg: f64,
    pub directions: usize,
    pub directions_solved: usize,
    pub unit_solves: usize,
}

/// The FKM local fatigue assessment of the cycle at its critical node ([`crate::rod::cycle::local_fatigue`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LocalFatigue {
    /// How the factor is formed.
    pub method: String,
    /// The critical node (the judged surface node of the smallest factor) and where it is, rod
    /// frame, mm.
    pub node: usize,
    pub at_mm: [f64; 3],
    pub outward_normal: [f64; 3],
    /// S = j_D / a_BK,sv: the load factor to the component fatigue limit.
    pub safety_factor: f64,
    /// Degree of utilisation a_BK,sv (≤ 1 passes FKM with j_D).
    pub utilisation: f64,
    /// j_D = j_S · j_F · j_G.
    pub j_d: f64,
    pub overload: crate::fatigue::OverloadCase,
    /// Crank angles of the two instants taken as the cycle's turning points.
    pub turning_points_deg: [f64; 2],
    /// χ* of the larger surface component there, 1/mm, and its support factor n(χ*).
    pub chi_star_per_mm: f64,
    pub support_factor: f64,
    /// Whether the stress gradient under the node could be formed (else n = 1).
    pub gradient_found: bool,
    /// The two surface stress components and their factor chains.
    pub sigma1: LocalComponent,
    pub sigma2: LocalComponent,
    /// Surface nodes assessed, and those without a gradient (n = 1 there).
    pub surface_nodes: usize,
    pub surface_nodes_without_gradient: usize,
    /// The local factor at the node of the smallest Goodman factor (absent off the surface).
    pub at_goodman_node: Option<f64>,
    /// The Findley critical-plane check.
    pub findley: FindleyCheck,
    /// The picture of the factor on the surface and the Haigh diagram at the critical node.
    pub map_picture: Option<PathBuf>,
    pub haigh_picture: Option<PathBuf>,
    /// Wall time of the local assessment (gradients, every surface node, Findley), s.
    pub seconds: f64,
}

/// One surface stress component at the critical node: the FKM chain, MPa and 1/mm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LocalComponent {
    /// Unit direction in the surface.
    pub direction: [f64; 3],
    /// Amplitude (signed relative to σ_1's) and mean, MPa.
    pub amplitude_mpa: f64,
    pub mean_mpa: f64,
    /// Related stress gradient χ*, 1/mm.
    pub chi_star_per_mm: f64,
    /// Support factor n, roughness factor K_R, surface-treatment factor K_V, design factor K_WK.
    pub support_factor: f64,
    pub roughness_factor: f64,
    pub treatment_factor: f64,
    pub design_factor: f64,
    /// σ_W,zd of the material and σ_WK of the component there, MPa.
    pub sigma_w_zd_mpa: f64,
    pub sigma_wk_mpa: f64,
    /// Mean-stress sensitivity M_σ, mean-stress factor K_AK, amplitude strength σ_AK (MPa).
    pub mean_stress_sensitivity: f64,
    pub mean_stress_factor: f64,
    pub sigma_ak_mpa: f64,
    /// Degree of utilisation |σ_a| j_D / σ_AK.
    pub utilisation: f64,
}

/// The Findley check at the nodes of the lowest local factors and the Goodman node.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FindleyCheck {
    /// Nodes checked.
    pub nodes_checked: usize,
    /// The normal-stress sensitivity k (from f_W,τ).
    pub k: f64,
    /// The node of the smallest Findley factor among them, where, and the factor f_lim / f.
    pub node: usize,
    pub at_mm: [f64; 3],
    pub factor: f64,
    /// The critical plane's normal, shear amplitude and largest normal stress, MPa.
    pub plane_normal: [f64; 3],
    pub shear_amplitude_mpa: f64,
    pub max_normal_stress_mpa: f64,
    /// The local FKM factor at that node.
    pub local_factor_there: Option<f64>,
    /// The Findley factor at the FKM critical node.
    pub factor_at_local_node: f64,
    /// The Findley factor at the Goodman node.
    pub factor_at_goodman_node: f64,
    /// Whether Findley's critical node is the FKM one, and how far apart they are, mm.
    pub same_node: bool,
    pub distance_from_local_mm: f64,
}
