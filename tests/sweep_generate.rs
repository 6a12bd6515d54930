//! `rodstudy sweep generate`: a seeded Latin-hypercube sweep of rods (pipeline/sweep_designs.py).
//! Needs Python: the pipeline environment (`RODSTUDY_PYTHON` or `.venv`, created on first use).
//! Same seed → byte-identical files, another seed → other rods, and stage 1 (`rodstudy mass`)
//! accepts every rod as a valid closed solid with the pins in 50 / 25 mm bores.

use std::path::Path;
use std::process::{Command, Output};

fn rodstudy(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .args(args)
        .output()
        .unwrap()
}

fn generate(seed: u64, out: &Path, count: u32) -> Output {
    let (seed, count) = (seed.to_string(), count.to_string());
    rodstudy(&[
        "sweep",
        "generate",
        "--count",
        &count,
        "--seed",
        &seed,
        "--out",
        out.to_str().unwrap(),
    ])
}

/// File names and contents of a folder, sorted by name.
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().into_string().unwrap(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

fn assert_ok(out: &Output, what: &str) {
    assert_eq!(
        out.status.code(),
        Some(0),
        "{what}\nstdout:\n{}\nstderr:\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn same_seed_same_bytes_and_stage_one_accepts_every_rod() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b, c) = (
        tmp.path().join("a"),
        tmp.path().join("b"),
        tmp.path().join("c"),
    );
    // The three runs in parallel (each is one single-threaded gmsh process).
    let (ra, rb, rc) = std::thread::scope(|s| {
        let ha = s.spawn(|| generate(7, &a, 3));
        let hb = s.spawn(|| generate(7, &b, 3));
        let hc = s.spawn(|| generate(8, &c, 3));
        (ha.join().unwrap(), hb.join().unwrap(), hc.join().unwrap())
    });
    assert_ok(&ra, "seed 7 (a)");
    assert_ok(&rb, "seed 7 (b)");
    assert_ok(&rc, "seed 8");
    let stdout = String::from_utf8_lossy(&ra.stdout);
    for id in ["rod0001", "rod0002", "rod0003"] {
        assert!(stdout.contains(&format!("{id} ")), "{stdout}");
    }
    assert!(stdout.contains("replaced"), "{stdout}");

    let names = [
        "rod0001.stl",
        "rod0001.toml",
        "rod0002.stl",
        "rod0002.toml",
        "rod0003.stl",
        "rod0003.toml",
        "sweep.json",
    ];
    let (fa, fb, fc) = (files(&a), files(&b), files(&c));
    assert_eq!(fa.iter().map(|f| f.0.as_str()).collect::<Vec<_>>(), names);
    assert!(fa == fb, "same seed, different files");
    for ((name, x), (_, y)) in fa.iter().zip(&fc) {
        assert_ne!(x, y, "{name}: seed 7 and seed 8 give the same file");
    }

    // The sidecar: the reader's keys, the sample in comments.
    let sidecar = std::fs::read_to_string(a.join("rod0001.toml")).unwrap();
    assert!(sidecar.contains("\n# kind = \""), "{sidecar}");
    assert!(sidecar.contains("\n# eye_a_r = "), "{sidecar}");
    assert!(sidecar.contains("\npin_axis = \"z\"\n"), "{sidecar}");
    let sweep: serde_json::Value =
        serde_json::from_slice(&std::fs::read(a.join("sweep.json")).unwrap()).unwrap();
    assert_eq!(sweep["seed"], 7);
    assert_eq!(sweep["count"], 3);
    let rods = sweep["rods"].as_array().unwrap();
    assert_eq!(rods.len(), 3);
    assert!(sweep["bounds"]["eye_a_r"]["min"].is_number());

    // Stage 1 in Rust: valid closed solids, pins in the 50 / 25 mm bores, distinct masses.
    let mass = rodstudy(&["mass", a.to_str().unwrap(), "--json"]);
    assert_ok(&mass, "rodstudy mass");
    let json: serde_json::Value = serde_json::from_slice(&mass.stdout).unwrap();
    let designs = json.as_array().unwrap();
    assert_eq!(designs.len(), 3);
    let mut masses = Vec::new();
    for rod in rods {
        let id = rod["id"].as_str().unwrap();
        let d = designs.iter().find(|d| d["id"] == id).unwrap();
        // The sidecar was read: its name and density.
        assert!(
            d["design"]
                .as_str()
                .unwrap()
                .starts_with(&format!("Sweep {id}: ")),
            "{d}"
        );
        assert_eq!(d["density_kg_m3"], 7800.0);
        assert!(d["warnings"].as_array().is_none_or(|w| w.is_empty()), "{d}");
        let r_a = d["crank_bore_radius_m"].as_f64().unwrap();
        let r_b = d["piston_bore_radius_m"].as_f64().unwrap();
        assert!((r_a - 0.025).abs() < 2e-4, "crank bore radius {r_a}");
        assert!((r_b - 0.0125).abs() < 2e-4, "piston bore radius {r_b}");
        assert!((d["centre_distance_m"].as_f64().unwrap() - 0.18).abs() < 1e-12);
        // Python's and Rust's integration of the same float32 file agree.
        let m = d["mass_kg"].as_f64().unwrap();
        let m_py = rod["mass_kg"].as_f64().unwrap();
        assert!(
            (m / m_py - 1.0).abs() < 1e-9,
            "mass {m} vs sweep.json {m_py}"
        );
        assert!(m > 1.0 && m < 6.0, "mass {m} kg");
        masses.push(m);
    }
    for i in 0..3 {
        for j in i + 1..3 {
            assert!(
                (masses[i] / masses[j] - 1.0).abs() > 1e-3,
                "rods {i} and {j} have the same mass: {masses:?}"
            );
        }
    }
}

#[test]
fn invalid_parameter_sets_are_reported_and_replaced_or_fail_the_run() {
    let tmp = tempfile::tempdir().unwrap();
    let run = |bounds: &str, count: u32, out: &str| {
        let file = tmp.path().join(format!("{out}.json"));
        std::fs::write(&file, bounds).unwrap();
        let out = tmp.path().join(out);
        let (count, o) = (count.to_string(), out.to_str().unwrap().to_owned());
        let r = rodstudy(&[
            "sweep",
            "generate",
            "--count",
            &count,
            "--seed",
            "3",
            "--out",
            &o,
            "--bounds",
            file.to_str().unwrap(),
        ]);
        (r, out)
    };
    // No big-end eye in these bounds has a 5 mm wall: every draw is replaced, then the run stops.
    let (r, out) = run(r#"{"eye_a_r": {"min": 26, "max": 29}}"#, 1, "hopeless");
    assert_eq!(r.status.code(), Some(1));
    let stdout = String::from_utf8_lossy(&r.stdout);
    assert!(
        stdout.contains("replacing") && stdout.contains("big-end wall around the bore < 5 mm"),
        "{stdout}"
    );
    assert!(stdout.contains("no valid rod in 100 attempts"), "{stdout}");
    assert!(!out.join("sweep.json").exists());
    // Walls of 1-6 mm: some draws are replaced, each recorded with its reason.
    let (r, out) = run(
        r#"{"kind": ["solid"], "eye_a_r": {"min": 26, "max": 31}}"#,
        1,
        "some",
    );
    assert_ok(&r, "bounds with some valid rods");
    let sweep: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("sweep.json")).unwrap()).unwrap();
    let rod = &sweep["rods"][0];
    let replaced = rod["replaced"].as_array().unwrap();
    assert!(!replaced.is_empty(), "{rod}");
    assert_eq!(rod["attempts"], replaced.len() + 1);
    assert_eq!(sweep["replaced"], replaced.len());
    assert!(
        replaced[0]["reason"]
            .as_str()
            .unwrap()
            .contains("check_sensible"),
        "{rod}"
    );
    assert!(rod["parameters"]["eye_a_r"].as_f64().unwrap() >= 30.0);
    assert!(String::from_utf8_lossy(&r.stdout).contains("parameter set(s) replaced"));
    // A usage error: an unknown parameter.
    let (r, _) = run(r#"{"eye_x": {"min": 1}}"#, 1, "usage");
    assert_eq!(r.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&r.stderr).contains("unknown parameter 'eye_x'"));
}
