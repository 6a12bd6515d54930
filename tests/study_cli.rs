//! `rodstudy study` and `rodstudy dynamics driven` end to end on generated designs: the reports,
//! one broken design not stopping the others, and the peak force against the closed form.

use rodstudy::geometry::primitives::{binary_stl, to_soup, voxel_rod};
use rodstudy::mechanism::{MechanismParams, RodInertia, tdc_peak_formula};
use std::path::Path;
use std::process::{Command, Output};

fn rodstudy(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .args(args)
        .output()
        .unwrap()
}

fn rod_file(dir: &Path, name: &str) {
    std::fs::write(
        dir.join(name),
        binary_stl(&to_soup(&voxel_rod().0.scaled(1000.0))),
    )
    .unwrap();
}

#[test]
fn study_writes_reports_and_lists_the_broken_design() {
    let designs = tempfile::tempdir().unwrap();
    let out = tempfile::tempdir().unwrap();
    rod_file(designs.path(), "good.stl");
    let mut open = to_soup(&voxel_rod().0.scaled(1000.0));
    open.pop();
    std::fs::write(designs.path().join("holed.stl"), binary_stl(&open)).unwrap();
    let o = rodstudy(&[
        "study",
        "--skip-fem",
        "--designs",
        designs.path().to_str().unwrap(),
        "--out",
        out.path().to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        o.status.code(),
        Some(1),
        "a failed design gives exit status 1: {stderr}"
    );
    assert!(
        stderr.contains("ran mass, dynamics driven") && stderr.contains("skipped: fem"),
        "{stderr}"
    );
    let results: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("results.json")).unwrap()).unwrap();
    assert_eq!(results["designs"].as_array().unwrap().len(), 1);
    let failed = &results["failed"][0];
    assert!(failed["file"].as_str().unwrap().ends_with("holed.stl"));
    assert!(failed["error"].as_str().unwrap().contains("open mesh"));
    let d = &results["designs"][0];
    // The peak at top dead centre follows from mass and l1 alone (gravity adds ~0.02 N).
    let rod = RodInertia::new(
        d["mass"]["mass_kg"].as_f64().unwrap(),
        d["mass"]["l1_m"].as_f64().unwrap(),
        0.02,
    );
    let formula = tdc_peak_formula(
        &MechanismParams::default(),
        &rod,
        40.0 * std::f64::consts::PI,
    );
    let peak = d["dynamics"]["peak_pin_force_n"].as_f64().unwrap();
    assert!((peak - formula).abs() < 0.1, "{peak} vs {formula}");
    let ranking = std::fs::read_to_string(out.path().join("ranking.md")).unwrap();
    assert!(
        ranking.contains("| 1 | good |") && ranking.contains("holed.stl"),
        "{ranking}"
    );
    let history = std::fs::read_to_string(out.path().join("good").join("pin_force.csv")).unwrap();
    assert_eq!(history.lines().count(), 5002, "header + 5001 samples");
    for entry in std::fs::read_dir(out.path()).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(
            !name.starts_with(".tmp"),
            "temporary file left behind: {name}"
        );
    }
}

#[test]
fn empty_designs_folder_is_a_clear_error() {
    let designs = tempfile::tempdir().unwrap();
    let out = tempfile::tempdir().unwrap();
    let o = rodstudy(&[
        "study",
        "--skip-fem",
        "--designs",
        designs.path().to_str().unwrap(),
        "--out",
        out.path().to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no .stl files"));
    assert!(
        std::fs::read_dir(out.path()).unwrap().next().is_none(),
        "nothing written"
    );
}

#[test]
fn dynamics_driven_json_and_csv() {
    let dir = tempfile::tempdir().unwrap();
    rod_file(dir.path(), "rod.stl");
    let csv = dir.path().join("history.csv");
    let o = rodstudy(&[
        "dynamics",
        "driven",
        dir.path().join("rod.stl").to_str().unwrap(),
        "--json",
        "--csv",
        csv.to_str().unwrap(),
        "--method",
        "multibody",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let d = &json[0];
    for field in [
        "design",
        "peak_pin_force_n",
        "peak_crank_angle_deg",
        "peak_time_s",
        "gravity",
    ] {
        assert!(d.get(field).is_some(), "missing {field}");
    }
    assert_eq!(d["method"], "multibody");
    assert_eq!(d["gravity"], true);
    let angle = d["peak_crank_angle_deg"].as_f64().unwrap();
    assert!(
        !(0.1..=359.9).contains(&angle),
        "peak at top dead centre, got {angle}°"
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("design,t_s,phi_rad,fa_x_n,fa_y_n,fa_abs_n"));
}

/// A designs folder with two rods, `a.stl` and `b.stl`, and an empty reports folder.
fn two_rods() -> (tempfile::TempDir, tempfile::TempDir) {
    let designs = tempfile::tempdir().unwrap();
    rod_file(designs.path(), "a.stl");
    rod_file(designs.path(), "b.stl");
    (designs, tempfile::tempdir().unwrap())
}

#[test]
fn second_run_uses_the_cache_and_a_changed_design_reruns_alone() {
    let (designs, out) = two_rods();
    let (d, o) = (
        designs.path().to_str().unwrap(),
        out.path().to_str().unwrap(),
    );
    // files of stage 3 and the cycle that an earlier study left in a design's folder
    let stale = out.path().join("a");
    std::fs::create_dir_all(&stale).unwrap();
    for f in ["fem_fx.vtu", "von_mises_fy.svg", "cycle.csv", "failure.log"] {
        std::fs::write(stale.join(f), "from an earlier study").unwrap();
    }
    let first = rodstudy(&["study", "--skip-fem", "--designs", d, "--out", o]);
    assert!(String::from_utf8_lossy(&first.stderr).contains("(0 from the cache)"));
    // a study without stage 3 keeps them (a whole study's cache needs them) but does not link
    // them; an old failure.log of a design now studied goes
    for f in ["fem_fx.vtu", "von_mises_fy.svg", "cycle.csv"] {
        assert!(stale.join(f).exists(), "{f} removed");
    }
    let index = std::fs::read_to_string(out.path().join("index.html")).unwrap();
    assert!(index.contains("a/pin_force.csv") && !index.contains("a/fem_fx.vtu"));
    assert!(!index.contains("a/cycle.csv") && !index.contains("a/von_mises_fy.svg"));
    assert!(!stale.join("failure.log").exists());
    let second = rodstudy(&["study", "--skip-fem", "--designs", d, "--out", o]);
    assert!(String::from_utf8_lossy(&second.stderr).contains("(2 from the cache)"));
    std::fs::write(designs.path().join("b.toml"), "name = \"B renamed\"\n").unwrap();
    let third = rodstudy(&["study", "--skip-fem", "--designs", d, "--out", o]);
    let log = String::from_utf8_lossy(&third.stderr);
    assert!(log.contains("(1 from the cache)"), "{log}");
    assert!(log.contains("a.stl: peak pin force") && log.contains("(cached)"));
    let results: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("results.json")).unwrap()).unwrap();
    assert_eq!(results["designs"][1]["mass"]["design"], "B renamed");
    // The cached figures are the computed ones.
    let fresh = rodstudy(&[
        "study",
        "--skip-fem",
        "--designs",
        d,
        "--out",
        o,
        "--no-cache",
    ]);
    assert!(String::from_utf8_lossy(&fresh.stderr).contains("(0 from the cache)"));
    let again: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("results.json")).unwrap()).unwrap();
    assert_eq!(results, again);
    // a study without stage 3 keeps its entries apart, so that it cannot replace a whole
    // study's (whose FEM it would throw away)
    let cache = out.path().join(".cache");
    assert!(cache.join("without-fem").join("a.json").is_file());
    assert!(!cache.join("a.json").exists());
    // the same designs moved elsewhere: answered from the cache, under the files' new names
    let moved = tempfile::tempdir().unwrap();
    for f in ["a.stl", "b.stl", "b.toml"] {
        std::fs::copy(designs.path().join(f), moved.path().join(f)).unwrap();
    }
    let m = moved.path().to_str().unwrap();
    let fourth = rodstudy(&["study", "--skip-fem", "--designs", m, "--out", o]);
    assert!(String::from_utf8_lossy(&fourth.stderr).contains("(2 from the cache)"));
    let there: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("results.json")).unwrap()).unwrap();
    let file = there["designs"][0]["mass"]["file"].as_str().unwrap();
    assert!(file.starts_with(m), "{file} is not in {m}");
}

#[test]
fn configuration_file_sets_the_scene_and_typos_are_refused() {
    let designs = tempfile::tempdir().unwrap();
    let out = tempfile::tempdir().unwrap();
    rod_file(designs.path(), "rod.stl");
    let config = designs.path().join("settings.toml");
    std::fs::write(
        &config,
        "[driven]\nomega_rad_s = 62.83185307179586\ngravity = false\n",
    )
    .unwrap();
    let (d, o, c) = (
        designs.path().to_str().unwrap(),
        out.path().to_str().unwrap(),
        config.to_str().unwrap(),
    );
    let run = rodstudy(&[
        "study",
        "--skip-fem",
        "--designs",
        d,
        "--out",
        o,
        "--config",
        c,
    ]);
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let results: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("results.json")).unwrap()).unwrap();
    assert_eq!(results["config"]["driven"]["gravity"], false);
    let dynamics = &results["designs"][0]["dynamics"];
    // Half the thesis' speed: a quarter of the force, exactly the TDC formula without gravity.
    let peak = dynamics["peak_pin_force_n"].as_f64().unwrap();
    let formula = dynamics["tdc_formula_n"].as_f64().unwrap();
    assert!(
        (peak - formula).abs() < 1e-6 * formula,
        "{peak} vs {formula}"
    );
    // a typo, and settings no design can use: the configuration's error, before any design runs
    for (text, says) in [
        ("[driven]\nspeed = 3.0\n", "unknown field `speed`"),
        (
            "[driven]\nsteps = 2000000\n",
            "`driven.steps` must be between 1 and 1000000",
        ),
        ("[fem]\nyoungs_modulus_pa = 210000\n", "looks like MPa"),
        (
            "[fem]\nmin_size_mm = 20\nmax_size_mm = 2\ninitial_size_mm = 50\n",
            "must be ordered",
        ),
    ] {
        std::fs::write(&config, text).unwrap();
        let bad = rodstudy(&[
            "study",
            "--skip-fem",
            "--designs",
            d,
            "--out",
            o,
            "--config",
            c,
        ]);
        let e = String::from_utf8_lossy(&bad.stderr);
        assert!(
            bad.status.code() == Some(2) && e.contains("settings.toml") && e.contains(says),
            "{text}: {e}"
        );
    }
    // a tolerance or a thread count that means nothing is a usage error
    for args in [
        &["check", "--rtol", "nan"][..],
        &["check", "--rtol-mass=-1"][..],
        &["study", "--jobs", "100000"][..],
    ] {
        let bad = rodstudy(args);
        assert_eq!(bad.status.code(), Some(2), "{args:?}");
    }
}

/// A design whose FEM stage fails (here: `RODSTUDY_PYTHON` names a program that is not Python, so
/// no mesh can be made) keeps its mass and peak force in every report, is not ranked on stress,
/// and `check` still fails on it.
#[test]
fn a_later_stage_failure_keeps_the_earlier_figures() {
    let designs = tempfile::tempdir().unwrap();
    let out = tempfile::tempdir().unwrap();
    rod_file(designs.path(), "good.stl");
    let o = Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .args(["study", "--no-cache", "--designs"])
        .arg(designs.path())
        .arg("--out")
        .arg(out.path())
        .env("RODSTUDY_PYTHON", "/bin/false")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    let results: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("results.json")).unwrap()).unwrap();
    assert_eq!(results["designs"].as_array().unwrap().len(), 0);
    let f = &results["failed"][0];
    assert_eq!(f["stage"], "fem", "{f}");
    let mass = f["mass"]["mass_kg"].as_f64().unwrap();
    let force = f["dynamics"]["peak_pin_force_n"].as_f64().unwrap();
    // the same figures as a study without stage 3
    let skip = tempfile::tempdir().unwrap();
    let o2 = rodstudy(&[
        "study",
        "--skip-fem",
        "--no-cache",
        "--designs",
        designs.path().to_str().unwrap(),
        "--out",
        skip.path().to_str().unwrap(),
    ]);
    assert_eq!(o2.status.code(), Some(0));
    let full: serde_json::Value =
        serde_json::from_slice(&std::fs::read(skip.path().join("results.json")).unwrap()).unwrap();
    assert_eq!(full["designs"][0]["mass"]["mass_kg"].as_f64(), Some(mass));
    assert_eq!(
        full["designs"][0]["dynamics"]["peak_pin_force_n"].as_f64(),
        Some(force)
    );
    // every report keeps them, with the failing stage, and ranks nothing
    let mut csv = csv::Reader::from_path(out.path().join("ranking.csv")).unwrap();
    let rows: Vec<csv::StringRecord> = csv.records().map(|r| r.unwrap()).collect();
    let headers = csv.headers().unwrap().clone();
    let col = |name: &str| headers.iter().position(|h| h == name).unwrap();
    assert_eq!(rows.len(), 1);
    assert_eq!(&rows[0][col("rank")], "", "not ranked");
    assert_eq!(&rows[0][col("status")], "not judged (fem failed)");
    assert_eq!(
        rows[0][col("peak_pin_force_n")].parse::<f64>().unwrap(),
        force
    );
    assert_eq!(&rows[0][col("safety_factor")], "");
    let md = std::fs::read_to_string(out.path().join("ranking.md")).unwrap();
    assert!(md.contains(&format!("{force:.1}")), "{md}");
    assert!(md.contains("(fem stage)"), "{md}");
    let html = std::fs::read_to_string(out.path().join("index.html")).unwrap();
    assert!(
        html.contains("<tr data-id=\"good\" class=\"failed\">"),
        "{html}"
    );
    assert!(html.contains("The fem stage failed"), "{html}");
    let masses = std::fs::read_to_string(out.path().join("mass_properties.csv")).unwrap();
    assert!(masses.contains(",failed,fem,"), "{masses}");
    assert!(out.path().join("good").join("pin_force.csv").is_file());
    // the regression gate still fails on it
    let base = out.path().join("baseline.json");
    std::fs::write(
        &base,
        format!(
            r#"{{"program_version":"x","designs":{{"good":{{"design":"good","peak_pin_force_n":{force},"mass_kg":{mass}}}}}}}"#
        ),
    )
    .unwrap();
    let c = rodstudy(&[
        "check",
        "--baseline",
        base.to_str().unwrap(),
        "--results",
        out.path().join("results.json").to_str().unwrap(),
    ]);
    assert_ne!(c.status.code(), Some(0));
    assert!(
        String::from_utf8_lossy(&c.stdout).contains("failed:"),
        "{}",
        String::from_utf8_lossy(&c.stdout)
    );
}

/// A study whose reports cannot all be written (a plain file where a design's folder goes)
/// fails without replacing any report: the last complete set stays.
#[test]
fn reports_are_replaced_as_a_set_or_not_at_all() {
    let (designs, out) = two_rods();
    let (d, o) = (
        designs.path().to_str().unwrap(),
        out.path().to_str().unwrap(),
    );
    let first = rodstudy(&["study", "--skip-fem", "--designs", d, "--out", o]);
    assert_eq!(first.status.code(), Some(0));
    let read = |f: &str| std::fs::read(out.path().join(f)).unwrap();
    let before: Vec<Vec<u8>> = ["results.json", "index.html", "ranking.md"]
        .iter()
        .map(|f| read(f))
        .collect();
    std::fs::write(designs.path().join("b.toml"), "name = \"B renamed\"\n").unwrap();
    std::fs::remove_dir_all(out.path().join("a")).unwrap();
    std::fs::write(out.path().join("a"), "in the way").unwrap();
    let second = rodstudy(&["study", "--skip-fem", "--designs", d, "--out", o]);
    let e = String::from_utf8_lossy(&second.stderr);
    assert_eq!(second.status.code(), Some(2), "{e}");
    let after: Vec<Vec<u8>> = ["results.json", "index.html", "ranking.md"]
        .iter()
        .map(|f| read(f))
        .collect();
    assert!(before == after, "a report was replaced: {e}");
    // a folder where a design's plot goes: refused before any report moves
    std::fs::remove_file(out.path().join("a")).unwrap();
    let plot = out.path().join("b").join("pin_force.svg");
    std::fs::remove_file(&plot).unwrap();
    std::fs::create_dir_all(&plot).unwrap();
    let third = rodstudy(&["study", "--skip-fem", "--designs", d, "--out", o]);
    let e = String::from_utf8_lossy(&third.stderr);
    assert!(
        third.status.code() == Some(2) && e.contains("a folder is in the way"),
        "{e}"
    );
    let after: Vec<Vec<u8>> = ["results.json", "index.html", "ranking.md"]
        .iter()
        .map(|f| read(f))
        .collect();
    assert!(before == after, "a report was replaced: {e}");
    let leftovers: Vec<String> = std::fs::read_dir(out.path())
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".reports-") || n.starts_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}
