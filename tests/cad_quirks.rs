//! Rods as other CAD systems write them (`pipeline/cad_quirks.py`): a SolidWorks-style STL whose
//! zero coordinates are rounded to ±1e-14 in some facets, a capless rod with two cap-bolt holes
//! beside its half bore, a STEP that declares millimetres but holds metres, two bodies that do
//! not touch; and the ranking of a rod body without its cap. Each is checked against the truth
//! the script writes (the pins it drew, OpenCASCADE's exact volume of the same solid).

use rodstudy::geometry::design::{PinsSource, load_design, mass_of_design};
use rodstudy::python_env::{pipeline_script, python};
use std::path::Path;
use std::process::Command;
use std::sync::OnceLock;

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The files of `cad_quirks.py`, written once for all tests of this binary.
fn quirks() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let o = Command::new(python().unwrap())
            .arg(pipeline_script("cad_quirks.py"))
            .arg(dir.path())
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        dir
    })
    .path()
}

fn manifest() -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(quirks().join("cad_quirks.json")).unwrap()).unwrap()
}

fn vec3(v: &serde_json::Value) -> [f64; 3] {
    let a = v.as_array().unwrap();
    [0, 1, 2].map(|k| a[k].as_f64().unwrap())
}

/// The SolidWorks-style STL: refused as open by equality of value, it closes once the vertices
/// within the welding tolerance merge; the record says how many; the polyhedron's volume is
/// within the fine export's chord error (3e-4) of OpenCASCADE's exact volume, and the pins are
/// found where the script drew them (the bores' vertices lie on the true cylinders: 0.01 mm).
#[test]
fn a_solidworks_stl_is_welded_and_ranked() {
    let rod = &manifest()["solidworks"];
    let m = mass_of_design(&quirks().join("solidworks.stl")).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(m.vertices_merged > 0, "{m:?}");
    assert!(
        m.warnings.iter().any(|w| w.contains("were merged")),
        "{:?}",
        m.warnings
    );
    let exact = rod["volume_mm3"].as_f64().unwrap() * 1e-9;
    assert!(
        (m.volume_m3 / exact - 1.0).abs() < 3e-4,
        "{} vs {exact}",
        m.volume_m3
    );
    assert!(dist(m.pins.crank_pin_file_units, vec3(&rod["crank_pin"])) < 0.01);
    assert!(dist(m.pins.piston_pin_file_units, vec3(&rod["piston_pin"])) < 0.01);
    let json = serde_json::to_string(&m).unwrap();
    assert!(json.contains("\"vertices_merged\""), "{json}");
}

/// The same STL with one rounded vertex moved 0.05 mm (a real crack, 100 000 times the welding
/// tolerance) stays refused, and the message measures the gap and calls it what it is.
#[test]
fn a_real_gap_stays_refused_with_its_width() {
    let mut bytes = std::fs::read(quirks().join("solidworks.stl")).unwrap();
    // the first rounded coordinate (a tiny non-zero f32 among the 9 of a record's corners)
    let records = (bytes.len() - 84) / 50;
    let at = (0..records)
        .flat_map(|r| (0..9).map(move |k| 84 + 50 * r + 12 + 4 * k))
        .find(|&i| {
            let v = f32::from_le_bytes(bytes[i..i + 4].try_into().unwrap());
            v != 0.0 && v.abs() < 1e-10
        })
        .unwrap();
    bytes[at..at + 4].copy_from_slice(&0.05f32.to_le_bytes());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cracked.stl");
    std::fs::write(&path, &bytes).unwrap();
    let e = format!("{:#}", mass_of_design(&path).unwrap_err());
    assert!(e.contains("cracked.stl") && e.contains("open mesh"), "{e}");
    assert!(e.contains("hole(s), the widest"), "{e}");
}

/// The capless rod with two cap-bolt holes along the rod in its big-end block: the pins are the
/// half bore R70 at A and the full bore R35 at B, in the STL and in the STEP, not the bolt holes
/// (whose wall area is the larger pair); and sidecar pins at the true centres are accepted.
#[test]
fn bolt_holes_are_not_pins() {
    let rod = &manifest()["bolted_capless"];
    for file in ["bolted_capless.stl", "bolted_capless.step"] {
        let m = mass_of_design(&quirks().join(file)).unwrap_or_else(|e| panic!("{file}: {e:#}"));
        assert_eq!(m.pins.pins_source, PinsSource::Found);
        assert!(
            dist(m.pins.crank_pin_file_units, vec3(&rod["crank_pin"])) < 0.01,
            "{file}: {:?}",
            m.pins
        );
        assert!(dist(m.pins.piston_pin_file_units, vec3(&rod["piston_pin"])) < 0.01);
        assert!((m.crank_bore_radius_m - 0.070).abs() < 1e-5, "{file}");
        assert!((m.piston_bore_radius_m - 0.035).abs() < 1e-5, "{file}");
        assert!((m.pins.crank_bore_arc_deg - 180.0).abs() < 1.0, "{file}");
    }
    let dir = tempfile::tempdir().unwrap();
    let stl = dir.path().join("bolted.stl");
    std::fs::copy(quirks().join("bolted_capless.stl"), &stl).unwrap();
    std::fs::write(
        dir.path().join("bolted.toml"),
        "crank_pin = [0, 0, 0]\npiston_pin = [620, 0, 0]\npin_axis = \"z\"\n",
    )
    .unwrap();
    let m = mass_of_design(&stl).unwrap_or_else(|e| panic!("{e:#}"));
    assert!((m.crank_bore_radius_m - 0.070).abs() < 1e-5);
}

/// A STEP whose header declares millimetres while its numbers are metres: without a sidecar it
/// is refused as 1e-9 of a rod's mass, and the message says to set `units` (which overrides the
/// declared unit); with `units = "m"` it weighs what OpenCASCADE's exact volume of the drawn rod
/// in millimetres gives (to 1e-9) and its pins are 180 mm apart.
#[test]
fn a_steps_wrong_declared_unit_is_overridden_by_the_sidecar() {
    let rod = &manifest()["metres"];
    let m = mass_of_design(&quirks().join("metres.step")).unwrap_or_else(|e| panic!("{e:#}"));
    let exact = rod["volume_mm3"].as_f64().unwrap() * 1e-9;
    assert!((m.volume_m3 / exact - 1.0).abs() < 1e-9, "{}", m.volume_m3);
    assert!(
        (m.centre_distance_m - 0.18).abs() < 1e-8,
        "{}",
        m.centre_distance_m
    );
    assert_eq!(m.units, "m");
    assert!(
        m.warnings
            .iter()
            .any(|w| w.contains("declares its lengths in millimetres") && w.contains("overrides")),
        "{:?}",
        m.warnings
    );
    let dir = tempfile::tempdir().unwrap();
    let alone = dir.path().join("metres.step");
    std::fs::copy(quirks().join("metres.step"), &alone).unwrap();
    let e = format!("{:#}", mass_of_design(&alone).unwrap_err());
    assert!(
        e.contains("metres.step")
            && e.contains("cannot be a connecting rod's")
            && e.contains("units = \"m\"")
            && e.contains("overrides the declared unit")
            && !e.contains("remove `units`"),
        "{e}"
    );
}

/// Two closed shells 80 mm apart: the mass of both (the exact volume of both solids, within the
/// fine export's 3e-4 for the STL), a warning with the gap, and the gap kept for stage 3, which
/// refuses the free body; the STEP likewise.
#[test]
fn bodies_that_do_not_touch_are_said_apart() {
    let rod = &manifest()["two_bodies"];
    let exact = rod["volume_mm3"].as_f64().unwrap() * 1e-9;
    for (file, tol) in [("two_bodies.stl", 3e-4), ("two_bodies.step", 1e-9)] {
        let d = load_design(&quirks().join(file)).unwrap_or_else(|e| panic!("{file}: {e:#}"));
        assert!(
            (d.mass.volume / exact - 1.0).abs() < tol,
            "{file}: {} vs {exact}",
            d.mass.volume
        );
        let gap = d.loose_gap_m.expect("two groups");
        assert!((gap - 0.080).abs() < 1e-6, "{file}: {gap}");
        assert!(
            d.warnings.iter().any(|w| w.contains("do not touch")),
            "{file}: {:?}",
            d.warnings
        );
    }
}

/// A rod body without its cap ranks after a complete rod, whatever its lower mass and force,
/// and its status says why (the force-only study: the capless and the plain rod of
/// `foreign_rods.py`).
#[test]
fn a_capless_rod_is_not_ranked_above_complete_rods() {
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new(python().unwrap())
        .arg(pipeline_script("foreign_rods.py"))
        .arg(dir.path())
        .args(["--only", "capless"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let designs = dir.path().join("designs");
    std::fs::create_dir(&designs).unwrap();
    std::fs::copy(
        dir.path().join("capless_coarse.stl"),
        designs.join("capless.stl"),
    )
    .unwrap();
    std::fs::copy(quirks().join("solidworks.stl"), designs.join("plain.stl")).unwrap();
    let out = dir.path().join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .args(["study", "--skip-fem", "--no-cache", "--designs"])
        .arg(&designs)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("ranking.csv")).unwrap();
    let order: Vec<&str> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(2).unwrap())
        .collect();
    assert_eq!(order, ["plain", "capless"], "{csv}");
    let md = std::fs::read_to_string(out.join("ranking.md")).unwrap();
    assert!(md.contains("rod body alone, without its cap"), "{md}");
    // the capless body is the lighter one: by mass alone it would have ranked first
    let results: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
    let mass = |id: &str| {
        results["designs"]
            .as_array()
            .unwrap()
            .iter()
            .find(|d| d["mass"]["id"] == id)
            .unwrap()["mass"]["mass_kg"]
            .as_f64()
            .unwrap()
    };
    assert!(mass("capless") < mass("plain"));
}

/// A STEP whose bore surface was moved 3 mm off the edges that bound it (a broken B-rep): refused
/// with the face, the distance (3.000 mm, as moved) and what to do, before any figure is made
/// from it (the triangulation of such a face gave a 177 mm centre distance and a false 357° arc).
#[test]
fn a_face_off_its_own_edges_is_refused() {
    let e = format!(
        "{:#}",
        mass_of_design(&quirks().join("moved_bore.step")).unwrap_err()
    );
    assert!(
        e.contains("moved_bore.step")
            && e.contains("lies 3.000 mm from its own edges")
            && e.contains("repair the solid in CAD"),
        "{e}"
    );
}

/// A closed, consistently oriented STL whose surface crosses itself (a vertex of the big eye's
/// outer wall pushed through the bore wall R25): stage 1 takes its mass (the divergence theorem
/// does not see the crossing), and the crossing facets are found where the vertex went through:
/// on the bore wall, 25 mm from the bore's axis (z) to 0.1 mm (the facets' chord), with y > 0.
/// On this file stage 3's mesher fails ("Invalid boundary mesh (overlapping facets)", 2 min of
/// fallbacks), and its error then leads with this finding (measured 2026-11-28; not run here).
#[test]
fn facets_that_cross_are_found_where_they_cross() {
    let d = load_design(&quirks().join("crossed.stl")).unwrap_or_else(|e| panic!("{e:#}"));
    let c = rodstudy::geometry::self_crossing::crossing_facets(&d.mesh).expect("crossing");
    let at = c.at * 1e3;
    assert!(c.pairs >= 2, "{c:?}");
    assert!(
        ((at.x.powi(2) + at.y.powi(2)).sqrt() - 25.0).abs() < 0.1,
        "{at:?}"
    );
    assert!(at.y > 0.0, "{at:?}");
    // no crossing on clean exports: the SolidWorks-style one and the five committed designs
    let root = rodstudy::python_env::project_root().join("designs");
    let clean = (1..=5)
        .map(|k| root.join(format!("design{k}.stl")))
        .chain([quirks().join("solidworks.stl")]);
    for file in clean {
        let d = load_design(&file).unwrap();
        assert_eq!(
            rodstudy::geometry::self_crossing::crossing_facets(&d.mesh),
            None,
            "{}",
            file.display()
        );
    }
}
