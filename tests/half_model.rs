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
        // (the parts that measure the mesh and the facets; both solves use the same load model)
        let mesh_parts = |c: &serde_json::Value| {
            c["estimated_discretisation_error_rel"].as_f64().unwrap()
                + c["estimated_geometry_error_rel"].as_f64().unwrap_or(0.0)
        };
        let bar = mesh_parts(a) * pa + mesh_parts(b) * pb;
        assert!(
            (pa - pb).abs() <= bar,
            "{case}: {pa} MPa against {pb} MPa, bars {bar} MPa"
        );
    }
    // the VTU file is the whole rod
    let vtu = std::fs::read_to_string(dir.path().join("auto/fem_fy.vtu")).unwrap();
    assert!(vtu.contains(&format!("NumberOfPoints=\"{}\"", nodes as usize)));
}

/// The half's cap is gmsh's: the Rust side hands over the half open at the cut, and the mesher
/// closes it with one plane surface on the cut's curves (`mesh_rod.py`, `cap_open_cut`). Checked
/// on the mesh gmsh made: the boundary faces in the plane z = c cover the section, whose area the
/// open surface gives independently (a closed surface has ∮ n_z dA = 0, so the cap's area is the
/// z-projected area of the rest), and every one of them points out of the half.
#[test]
fn the_half_is_capped_by_gmsh_on_the_cut() {
    use std::collections::HashMap;
    let dir = tempfile::tempdir().unwrap();
    let half = fem_json(dir.path(), "auto");
    let c = half["fem"]["half_model"]["plane_z_mm"].as_f64().unwrap();
    // the open surface gmsh was given
    let (soup, _) =
        rodstudy::geometry::stl_file::read_stl_file(&dir.path().join("auto/mesh/rod_frame.stl"))
            .unwrap();
    let projected: f64 = soup
        .iter()
        .map(|t| {
            let p = t.map(|v| v.map(f64::from));
            0.5 * ((p[1][0] - p[0][0]) * (p[2][1] - p[0][1])
                - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]))
        })
        .sum();
    let on_plane = soup
        .iter()
        .filter(|t| t.iter().all(|v| f64::from(v[2]) == c))
        .count();
    assert_eq!(on_plane, 0, "the STL handed to gmsh is open at the cut");
    // the mesh gmsh made of the half
    let mesh = rodstudy::mesher::read_volume_mesh_native(
        &dir.path().join("auto/mesh/fixed/rod.msh"),
        "mm",
    )
    .unwrap();
    let mut faces: HashMap<[usize; 3], ([usize; 3], usize)> = HashMap::new();
    for el in mesh.elements() {
        for f in [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]] {
            let tri = f.map(|k| el[k]);
            let mut key = tri;
            key.sort_unstable();
            faces.entry(key).or_insert((tri, 0)).1 += 1;
        }
    }
    let nodes = mesh.nodes();
    let (mut area, mut facing_down) = (0.0, 0usize);
    let mut cap_faces = 0usize;
    for (tri, count) in faces.values() {
        if *count != 1 || !tri.iter().all(|&n| (nodes[n][2] * 1e3 - c).abs() < 1e-9) {
            continue;
        }
        cap_faces += 1;
        let p = tri.map(|n| nodes[n].map(|x| x * 1e3));
        let nz =
            (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
        area += 0.5 * nz.abs();
        facing_down += usize::from(nz < 0.0);
    }
    eprintln!(
        "cap: {cap_faces} faces, {area:.3} mm² of a section of {projected:.3} mm² (from the open surface)"
    );
    assert!(cap_faces > 100);
    assert_eq!(
        facing_down, cap_faces,
        "every cap face points out of the half (−z)"
    );
    // within the chords of the 6 mm elements along the section's round edges (a chord s across
    // a radius r cuts off about s²/(6 r²) of a circle's area: ~1 % of a bore's, bores being holes
    // in the section; measured 0.13 %)
    assert!(
        (area / projected - 1.0).abs() < 5e-3,
        "cap {area} mm² against the section {projected} mm²"
    );
}
