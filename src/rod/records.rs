//! The records of the rod analysis (what `results.json` holds of stage 3): per load case its peaks,
//! checks and error bar ([`LoadCaseResult`]), the analysis as a whole ([`FemResult`]) with its
//! cases ([`LoadCases`]), the adaptive sequence ([`AdaptiveStep`]), the bores as found, the half
//! model and the geometry check.

use std::path::PathBuf;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::bores::BoreSurface;
use super::pin_load::BoreLoad;
use crate::fem::element::QuadratureChoice;
use crate::fem::error::Result;
use crate::fem::estimate::EstimateSummary;
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;
use crate::fem::statics::Timings;

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
    /// The case's name ([`super::cases::LoadCase::name`]: "fx", "fy").
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
    /// The load-model part: how far the judged peak of the thesis' uniform traction is from that
    /// of contact with the pins (the most faithful of the load models, at the clearances of
    /// `load_models.contact`), |P_uniform − P_contact| / P_contact on the final mesh; `None` where
    /// the comparison was not made (`[fem] load_model_error = false`, a command on one mesh).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub estimated_load_model_error_rel: Option<f64>,
    /// The judged peak of this case on the final mesh under each load model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load_models: Option<LoadModelPeaks>,
    /// With contact (`[fem] bore_load = "contact"`): the pins' contact in this case.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact: Option<PinContactRecord>,
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
        self.sum_error_bar();
    }

    /// The load-model part of the error bar ([`Self::estimated_load_model_error_rel`]) with the
    /// peaks it comes from; the sum ε = ε_disc + ε_geom + ε_load (a bound, as in
    /// [`Self::set_error_bar`]).
    pub fn set_load_model_error(&mut self, peaks: LoadModelPeaks) {
        self.estimated_load_model_error_rel = Some(peaks.error_rel());
        self.load_models = Some(peaks);
        self.sum_error_bar();
    }

    fn sum_error_bar(&mut self) {
        self.estimated_error_rel = self.estimated_discretisation_error_rel
            + self.estimated_geometry_error_rel.unwrap_or(0.0)
            + self.estimated_load_model_error_rel.unwrap_or(0.0);
    }

    /// Which part of the error bar is largest: `"discretisation"`, `"geometry"` or `"load model"`.
    pub fn dominant_error(&self) -> &'static str {
        let parts = [
            ("discretisation", self.estimated_discretisation_error_rel),
            ("geometry", self.estimated_geometry_error_rel.unwrap_or(0.0)),
            (
                "load model",
                self.estimated_load_model_error_rel.unwrap_or(0.0),
            ),
        ];
        parts
            .iter()
            .fold(parts[0], |a, b| if b.1 > a.1 { *b } else { a })
            .0
    }
}

/// One case's judged peak (max nodally averaged von Mises away from bore B and the sharp edges,
/// MPa) on the final mesh under each load model: the uniform traction (the thesis'), the cosine
/// bearing pressure and contact with rigid pins (with its record).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LoadModelPeaks {
    pub uniform_mpa: f64,
    /// `None` where the cosine pressure cannot load the bore (a big end without its cap, loaded
    /// across the rod: the pressed half is not all there).
    pub cosine_mpa: Option<f64>,
    pub contact_mpa: f64,
    /// Where the contact peak is, mm.
    pub contact_at_mm: [f64; 3],
    /// The contact peak's discretisation error on this mesh (the single-mesh recovery bound: the
    /// mesh was refined for the model the case was solved under, not for contact's peak).
    pub contact_discretisation_error_rel: f64,
    /// The pins' contact.
    pub contact: PinContactRecord,
}

impl LoadModelPeaks {
    /// |P_uniform − P_contact| / P_contact.
    pub fn error_rel(&self) -> f64 {
        (self.uniform_mpa - self.contact_mpa).abs() / self.contact_mpa
    }
}

/// The contact of the pins with their bores in one case: arcs (degrees about the pin axis, from
/// the contact resultant's direction), peak pressures (face-smoothed, MPa), the big-end bore's
/// change of diameter, the acceptance figures.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PinContactRecord {
    /// The pins: rigid (the default, not written) or elastic ([`crate::rod::pin_model::PinModel`]).
    #[serde(
        default,
        skip_serializing_if = "crate::rod::pin_model::PinModel::is_rigid"
    )]
    pub pins: crate::rod::pin_model::PinModel,
    /// Radial clearances of pins A and B in their bores, µm (negative: interference).
    pub clearance_a_um: f64,
    pub clearance_b_um: f64,
    /// The contact arc on bore A and its ends.
    pub arc_a_deg: f64,
    pub arc_a_ends_deg: [f64; 2],
    pub peak_pressure_a_mpa: f64,
    /// Where the peak pressure is, from the resultant's direction.
    pub peak_pressure_a_at_deg: f64,
    /// The same on bore B; `None` where bore B is clamped (a force across the rod).
    pub arc_b_deg: Option<f64>,
    pub peak_pressure_b_mpa: Option<f64>,
    /// Bore A's change of diameter along the pin force and across it, µm.
    pub ovality_a_along_um: f64,
    pub ovality_a_across_um: f64,
    /// Largest penetration of a wall node into its pin, µm.
    pub penetration_max_um: f64,
    /// Largest tensile contact pressure (0: none), MPa.
    pub max_tensile_pressure_mpa: f64,
    /// |moment| of the support of the rotation that frictionless contact leaves free, N·m (~0).
    pub restraint_moment_nm: f64,
    /// Active-set iterations.
    pub iterations: usize,
    /// Wall time of the solve, s (not in `results.json`).
    #[serde(skip)]
    pub seconds: f64,
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
/// around the calls; `pipeline/meshing/volume.py`, `mesh_volume`). `model`: building the model before
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
    /// The load cases ([`super::cases::STATIC_CASES`]), in their order; written as one field per
    /// case, named by the case (`"fx"`, `"fy"`).
    #[serde(flatten)]
    pub cases: LoadCases,
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
    /// Solved on the half model of a mirror-symmetric rod and mirrored ([`super::half_model::solve_rod_on`]): `nodes`
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

/// A solution made on a half model and mirrored ([`super::half_model::solve_rod_on`]): what was
/// solved.
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

    /// The half model that was solved, out of the mirrored `whole` [`super::half_model::solve_rod_on`] returned: its
    /// first nodes and elements ([`crate::fem::mesh::mirror::MirroredMesh::whole`] puts the images
    /// after them).
    pub fn half_of(&self, whole: &TetMesh) -> Result<TetMesh> {
        TetMesh::new(
            whole.nodes()[..self.nodes].to_vec(),
            whole.elements()[..self.elements].to_vec(),
        )
    }
}

/// The results of the load cases of one analysis, in the order of
/// [`super::cases::STATIC_CASES`]. Written as a map from the case's name to its record, so that each
/// case is a field of [`FemResult`] named by the case (`"fx": {…}, "fy": {…}`).
#[derive(Clone, Debug, Default)]
pub struct LoadCases(pub Vec<LoadCaseResult>);

impl LoadCases {
    /// The case named `name`.
    pub fn get(&self, name: &str) -> Option<&LoadCaseResult> {
        self.0.iter().find(|c| c.name == name)
    }

    /// The case whose judged peak governs: the largest `judged(case)`, the later case where two
    /// are equal.
    pub fn governing_by(&self, judged: impl Fn(&LoadCaseResult) -> f64) -> &LoadCaseResult {
        let mut best = &self.0[0];
        for c in &self.0[1..] {
            if judged(c) >= judged(best) {
                best = c;
            }
        }
        best
    }

    /// The largest of `value` over the cases.
    pub fn max_of(&self, value: impl Fn(&LoadCaseResult) -> f64) -> f64 {
        self.0.iter().map(value).fold(f64::NEG_INFINITY, f64::max)
    }
}

/// `cases["fx"]`: the case named so; panics where there is none (use [`LoadCases::get`] where a
/// case may be absent).
impl std::ops::Index<&str> for LoadCases {
    type Output = LoadCaseResult;
    fn index(&self, name: &str) -> &LoadCaseResult {
        self.get(name)
            .unwrap_or_else(|| panic!("no load case named {name}"))
    }
}

impl std::ops::IndexMut<&str> for LoadCases {
    fn index_mut(&mut self, name: &str) -> &mut LoadCaseResult {
        self.0
            .iter_mut()
            .find(|c| c.name == name)
            .unwrap_or_else(|| panic!("no load case named {name}"))
    }
}

impl std::ops::Deref for LoadCases {
    type Target = Vec<LoadCaseResult>;
    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

impl std::ops::DerefMut for LoadCases {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.0
    }
}

impl Serialize for LoadCases {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = s.serialize_map(Some(self.0.len()))?;
        for c in &self.0 {
            map.serialize_entry(&c.name, c)?;
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for LoadCases {
    /// The entries named by a case of [`super::cases::STATIC_CASES`], in that order; the other
    /// fields of the record pass by.
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Cases;
        impl<'de> serde::de::Visitor<'de> for Cases {
            type Value = LoadCases;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("the load cases, one field per case")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut map: A,
            ) -> std::result::Result<LoadCases, A::Error> {
                let mut found = Vec::new();
                while let Some(key) = map.next_key::<String>()? {
                    if super::cases::case(&key).is_some() {
                        found.push(map.next_value::<LoadCaseResult>()?);
                    } else {
                        map.next_value::<serde::de::IgnoredAny>()?;
                    }
                }
                let order = |c: &LoadCaseResult| {
                    super::cases::STATIC_CASES
                        .iter()
                        .position(|d| d.name == c.name)
                };
                found.sort_by_key(order);
                Ok(LoadCases(found))
            }
        }
        d.deserialize_map(Cases)
    }
}
