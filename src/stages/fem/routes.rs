//! The mesh modes of stage 3, one function each: a fixed gmsh mesh ([`fem_fixed`]), the adaptive
//! loop ([`fem_adaptive`]), the user's volume mesh ([`fem_user_mesh`]), and the refinement study
//! of uniform meshes ([`fem_refinement`]).

use super::super::records::{AdaptiveSummary, LoadedDesign, MeshSummary};
use super::super::rod_surface::RodFrameSurface;
use crate::config::StudyConfig;
use crate::fem::TetMesh;
use crate::mesher::{MeshReport, read_volume_mesh};
use crate::rod::RodOptions;
use crate::rod::adapt::{AdaptOptions, GeometrySizes, adaptive_rod};
use crate::rod::facets::FacetScale;
use crate::rod::half_model::solve_rod_on;
use crate::rod::refinement::{RefinementStudy, refinement_study};
use crate::rod::small_fillets::{SMALL_FILLET_RADIUS_MM, SMALL_FILLET_REACH_MM, SmallFillets};
use crate::rod::solve::{rod_fields, solve_rod_static};
use anyhow::{Context, Result};
use std::path::Path;

use super::setup::*;
use super::*;

/// The mesher's fallbacks of a run, for `mesh.fallback` (`None` when no mesh needed one).
fn joined(fallbacks: &[String]) -> Option<String> {
    (!fallbacks.is_empty()).then(|| fallbacks.join("; "))
}

/// Stage 3 on one gmsh mesh of uniform size `size_mm` (the thesis' setting is 5 mm).
pub fn fem_fixed(
    design: &LoadedDesign,
    loads: &FemLoads,
    config: &StudyConfig,
    work_dir: &Path,
    size_mm: f64,
    keep_system: bool,
    buckling_n: Option<f64>,
) -> Result<FemOutcome> {
    let setup = Setup::new(design, loads, config, true, keep_system)?;
    let force_n = loads.force_n;
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
/// the target ([`crate::rod::adapt`]), sizes floored at the STL's local facet spacing.
pub fn fem_adaptive(
    design: &LoadedDesign,
    loads: &FemLoads,
    config: &StudyConfig,
    work_dir: &Path,
    adaptive: &AdaptiveMeshing,
    keep_system: bool,
    buckling_n: Option<f64>,
) -> Result<FemOutcome> {
    let setup = Setup::new(design, loads, config, true, keep_system)?;
    let force_n = loads.force_n;
    let c = &config.fem;
    setup.check_uniform_size(
        design,
        c.initial_size_mm,
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
    let min_size_mm = if exact {
        c.step_min_size_mm
    } else {
        c.min_size_mm
    };
    let opts = AdaptOptions {
        target_error_rel: adaptive.target_error,
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
    let iterations = out
        .solution
        .result
        .cases
        .first()
        .map_or(0, |c| c.adaptive.len());
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
            target_error_rel: adaptive.target_error,
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
    loads: &FemLoads,
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
        let setup = Setup::without_edges(design, loads, config, false, keep_system);
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
        || {
            solve_rod_static(
                &mesh,
                &setup.material,
                &setup.bores,
                loads.force_n,
                &setup.rod,
            )
        },
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
    Ok(setup.outcome(loads.force_n, config, summary, mesh, solution))
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

/// A refinement study of a loaded design (`rodstudy fem --refine`): one uniform gmsh mesh per size
/// in `sizes_mm` (each in `work_dir/<size>mm`), both cases at `force_n`, the band around the fixed
/// bore from the configuration ([`crate::rod::refinement`]).
pub fn fem_refinement(
    design: &LoadedDesign,
    loads: &FemLoads,
    config: &StudyConfig,
    work_dir: &Path,
    sizes_mm: &[f64],
) -> Result<RefinementStudy> {
    // meshed in the rod frame, mm, as stage 3 meshes (any units and pose); the whole rod, whose
    // uniform meshes the study compares
    let mut setup = Setup::new(design, loads, config, true, false)?;
    let force_n = loads.force_n;
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
