//! Every kind of bad input the study meets (issue "The study", bad input): each design fails with
//! a message naming its file and its defect, the good design is still studied, the exit status
//! is 1, the reports are complete, and nothing panics.

use rodstudy::geometry::primitives::{ascii_stl, binary_stl, to_soup, voxel_rod};
use std::path::Path;
use std::process::Command;

fn write(dir: &Path, name: &str, bytes: &[u8]) {
    std::fs::write(dir.join(name), bytes).unwrap();
}

#[test]
fn each_bad_design_is_reported_and_the_good_one_studied() {
    let designs = tempfile::tempdir().unwrap();
    let out = tempfile::tempdir().unwrap();
    let d = designs.path();
    let rod = voxel_rod().0.scaled(1000.0);
    let good = binary_stl(&to_soup(&rod));
    write(d, "good.stl", &good);
    write(
        d,
        "not_stl.stl",
        b"%PDF-1.7 this is a drawing, not a mesh, and it goes on for a while.",
    );
    write(d, "empty.stl", b"");
    write(d, "truncated.stl", &good[..good.len() / 2]);
    // The first coordinate 0.0 of the ASCII text replaced by nan.
    let nan_ascii = ascii_stl("rod", &to_soup(&rod)).replacen(" 0.0 ", " nan ", 1);
    write(d, "nan_ascii.stl", nan_ascii.as_bytes());
    let mut open = rod.clone();
    open.triangles.pop();
    write(d, "open.stl", &binary_stl(&to_soup(&open)));
    let mut flipped = rod.clone();
    flipped.triangles[3].swap(0, 1);
    write(d, "flipped_triangle.stl", &binary_stl(&to_soup(&flipped)));
    let mut two = rod.clone();
    let n = two.vertices.len() as u32;
    two.vertices.extend(
        rod.vertices
            .iter()
            .map(|v| v + nalgebra::Vector3::new(0.0, 400.0, 0.0)),
    );
    two.triangles
        .extend(rod.triangles.iter().map(|t| t.map(|i| i + n)));
    write(d, "two_shells.stl", &binary_stl(&to_soup(&two)));
    write(d, "metres.stl", &binary_stl(&to_soup(&voxel_rod().0)));
    write(d, "typo.stl", &good);
    write(d, "typo.toml", b"unit = \"mm\"\n");
    write(d, "wrong_type.stl", &good);
    write(d, "wrong_type.toml", b"density = \"steel\"\n");
    write(d, "pins.stl", &good);
    write(d, "pins.toml", b"crank_pin = [40.0, 0.0, 0.0]\n");
    // two designs whose reports would share a folder
    write(d, "twin.stl", &good);
    write(d, "twin.STL", &good);

    let o = Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .args([
            "study",
            "--skip-fem",
            "--designs",
            d.to_str().unwrap(),
            "--out",
            out.path().to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let results: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("results.json")).unwrap()).unwrap();
    // two closed shells in one file 320 mm apart: their masses add, and the warning says they
    // do not touch (stage 3, skipped here, refuses the free body)
    let designs = results["designs"].as_array().unwrap();
    assert_eq!(designs.len(), 2, "{designs:#?}");
    let by_id = |id: &str| designs.iter().find(|d| d["mass"]["id"] == id);
    assert!(by_id("good").is_some(), "{designs:#?}");
    let two = by_id("two_shells").expect("two_shells.stl studied");
    assert!(
        two["mass"]["warnings"].to_string().contains(
            "2 groups that do not touch (the nearest two at least 320.000 file units apart)"
        ),
        "{}",
        two["mass"]["warnings"]
    );
    let failed = results["failed"].as_array().unwrap();
    let expect = [
        ("not_stl.stl", "not an STL"),
        ("empty.stl", "empty file"),
        ("truncated.stl", "truncated binary STL"),
        ("nan_ascii.stl", "NaN"),
        ("open.stl", "open mesh"),
        ("flipped_triangle.stl", "inconsistently oriented"),
        ("metres.stl", "units"),
        ("typo.toml", "unknown field `unit`"),
        ("wrong_type.toml", "invalid type"),
        ("pins.stl", "crank pin (A)"),
        ("twin.stl", "names the same report folder as"),
        ("twin.STL", "names the same report folder as"),
    ];
    assert_eq!(failed.len(), expect.len(), "{failed:#?}");
    for (name, defect) in expect {
        let hit = failed
            .iter()
            .find(|f| f["error"].as_str().unwrap().contains(name));
        let f = hit.unwrap_or_else(|| panic!("no failure names {name}: {failed:#?}"));
        let e = f["error"].as_str().unwrap();
        assert!(e.contains(defect), "{name}: expected «{defect}» in «{e}»");
        assert!(!e.contains('\n'), "one line: «{e}»");
    }
    for report in ["ranking.md", "mass_properties.csv", "index.html"] {
        let text = std::fs::read_to_string(out.path().join(report)).unwrap();
        assert!(
            text.contains("truncated.stl"),
            "{report} lists the failures"
        );
    }
}
