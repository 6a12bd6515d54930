//! The bore finder on real rods: the committed designs read without their sidecars, and the
//! foreign rods of `pipeline/foreign_rods.py` (fillets everywhere, a capless big end, rod and cap
//! as two bodies, inches with the pins along y, a plain rod), each as a coarse and a fine STL,
//! against the true centres of the manifest; and the fine STLs' volume against OpenCASCADE's
//! exact integrals.

use rodstudy::geometry::design::{PinsSource, mass_of_design};
use rodstudy::python_env::{pipeline_script, python};
use std::path::Path;
use std::process::Command;

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Each committed design, its STL alone (no sidecar): A at (0,0,0) mm and B at (180,0,0) mm within
/// 0.01 mm, axis z, the bore radii of the normal run within 1e-3 relative.
#[test]
fn committed_designs_without_sidecar() {
    let root = rodstudy::python_env::project_root().join("designs");
    let tmp = tempfile::tempdir().unwrap();
    for k in 1..=5 {
        let name = format!("design{k}.stl");
        let alone = tmp.path().join(&name);
        std::fs::copy(root.join(&name), &alone).unwrap();
        let normal = mass_of_design(&root.join(&name)).unwrap();
        let found = mass_of_design(&alone).unwrap();
        let p = &found.pins;
        assert_eq!(p.pins_source, PinsSource::Found, "{name}");
        assert!(
            dist(p.crank_pin_file_units, [0.0; 3]) <= 0.01,
            "{name}: {p:?}"
        );
        assert!(
            dist(p.piston_pin_file_units, [180.0, 0.0, 0.0]) <= 0.01,
            "{name}: {p:?}"
        );
        assert!(dist(p.pin_axis, [0.0, 0.0, 1.0]) <= 1e-6, "{name}: {p:?}");
        let f = p.found.as_ref().unwrap();
        let rel = |a: f64, b: f64| (a / b - 1.0).abs();
        assert!(
            rel(f.crank.radius, normal.crank_bore_radius_m) <= 1e-3,
            "{name}"
        );
        assert!(
            rel(f.piston.radius, normal.piston_bore_radius_m) <= 1e-3,
            "{name}"
        );
        assert!(f.crank.full && f.piston.full);
        assert_eq!(
            (p.crank_bore_arc_deg, p.piston_bore_arc_deg),
            (360.0, 360.0)
        );
        assert!((found.l1_m - normal.l1_m).abs() < 1e-8, "{name}");
        assert!(found.warnings.is_empty(), "{name}: {:?}", found.warnings);
        // the sidecar run says nothing new in its JSON
        let json = serde_json::to_string(&normal).unwrap();
        assert!(!json.contains("pins_source"), "{json}");
        assert!(
            serde_json::to_string(&found)
                .unwrap()
                .contains("\"pins_source\":\"found\"")
        );
    }
}

fn run_foreign_rods(out: &Path) -> serde_json::Value {
    let o = Command::new(python().unwrap())
        .arg(pipeline_script("foreign_rods.py"))
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap()
}

/// Centre tolerance [file units converted from mm]: vertices of an STL lie on the true surface,
/// so the fits are exact to rounding on the coarse and the fine STL alike (measured: below
/// 1e-6 mm on every rod and tolerance).
const CENTRE_TOL_MM: f64 = 0.01;

#[test]
fn foreign_rods_against_their_manifest() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = run_foreign_rods(dir.path());
    let rods = manifest.as_object().unwrap();
    assert_eq!(rods.len(), 6);
    for (name, rod) in rods {
        let mm = match rod["units"].as_str().unwrap() {
            "mm" => 1.0,
            "in" => 25.4,
            u => panic!("{u}"),
        };
        let vec3 = |v: &serde_json::Value| -> [f64; 3] {
            let a = v.as_array().unwrap();
            [0, 1, 2].map(|k| a[k].as_f64().unwrap())
        };
        for tol in ["coarse", "fine"] {
            let stl = dir.path().join(rod["stl"][tol]["file"].as_str().unwrap());
            let m = mass_of_design(&stl).unwrap_or_else(|e| panic!("{name} {tol}: {e:#}"));
            let p = &m.pins;
            let f = p.found.as_ref().unwrap();
            let (ea, eb) = (
                dist(p.crank_pin_file_units, vec3(&rod["crank_pin"])) * mm,
                dist(p.piston_pin_file_units, vec3(&rod["piston_pin"])) * mm,
            );
            let scale = 1e-3 * mm;
            let (ra, rb) = (f.crank.radius / scale, f.piston.radius / scale);
            let (ta, tb) = (
                rod["crank_bore_radius"].as_f64().unwrap() * mm,
                rod["piston_bore_radius"].as_f64().unwrap() * mm,
            );
            let arc = rod["crank_bore_arc_deg"].as_f64().unwrap();
            println!(
                "{name} {tol}: |ΔA| {ea:.2e} mm, |ΔB| {eb:.2e} mm, ΔrA {:.2e} mm, ΔrB {:.2e} mm, arc A {:.6}° (true {arc}), axis {:?}",
                ra * mm - ta,
                rb * mm - tb,
                p.crank_bore_arc_deg,
                p.pin_axis
            );
            assert_eq!(p.pins_source, PinsSource::Found);
            assert!(
                ea <= CENTRE_TOL_MM && eb <= CENTRE_TOL_MM,
                "{name} {tol}: {p:?}"
            );
            assert!((ra * mm - ta).abs() <= 1e-3 && (rb * mm - tb).abs() <= 1e-3);
            assert!(
                dist(p.pin_axis, vec3(&rod["pin_axis"])) <= 1e-6,
                "{name} {tol}"
            );
            assert!((p.crank_bore_arc_deg - arc).abs() <= 0.01, "{name} {tol}");
            assert_eq!(p.piston_bore_arc_deg, 360.0);
            let capless = m
                .warnings
                .iter()
                .any(|w| w.contains("big end without cap: loads on the existing arc (180°)"));
            assert_eq!(capless, name == "capless", "{name}: {:?}", m.warnings);
            let bodies = m
                .warnings
                .iter()
                .any(|w| w.contains("2 bodies (shells) in one file: treated as one bonded body"));
            assert_eq!(bodies, name == "rod_and_cap", "{name}: {:?}", m.warnings);
            // mass properties against OpenCASCADE's exact solid
            let exact = rod["exact"]["volume"].as_f64().unwrap() * scale.powi(3);
            let rel = m.volume_m3 / exact - 1.0;
            let com = vec3(&rod["exact"]["centre_of_mass"]).map(|c| c * scale);
            let dcom = dist(m.centroid_m, com) * 1e3;
            println!("{name} {tol}: volume vs OCC {rel:+.2e}, centroid {dcom:.2e} mm");
            let bound = if tol == "fine" { 3e-4 } else { 5e-3 };
            assert!(rel.abs() <= bound, "{name} {tol}: {rel:e}");
            assert!(
                dcom <= if tol == "fine" { 0.02 } else { 0.2 },
                "{name} {tol}: {dcom}"
            );
        }
    }
    // the capless rod with its pins given in the sidecar: accepted, the open arc said
    std::fs::copy(
        dir.path().join("capless_fine.stl"),
        dir.path().join("given.stl"),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("given.toml"),
        "crank_pin = [0.0, 0.0, 0.0]\npiston_pin = [180.0, 0.0, 0.0]\npin_axis = \"z\"\n",
    )
    .unwrap();
    let m = mass_of_design(&dir.path().join("given.stl")).unwrap();
    assert_eq!(m.pins.pins_source, PinsSource::Sidecar);
    assert!((m.pins.crank_bore_arc_deg - 180.0).abs() < 0.01);
    assert!((m.crank_bore_radius_m - 0.025).abs() < 1e-6);
    assert!(
        m.warnings.iter().any(|w| w.contains("big end without cap")),
        "{:?}",
        m.warnings
    );
    // given off the arc's axis: refused with the open arc named, not "outside the rod"
    std::fs::write(
        dir.path().join("given.toml"),
        "crank_pin = [2.0, 0.0, 0.0]\npiston_pin = [180.0, 0.0, 0.0]\n",
    )
    .unwrap();
    let e = format!(
        "{:#}",
        mass_of_design(&dir.path().join("given.stl")).unwrap_err()
    );
    assert!(
        e.contains("big end without cap: bore A is an arc of 180° (open on one side)")
            && e.contains("given.stl"),
        "{e}"
    );
}
