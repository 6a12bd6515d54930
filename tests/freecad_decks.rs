//! `rodstudy solve` on decks written by FreeCAD's FEM workbench itself (FreeCAD 0.20.2, its
//! CalculiX writer, gmsh meshes; `pipeline/freecad_decks.py` run by `freecadcmd` wrote them, unedited,
//! into `tests/data/freecad/`), each solved as written and through CalculiX (`ccx`) in the same
//! test. Agreement: every node's displacement to 1e-5 of the largest (rodstudy's VTU against
//! ccx's .frd), every printed reaction total to 1e-5 of the largest, buckling factors to 1e-5
//! (relative).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

#[path = "common/ccx.rs"]
mod ccx;
use ccx::{Ccx, max_abs, run_ccx, solve};

fn work_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("freecad_decks")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The committed deck `name` solved by both programs in a folder of its own.
fn run_both(name: &str) -> (PathBuf, serde_json::Value, Ccx) {
    let dir = work_dir(name);
    let deck = dir.join(format!("{name}.inp"));
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/freecad")
            .join(format!("{name}.inp")),
        &deck,
    )
    .unwrap();
    (deck.clone(), solve(&deck), run_ccx(&deck))
}

/// A `<DataArray Name="name">` of an ASCII VTU, its numbers.
fn vtu_array(text: &str, name: &str) -> Vec<f64> {
    let at = text
        .find(&format!("Name=\"{name}\""))
        .unwrap_or_else(|| panic!("{name} in the VTU"));
    let start = at + text[at..].find('>').unwrap() + 1;
    let end = start + text[start..].find("</DataArray>").unwrap();
    text[start..end]
        .split_whitespace()
        .map(|w| w.parse().unwrap())
        .collect()
}

/// Every node's U of step 1 (our VTU) against ccx's DISP, relative to ccx's largest |U|.
fn compare_u(deck: &Path, ccx: &Ccx) -> f64 {
    let stem = deck.file_stem().unwrap().to_str().unwrap();
    let vtu = std::fs::read_to_string(deck.with_extension("out").join(format!("{stem}_step1.vtu")))
        .unwrap();
    let ids = vtu_array(&vtu, "node_id");
    let u = vtu_array(&vtu, "U");
    let theirs: &HashMap<i64, Vec<f64>> = &ccx.frd["DISP"];
    let scale = max_abs(theirs.values().flatten());
    assert!(scale > 0.0);
    let mut d = 0.0f64;
    let mut compared = 0;
    for (k, id) in ids.iter().enumerate() {
        let Some(c) = theirs.get(&(*id as i64)) else {
            continue;
        };
        compared += 1;
        for j in 0..3 {
            d = d.max((u[3 * k + j] - c[j]).abs() / scale);
        }
    }
    assert_eq!(compared, theirs.len(), "every node ccx wrote compared");
    d
}

/// Every reaction total ccx printed against ours, relative to the largest.
fn compare_totals(ours: &serde_json::Value, ccx: &Ccx) -> f64 {
    let scale = max_abs(ccx.totals.values().flatten());
    assert!(scale > 0.0 && !ccx.totals.is_empty());
    let mut d = 0.0f64;
    for (set, theirs) in &ccx.totals {
        let o: [f64; 3] = serde_json::from_value(ours["steps"][0]["reaction_totals"][set].clone())
            .unwrap_or_else(|e| panic!("our total of {set}: {e}"));
        for j in 0..3 {
            d = d.max((o[j] - theirs[j]).abs() / scale);
        }
    }
    d
}

/// The committed decks whose names start with `prefix` (the generator writes more than are
/// committed: a deck dropped into the folder is tested by its name).
fn decks(prefix: &str) -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/freecad");
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| {
            let name = e.unwrap().file_name().into_string().unwrap();
            let stem = name.strip_suffix(".inp")?;
            stem.starts_with(prefix).then(|| stem.to_string())
        })
        .collect();
    names.sort();
    names
}

/// Ours against ccx's, relative, the largest difference.
fn compare_values(name: &str, what: &str, ours: &serde_json::Value, theirs: &[f64]) -> f64 {
    let ours: Vec<f64> = serde_json::from_value(ours.clone()).unwrap();
    assert_eq!(
        ours.len(),
        theirs.len(),
        "{name}: {what}, ours {ours:?} and ccx's {theirs:?}"
    );
    assert!(!ours.is_empty());
    let d = ours
        .iter()
        .zip(theirs)
        .map(|(a, b)| (a / b - 1.0).abs())
        .fold(0.0, f64::max);
    eprintln!("{name}: {what} ours {ours:?}, ccx {theirs:?}: {d:.1e}");
    d
}

#[test]
fn freecad_static_decks_match_ccx() {
    assert!(!decks("static_").is_empty());
    for name in decks("static_") {
        let (deck, ours, ccx) = run_both(&name);
        let du = compare_u(&deck, &ccx);
        let dt = compare_totals(&ours, &ccx);
        eprintln!("{name}: U {du:.1e} of max |U|, RF totals {dt:.1e} of the largest");
        assert!(du < 1e-5, "{name}: U differs by {du:e}");
        assert!(dt < 1e-5, "{name}: RF totals differ by {dt:e}");
    }
}

#[test]
fn freecad_buckling_and_frequency_decks_match_ccx() {
    assert!(!decks("buckle_").is_empty());
    for name in decks("buckle_") {
        let (_, ours, ccx) = run_both(&name);
        let eigen = &ours["steps"][0]["eigen"];
        let d = compare_values(
            &name,
            "buckling factors",
            &eigen["buckling_factors"],
            &ccx.buckling,
        );
        assert!(d < 1e-5);
    }
    for name in decks("frequency_") {
        let (_, ours, ccx) = run_both(&name);
        let eigen = &ours["steps"][0]["eigen"];
        let d = compare_values(&name, "eigenvalues", &eigen["eigenvalues"], &ccx.eigen);
        assert!(d < 1e-5);
    }
}
