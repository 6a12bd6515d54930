//! Every meshing decision, written once, here: `pipeline/mesh_rod.py` is a gmsh adapter that
//! executes what this policy says and defines no setting of its own.
//!
//! The policy goes to the script as one JSON argument (`--policy=…`, [`MeshPolicy::arg`]) on every
//! call (`mesh`, `mesh-step`, `serve`; the script hands it on to its child processes). It holds
//! the ladder of surface classifications tried in order, the fallbacks and their order, the
//! rounds and floor of the local refinement, the quality limits, the gmsh options and the time
//! the script may take. The ladder and its fallbacks stay in one call of the script rather than
//! one call per rung: a call costs a Python start-up, gmsh's import and the STL's read again
//! (about 0.5 s on this machine, 2026-11-29), while a rod that meshes on the first rung (every
//! design of the study) pays nothing for the rest of the ladder.

use serde::Serialize;

/// The dihedral angle (degrees) of gmsh's first surface classification: edges sharper than this
/// are features, not facet kinks of a curved surface. The same angle sorts the STL's edges on the
/// Rust side (stage 3's surface edges, the facet spacing of the adaptive loop's first mesh).
pub const FEATURE_ANGLE_DEG: f64 = 40.0;

/// Classification settings tried in order, (dihedral angle, curve split angle) in degrees. The
/// first works for most rods; splitting curves at 60° kinks helps where tiny faces meet large ones.
pub const LADDER: [(f64, f64); 6] = [
    (FEATURE_ANGLE_DEG, 180.0),
    (FEATURE_ANGLE_DEG, 60.0),
    (30.0, 180.0),
    (50.0, 180.0),
    (30.0, 60.0),
    (50.0, 60.0),
];

/// The surface meshed differently when every rung of [`LADDER`] fails, in this order (the
/// report's `fallback` names the one that made the mesh):
/// - `local refinement`: the first rung's classification (or the cached one) meshed again with
///   the size reduced around the patch gmsh names in "overlapping facets on surface A surface B"
///   (the smaller of the two by area), round after round ([`LocalRefinement`]); gmsh's Delaunay,
///   whose errors name the surfaces;
/// - `STL surface kept`: the STL's own triangles as the boundary, only the interior meshed.
///
/// Both mesh the bonded body where the STL holds shells touching face to face.
pub const FALLBACKS: [&str; 2] = ["local refinement", "STL surface kept"];

/// The fallback `local refinement`: each round multiplies the size within reach of the blamed
/// patch's boundary curves by `factor`, and grows back to the target over `grow_sizes` target
/// sizes; the curves are sampled at `samples_per_size` points per refined size (their bounding
/// box diagonal as the length), between `samples_min` and `samples_max` points.
#[derive(Clone, Debug, Serialize)]
pub struct LocalRefinement {
    pub rounds: usize,
    pub min_size_mm: f64,
    pub factor: f64,
    pub grow_sizes: f64,
    pub samples_per_size: f64,
    pub samples_min: usize,
    pub samples_max: usize,
}

/// The meshing policy handed to `pipeline/mesh_rod.py` (see the module's doc).
#[derive(Clone, Debug, Serialize)]
pub struct MeshPolicy {
    /// [`LADDER`].
    pub ladder: Vec<(f64, f64)>,
    /// [`FALLBACKS`].
    pub fallbacks: Vec<&'static str>,
    pub local_refinement: LocalRefinement,
    /// The 3D algorithm tried first (`hxt`: Marot, Pellerin & Remacle 2019, 1.6× faster than
    /// Delaunay + Netgen optimisation here, fewer elements for the same sizes; deterministic with
    /// one thread, not with two) and the one tried where it refuses a surface mesh or leaves a
    /// sliver (`delaunay`, with Netgen's optimisation, whose errors name the surfaces: the local
    /// refinement's algorithm, and the one that meshes a kept STL surface).
    pub algorithm_3d: &'static str,
    pub algorithm_3d_fallback: &'static str,
    /// Smallest acceptable signed inverse condition number of an element: a sliver makes K
    /// ill-conditioned (the reactions stop balancing the load to 1e-6).
    pub min_sicn: f64,
    /// A STEP's curved element whose scaled Jacobian is below this is made straight-sided (gmsh's
    /// own target for its high-order optimiser, `Mesh.HighOrderThresholdMin`).
    pub curved_sj_min: f64,
    /// The open edges of a half model lie in one plane z = const within this fraction of the
    /// part's extent (the classified curves' boxes come from their reparametrisation: 3e-6 mm
    /// off the plane seen on a 200 mm rod).
    pub cut_plane_tol_rel: f64,
    /// Seconds the script's `mesh` may take before it stops trying and writes what it tried
    /// ([`time_limit_s`]).
    pub time_limit_s: f64,
    /// gmsh options in the order they are set; `None`: set per request (the size, curved or
    /// straight-sided midside nodes).
    pub gmsh_options: Vec<(&'static str, Option<f64>)>,
    /// Set after [`Self::gmsh_options`] for a mesh from a size field.
    pub size_field_options: Vec<(&'static str, f64)>,
    /// Set after [`Self::gmsh_options`] for a uniform mesh.
    pub uniform_options: Vec<(&'static str, f64)>,
    /// What the last line of a total failure suggests.
    pub what_to_try: &'static str,
}

/// The script's own time limit inside the limit `limit_s` the Rust side kills it at: a little
/// before, so that a fallback that runs out of time still ends in a message saying what was
/// tried: `limit − max(3 s, 5 % of limit)`.
pub fn time_limit_s(limit_s: f64) -> f64 {
    limit_s - (0.05 * limit_s).max(3.0)
}

impl MeshPolicy {
    /// The policy of every mesh rodstudy makes, under the pipeline's time limit
    /// ([`crate::python_env::pipeline_timeout`]).
    pub fn standard() -> Self {
        MeshPolicy {
            ladder: LADDER.to_vec(),
            fallbacks: FALLBACKS.to_vec(),
            local_refinement: LocalRefinement {
                rounds: 12,
                min_size_mm: 0.1,
                factor: 0.5,
                grow_sizes: 2.0,
                samples_per_size: 4.0,
                samples_min: 20,
                samples_max: 2000,
            },
            algorithm_3d: "hxt",
            algorithm_3d_fallback: "delaunay",
            min_sicn: 0.01,
            curved_sj_min: 0.1,
            cut_plane_tol_rel: 1e-6,
            time_limit_s: time_limit_s(crate::python_env::pipeline_timeout().as_secs_f64()),
            gmsh_options: GMSH_OPTIONS.to_vec(),
            size_field_options: vec![
                // the background field alone sets the sizes (gmsh's examples/api/adapt_mesh.py)
                ("Mesh.MeshSizeExtendFromBoundary", 0.0),
                // the curves' 1D mesh integrates 1/size along each curve to this relative
                // precision; gmsh's default 1e-9 made the 1D mesh 0.8 s of a 1.5 s mesh (design
                // 1); 1e-3 takes 0.15-0.36 s on a half model's later mesh (the node spacing along
                // a curve moves by far less than the element sizes the loop asks for)
                ("Mesh.LcIntegrationPrecision", 1e-3),
            ],
            // gmsh's default (a session's later mesh resets it)
            uniform_options: vec![("Mesh.LcIntegrationPrecision", 1e-9)],
            what_to_try: "try: an STL exported at a different chord tolerance (finer or coarser), a STEP export of the part (meshed on the exact geometry), another --size, or a volume mesh of your own (--mesh)",
        }
    }

    /// The policy as the script's argument `--policy=JSON`.
    pub fn arg(&self) -> String {
        format!(
            "--policy={}",
            serde_json::to_string(self).expect("the policy is plain data")
        )
    }
}

/// Every gmsh option that influences the mesh, fixed so that results depend neither on defaults
/// nor on a user's gmsh configuration files (which are not read). Deterministic: one thread, a
/// fixed 3D algorithm and random seed, so the same STL and size give the same mesh bit for bit.
const GMSH_OPTIONS: [(&str, Option<f64>); 22] = [
    ("General.Terminal", Some(0.0)),
    ("General.NumThreads", Some(1.0)),
    ("Mesh.Algorithm", Some(6.0)), // Frontal-Delaunay (2D)
    ("Mesh.Algorithm3D", None),    // MeshPolicy::algorithm_3d
    ("Mesh.RandomSeed", Some(1.0)),
    ("Mesh.MeshSizeMax", None), // the size asked for
    ("Mesh.MeshSizeMin", Some(0.0)),
    ("Mesh.MeshSizeFactor", Some(1.0)),
    ("Mesh.MeshSizeFromCurvature", Some(0.0)),
    ("Mesh.MeshSizeFromPoints", Some(0.0)),
    // sizes of boundary curves extend into the surfaces, not into the volume: a tiny curve (a
    // sliver face of the STL) refines its surroundings on the surface only
    ("Mesh.MeshSizeExtendFromBoundary", Some(-2.0)),
    ("Mesh.Optimize", Some(1.0)),
    ("Mesh.OptimizeNetgen", Some(1.0)),
    ("Mesh.OptimizeThreshold", Some(0.3)),
    ("Mesh.ElementOrder", Some(2.0)),
    // midside nodes at the straight edge midpoints (1) unless curved elements are asked for:
    // snapping them onto a surface reconstructed from an STL (faceted, so nothing is gained in
    // accuracy) can invert elements
    ("Mesh.SecondOrderLinear", None),
    ("Mesh.SecondOrderIncomplete", Some(0.0)),
    ("Mesh.HighOrderOptimize", Some(0.0)),
    ("Mesh.MshFileVersion", Some(4.1)),
    ("Mesh.Binary", Some(0.0)),
    ("Mesh.SaveAll", Some(0.0)),
    ("Mesh.LcIntegrationPrecision", None), // size_field_options or uniform_options
];

#[cfg(test)]
mod tests {
    use super::*;

    /// The script reads the policy as JSON: every field it uses is there, the ladder starts at the
    /// feature angle, and the time limit sits inside the Rust side's.
    #[test]
    fn the_policy_is_json_the_script_reads() {
        let p = MeshPolicy::standard();
        let v: serde_json::Value =
            serde_json::from_str(p.arg().strip_prefix("--policy=").unwrap()).unwrap();
        assert_eq!(v["ladder"][0][0].as_f64(), Some(FEATURE_ANGLE_DEG));
        assert_eq!(v["fallbacks"][1], "STL surface kept");
        assert_eq!(v["gmsh_options"][5][0], "Mesh.MeshSizeMax");
        assert!(v["gmsh_options"][5][1].is_null());
        assert_eq!(time_limit_s(600.0), 570.0);
        assert_eq!(time_limit_s(10.0), 7.0);
    }
}
