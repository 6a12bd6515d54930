//! Stage 3 on the half model of a mirror-symmetric rod (`[fem] symmetry = "auto"`): design 1 (symmetric
//! about its mid-plane within 0.02 mm) meshed as its half by gmsh, solved with half the pin loads
//! and u_z = 0 on the plane, mirrored into the whole. Needs Python (gmsh).
//!
//! What is checked against the whole rod's route on a uniform mesh of the same size: the half
//! solved about 60 % of the DOFs; the mirrored mesh is the whole rod (bounding box, volume within
//! the meshes' facets); the displacements and peaks agree within the two routes' own error bars
//! (the meshes differ); the reactions balance the load. That the mirrored solution is the whole
//! model's solution on the same mesh, to round-off, is `fem::rod`'s unit test.

use std::path::Path;
use std::process::Command;

fn fem_json(dir: &Path, symmetry: &str) -> serde_json::Value {
    let config = dir.join(format!("{symmetry}.toml"));
    std::fs::write(&config, format!("[fem]\nsymmetry = \"{symmetry}\"\n")).unwrap();
    let out = dir.join(symmetry);
    let o = Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env_remove("RODSTUDY_HALF_MODEL")
        .args([
            "fem",
            "designs/design1.stl",
            "--size",
            "6",
            "--json",
            "--no-pictures",
        ])
        .arg("--config")
        .arg(&config)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn a_symmetric_rod_solved_as_its_half_agrees_with_the_whole() {
    let dir = tempfile::tempdir().unwrap();
    let half = fem_json(dir.path(), "auto");
    let whole = fem_json(dir.path(), "off");
    let (h, w) = (&half["fem"], &whole["fem"]);
    assert!(w.get("half_model").is_none());
    let hm = &h["half_model"];
    assert_eq!(hm["plane_z_mm"].as_f64().unwrap(), 0.0);
    // the half's system, the whole's mesh
    let (dofs_h, dofs_w) = (h["dofs"].as_f64().unwrap(), w["dofs"].as_f64().unwrap());
    assert_eq!(dofs_h, 3.0 * hm["nodes"].as_f64().unwrap());
    assert!(dofs_h < 0.75 * dofs_w, "half {dofs_h} DOFs, whole {dofs_w}");
    let nodes = h["nodes"].as_f64().unwrap();
    assert_eq!(
        nodes,
        2.0 * hm["nodes"].as_f64().unwrap() - hm["plane_nodes"].as_f64().unwrap()
    );
    assert_eq!(half["mesh"]["nodes"], h["nodes"]);
    for case in ["fx", "fy"] {
        let (a, b) = (&h[case], &w[case]);
        let f = b["force_n"].as_f64().unwrap();
        assert_eq!(a["force_n"].as_f64().unwrap(), f);
        // the whole load, and reactions balancing it
        for j in 0..3 {
            let (ra, rb) = (
                a["applied_resultant_n"][j].as_f64().unwrap(),
                b["applied_resultant_n"][j].as_f64().unwrap(),
            );
            assert!((ra - rb).abs() < 1e-6 * f, "{case}: {ra} against {rb}");
        }
        assert!(a["reaction_balance_rel"].as_f64().unwrap() < 1e-6);
        // the largest displacement (a global figure): within 0.5 %
        let (da, db) = (
            a["max_displacement_mm"].as_f64().unwrap(),
            b["max_displacement_mm"].as_f64().unwrap(),
        );
        assert!(
            (da / db - 1.0).abs() < 5e-3,
            "{case}: {da} mm against {db} mm"
        );
        // the judged peaks: within the two estimates together
        let (pa, pb) = (
            a["max_von_mises_away_from_fixed_mpa"].as_f64().unwrap(),
            b["max_von_mises_away_from_fixed_mpa"].as_f64().unwrap(),
        );
        let bar = a["estimated_error_rel"].as_f64().unwrap() * pa
            + b["estimated_error_rel"].as_f64().unwrap() * pb;
        assert!(
            (pa - pb).abs() <= bar,
            "{case}: {pa} MPa against {pb} MPa, bars {bar} MPa"
        );
    }
    // the VTU file is the whole rod
    let vtu = std::fs::read_to_string(dir.path().join("auto/fem_fy.vtu")).unwrap();
    assert!(vtu.contains(&format!("NumberOfPoints=\"{}\"", nodes as usize)));
}
