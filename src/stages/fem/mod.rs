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
use super::records::{DesignDynamics, DesignFem, LoadedDesign, StageMesh};
use crate::config::StudyConfig;
use crate::fem::buckling::{BucklingMode, BucklingOptions, BucklingSolution};
use crate::fem::statics::FactorisedSystem;
use crate::fem::{Material, TetMesh};
use crate::geometry::design::DesignMass;
use crate::rod::buckling::rod_buckling;
use crate::rod::load_models::compare_load_models;
use crate::rod::solve::RodSolution;
use crate::rod::{BoreSpec, RodOptions};
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

pub use crate::mesher::policy::FEATURE_ANGLE_DEG;

/// How stage 3 meshes: one fixed mesh, adaptive refinement, or the user's mesh.
#[derive(Debug, Clone, PartialEq)]
pub enum MeshMode {
    /// One gmsh mesh of this size, mm.
    Fixed(f64),
    /// Adaptive refinement to this target (the sizes and limits: the configuration's `[fem]`).
    Adaptive(AdaptiveMeshing),
    /// The user's volume mesh (in the design's units and pose).
    User(PathBuf),
}

/// Adaptive refinement to a target: the target error of each case's judged peak. The loop's
/// sizes and limits (`fem.initial_size_mm`, `max_size_mm`, `min_size_mm`, `step_min_size_mm`,
/// `max_iterations`, `max_dofs`) are read where they live, the configuration's `[fem]` handed to
/// the stage beside the mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveMeshing {
    /// Target estimated relative error of each case's judged peak.
    pub target_error: f64,
}

impl AdaptiveMeshing {
    /// Refinement to the target `target_error`.
    pub fn new(target_error: f64) -> Self {
        AdaptiveMeshing { target_error }
    }
}

impl MeshMode {
    /// The configuration's choice: adaptive when `fem.target_error` > 0, else fixed.
    pub fn from_config(config: &StudyConfig) -> Self {
        if config.fem.adaptive() {
            MeshMode::Adaptive(AdaptiveMeshing::new(config.fem.target_error))
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
    /// The contact solution of the load-model comparison on the whole mesh, for the report's
    /// fields (`None`: not compared, or the solution is itself contact's).
    pub contact: Option<(TetMesh, RodSolution)>,
}

/// A buckling analysis of stage 3's final mesh under `compression_n` (N), and what came of it.
pub struct BucklingRun {
    pub compression_n: f64,
    pub result: Result<BucklingSolution>,
}

/// Stage 3 of a loaded design under `loads` in the mode asked for; gmsh's files go under
/// `work_dir`.
pub fn fem(
    design: &LoadedDesign,
    loads: &FemLoads,
    config: &StudyConfig,
    work_dir: &Path,
    mode: &MeshMode,
) -> Result<FemOutcome> {
    fem_and_buckling(design, loads, config, work_dir, mode, false, None)
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
    loads: &FemLoads,
    config: &StudyConfig,
    work_dir: &Path,
    mode: &MeshMode,
    keep_system: bool,
    buckling_n: Option<f64>,
) -> Result<FemOutcome> {
    let engine = loads.engine;
    let engine_n = engine.then_some(loads.compression_n);
    // one analysis beside the geometry check: the engine's, else the one asked for
    let beside = engine_n.or(buckling_n);
    let keep = keep_system || beside.is_some();
    let mut outcome = match mode {
        MeshMode::Fixed(size_mm) => {
            fem_fixed(design, loads, config, work_dir, *size_mm, keep, beside)
                .map_err(|e| crossing_facets_said(design, e))
        }
        MeshMode::Adaptive(a) => fem_adaptive(design, loads, config, work_dir, a, keep, beside)
            .map_err(|e| crossing_facets_said(design, e)),
        MeshMode::User(file) => {
            let mut outcome = fem_user_mesh(design, loads, config, work_dir, file, keep)?;
            outcome.buckling_run = beside.map(|n| buckling_run(&outcome, config, n));
            Ok(outcome)
        }
    }?;
    if config.fem.load_model_error
        && let Err(e) = add_load_model_error(&mut outcome, loads, config)
    {
        // the comparison is a figure beside the analysis: its failure is said, not fatal
        let w = format!("the load model's error was not estimated: {e:#}");
        outcome.record.fem.warnings.push(w.clone());
        outcome.solution.result.warnings.push(w);
    }
    if engine {
        let run = outcome
            .buckling_run
            .take()
            .expect("run beside the geometry check");
        let b = run
            .result
            .with_context(|| format!("{}: buckling", design.file.display()))?;
        apply_buckling(&mut outcome, run.compression_n, b, Some(config));
        if config.fem.load_model_error {
            add_contact_buckling(&mut outcome, run.compression_n, config);
        }
        // an analysis under another load asked for besides (`fem --force`) runs after
        outcome.buckling_run = buckling_n.map(|n| buckling_run(&outcome, config, n));
    }
    if !keep_system {
        outcome.solution.system = None;
    }
    Ok(outcome)
}

/// The load model's part of each case's error bar ([`crate::rod::load_models`]): the cases solved
/// on the final mesh under the other load models, ε_load into the record and the solution, the
/// verdict judged again with it; the contact solution's fields kept for the report.
fn add_load_model_error(
    outcome: &mut FemOutcome,
    loads: &FemLoads,
    config: &StudyConfig,
) -> Result<()> {
    let stage = &outcome.mesh;
    let options = RodOptions {
        fixed_band_m: Some(stage.fixed_band_m),
        singular_band_m: Some(stage.singular_band_m),
        singular_edges_m: stage.singular_edges_m.clone(),
        fy_force_n: loads.transverse_n,
        ..RodOptions::default()
    };
    let compared = compare_load_models(
        &stage.mesh,
        &outcome.solution,
        &Material::from(&config.fem),
        &stage.bores,
        loads.force_n,
        &options,
    )?;
    for (c, peaks) in compared.peaks.into_iter().enumerate() {
        outcome.record.fem.cases.0[c].set_load_model_error(peaks.clone());
        outcome.solution.result.cases.0[c].set_load_model_error(peaks);
    }
    let b = stage.bores.fixed_centre_m;
    let a = stage.bores.loaded_centre_m;
    let centre_distance_mm = 1e3 * (0..3).map(|j| (b[j] - a[j]).powi(2)).sum::<f64>().sqrt();
    outcome.record.criterion = verdict(&outcome.record.fem, config, centre_distance_mm);
    outcome.contact = compared.contact;
    if let Some(e) = compared.cosine_error {
        let w = format!("the load-model comparison has no cosine pressure: {e}");
        outcome.record.fem.warnings.push(w.clone());
        outcome.solution.result.warnings.push(w);
    }
    Ok(())
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

/// What stage 3 takes from the records of stages 1 and 2: the forces of its load cases and of its
/// buckling case, and the arcs of the bores. Whether the study is the engine's (a pressure trace,
/// read and checked once with the configuration, [`crate::config::EngineConfig::pressure_trace`])
/// is read from stage 2's record, which holds the cycle's figures exactly then.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FemLoads {
    /// The pin force: the F_x case's magnitude (stage 2's peak pin force, or `fem --force`), N.
    pub force_n: f64,
    /// With a pressure trace, the largest pin force across the rod over the cycle: the F_y case's
    /// magnitude (`None`: the pin force, the thesis' setting), N.
    pub transverse_n: Option<f64>,
    /// The buckling case's compression: with a pressure trace the peak compression along A→B,
    /// else the peak pin force, N.
    pub compression_n: f64,
    /// The engine study (stage 2 ran the four-stroke cycle with the gas force): stage 3 judges
    /// buckling under `compression_n` itself.
    pub engine: bool,
    /// The arcs of the crank-pin bore A and the piston-pin bore B (a partial bore, a big end
    /// without its cap, is loaded or fixed on the arc that exists), degrees.
    pub bore_arcs_deg: [f64; 2],
}

impl FemLoads {
    /// The loads of stage 3 from the records of stage 1 (`mass`) and stage 2 (`dynamics`, on the
    /// configured engine: its cycle's figures are there exactly with a pressure trace).
    pub fn from_records(mass: &DesignMass, dynamics: &DesignDynamics) -> Self {
        FemLoads {
            force_n: dynamics.peak_pin_force_n,
            transverse_n: dynamics.peak_transverse_n,
            compression_n: dynamics
                .peak_compression_n
                .unwrap_or(dynamics.peak_pin_force_n),
            engine: dynamics.peak_compression_n.is_some(),
            bore_arcs_deg: [mass.pins.crank_bore_arc_deg, mass.pins.piston_bore_arc_deg],
        }
    }

    /// The loads of a design whose stages 1 and 2 have not run (a command on one design, a test):
    /// they run here (stage 2 in closed form on the configured scene and engine, as the study runs
    /// it).
    pub fn of_design(design: &LoadedDesign, config: &StudyConfig) -> Result<Self> {
        let mass = super::mass::mass(design)?;
        let (dynamics, _) = super::dynamics::dynamics_with(
            &mass,
            &config.driven_scene(),
            config.driven.gravity,
            &config.engine,
            crate::mechanism::Method::ClosedForm,
        )?;
        Ok(Self::from_records(&mass, &dynamics))
    }

    /// These loads with the pin force `force_n` (N) instead (`fem --force`).
    pub fn with_force(self, force_n: f64) -> Self {
        FemLoads { force_n, ..self }
    }
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
/// [`crate::rod::buckling::rod_buckling`]): the smallest positive load factor λ₁ and its mode.
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

/// The buckling factor with the compression entering bore A through contact
/// ([`crate::rod::buckling::rod_buckling_contact`]) beside the record's, on the kept factorisation
/// (the same supports: bore B clamped); a figure beside the analysis: its failure is a warning.
fn add_contact_buckling(outcome: &mut FemOutcome, compression_n: f64, config: &StudyConfig) {
    let stage = &outcome.mesh;
    let b = crate::rod::buckling::rod_buckling_contact(
        &stage.mesh,
        &Material::from(&config.fem),
        &stage.bores,
        compression_n,
        RodOptions::default().quadrature,
        &BucklingOptions::default(),
        outcome.solution.system.as_deref(),
    );
    match b {
        Ok(b) => outcome.record.buckling_load_factor_contact = Some(b.load_factor),
        Err(e) => {
            let w = format!("the buckling factor under contact was not computed: {e}");
            outcome.record.fem.warnings.push(w.clone());
            outcome.solution.result.warnings.push(w);
        }
    }
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

mod routes;
mod setup;

pub use routes::{
    USER_MESH_EXTENT_TOLERANCE, USER_MESH_VOLUME_TOLERANCE, fem_adaptive, fem_fixed,
    fem_refinement, fem_user_mesh,
};
pub use setup::{MIRROR_TOLERANCE_MM, UNIFORM_MESH_MAX_DOFS};
