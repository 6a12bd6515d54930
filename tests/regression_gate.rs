//! The CI regression gate end to end: a baseline from the committed designs passes its own check,
//! and a copy of the designs with one rod made 5 % denser fails it on the peak force alone.

use std::path::Path;
use std::process::{Command, Output};

fn rodstudy(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .args(args)
        .output()
        .unwrap()
}

fn copy_designs(to: &Path) {
    let from = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs");
    for entry in std::fs::read_dir(from).unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, to.join(path.file_name().unwrap())).unwrap();
    }
}

#[test]
fn a_drifting_peak_force_fails_the_check() {
    let designs = tempfile::tempdir().unwrap();
    let out = tempfile::tempdir().unwrap();
    copy_designs(designs.path());
    let (d, o) = (
        designs.path().to_str().unwrap(),
        out.path().to_str().unwrap(),
    );
    let study = rodstudy(&[
        "study",
        "--skip-fem",
        "--designs",
        d,
        "--out",
        o,
        "--update-baseline",
    ]);
    assert_eq!(
        study.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&study.stderr)
    );
    let baseline = out.path().join("baseline.json");
    let results = out.path().join("results.json");
    let (b, r) = (baseline.to_str().unwrap(), results.to_str().unwrap());
    let pass = rodstudy(&["check", "--baseline", b, "--results", r]);
    assert_eq!(
        pass.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&pass.stdout)
    );

    // Design 3 made 5 % denser: its peak force rises by about 1.7 %.
    let sidecar = designs.path().join("design3.toml");
    let text = std::fs::read_to_string(&sidecar).unwrap();
    assert!(text.contains("density = 7800"), "{text}");
    std::fs::write(&sidecar, text.replace("density = 7800", "density = 8190")).unwrap();
    let study = rodstudy(&["study", "--skip-fem", "--designs", d, "--out", o]);
    assert_eq!(study.status.code(), Some(0));
    // Ignore the mass (huge mass tolerance): the force alone must trip the gate.
    let fail = rodstudy(&[
        "check",
        "--baseline",
        b,
        "--results",
        r,
        "--rtol-mass",
        "1.0",
    ]);
    assert_eq!(fail.status.code(), Some(1));
    let table = String::from_utf8_lossy(&fail.stdout);
    let row = table
        .lines()
        .find(|l| l.starts_with("| design3 |"))
        .unwrap();
    assert!(row.contains("regressed"), "{table}");
    assert!(
        table.lines().filter(|l| l.ends_with("| ok |")).count() == 4,
        "{table}"
    );
    assert!(String::from_utf8_lossy(&fail.stderr).contains("check FAILED"));
}

#[test]
fn a_missing_results_file_is_a_clear_error() {
    let out = rodstudy(&["check", "--results", "/no/such/results.json"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("run `rodstudy study` first"));
}
