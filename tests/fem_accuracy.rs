//! Stage 3 accuracy end to end: the stress does not depend on the units or the pose of
//! the export, and the adaptive loop reaches a converged reference within its target.
//!
//! References: the same rod in millimetres as the one to compare with (units, pose); for the
//! adaptive loop, the fillet test rod of `pipeline/fillet_rod.py` whose converged peaks were
//! established independently of the STL route (`tests/data/fillet_rod_reference.json`: curved
//! tetra10 meshes of the exact OpenCASCADE geometry, refined at the fillets, extrapolated).

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use rodstudy::config::StudyConfig;
use rodstudy::geometry::primitives::{binary_stl, to_soup, transformed};
use rodstudy::geometry::stl_file::read_stl_file;
use rodstudy::geometry::weld::weld;
use rodstudy::stages;
use rodstudy::stages::fem::{AdaptiveMeshing, MeshMode};
use rodstudy::stages::records::DesignFem;
use std::path::Path;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Writes `dir/NAME.stl` (design 1 scaled by `scale` from mm, then rotated and moved) with its
/// sidecar in `units`.
fn variant(
    dir: &Path,
    name: &str,
    units: &str,
    scale: f64,
    rot: Matrix3<f64>,
    shift: Vector3<f64>,
) {
    let (soup, _) = read_stl_file(&root().join("designs/design1.stl")).unwrap();
    let mesh = weld(&soup).scaled(scale);
    let moved = transformed(&mesh, &rot, shift);
    std::fs::write(
        dir.join(format!("{name}.stl")),
        binary_stl(&to_soup(&moved)),
    )
    .unwrap();
    let a = shift;
    let b = rot * Vector3::new(180.0 * scale, 0.0, 0.0) + shift;
    let z = rot * Vector3::z();
    std::fs::write(
        dir.join(format!("{name}.toml")),
        format!(
            "units = \"{units}\"\ncrank_pin = [{}, {}, {}]\npiston_pin = [{}, {}, {}]\npin_axis = [{}, {}, {}]\n",
            a.x, a.y, a.z, b.x, b.y, b.z, z.x, z.y, z.z
        ),
    )
    .unwrap();
}

fn fem(dir: &Path, name: &str, config: &StudyConfig, mode: &MeshMode) -> DesignFem {
    let work = dir.join(format!("work-{name}"));
    let design = stages::mass::load(&dir.join(format!("{name}.stl")))
        .unwrap_or_else(|e| panic!("{name}: {e:#}"));
    stages::fem::fem(
        &design,
        &stages::fem::FemLoads::of_design(&design, config)
            .unwrap()
            .with_force(7500.0),
        config,
        &work,
        mode,
    )
    .unwrap_or_else(|e| panic!("{name}: {e:#}"))
    .record
}

/// Stage 3 of the STL `stl` under `force` [N], refined adaptively to the configuration's target.
fn adaptive_record(
    stl: &std::path::Path,
    force: f64,
    config: &StudyConfig,
    work: &std::path::Path,
) -> rodstudy::stages::records::DesignFem {
    let design = stages::mass::load(stl).unwrap();
    let mode = MeshMode::Adaptive(AdaptiveMeshing::new(config.fem.target_error));
    stages::fem::fem(
        &design,
        &stages::fem::FemLoads::of_design(&design, config)
            .unwrap()
            .with_force(force),
        config,
        work,
        &mode,
    )
    .unwrap()
    .record
}

#[test]
fn the_stress_does_not_depend_on_units_or_pose() {
    let dir = tempfile::tempdir().unwrap();
    let id = Matrix3::identity();
    let turn = *Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(1.0, 2.0, 3.0)), 0.7)
        .matrix();
    variant(dir.path(), "mm", "mm", 1.0, id, Vector3::zeros());
    variant(dir.path(), "m", "m", 1e-3, id, Vector3::zeros());
    variant(dir.path(), "in", "in", 1.0 / 25.4, id, Vector3::zeros());
    // metres, turned about a skew axis and moved 1.24 m away
    variant(
        dir.path(),
        "m_moved",
        "m",
        1e-3,
        turn,
        Vector3::new(1.2, -0.3, 0.05),
    );
    // millimetres, turned and moved 2 m away
    variant(
        dir.path(),
        "mm_moved",
        "mm",
        1.0,
        turn,
        Vector3::new(-2000.0, 150.0, 700.0),
    );
    let config = StudyConfig::default();
    let mode = MeshMode::Fixed(6.0);
    let base = fem(dir.path(), "mm", &config, &mode);
    for name in ["m", "in", "m_moved", "mm_moved"] {
        let v = fem(dir.path(), name, &config, &mode);
        for (a, b, case) in [
            (&base.fem.cases["fx"], &v.fem.cases["fx"], "fx"),
            (&base.fem.cases["fy"], &v.fem.cases["fy"], "fy"),
        ] {
            let (sa, sb) = (
                a.max_von_mises_away_from_fixed_mpa,
                b.max_von_mises_away_from_fixed_mpa,
            );
            let bar = a.estimated_error_rel + b.estimated_error_rel;
            let diff = (sa - sb).abs() / sa;
            eprintln!(
                "{name} {case}: {sb:.3} vs {sa:.3} MPa ({diff:.1e}; error bars {bar:.3}); displacement {:.5} vs {:.5} mm",
                b.max_displacement_mm, a.max_displacement_mm
            );
            assert!(
                diff <= bar,
                "{name} {case}: {sb} vs {sa} MPa beyond the error bars {bar}"
            );
            let du = (a.max_displacement_mm - b.max_displacement_mm).abs() / a.max_displacement_mm;
            assert!(du <= bar, "{name} {case}: displacement {du}");
            // The largest displacement is a smooth, global quantity: the meshes of the five
            // variants differ only through the float32 rounding of the exports (gmsh's mesh is
            // not stable under it, so a coarse mesh's peak stress moves within its error bar),
            // and it agrees far more closely (measured: 1e-4).
            assert!(du < 5e-3, "{name} {case}: displacement differs by {du}");
        }
    }
}

/// Richardson extrapolation of the last two of a sequence of peaks with element sizes `h` and
/// order `q`; with the order observed from the last three where they change monotonically.
fn extrapolate(h: &[f64], p: &[f64]) -> (f64, f64) {
    let n = p.len();
    let (d1, d2) = (p[n - 2] - p[n - 3], p[n - 1] - p[n - 2]);
    let r = h[n - 2] / h[n - 1];
    if d1 * d2 > 0.0 {
        let q = (d1 / d2).ln() / r.ln();
        let c = d2 / (r.powf(q) - 1.0);
        (p[n - 1] + c, c.abs().max(1e-9))
    } else {
        // not monotone: the mean of the last two, half their difference as the uncertainty
        (0.5 * (p[n - 1] + p[n - 2]), 0.5 * d2.abs())
    }
}

#[test]
fn adaptive_peak_reaches_the_converged_reference_of_the_fillet_rod() {
    let data: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("tests/data/fillet_rod_reference.json")).unwrap(),
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let stl = dir.path().join("fillet_rod.stl");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .args(["pipeline", "fillet_rod.py", "stl"])
        .arg(&stl)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let config = StudyConfig::default();
    assert_eq!(config.fem.target_error, 0.03);
    let force = data["force_n"].as_f64().unwrap();
    let work = dir.path().join("work");
    let r = adaptive_record(&stl, force, &config, &work);
    let h: Vec<f64> = data["near_size_mm"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    // the target holds for the governing case (F_y here); the smaller case's error need only be
    // as small in MPa (3 % of the governing peak)
    let governing = r.fem.cases["fx"]
        .max_von_mises_away_from_fixed_mpa
        .max(r.fem.cases["fy"].max_von_mises_away_from_fixed_mpa);
    for (case, got) in [("fx", &r.fem.cases["fx"]), ("fy", &r.fem.cases["fy"])] {
        let p: Vec<f64> = data[case]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let (reference, uncertainty) = extrapolate(&h, &p);
        let peak = got.max_von_mises_away_from_fixed_mpa;
        let target = 0.03 * (governing / peak).max(1.0);
        let true_error = (peak - reference).abs() / reference;
        // the estimate: the discretisation's (what the loop converges) plus the geometry's (what
        // the STL's facets do, measured by the same mesh curved onto a smooth surface)
        // (the load-model part is not what the reference measures: both use the uniform traction)
        let d = got.estimated_discretisation_error_rel;
        let g = got
            .estimated_geometry_error_rel
            .expect("an STL's geometry error");
        let l = got.estimated_load_model_error_rel.unwrap_or(0.0);
        let est = d + g;
        eprintln!(
            "{case}: adaptive {peak:.2} MPa ± {:.2} % = {:.2} % + {:.2} % geometry (target {:.1} %), reference {reference:.2} ± {:.2} MPa: true error {:.2} %, true / estimated {:.2}",
            100.0 * est,
            100.0 * d,
            100.0 * g,
            100.0 * target,
            uncertainty,
            100.0 * true_error,
            true_error / est
        );
        assert!(
            (got.estimated_error_rel - (d + g + l)).abs() < 1e-15,
            "{case}: the sum of the parts"
        );
        assert!(g > 0.0 && got.smooth_surface_peak_mpa.is_some(), "{case}");
        assert!(d <= target, "{case}: converged to the target");
        assert!(
            true_error <= target,
            "{case}: within the target of the reference"
        );
        // the error bar is honest: the true error is within twice the estimate (with the
        // reference's own uncertainty)
        assert!(
            true_error <= 2.0 * est + uncertainty / reference,
            "{case}: true {true_error} vs estimated {est}"
        );
    }
}

/// Each triangle of `soup` split into four at its edge midpoints (float32, as an export stores
/// them): the same surface in four times the triangles.
fn subdivide(soup: &[[[f32; 3]; 3]]) -> Vec<[[f32; 3]; 3]> {
    let mid = |a: [f32; 3], b: [f32; 3]| std::array::from_fn(|j| 0.5 * (a[j] + b[j]));
    soup.iter()
        .flat_map(|&[a, b, c]| {
            let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
            [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
        })
        .collect()
}

#[test]
fn a_finer_export_of_the_same_surface_gives_the_same_stress() {
    let dir = tempfile::tempdir().unwrap();
    let (soup, _) = read_stl_file(&root().join("designs/design2.stl")).unwrap();
    let fine = subdivide(&subdivide(&soup));
    assert_eq!(fine.len(), 16 * soup.len());
    std::fs::write(dir.path().join("coarse.stl"), binary_stl(&soup)).unwrap();
    std::fs::write(dir.path().join("fine.stl"), binary_stl(&fine)).unwrap();
    let config = StudyConfig::default();
    let mode = MeshMode::Fixed(5.0);
    let coarse = fem(dir.path(), "coarse", &config, &mode);
    let finer = fem(dir.path(), "fine", &config, &mode);
    let [export_c, meshed_c] = coarse.mesh.surface_triangles;
    let [export_f, meshed_f] = finer.mesh.surface_triangles;
    eprintln!("triangles: export {export_c} → {meshed_c}, 16× export {export_f} → {meshed_f}");
    // the simplification gives gmsh about the same surface (the subdivision points all go; the
    // guard against new slivers keeps a few more triangles than the coarse export's own)
    assert!(
        (meshed_f as f64) < 1.3 * meshed_c as f64,
        "{meshed_f} vs {meshed_c}"
    );
    for (a, b, case) in [
        (&coarse.fem.cases["fx"], &finer.fem.cases["fx"], "fx"),
        (&coarse.fem.cases["fy"], &finer.fem.cases["fy"], "fy"),
    ] {
        let (sa, sb) = (
            a.max_von_mises_away_from_fixed_mpa,
            b.max_von_mises_away_from_fixed_mpa,
        );
        let diff = (sa - sb).abs() / sa;
        let bar = a.estimated_error_rel + b.estimated_error_rel;
        eprintln!("{case}: {sb:.2} vs {sa:.2} MPa ({diff:.1e}; error bars {bar:.3})");
        assert!(
            diff <= bar,
            "{case}: {sb} vs {sa} MPa beyond the error bars {bar}"
        );
    }
}

/// Runs `pipeline/fillet_rod.py` with `args` (in the project's Python environment).
fn fillet_rod(args: &[&str]) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .args(["pipeline", "fillet_rod.py"])
        .args(args)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The fillet test rod exported as a CAD system tessellates by chord alone (24
/// facets per turn, 15° kinks on the R8 fillets, the flat shank faces in two triangles each,
/// fillet strips 40 mm long). Adaptive refinement reaches the peak with elements of the fillet's
/// facet spacing (the huge flat triangles beside it set no floor there); the geometry part of the
/// error bar (the same mesh curved onto a smooth surface through the STL's vertices) is measured
/// against the truth of the same mesh with its boundary moved onto the exact B-rep
/// (`fillet_rod.py project`), and the whole bar holds the converged reference of the STEP.
#[test]
fn the_geometry_error_of_a_coarse_cad_export_is_estimated_honestly() {
    let data: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("tests/data/fillet_rod_reference.json")).unwrap(),
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let stl = dir.path().join("cad_export.stl");
    let step = dir.path().join("fillet_rod.step");
    let stl_s = stl.to_str().unwrap();
    fillet_rod(&[
        "stl",
        stl_s,
        "--per-turn",
        "24",
        "--min-size",
        "0.5",
        "--max-size",
        "200",
    ]);
    fillet_rod(&["step", step.to_str().unwrap()]);
    let config = StudyConfig::default();
    let force = data["force_n"].as_f64().unwrap();
    let work = dir.path().join("work");
    let r = adaptive_record(&stl, force, &config, &work);
    let last = r.mesh.adaptive.as_ref().unwrap().iterations - 1;
    let size = r.fem.cases["fy"].adaptive.last().unwrap().size_at_peak_mm;
    assert!(size < 2.5, "F_y: {size} mm elements at the peak");
    // the truth of the geometry part: the same mesh on the exact geometry
    let exact = dir.path().join("on_the_brep.vtu");
    fillet_rod(&[
        "project",
        work.join(format!("adapt{last}/rod.msh")).to_str().unwrap(),
        step.to_str().unwrap(),
        exact.to_str().unwrap(),
    ]);
    let brep_design = stages::mass::load(&stl).unwrap();
    let on_brep = stages::fem::fem(
        &brep_design,
        &stages::fem::FemLoads::of_design(&brep_design, &config)
            .unwrap()
            .with_force(force),
        &config,
        &dir.path().join("work-exact"),
        &MeshMode::User(exact),
    )
    .unwrap()
    .record;
    let reference = 385.58; // F_y, see tests/step_input.rs (curved_tet10_on_the_step_fillet_rod)
    for (case, got, truth) in [
        ("fy", &r.fem.cases["fy"], &on_brep.fem.cases["fy"]),
        ("fx", &r.fem.cases["fx"], &on_brep.fem.cases["fx"]),
    ] {
        let p = got.max_von_mises_away_from_fixed_mpa;
        let g = got.estimated_geometry_error_rel.unwrap();
        let true_g = (truth.max_von_mises_away_from_fixed_mpa - p).abs() / p;
        eprintln!(
            "{case}: {p:.2} MPa ± {:.2} % = {:.2} % discretisation + {:.2} % geometry (smooth surface {:.2} MPa); on the B-rep {:.2} MPa: true geometry error {:.2} %, true / estimated {:.2}",
            100.0 * got.estimated_error_rel,
            100.0 * got.estimated_discretisation_error_rel,
            100.0 * g,
            got.smooth_surface_peak_mpa.unwrap(),
            truth.max_von_mises_away_from_fixed_mpa,
            100.0 * true_g,
            true_g / g
        );
        // within a factor of two of the truth, both ways (a floor of 0.1 % for a tiny part)
        assert!(
            true_g <= 2.0 * g + 1e-3,
            "{case}: true {true_g}, estimated {g}"
        );
        assert!(
            g <= 2.0 * true_g + 1e-3,
            "{case}: true {true_g}, estimated {g}"
        );
        if case == "fy" {
            let true_error = (p - reference).abs() / reference;
            eprintln!(
                "fy: true error against the STEP reference {:.2} %, estimated {:.2} %",
                100.0 * true_error,
                100.0 * got.estimated_error_rel
            );
            assert!(true_error <= 2.0 * got.estimated_error_rel, "{case}");
        }
    }
}

/// The exact-geometry references of the committed designs (`tests/data/design_references.json`).
fn design_references() -> serde_json::Value {
    serde_json::from_str(
        &std::fs::read_to_string(root().join("tests/data/design_references.json")).unwrap(),
    )
    .unwrap()
}

/// True error of `peak` against a design's reference of `case`, with the reference's own
/// estimated uncertainty (relative): (true error, reference, its uncertainty).
fn against_reference(refs: &serde_json::Value, id: &str, case: &str, peak: f64) -> (f64, f64, f64) {
    let r = &refs["designs"][id][case];
    let reference = r["peak_mpa"].as_f64().unwrap();
    let uncertainty = r["estimated_error_rel"].as_f64().unwrap();
    ((peak - reference).abs() / reference, reference, uncertainty)
}

/// The judged F_y peak of each committed design, as `cargo run --release -- study`
/// wrote it into `reports/results.json` (which CI regenerates and compares byte for byte), is
/// honest against the design's exact geometry: curved tet10 on the calibrated B-rep refined to
/// 1 % (`make_designs.py --step`, `tests/data/design_references.json`). The true error is within
/// twice the reported bar (with the reference's own uncertainty) and within the 3 % target.
#[test]
fn the_committed_reports_agree_with_the_exact_geometry() {
    let refs = design_references();
    let results: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("reports/results.json")).unwrap(),
    )
    .unwrap();
    let designs = results["designs"].as_array().unwrap();
    assert_eq!(designs.len(), 5);
    for d in designs {
        let id = d["mass"]["id"].as_str().unwrap();
        let fy = &d["fem"]["fem"]["fy"];
        let peak = fy["max_von_mises_away_from_fixed_mpa"].as_f64().unwrap();
        let est = fy["estimated_error_rel"].as_f64().unwrap();
        let (true_error, reference, unc) = against_reference(&refs, id, "fy", peak);
        eprintln!(
            "{id}: F_y {peak:.2} ± {:.2} % against {reference:.2} ± {:.2} %: true {:.2} %, true / estimated {:.2}",
            100.0 * est,
            100.0 * unc,
            100.0 * true_error,
            true_error / est
        );
        assert!(true_error <= 2.0 * est + unc, "{id}: {true_error} vs {est}");
        assert!(true_error <= 0.03 + unc, "{id}: {true_error}");
    }
}

/// Designs 4 and 5 through the adaptive loop as the study runs it (the half
/// model, the grid convergence index on three meshes), against their exact geometry. Design 4's
/// F_y peak sits on a slot-end R4 fillet faceted at 10° whose facet floor (0.7 mm) the loop
/// reaches on its third mesh; design 5's had the largest true / estimated of the five. Both
/// converge to the 3 % target, within twice their bars of the reference.
#[test]
fn designs_4_and_5_converge_honestly_against_their_exact_geometry() {
    let refs = design_references();
    let config = StudyConfig::default();
    let dir = tempfile::tempdir().unwrap();
    for id in ["design4", "design5"] {
        let force = refs["designs"][id]["force_n"].as_f64().unwrap();
        let stl = root().join(format!("designs/{id}.stl"));
        let r = adaptive_record(&stl, force, &config, &dir.path().join(id));
        let adaptive = r.mesh.adaptive.as_ref().expect("an adaptive record");
        eprintln!(
            "{id}: {:?}, meshes (DOFs, F_y peak MPa, size at it mm): {:?}",
            adaptive.stop,
            r.fem.cases["fy"]
                .adaptive
                .iter()
                .map(|s| (s.dofs, s.peak_mpa, s.size_at_peak_mm))
                .collect::<Vec<_>>()
        );
        assert!(r.fem.half_model.is_some(), "{id}: meshed as its half");
        assert_eq!(
            adaptive.stop,
            rodstudy::rod::adapt::StopReason::Converged,
            "{id}"
        );
        for (case, got) in [("fx", &r.fem.cases["fx"]), ("fy", &r.fem.cases["fy"])] {
            let peak = got.max_von_mises_away_from_fixed_mpa;
            // the parts the reference measures (it is under the same uniform traction)
            let est = got.estimated_discretisation_error_rel
                + got.estimated_geometry_error_rel.unwrap_or(0.0);
            let (true_error, reference, unc) = against_reference(&refs, id, case, peak);
            eprintln!(
                "{id} {case}: {peak:.2} MPa ± {:.2} % ({:.2} % + {:.2} % geometry) against {reference:.2} ± {:.2} %: true {:.2} %, true / estimated {:.2}",
                100.0 * est,
                100.0 * got.estimated_discretisation_error_rel,
                100.0 * got.estimated_geometry_error_rel.unwrap_or(0.0),
                100.0 * unc,
                100.0 * true_error,
                true_error / est
            );
            assert!(
                true_error <= 2.0 * est + unc,
                "{id} {case}: true {true_error} vs estimated {est}"
            );
        }
        let fy = &r.fem.cases["fy"];
        assert!(fy.estimated_discretisation_error_rel <= 0.03, "{id}");
    }
}
