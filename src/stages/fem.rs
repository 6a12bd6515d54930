//! Stage 3 for one design: mesh the rod with gmsh (tet10, `pipeline/mesh_rod.py`, through
//! [`crate::mesher`]), solve the two load cases F_x and F_y of the design's peak pin force, refine
//! adaptively until the estimated error of the judged peak is at most the target (or keep one
//! fixed mesh, or take the user's), judge the stress criterion (SPEC "Stage 3", "Outputs"). One
//! function per mesh mode; [`fem`] picks by [`MeshMode`]. The stage writes no report file: it
//! returns the record, the final mesh and the fields ([`crate::report::fields`] writes them).
//!
//! **Any units, any pose.** The rod is meshed in its own frame, in millimetres
//! ([`super::rod_surface`]). Locations in the results are rod-frame millimetres; the VTU files
//! are in the same frame.
//!
//! The criterion is judged on the convergent measure, the maximum nodally averaged von Mises
//! stress outside a fixed physical band around the fixed bore (the fully fixed bore edge is a
//! singularity whose peak grows with refinement), optionally plus its estimated error; the raw
//! peak is reported beside it.
//!
//! **Buckling.** With a pressure trace (`[engine] pressure_trace`, the engine study) the stage
//! also computes the linear buckling load factor of the rod under its peak compression
//! ([`buckling`]: the F_x case with that magnitude, B fixed, load on A towards B) and judges it
//! against `[criterion] buckling_factor`; without a trace the default study does not (its results
//! stay as they were). `rodstudy fem` always reports it.

use super::criterion::{judge_buckling, verdict};
use super::records::{
    AdaptiveSummary, DesignDynamics, DesignFem, LoadedDesign, MeshSummary, StageMesh,
};
use super::rod_surface::{RodFrameSurface, rod_frame_surface};
use crate::config::{FemConfig, StudyConfig, Symmetry};
use crate::fem::adapt::{AdaptOptions, GeometrySizes, adaptive_rod};
use crate::fem::buckling::{BucklingMode, BucklingOptions, BucklingSolution};
use crate::fem::facets::{FacetScale, MAX_FILLET_RADIUS_MM, SurfaceEdges};
use crate::fem::refinement::{RefinementStudy, refinement_study};
use crate::fem::rod::{HalfModel, RodSolution, rod_fields, solve_rod_on, solve_rod_static};
use crate::fem::rod_buckling::rod_buckling;
use crate::fem::small_fillets::{SMALL_FILLET_RADIUS_MM, SMALL_FILLET_REACH_MM, SmallFillets};
use crate::fem::smooth::{SmoothSurface, geometry_check};
use crate::fem::statics::FactorisedSystem;
use crate::fem::{BoreSpec, Material, RodOptions, TetMesh};
use crate::mesher::{GmshRodMesher, MESHER_SCRIPT, MeshReport, StepInRodFrame, read_volume_mesh};
use crate::python_env::{pipeline_script, python};
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// The dihedral angle (degrees) of gmsh's first surface classification: edges sharper than this
/// are features, not facet kinks of a curved surface.
pub const FEATURE_ANGLE_DEG: f64 = 40.0;

/// How stage 3 meshes: one fixed mesh, adaptive refinement, or the user's mesh.
#[derive(Debug, Clone, PartialEq)]
pub enum MeshMode {
    /// One gmsh mesh of this size, mm.
    Fixed(f64),
    /// Adaptive refinement with these settings.
    Adaptive(AdaptiveMeshing),
    /// The user's volume mesh (in the design's units and pose).
    User(PathBuf),
}

/// The settings of adaptive refinement (`[fem]` of the configuration, `--target-error`).
#[derive(Debug, Clone, PartialEq)]
pub struct AdaptiveMeshing {
    /// Target estimated relative error of each case's judged peak.
    pub target_error: f64,
    /// Uniform size of the first mesh, the largest and the smallest size asked for, mm.
    pub initial_size_mm: f64,
    pub max_size_mm: f64,
    pub min_size_mm: f64,
    /// The smallest size on a STEP's exact geometry, mm.
    pub step_min_size_mm: f64,
    pub max_iterations: usize,
    pub max_dofs: usize,
}

impl AdaptiveMeshing {
    /// The configuration's settings, with the target `target_error`.
    pub fn new(c: &FemConfig, target_error: f64) -> Self {
        AdaptiveMeshing {
            target_error,
            initial_size_mm: c.initial_size_mm,
            max_size_mm: c.max_size_mm,
            min_size_mm: c.min_size_mm,
            step_min_size_mm: c.step_min_size_mm,
            max_iterations: c.max_iterations,
            max_dofs: c.max_dofs,
        }
    }
}

impl MeshMode {
    /// The configuration's choice: adaptive when `fem.target_error` > 0, else fixed.
    pub fn from_config(config: &StudyConfig) -> Self {
        if config.fem.adaptive() {
            MeshMode::Adaptive(AdaptiveMeshing::new(&config.fem, config.fem.target_error))
        } else {
            MeshMode::Fixed(config.fem.mesh_size_mm)
        }
    }
}

/// What stage 3 returns: the record, the mesh it ended on (for the cycle) and the fields of the
/// final solution (for the report's VTU files and pictures).
pub struct FemOutcome {
    pub record: DesignFem,
    pub mesh: StageMesh,
    pub solution: RodSolution,
    /// The buckling analysis [`fem_and_buckling`] ran beside the geometry check, not yet applied
    /// to the record ([`apply_buckling`]); `None` when none was asked for.
    pub buckling_run: Option<BucklingRun>,
}

/// A buckling analysis of stage 3's final mesh under `compression_n` (N), and what came of it.
pub struct BucklingRun {
    pub compression_n: f64,
    pub result: Result<BucklingSolution>,
}

/// Stage 3 of a loaded design under `force_n` in the mode asked for; gmsh's files go under
/// `work_dir`.
pub fn fem(
    design: &LoadedDesign,
    force_n: f64,
    config: &StudyConfig,
    work_dir: &Path,
    mode: &MeshMode,
) -> Result<FemOutcome> {
    fem_and_buckling(design, force_n, config, work_dir, mode, false, None)
}

/// [`fem`]; `keep_system`: the outcome keeps the factorised K of the final mesh
/// ([`RodSolution::system`]) for an analysis the caller runs on it; with `buckling_n` a buckling
/// analysis under that compression (N) on the final mesh, left in [`FemOutcome::buckling_run`]
/// for the caller to apply ([`apply_buckling`]). The engine study (a pressure trace) judges
/// buckling under the peak compression itself (an error there is stage 3's). Either buckling
/// analysis runs beside the geometry check of an STL (`fem DESIGN`'s time beyond the adaptive
/// loop 0.1–1.0 s less on the five designs; docs/fem.md).
pub fn fem_and_buckling(
    design: &LoadedDesign,
    force_n: f64,
    config: &StudyConfig,
    work_dir: &Path,
    mode: &MeshMode,
    keep_system: bool,
    buckling_n: Option<f64>,
) -> Result<FemOutcome> {
    let engine = config.engine.pressure_trace.is_some();
    let engine_n = if engine {
        Some(buckling_load(design, config)?)
    } else {
        None
    };
    // one analysis beside the geometry check: the engine's, else the one asked for
    let beside = engine_n.or(buckling_n);
    let keep = keep_system || beside.is_some();
    let mut outcome = match mode {
        MeshMode::Fixed(size_mm) => {
            fem_fixed(design, force_n, config, work_dir, *size_mm, keep, beside)
                .map_err(|e| crossing_facets_said(design, e))
        }
        MeshMode::Adaptive(a) => fem_adaptive(design, force_n, config, work_dir, a, keep, beside)
            .map_err(|e| crossing_facets_said(design, e)),
        MeshMode::User(file) => {
            let mut outcome = fem_user_mesh(design, force_n, config, work_dir, file, keep)?;
            outcome.buckling_run = beside.map(|n| buckling_run(&outcome, config, n));
            Ok(outcome)
        }
    }?;
    if engine {
        let run = outcome
            .buckling_run
            .take()
            .expect("run beside the geometry check");
        let b = run
            .result
            .with_context(|| format!("{}: buckling", design.file.display()))?;
        apply_buckling(&mut outcome, run.compression_n, b, Some(config));
        // an analysis under another load asked for besides (`fem --force`) runs after
        outcome.buckling_run = buckling_n.map(|n| buckling_run(&outcome, config, n));
    }
    if !keep_system {
        outcome.solution.system = None;
    }
    Ok(outcome)
}

/// A mesher failure on an STL whose facets cross each other says so first (gmsh's own words,
/// "Invalid boundary mesh (overlapping facets)" or a parametrisation it cannot make, do not say
/// where): the pairs, one of them and where, and what to do. Other errors pass unchanged.
fn crossing_facets_said(design: &LoadedDesign, e: anyhow::Error) -> anyhow::Error {
    let message = format!("{e:#}");
    if design.format.step().is_some() || !(message.contains("gmsh") || message.contains("mesher")) {
        return e;
    }
    let Some(c) = crate::geometry::self_crossing::crossing_facets(&design.mesh) else {
        return e;
    };
    let s = 1.0 / design.settings.units.to_metres();
    let u = design.settings.units.symbol();
    e.context(format!(
        "{}: the STL's surface crosses itself ({} pair(s) of facets cross or overlap, e.g. \
         triangles {} and {} at ({:.3}, {:.3}, {:.3}) {u}), which gmsh cannot mesh: repair the \
         surface in CAD (or a mesh repair tool) and export it again",
        design.file.display(),
        c.pairs,
        c.triangles.0,
        c.triangles.1,
        c.at.x * s,
        c.at.y * s,
        c.at.z * s
    ))
}

/// The engine's loads of a design (with a pressure trace): stage 2's record on the configured
/// engine (closed form), whose peak compression is the buckling case's load and whose largest
/// pin force across the rod is the F_y case's magnitude. `None` without a trace.
pub fn engine_loads(design: &LoadedDesign, config: &StudyConfig) -> Result<Option<DesignDynamics>> {
    if config.engine.pressure_trace.is_none() {
        return Ok(None);
    }
    let mass = super::mass::mass(design)?;
    let (dynamics, _) = super::dynamics::dynamics_with(
        &mass,
        &config.driven_scene(),
        config.driven.gravity,
        &config.engine,
        crate::mechanism::Method::ClosedForm,
    )?;
    Ok(Some(dynamics))
}

/// The load of the buckling case of a design: with a pressure trace its peak compression along
/// A→B (`peak_compression_n` of stage 2), else its peak pin force (the F_x case's magnitude).
pub fn buckling_load(design: &LoadedDesign, config: &StudyConfig) -> Result<f64> {
    let dynamics = match engine_loads(design, config)? {
        Some(d) => d,
        None => {
            let mass = super::mass::mass(design)?;
            super::dynamics::dynamics_with(
                &mass,
                &config.driven_scene(),
                config.driven.gravity,
                &config.engine,
                crate::mechanism::Method::ClosedForm,
            )?
            .0
        }
    };
    Ok(dynamics
        .peak_compression_n
        .unwrap_or(dynamics.peak_pin_force_n))
}

/// [`buckling`] on the outcome's mesh and its kept factorisation, not yet applied.
fn buckling_run(outcome: &FemOutcome, config: &StudyConfig, compression_n: f64) -> BucklingRun {
    BucklingRun {
        compression_n,
        result: buckling(
            &outcome.mesh,
            config,
            compression_n,
            outcome.solution.system.as_deref(),
        ),
    }
}

/// Linear buckling of the rod on stage 3's mesh (supports as stage 3: bore B fixed) under the
/// compression `compression_n` on bore A towards B (the F_x case;
/// [`crate::fem::rod_buckling::rod_buckling`]): the smallest positive load factor λ₁ and its mode.
/// `system`: the factorised K of stage 3 on this mesh, if kept ([`fem_and_buckling`]).
pub fn buckling(
    stage: &StageMesh,
    config: &StudyConfig,
    compression_n: f64,
    system: Option<&FactorisedSystem>,
) -> Result<BucklingSolution> {
    Ok(rod_buckling_with(
        &stage.mesh,
        &Material::from(&config.fem),
        &stage.bores,
        compression_n,
        system,
    )?)
}

/// The rod's buckling analysis with stage 3's settings.
fn rod_buckling_with(
    mesh: &TetMesh,
    material: &Material,
    bores: &BoreSpec,
    compression_n: f64,
    system: Option<&FactorisedSystem>,
) -> crate::fem::Result<BucklingSolution> {
    rod_buckling(
        mesh,
        material,
        bores,
        compression_n,
        RodOptions::default().quadrature,
        &BucklingOptions::default(),
        system,
    )
}

/// A buckling analysis' factor into the record, its mode into the fields (the report writes
/// `buckling_mode.vtu`); with `judge`, the verdict too (`[criterion] buckling_factor`).
pub fn apply_buckling(
    outcome: &mut FemOutcome,
    compression_n: f64,
    b: BucklingSolution,
    judge: Option<&StudyConfig>,
) {
    outcome.record.buckling_load_factor = Some(b.load_factor);
    if let Some(config) = judge {
        judge_buckling(&mut outcome.record.criterion, b.load_factor, config);
    }
    outcome.solution.buckling = Some(BucklingMode {
        load_factor: b.load_factor,
        load_n: compression_n,
        mode: b.mode,
    });
}

/// What every mode shares: the rod-frame surface, its bores, the material, the singular edges
/// and the options of the rod analysis.
struct Setup {
    surface: RodFrameSurface,
    /// The half model's surface, when the rod is mirror-symmetric ([`half_surface`]): what gmsh
    /// meshes instead of `surface`.
    half: Option<HalfSurface>,
    /// The exact geometry in the rod frame, for a STEP design.
    step: Option<StepInRodFrame>,
    bores: BoreSpec,
    material: Material,
    /// The surface's edges: kinks, faceted small fillets, sharp edges ([`Setup::edges`]).
    edges: Option<SurfaceEdges>,
    /// The caller keeps the factorised K of the final mesh (buckling on it).
    keep_system: bool,
    singular_edges: Vec<[[f64; 3]; 2]>,
    rod: RodOptions,
    /// `<file>: FEM`, the context of every error.
    context: String,
}

const FRAME: &str = "rod frame, mm: origin at the crank pin A, x along A→B, z along the pin axis";

impl Setup {
    /// Everything but the surface's edges, which [`Setup::set_edges`] adds (a given mesh works
    /// them out while K is factorised, [`fem_user_mesh`]). `for_gmsh`: the surface is what gmsh
    /// will mesh (simplified); else a given mesh is solved and the surface only tells the sharp
    /// re-entrant edges. With a pressure trace the F_y case carries the largest pin force across
    /// the rod over the engine's cycle ([`engine_loads`]).
    fn without_edges(
        design: &LoadedDesign,
        config: &StudyConfig,
        for_gmsh: bool,
        keep_system: bool,
    ) -> Result<Self> {
        let context = format!("{}: FEM", design.file.display());
        if let Some(gap) = design.loose_gap_m {
            anyhow::bail!(
                "{context}: the file holds bodies that do not touch (the nearest two at least \
                 {:.3} mm apart): a body that touches nothing carries no load and has no static \
                 solution; join them in CAD (rod and cap meet at the joint face) or remove the \
                 loose body",
                gap * 1e3
            );
        }
        let fy_force_n = engine_loads(design, config)
            .with_context(|| context.clone())?
            .and_then(|d| d.peak_transverse_n);
        let surface = rod_frame_surface(design, for_gmsh);
        let half = if for_gmsh && design.format.step().is_none() {
            half_surface(&surface, config.fem.symmetry)
        } else {
            None
        };
        let rod = RodOptions {
            mirror_plane_z_m: half.as_ref().map(|h| h.plane_z_mm * 1e-3),
            fixed_band_m: Some(config.fem.fixed_band_mm * 1e-3),
            singular_band_m: Some(config.fem.singular_band_mm * 1e-3),
            fy_force_n,
            exact_geometry: design.format.step().is_some(),
            // the STL route keeps the last solve's system: the geometry check reuses its symbolic
            // analysis
            keep_system: keep_system || (for_gmsh && design.format.step().is_none()),
            ..RodOptions::default()
        };
        let step = design.format.step().map(|report| {
            let f = &design.frame;
            let to_metres = report.metres_per_unit;
            StepInRodFrame {
                step: design.file.clone(),
                origin: (f.origin / to_metres).into(),
                axes: [f.x.into(), f.y.into(), f.z.into()],
                scale: to_metres * 1e3,
            }
        });
        // a partial bore (a big end without its cap) is loaded or fixed on the arc that exists
        let mut bores = surface.bores();
        if let Ok(m) = crate::geometry::design::rod_mass(design) {
            bores.loaded_arc_deg = m.pins.crank_bore_arc_deg;
            bores.fixed_arc_deg = m.pins.piston_bore_arc_deg;
        }
        bores.bore_load = config.fem.bore_load;
        Ok(Setup {
            step,
            bores,
            surface,
            half,
            material: Material::from(&config.fem),
            edges: None,
            keep_system,
            singular_edges: Vec::new(),
            rod,
            context,
        })
    }

    /// [`Setup::without_edges`] with the surface's edges ([`Setup::set_edges`]).
    fn new(
        design: &LoadedDesign,
        config: &StudyConfig,
        for_gmsh: bool,
        keep_system: bool,
    ) -> Result<Self> {
        let mut setup = Self::without_edges(design, config, for_gmsh, keep_system)?;
        let edges = setup.surface_edges();
        setup.set_edges(edges);
        Ok(setup)
    }

    /// The surface's edges classified, and its sharp re-entrant edges (segments, m).
    fn surface_edges(&self) -> (SurfaceEdges, Vec<[[f64; 3]; 2]>) {
        let edges = SurfaceEdges::new(
            &self.surface.vertices,
            &self.surface.triangles,
            FEATURE_ANGLE_DEG,
            MAX_FILLET_RADIUS_MM,
        );
        let singular = edges
            .sharp_reentrant(&self.surface.vertices)
            .into_iter()
            .map(|s| s.map(|p| p.map(|v| v * 1e-3)))
            .collect();
        (edges, singular)
    }

    /// Sets the edges of [`Setup::surface_edges`] and what the rod analysis takes of them.
    fn set_edges(&mut self, (edges, singular): (SurfaceEdges, Vec<[[f64; 3]; 2]>)) {
        self.rod.singular_edges_m = singular.clone();
        self.rod.fillet_kink_edges = edges.fillet_kinks();
        self.singular_edges = singular;
        self.edges = Some(edges);
    }

    /// The surface's edges ([`Setup::set_edges`] has set them: every constructor but
    /// [`Setup::without_edges`] does).
    fn edges(&self) -> &SurfaceEdges {
        self.edges
            .as_ref()
            .expect("the surface's edges are set before they are used")
    }

    /// The gmsh adapter on this surface (writes `work_dir/rod_frame.stl`), or on the exact
    /// geometry of a STEP design (curved tet10).
    fn mesher(&self, work_dir: &Path) -> Result<GmshRodMesher> {
        let python = python().with_context(|| self.context.clone())?;
        let (stl_bytes, digest) = match &self.half {
            Some(h) => (&h.stl_bytes, &h.digest),
            None => (&self.surface.stl_bytes, &self.surface.digest),
        };
        let mesher = GmshRodMesher::new(
            &python,
            &pipeline_script(MESHER_SCRIPT),
            stl_bytes,
            digest,
            work_dir,
            &self.context[..self.context.len() - ": FEM".len()],
        )
        .with_context(|| self.context.clone())?;
        Ok(match &self.step {
            Some(step) => mesher.with_step(step.clone()),
            None => mesher,
        })
    }

    /// What the meshes are made from, for `mesh.source`.
    fn source(&self) -> &'static str {
        if self.step.is_some() {
            "gmsh from the STEP (curved tet10 on the exact geometry)"
        } else {
            "gmsh from the STL (straight-sided tet10)"
        }
    }

    /// The record and the outcome of a solution on `mesh`.
    fn outcome(
        self,
        force_n: f64,
        config: &StudyConfig,
        summary: MeshSummary,
        mesh: TetMesh,
        solution: RodSolution,
    ) -> FemOutcome {
        let criterion = verdict(&solution.result, config, self.surface.centre_distance_mm);
        FemOutcome {
            record: DesignFem {
                force_n,
                mesh: summary,
                fem: solution.result.clone(),
                criterion,
                buckling_load_factor: None,
            },
            mesh: StageMesh {
                mesh,
                bores: self.bores,
                singular_edges_m: self.singular_edges,
                fixed_band_m: config.fem.fixed_band_mm * 1e-3,
                singular_band_m: config.fem.singular_band_mm * 1e-3,
            },
            solution,
            buckling_run: None,
        }
    }

    /// Splits each case's estimated error into its discretisation part (as estimated so far) and
    /// its geometry part, and folds the two into `estimated_error_rel` (their sum: a bound). The
    /// geometry part of a STEP design is 0 (the exact geometry, curved elements); of an STL, the
    /// change of the judged peak when the same mesh is curved onto the smooth surface through the
    /// STL's vertices ([`crate::fem::smooth`]).
    ///
    /// With `buckling_n`, the buckling analysis under that compression runs beside the geometry
    /// check, on the kept factorisation, and is returned.
    fn add_geometry_error(
        &self,
        mesh: &TetMesh,
        solution: &mut RodSolution,
        force_n: f64,
        buckling_n: Option<f64>,
    ) -> Option<BucklingRun> {
        // the first solve's symbolic analysis serves the second; its factor is freed first unless
        // the caller keeps it
        let symbolic = solution
            .system
            .as_ref()
            .map(|s| s.factor.symbolic().clone());
        let system = solution.system.clone();
        if !self.keep_system {
            solution.system = None;
        }
        let buckle = || {
            buckling_n.map(|n| BucklingRun {
                compression_n: n,
                result: rod_buckling_with(mesh, &self.material, &self.bores, n, system.as_deref())
                    .map_err(Into::into),
            })
        };
        let r = &mut solution.result;
        let peaks = [
            r.fx.max_von_mises_away_from_fixed_mpa,
            r.fy.max_von_mises_away_from_fixed_mpa,
        ];
        // per case: the geometry part (None: could not be estimated) and the smooth peak
        let (smooth, buckled): ([(Option<f64>, Option<f64>); 2], _) = if self.step.is_some() {
            ([(Some(0.0), None); 2], buckle())
        } else {
            let surface = SmoothSurface::new(
                &self.surface.vertices,
                &self.surface.triangles,
                self.edges(),
                2.0,
            );
            // the mesh solved, curved: a half model's half, solved as the half and mirrored;
            // else the whole
            let half = r.half_model.as_ref();
            let rod = RodOptions {
                keep_system: false,
                reuse_symbolic: symbolic,
                mirror_plane_z_m: half.map(HalfModel::plane_z_m),
                ..self.rod.clone()
            };
            let (checked, buckled) = rayon::join(
                || {
                    let half_mesh = half.map(|h| h.half_of(mesh)).transpose()?;
                    let solved = half_mesh.as_ref().unwrap_or(mesh);
                    geometry_check(solved, &surface, &self.material, &self.bores, force_n, &rod)
                },
                buckle,
            );
            let smooth = match checked {
                Ok(check) => {
                    r.geometry_check = Some(check.record());
                    std::array::from_fn(|c| {
                        let p = check.peaks_mpa[c];
                        (Some((p - peaks[c]).abs() / peaks[c]), Some(p))
                    })
                }
                Err(e) => {
                    r.warnings.push(format!(
                        "the geometry error (what the STL's facets do to the judged peak) is unknown: the mesh curved onto the smooth surface through the STL's vertices could not be solved ({e}); the error bars are the discretisation's alone"
                    ));
                    [(None, None); 2]
                }
            };
            (smooth, buckled)
        };
        for (case, (g, p)) in [&mut r.fx, &mut r.fy].into_iter().zip(smooth) {
            let d = case.estimated_error_rel;
            case.estimated_discretisation_error_rel = d;
            case.estimated_geometry_error_rel = g;
            case.smooth_surface_peak_mpa = p;
            case.estimated_error_rel = d + g.unwrap_or(0.0);
        }
        buckled
    }

    fn surface_triangles(&self) -> [usize; 2] {
        [self.surface.triangles_export, self.surface.triangles.len()]
    }
}

/// The half model's surface: the rod-frame surface's half z ≥ c as the binary STL gmsh meshes,
/// open at the cut (gmsh closes it with a plane surface on the cut's classified curves,
/// `mesh_rod.py`'s `cap_open_cut`; the cap of [`crate::geometry::half_solid::half_above`] is what
/// shows the half to be a closed solid of half the volume).
struct HalfSurface {
    stl_bytes: Vec<u8>,
    /// SHA-256 of the STL bytes (keys the classified-surface cache).
    digest: String,
    /// The symmetry plane z = c, mm (rod frame).
    plane_z_mm: f64,
}

/// Largest distance of a vertex's mirror image from the rod-frame surface for the rod to count as
/// mirror-symmetric about its mid-plane across the pin axis, mm (the five designs' exports: 0.017–0.024
/// mm, their tessellations' chordal error). Also the largest move of a vertex onto the plane when
/// the surface is halved.
pub const MIRROR_TOLERANCE_MM: f64 = 0.05;

/// The half of `surface` (rod frame, mm) when the rod is mirror-symmetric about the plane halving
/// its thickness ([`crate::geometry::mirror_symmetry`]) and `symmetry` allows; `None` otherwise,
/// or when the halved surface is not a valid closed solid of half the volume (then the whole rod
/// is meshed, as without symmetry).
fn half_surface(surface: &RodFrameSurface, symmetry: Symmetry) -> Option<HalfSurface> {
    use crate::geometry::primitives::{binary_stl, to_soup};
    if symmetry == Symmetry::Off {
        return None;
    }
    let mesh = crate::geometry::IndexedMesh {
        vertices: surface
            .vertices
            .iter()
            .map(|v| nalgebra::Vector3::from(*v))
            .collect(),
        triangles: surface.triangles.clone(),
    };
    let fit = crate::geometry::mirror_symmetry::mirror_fit_z(&mesh)?;
    if !fit.is_symmetric(MIRROR_TOLERANCE_MM) {
        return None;
    }
    let half = crate::geometry::half_solid::half_above(&mesh, fit.z, MIRROR_TOLERANCE_MM).ok()?;
    let half = crate::geometry::validate::validate(half).ok()?;
    let ratio = crate::geometry::mass_properties::signed_volume(&half.mesh)
        / crate::geometry::mass_properties::signed_volume(&mesh);
    if !half.warnings.is_empty() || (ratio - 0.5).abs() > 1e-3 {
        return None;
    }
    // gmsh gets the half open at the cut and builds the cap itself, as one plane surface on the
    // cut's classified curves (`mesh_rod.py`, `cap_open_cut`): the cap's triangles would be
    // classified into patches whose cuts meet the cut's edge, where the peaks of a bending rod lie
    let open = crate::geometry::IndexedMesh {
        vertices: half.mesh.vertices.clone(),
        triangles: half
            .mesh
            .triangles
            .iter()
            .filter(|t| t.iter().any(|&i| half.mesh.vertices[i as usize].z > fit.z))
            .copied()
            .collect(),
    };
    let stl_bytes = binary_stl(&to_soup(&open));
    Some(HalfSurface {
        digest: super::rod_surface::sha256_hex(&stl_bytes),
        stl_bytes,
        plane_z_mm: fit.z,
    })
}

/// The mesher's fallbacks of a run, for `mesh.fallback` (`None` when no mesh needed one).
fn joined(fallbacks: &[String]) -> Option<String> {
    (!fallbacks.is_empty()).then(|| fallbacks.join("; "))
}

/// Stage 3 on one gmsh mesh of uniform size `size_mm` (the thesis' setting is 5 mm).
pub fn fem_fixed(
    design: &LoadedDesign,
    force_n: f64,
    config: &StudyConfig,
    work_dir: &Path,
    size_mm: f64,
    keep_system: bool,
    buckling_n: Option<f64>,
) -> Result<FemOutcome> {
    let setup = Setup::new(design, config, true, keep_system)?;
    setup.check_uniform_size(design, size_mm, "size (`--size`, `fem.mesh_size_mm`)")?;
    let mut mesher = setup.mesher(work_dir)?;
    let meshed = mesher
        .fixed(size_mm)
        .with_context(|| setup.context.clone())?;
    let r: &MeshReport = &meshed.report;
    let (mesh, mut solution) = solve_rod_on(
        meshed.mesh,
        &setup.material,
        &setup.bores,
        force_n,
        &setup.rod,
    )
    .with_context(|| setup.context.clone())?;
    let buckling_run = setup.add_geometry_error(&mesh, &mut solution, force_n, buckling_n);
    let summary = MeshSummary {
        source: setup.source().into(),
        size_mm: Some(r.size_mm),
        elements: mesh.n_elements(),
        nodes: mesh.n_nodes(),
        min_sicn: Some(r.min_sicn),
        min_scaled_jacobian: Some(r.min_scaled_jacobian),
        seconds: r.seconds_wall.max(r.seconds_total),
        frame: FRAME.into(),
        adaptive: None,
        surface_triangles: setup.surface_triangles(),
        fallback: joined(&mesher.fallbacks),
        curved_elements_straightened: r.curved_elements_straightened,
    };
    let mut outcome = setup.outcome(force_n, config, summary, mesh, solution);
    outcome.buckling_run = buckling_run;
    Ok(outcome)
}

/// Stage 3 refined adaptively until the estimated error of each case's judged peak is at most
/// the target ([`crate::fem::adapt`]), sizes floored at the STL's local facet spacing.
pub fn fem_adaptive(
    design: &LoadedDesign,
    force_n: f64,
    config: &StudyConfig,
    work_dir: &Path,
    settings: &AdaptiveMeshing,
    keep_system: bool,
    buckling_n: Option<f64>,
) -> Result<FemOutcome> {
    let setup = Setup::new(design, config, true, keep_system)?;
    setup.check_uniform_size(
        design,
        settings.initial_size_mm,
        "first mesh of the adaptive loop (`fem.initial_size_mm`, with `fem.max_size_mm` at least as large)",
    )?;
    let mut mesher = setup.mesher(work_dir)?;
    let facets = FacetScale::from_edges(setup.edges(), &setup.surface.vertices, 2.0);
    // an STL's facets set a floor below which refinement resolves the facets, not the part; the
    // exact geometry of a STEP has none
    let exact = setup.step.is_some();
    let floor = |p: [f64; 3]| {
        if exact {
            0.0
        } else {
            facets.at(p.map(|v| v * 1e3)) * 1e-3
        }
    };
    // a concave fillet far below the first mesh's size is refined from the second mesh on, on
    // an STL and on a STEP's tessellation alike
    let small_fillets = SmallFillets::from_edges(
        setup.edges(),
        &setup.surface.vertices,
        SMALL_FILLET_RADIUS_MM,
        SMALL_FILLET_REACH_MM,
    );
    let ceiling = |p: [f64; 3]| small_fillets.ceiling_at(p.map(|v| v * 1e3)) * 1e-3;
    let c = settings;
    let min_size_mm = if exact {
        c.step_min_size_mm
    } else {
        c.min_size_mm
    };
    let opts = AdaptOptions {
        target_error_rel: c.target_error,
        initial_size_m: c.initial_size_mm * 1e-3,
        max_size_m: c.max_size_mm * 1e-3,
        min_size_m: min_size_mm * 1e-3,
        max_iterations: c.max_iterations,
        max_dofs: c.max_dofs,
        ..AdaptOptions::default()
    };
    let out = adaptive_rod(
        &mut mesher,
        &setup.material,
        &setup.bores,
        force_n,
        &setup.rod,
        &opts,
        &GeometrySizes {
            floor: &floor,
            ceiling: &ceiling,
        },
    )
    .with_context(|| setup.context.clone())?;
    let mut out = out;
    let buckling_run = setup.add_geometry_error(&out.mesh, &mut out.solution, force_n, buckling_n);
    let r = mesher.last_report.expect("at least one mesh");
    let iterations = out.solution.result.fx.adaptive.len();
    let summary = MeshSummary {
        source: format!("{}, adaptive", setup.source()),
        size_mm: None,
        elements: out.mesh.n_elements(),
        nodes: out.mesh.n_nodes(),
        min_sicn: Some(r.min_sicn),
        min_scaled_jacobian: Some(r.min_scaled_jacobian),
        seconds: out.mesh_s,
        frame: FRAME.into(),
        adaptive: Some(AdaptiveSummary {
            target_error_rel: c.target_error,
            stop: out.stop,
            iterations,
            initial_size_mm: c.initial_size_mm,
            min_size_mm,
            floor: if exact {
                "none: the exact geometry (STEP); at least step_min_size_mm".into()
            } else {
                format!(
                    "the STL's local facet spacing: the spacing of the nearest kink (below {FEATURE_ANGLE_DEG}°, or a kink of a faceted small fillet), at least min_size_mm"
                )
            },
            facet_spacing_median_mm: if exact { 0.0 } else { facets.median_spacing() },
            monotone: out.monotone,
        }),
        surface_triangles: setup.surface_triangles(),
        fallback: joined(&mesher.fallbacks),
        curved_elements_straightened: r.curved_elements_straightened,
    };
    let mut outcome = setup.outcome(force_n, config, summary, out.mesh, out.solution);
    outcome.buckling_run = buckling_run;
    Ok(outcome)
}

/// Stage 3 on the user's volume mesh `file` (tet10, in the design's units and pose), moved into
/// the rod frame.
pub fn fem_user_mesh(
    design: &LoadedDesign,
    force_n: f64,
    config: &StudyConfig,
    work_dir: &Path,
    file: &Path,
    keep_system: bool,
) -> Result<FemOutcome> {
    // the mesh is read (gmsh MSH 4.1 and .inp natively, other formats through meshio, into
    // work_dir/user.rodmesh) while the rod-frame surface and its singular edges are prepared
    let (setup, read) = std::thread::scope(|scope| {
        let reading = scope.spawn(|| {
            let start = std::time::Instant::now();
            read_volume_mesh(file, "mm", work_dir).map(|(m, _)| (m, start.elapsed()))
        });
        let setup = Setup::without_edges(design, config, false, keep_system);
        let read = reading
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (setup, read)
    });
    let mut setup = setup?;
    // the reader's errors mostly start with the file's name already
    let (read, read_time) = read.map_err(|e| {
        let (name, m) = (file.display().to_string(), e.to_string());
        if m.starts_with(&name) {
            anyhow::anyhow!("cannot use this volume mesh: {m}")
        } else {
            anyhow::anyhow!("{name}: cannot use this volume mesh: {m}")
        }
    })?;
    let start = std::time::Instant::now();
    // the file's numbers were read as mm (×1e-3); the file is in the design's units
    let f = setup.surface.frame;
    let s = setup.surface.to_metres * 1e3;
    let mesh = read
        .map_nodes(|_, p| {
            let q = nalgebra::Vector3::new(p[0], p[1], p[2]) * s - f.origin;
            [q.dot(&f.x), q.dot(&f.y), q.dot(&f.z)]
        })
        .with_context(|| format!("{}: the mesh in the rod frame", file.display()))?;
    check_mesh_is_the_designs(&mesh, &setup.surface).with_context(|| {
        format!(
            "{}: not a mesh of {}",
            file.display(),
            design.file.display()
        )
    })?;
    // reading and moving the mesh, not the analysis (fem.total_s)
    let mesh_seconds = (read_time + start.elapsed()).as_secs_f64();
    // the surface's sharp edges matter only to the stresses' post-processing: worked out while K
    // is factorised (on one thread)
    let (solved, edges) = rayon::join(
        || solve_rod_static(&mesh, &setup.material, &setup.bores, force_n, &setup.rod),
        || setup.surface_edges(),
    );
    setup.set_edges(edges);
    let solution = solved
        .and_then(|st| rod_fields(st, &setup.rod))
        .with_context(|| setup.context.clone())?;
    let summary = MeshSummary {
        source: file.display().to_string(),
        size_mm: None,
        elements: mesh.n_elements(),
        nodes: mesh.n_nodes(),
        min_sicn: None,
        min_scaled_jacobian: None,
        seconds: mesh_seconds,
        frame: FRAME.into(),
        adaptive: None,
        surface_triangles: setup.surface_triangles(),
        fallback: None,
        curved_elements_straightened: None,
    };
    Ok(setup.outcome(force_n, config, summary, mesh, solution))
}

/// How far a given mesh's volume may lie from the design's (relative): a straight-sided tet10
/// mesh of a rod at 8 mm loses well under 1 % on its bores' chords, gmsh's meshes of the
/// designs 0.02–0.08 %.
pub const USER_MESH_VOLUME_TOLERANCE: f64 = 0.02;

/// How far a given mesh's bounding box may lie from the design's, as a fraction of the centre
/// distance A→B.
pub const USER_MESH_EXTENT_TOLERANCE: f64 = 0.02;

/// A given mesh must be a mesh of the design it is analysed as: the same volume (within
/// [`USER_MESH_VOLUME_TOLERANCE`]) and the same extent in the rod frame (within
/// [`USER_MESH_EXTENT_TOLERANCE`] of l), or the loads and supports (placed from the design's
/// pins) would land on another part, in other units or in another pose.
fn check_mesh_is_the_designs(mesh: &TetMesh, surface: &RodFrameSurface) -> Result<()> {
    let mesh_mm3 = crate::fem::body_force::mesh_mass_properties(mesh, 1.0).volume_m3 * 1e9;
    let design_mm3 = surface.volume_mm3();
    let rel = (mesh_mm3 - design_mm3) / design_mm3;
    if rel.is_nan() || rel.abs() > USER_MESH_VOLUME_TOLERANCE {
        anyhow::bail!(
            "the mesh's volume, {mesh_mm3:.6e} mm³, differs by {:+.1} % from the design's, \
             {design_mm3:.6e} mm³ (more than {:.0} %): give a mesh of this design, in the design's \
             units (sidecar `units`) and its file's axes",
            100.0 * rel,
            100.0 * USER_MESH_VOLUME_TOLERANCE
        );
    }
    let (lo, hi) = mesh.bounding_box();
    let (mut dlo, mut dhi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for v in &surface.vertices {
        for k in 0..3 {
            dlo[k] = dlo[k].min(v[k]);
            dhi[k] = dhi[k].max(v[k]);
        }
    }
    let worst = (0..3)
        .flat_map(|k| [(lo[k] * 1e3 - dlo[k]).abs(), (hi[k] * 1e3 - dhi[k]).abs()])
        .fold(0.0, f64::max);
    let allowed = USER_MESH_EXTENT_TOLERANCE * surface.centre_distance_mm;
    if worst.is_nan() || worst > allowed {
        let fmt = |l: [f64; 3], h: [f64; 3], s: f64| {
            format!(
                "x {:.1}…{:.1}, y {:.1}…{:.1}, z {:.1}…{:.1} mm",
                l[0] * s,
                h[0] * s,
                l[1] * s,
                h[1] * s,
                l[2] * s,
                h[2] * s
            )
        };
        anyhow::bail!(
            "the mesh spans {} in the rod frame, the design {} (a corner {worst:.1} mm off, more \
             than {allowed:.1} mm): give the mesh in the design file's axes and units",
            fmt(lo, hi, 1e3),
            fmt(dlo, dhi, 1.0)
        );
    }
    Ok(())
}

/// DOFs of a uniform gmsh tet10 mesh per (volume / size³): 35.6 on design 1 at 5 mm (111,150 DOFs,
/// 3.90e5 mm³), 39 on design 5 (99,285, 3.18e5 mm³); the guard below takes 30, an estimate
/// from below.
const UNIFORM_MESH_DOFS_PER_CELL: f64 = 30.0;

/// The largest uniform mesh stage 3 starts: far beyond a rod's useful meshes (design 1 at 2 mm
/// has about 1.7 M DOFs, at 1 mm about 14 M), and far below a rod read in the wrong units (a
/// centimetre file read as millimetres makes its 5 mm mesh 1000 times larger, 1.1e8 DOFs).
pub const UNIFORM_MESH_MAX_DOFS: f64 = 2e7;

impl Setup {
    /// Refuses, before gmsh starts, a uniform mesh of `size_mm` that would be far beyond what can
    /// be solved: a size meant for another part, or a design read in the wrong units (a
    /// millimetre rod read as metres is 1e9 times its volume).
    /// `knob` names the setting that chose the size.
    fn check_uniform_size(&self, design: &LoadedDesign, size_mm: f64, knob: &str) -> Result<()> {
        let v = self.surface.volume_mm3();
        let dofs = UNIFORM_MESH_DOFS_PER_CELL * v / size_mm.powi(3);
        if dofs > UNIFORM_MESH_MAX_DOFS {
            anyhow::bail!(
                "{}: a uniform {size_mm} mm mesh of this part ({v:.3e} mm³, {:.1} mm between the \
                 pins) would have about {dofs:.1e} DOFs, beyond the {UNIFORM_MESH_MAX_DOFS:.0e} \
                 stage 3 starts: check the units (sidecar `units`, now {}), or give a larger {knob}",
                self.context,
                self.surface.centre_distance_mm,
                design.settings.units.symbol()
            );
        }
        Ok(())
    }
}

/// A refinement study of a loaded design (`rodstudy fem --refine`): one uniform gmsh mesh per size
/// in `sizes_mm` (each in `work_dir/<size>mm`), both cases at `force_n`, the band around the fixed
/// bore from the configuration ([`crate::fem::refinement`]).
pub fn fem_refinement(
    design: &LoadedDesign,
    force_n: f64,
    config: &StudyConfig,
    work_dir: &Path,
    sizes_mm: &[f64],
) -> Result<RefinementStudy> {
    // meshed in the rod frame, mm, as stage 3 meshes (any units and pose); the whole rod, whose
    // uniform meshes the study compares
    let mut setup = Setup::new(design, config, true, false)?;
    setup.half = None;
    setup.rod.mirror_plane_z_m = None;
    for &size in sizes_mm {
        setup.check_uniform_size(design, size, "`--refine` size")?;
    }
    let mesher = setup.mesher(work_dir)?;
    Ok(refinement_study(
        sizes_mm,
        |size| {
            let t = std::time::Instant::now();
            let m = mesher.uncached(size, &work_dir.join(format!("{size}mm")))?;
            Ok((m.mesh, t.elapsed().as_secs_f64()))
        },
        &setup.material,
        &setup.bores,
        force_n,
        // stage 3's options: "away" is the stress stage 3 judges (the bands around the fixed
        // bore and the sharp re-entrant edges left out)
        &RodOptions {
            keep_system: false,
            ..setup.rod.clone()
        },
    )?)
}
