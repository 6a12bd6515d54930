//! Every kind of bad input the study meets: each design fails with a message naming its file and
//! its defect, the good design is still studied, the exit status is 1, the reports are complete,
//! and nothing panics. A STEP reader that runs past the time limit fails its design alone; a STEP
//! with an absurd number is refused by entity and line before OpenCASCADE sees it; a STEP that
//! fails beside an STL leaves the STL as the design; settings and trace rows out of range are
//! refused up front by key or line; a closed standard output ends a command quietly.

use rodstudy::geometry::primitives::{ascii_stl, binary_stl, to_soup, voxel_rod};
use std::path::Path;
use std::process::{Command, Output, Stdio};

mod common;

fn rodstudy(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_rodstudy"));
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().unwrap()
}

fn design1(dir: &Path, name: &str) {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::copy(repo.join("designs/design1.stl"), dir.join(name)).unwrap();
}

/// results.json of a study: (ids studied with their warnings, errors of the failed designs).
fn study_outcome(out: &Path) -> (Vec<(String, String)>, Vec<String>) {
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
    let designs = r["designs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| {
            (
                d["mass"]["id"].as_str().unwrap().to_string(),
                d["mass"]["warnings"].to_string(),
            )
        })
        .collect();
    let failed = r["failed"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["error"].as_str().unwrap().to_string())
        .collect();
    (designs, failed)
}

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

/// A STEP reader that does not finish (here an interpreter that only sleeps, named by
/// `RODSTUDY_PYTHON`: it answers the import check and hangs on the read) is stopped at the time
/// limit; its design fails alone, named, with the limit and what to do, and the STL design
/// beside it is studied.
#[test]
fn a_step_reader_past_the_time_limit_fails_its_design_alone() {
    let designs = tempfile::tempdir().unwrap();
    let out = tempfile::tempdir().unwrap();
    let d = designs.path();
    design1(d, "design1.stl");
    write(
        d,
        "hangs.step",
        b"ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\nENDSEC;\nEND-ISO-10303-21;\n",
    );
    let fake = d.join("python-that-hangs");
    write(
        d,
        "python-that-hangs",
        b"#!/bin/sh\nif [ \"$1\" = \"-c\" ]; then exit 0; fi\nexec sleep 60\n",
    );
    std::fs::set_permissions(&fake, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    let env = [
        ("RODSTUDY_PYTHON", fake.to_str().unwrap()),
        ("RODSTUDY_MESHER_TIMEOUT_S", "1"),
    ];
    let o = rodstudy(
        &[
            "study",
            "--skip-fem",
            "--designs",
            d.to_str().unwrap(),
            "--out",
            out.path().to_str().unwrap(),
        ],
        &env,
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    let (studied, failed) = study_outcome(out.path());
    assert_eq!(studied.len(), 1, "{studied:?}");
    assert_eq!(studied[0].0, "design1");
    assert_eq!(failed.len(), 1, "{failed:?}");
    let e = &failed[0];
    for part in [
        "hangs.step",
        "did not finish",
        "stopped after 1 s",
        "RODSTUDY_MESHER_TIMEOUT_S",
        "export the part again",
    ] {
        assert!(e.contains(part), "«{part}» in «{e}»");
    }
    // `rodstudy mass` returns too, with the same message
    let o = rodstudy(&["mass", d.join("hangs.step").to_str().unwrap()], &env);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("stopped after 1 s"), "{stderr}");
}

/// The box of [`common::box_step`] and (entity, 1-based line) of its first `CARTESIAN_POINT`.
fn box_step(dir: &Path) -> (String, String, usize) {
    let text = common::box_step(dir);
    let (i, line) = text
        .lines()
        .enumerate()
        .find(|(_, l)| l.contains("CARTESIAN_POINT"))
        .unwrap();
    let entity = line.split('=').next().unwrap().trim().to_string();
    (text, entity, i + 1)
}

/// The first `CARTESIAN_POINT` of `text` with its coordinates replaced by `coords`.
fn with_point(text: &str, coords: &str) -> String {
    let at = text.find("CARTESIAN_POINT").unwrap();
    let open = at + text[at..].find(",(").unwrap() + 1;
    let close = open + text[open..].find(')').unwrap() + 1;
    format!("{}{coords}{}", &text[..open], &text[close..])
}

/// A `1.E300` or `NaN` coordinate is refused before OpenCASCADE reads the file (it runs for
/// minutes on one, crashes on another): the message names the file, the entity, its line and what
/// to do; the STL design beside them is studied. A STEP with a UTF-8 byte-order mark is read.
#[test]
fn a_step_with_an_absurd_number_is_refused_by_entity_and_line() {
    let designs = tempfile::tempdir().unwrap();
    let out = tempfile::tempdir().unwrap();
    let d = designs.path();
    let (text, entity, line) = box_step(d);
    design1(d, "design1.stl");
    write(
        d,
        "huge.step",
        with_point(&text, "(0.,0.,1.E300)").as_bytes(),
    );
    write(d, "nan.step", with_point(&text, "(NaN,0.,0.)").as_bytes());
    let o = rodstudy(
        &[
            "study",
            "--skip-fem",
            "--designs",
            d.to_str().unwrap(),
            "--out",
            out.path().to_str().unwrap(),
        ],
        &[],
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    let (studied, failed) = study_outcome(out.path());
    assert_eq!(studied.len(), 1, "{studied:?}");
    assert_eq!(failed.len(), 2, "{failed:?}");
    for (name, number) in [("huge.step", "1.E300"), ("nan.step", "NaN")] {
        let e = failed.iter().find(|e| e.contains(name)).unwrap();
        let at = format!("{name}:{line}: malformed STEP: entity {entity} (CARTESIAN_POINT)");
        assert!(e.contains(&at), "«{at}» in «{e}»");
        assert!(
            e.contains(number) && e.contains("export the part again"),
            "{e}"
        );
    }
    let mut bom = b"\xef\xbb\xbf".to_vec();
    bom.extend_from_slice(text.as_bytes());
    write(d, "bom.step", &bom);
    let o = rodstudy(
        &["mass", "--json", d.join("bom.step").to_str().unwrap()],
        &[],
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    let m: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // the box is 100 × 40 × 20 mm: 8e-5 m³
    assert!((m[0]["volume_m3"].as_f64().unwrap() / 8e-5 - 1.0).abs() < 1e-9);
}

/// `rod.step` that cannot be read beside `rod.stl`: the STL is the design, its warnings name the
/// STEP and its error; with both unreadable, the failure names both.
#[test]
fn a_failed_step_leaves_the_stl_beside_it_as_the_design() {
    let designs = tempfile::tempdir().unwrap();
    let out = tempfile::tempdir().unwrap();
    let d = designs.path();
    design1(d, "rod.stl");
    write(d, "rod.step", b"");
    design1(d, "other.stl");
    write(d, "broken.stl", b"solid x\n");
    write(d, "broken.step", b"");
    let o = rodstudy(
        &[
            "study",
            "--skip-fem",
            "--designs",
            d.to_str().unwrap(),
            "--out",
            out.path().to_str().unwrap(),
        ],
        &[],
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    let (studied, failed) = study_outcome(out.path());
    let ids: Vec<&str> = studied.iter().map(|(id, _)| id.as_str()).collect();
    assert_eq!(ids, ["other", "rod"], "{studied:?}");
    let warnings = &studied[1].1;
    assert!(
        warnings.contains("rod.step beside it could not be read (empty file")
            && warnings.contains("this design is the STL"),
        "{warnings}"
    );
    assert_eq!(failed.len(), 1, "{failed:?}");
    assert!(
        failed[0].contains("broken.step") && failed[0].contains("the STL beside it fails too"),
        "{}",
        failed[0]
    );
}

/// Settings out of range are refused when the settings are read, naming the key (or the trace
/// file and its row), before any design is computed; byte-order marks are skipped.
#[test]
fn settings_and_trace_rows_out_of_range_are_refused_up_front() {
    use rodstudy::config::StudyConfig;
    let dir = tempfile::tempdir().unwrap();
    let read = |name: &str, text: &[u8]| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        StudyConfig::read(&p).map_err(|e| format!("{e:#}"))
    };
    for (text, key) in [
        ("[cycle]\ninstants = 1000000000000\n", "`cycle.instants`"),
        ("[driven]\nomega_rad_s = 1e200\n", "`driven.omega_rad_s`"),
        ("[fem]\nmesh_size_mm = 1e300\n", "`fem.mesh_size_mm`"),
        ("[fem]\nmin_size_mm = 1e-300\n", "`fem.min_size_mm`"),
        (
            "[engine]\npiston_mass_kg = 1e30\n",
            "`engine.piston_mass_kg`",
        ),
    ] {
        let e = read("rodstudy.toml", text.as_bytes()).unwrap_err();
        assert!(e.contains("rodstudy.toml") && e.contains(key), "{key}: {e}");
        assert!(
            e.contains("at most") || e.contains("at least") || e.contains("between"),
            "{e}"
        );
    }
    let trace = "crank_angle_deg,pressure_bar\n0,1\n360,1e300\n720,1\n";
    std::fs::write(dir.path().join("trace.csv"), trace).unwrap();
    let e = read(
        "rodstudy.toml",
        b"[engine]\npressure_trace = \"trace.csv\"\n",
    )
    .unwrap_err();
    assert!(
        e.contains("trace.csv") && e.contains("line 3") && e.contains("bar"),
        "{e}"
    );
    // UTF-8 byte-order marks before the settings and the trace
    let mut bom_trace = b"\xef\xbb\xbf".to_vec();
    bom_trace.extend_from_slice(b"crank_angle_deg,pressure_bar\n0,1\n360,50\n720,1\n");
    std::fs::write(dir.path().join("trace.csv"), bom_trace).unwrap();
    let c = read(
        "bom.toml",
        b"\xef\xbb\xbf[engine]\npressure_trace = \"trace.csv\"\n",
    )
    .unwrap();
    assert!(c.engine.pressure_trace().unwrap().is_some());
    // the study refuses them before any design: exit 2, no results
    let out = tempfile::tempdir().unwrap();
    let designs = tempfile::tempdir().unwrap();
    design1(designs.path(), "design1.stl");
    let cfg = dir.path().join("instants.toml");
    std::fs::write(&cfg, "[cycle]\ninstants = 1000000000000\n").unwrap();
    let o = rodstudy(
        &[
            "study",
            "--skip-fem",
            "--config",
            cfg.to_str().unwrap(),
            "--designs",
            designs.path().to_str().unwrap(),
            "--out",
            out.path().to_str().unwrap(),
        ],
        &[],
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("`cycle.instants`"), "{stderr}");
    assert!(!out.path().join("results.json").exists());
    // the flag that overrides the setting, likewise, once and not per design
    let design = designs.path().join("design1.stl");
    let o = rodstudy(
        &[
            "dynamics",
            "driven",
            "--omega",
            "1e200",
            design.to_str().unwrap(),
        ],
        &[],
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--omega 1e200 is out of range"), "{stderr}");
}

/// A reader that closes standard output before the command writes (`| head -c 10`) ends the
/// command quietly with status 0, no panic.
#[test]
fn a_closed_standard_output_ends_a_command_quietly() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let design = repo.join("designs/design1.stl");
    let mut child = Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .args(["mass", "--json", design.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // the reader goes before the mass properties are computed and printed
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(o.status.code(), Some(0), "{stderr}");
}
