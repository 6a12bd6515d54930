//! The command line: `rodstudy mass`, `rodstudy setup`, exit statuses and messages.

use rodstudy::geometry::primitives::{binary_stl, to_soup, voxel_rod};
use std::path::Path;
use std::process::{Command, Output};

fn rodstudy(args: &[&str], envs: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_rodstudy"));
    c.args(args);
    for (k, v) in envs {
        c.env(k, v);
    }
    c.output().unwrap()
}

fn rod_file(dir: &Path, name: &str) {
    std::fs::write(
        dir.join(name),
        binary_stl(&to_soup(&voxel_rod().0.scaled(1000.0))),
    )
    .unwrap();
}

#[test]
fn mass_json_reports_good_designs_and_fails_on_bad_ones() {
    let dir = tempfile::tempdir().unwrap();
    rod_file(dir.path(), "a_good.stl");
    std::fs::write(dir.path().join("b_broken.stl"), b"solid broken\nfacet\n").unwrap();
    let out = rodstudy(&["mass", "--json", dir.path().to_str().unwrap()], &[]);
    assert_eq!(
        out.status.code(),
        Some(1),
        "a failed design makes the exit status non-zero"
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let designs = json.as_array().unwrap();
    assert_eq!(designs.len(), 1);
    let d = &designs[0];
    for field in [
        "design",
        "file",
        "volume_m3",
        "mass_kg",
        "centroid_m",
        "inertia_about_centroid_kgm2",
        "principal_moments_kgm2",
        "l1_m",
        "offset_m",
        "i_zz_kgm2",
        "i_xx_kgm2",
    ] {
        assert!(d.get(field).is_some(), "missing field {field}");
    }
    assert_eq!(
        d["inertia_about_centroid_kgm2"].as_array().unwrap().len(),
        3
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("b_broken.stl") && stderr.contains("ASCII STL"),
        "{stderr}"
    );
}

#[test]
fn mass_table_for_people_and_success_status() {
    let dir = tempfile::tempdir().unwrap();
    rod_file(dir.path(), "rod.stl");
    let out = rodstudy(&["mass", dir.path().join("rod.stl").to_str().unwrap()], &[]);
    assert_eq!(out.status.code(), Some(0));
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("| rod |") && table.contains("I_zz pin axis"),
        "{table}"
    );
}

#[test]
fn missing_paths_and_interpreters_are_clear_errors() {
    let out = rodstudy(&["mass", "/no/such/place.stl"], &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no such file or folder"));

    let out = rodstudy(&["setup"], &[("RODSTUDY_PYTHON", "/no/such/python3")]);
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("RODSTUDY_PYTHON=/no/such/python3 cannot be used"),
        "{e}"
    );

    // A fresh project root on a machine without python3 on the PATH.
    let root = tempfile::tempdir().unwrap();
    std::fs::create_dir(root.path().join("pipeline")).unwrap();
    std::fs::write(root.path().join("pipeline/requirements.txt"), "numpy\n").unwrap();
    let empty_path = tempfile::tempdir().unwrap();
    let out = rodstudy(
        &["setup"],
        &[
            ("RODSTUDY_ROOT", root.path().to_str().unwrap()),
            ("PATH", empty_path.path().to_str().unwrap()),
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("python3") && e.contains("not found on the PATH"),
        "{e}"
    );
}

/// The default step cap grows with the simulated time, so a 100 s run at
/// 1e-12 (9.1 million RK45 steps, more than the old fixed cap of a million) finishes; an explicit
/// `--max-steps` is still a total and stops it with the step-limit message.
#[test]
fn long_free_run_finishes_under_the_default_cap() {
    let args = [
        "dynamics", "free", "--method", "rk45", "--rtol", "1e-12", "--atol", "1e-12", "--t-end",
        "100", "--json",
    ];
    let o = rodstudy(&args, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["steps"].as_u64().unwrap() > 1_000_000, "{v}");
    assert_eq!(v["t_end_s"].as_f64(), Some(100.0));
    // φ(100 s) against the energy-integral reference (independent of the integrator): φ reaches
    // 1.8e5 rad; 9.1e6 steps with plain sums of the increments measured 4.8e-4 rad (2.7e-9 of
    // φ), with the compensated sum and φ as turns + remainder 1.19e-4 rad (6.6e-10
    // of φ), the truncation error left by rtol 1e-12 (1.8e-7 rad per step at the end)
    let err = v["max_err_phi_rad"].as_f64().unwrap();
    let phi = v["phi_rad"].as_f64().unwrap();
    assert!(
        (phi / 180_408.410_63 - 1.0).abs() < 1e-8,
        "φ(100 s) = {phi}"
    );
    assert!(err / phi < 1e-8, "max |Δφ| = {err} rad");
    let capped = rodstudy(&[&args[..10], &["--max-steps", "1000000"]].concat(), &[]);
    assert!(!capped.status.success());
    let msg = String::from_utf8_lossy(&capped.stderr);
    assert!(msg.contains("step limit of 1000000 steps"), "{msg}");
}

/// `dynamics free --project-energy` reports its projections in the JSON
/// (`energy_projection`), agrees with the exact reference, and is refused with another method.
#[test]
fn free_run_with_the_energy_projection() {
    let o = rodstudy(
        &[
            "dynamics",
            "free",
            "--method",
            "rk45",
            "--atol",
            "1e-10",
            "--project-energy",
            "--json",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let p = &v["energy_projection"];
    assert!(
        p["projections"].as_u64().unwrap() >= v["steps"].as_u64().unwrap(),
        "{v}"
    );
    assert!(p["max_change_rad_s"].as_f64().unwrap() < 1e-6, "{v}");
    assert!(v["max_err_phi_rad"].as_f64().unwrap() < 1e-9, "{v}");
    let plain = rodstudy(&["dynamics", "free", "--json"], &[]);
    let v: serde_json::Value = serde_json::from_slice(&plain.stdout).unwrap();
    assert!(v.get("energy_projection").is_none(), "{v}");
    let bdf = rodstudy(
        &["dynamics", "free", "--method", "bdf", "--project-energy"],
        &[],
    );
    assert!(!bdf.status.success());
    let msg = String::from_utf8_lossy(&bdf.stderr);
    assert!(msg.contains("rk45 only"), "{msg}");
}

/// A plain RK45 run of the conservative free scene whose error against the exact reference
/// exceeds 10× its tolerance (10 s at atol 1e-9, rtol 0) is told, beside that warning, what keeps
/// it on the energy integral; the projected run of the same settings meets its tolerance and is
/// told nothing.
/// What a new user may type into `dynamics free` and what comes back: a horizon whose output grid
/// would not fit in memory and a relative tolerance of 1 are refused at once with what to give
/// instead; a tolerance so loose that the run blows up warns; a picosecond run from rest gives no
/// energy warning; `--max-steps` takes the help's own `1e6` form and raises the evaluation cap
/// with it (genalpha at 1e-7 s needs more than the default 1e7 evaluations for 0.1 s); a run that
/// hits the cap says what to raise.
#[test]
fn free_runs_refuse_what_cannot_work_and_say_what_to_try() {
    let warnings = |o: &Output| -> Vec<String> {
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .map(|w| w.as_str().unwrap().to_string())
            .collect()
    };
    let t = std::time::Instant::now();
    let o = rodstudy(&["dynamics", "free", "--t-end", "1e6"], &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("the longest run is 1000 s"),
        "{err}"
    );
    assert!(
        t.elapsed().as_secs_f64() < 5.0,
        "refused before integrating"
    );
    let o = rodstudy(&["dynamics", "free", "--rtol", "1"], &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("below 1"), "{err}");
    // a flag the method would not read is refused, not ignored
    let o = rodstudy(
        &["dynamics", "free", "--method", "rk45", "--dt", "1e-4"],
        &[],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("rk45 chooses its own steps") && err.contains("--dt"),
        "{err}"
    );
    let o = rodstudy(
        &[
            "dynamics",
            "free",
            "--method",
            "initial-acceleration",
            "--atol",
            "1e-9",
        ],
        &[],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("does not read --atol") && err.contains("--dt"),
        "{err}"
    );
    let o = rodstudy(&["dynamics", "free", "--atol=1e308", "--json"], &[]);
    assert!(
        warnings(&o).iter().any(|w| w.contains("blew up")),
        "{:?}",
        warnings(&o)
    );
    let o = rodstudy(
        &[
            "dynamics", "free", "--method", "bdf", "--t-end", "1e-12", "--json",
        ],
        &[],
    );
    assert!(warnings(&o).is_empty(), "{:?}", warnings(&o));
    let o = rodstudy(
        &[
            "dynamics",
            "free",
            "--method",
            "dae-genalpha",
            "--t-end",
            "0.1",
            "--dt",
            "1e-7",
            "--max-steps",
            "1.1e6",
            "--json",
        ],
        &[],
    );
    warnings(&o);
    let o = rodstudy(
        &["dynamics", "free", "--max-steps", "2", "--t-end", "0.01"],
        &[],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("raise --max-steps") && !err.contains("rk45: rk45:"),
        "{err}"
    );
}

#[test]
fn a_drifting_rk45_run_is_pointed_to_the_energy_projection() {
    let run = |extra: &[&str]| {
        let mut args = vec![
            "dynamics", "free", "--method", "rk45", "--rtol", "0", "--atol", "1e-9", "--t-end",
            "10", "--json",
        ];
        args.extend_from_slice(extra);
        let o = rodstudy(&args, &[]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice::<serde_json::Value>(&o.stdout).unwrap()
    };
    let plain = run(&[]);
    let warnings: Vec<&str> = plain["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap())
        .collect();
    assert!(plain["max_err_phi_rad"].as_f64().unwrap() > 1e-8, "{plain}");
    assert!(
        warnings.iter().any(|w| w.contains("exact reference"))
            && warnings.iter().any(|w| w.contains("--project-energy")),
        "{warnings:?}"
    );
    let projected = run(&["--project-energy"]);
    assert!(
        projected["max_err_phi_rad"].as_f64().unwrap() < 1e-8,
        "{projected}"
    );
    assert!(
        !projected.to_string().contains("--project-energy keeps"),
        "{projected}"
    );
}

/// `rodstudy mass` gives the mass properties of any closed solid; without bores
/// at the pins the mechanism-frame fields are null with a warning, and the study still refuses it.
#[test]
fn mass_of_a_plain_box_without_bores() {
    use nalgebra::Vector3;
    use rodstudy::geometry::primitives::cuboid;
    let dir = tempfile::tempdir().unwrap();
    // 50 × 40 × 30 mm, centred at (10, 0, 0) mm: the default crank pin (0, 0, 0) is inside it
    let b = cuboid(Vector3::new(50.0, 40.0, 30.0), Vector3::new(10.0, 0.0, 0.0));
    std::fs::write(dir.path().join("box.stl"), binary_stl(&to_soup(&b))).unwrap();
    let out = rodstudy(&["mass", "--json", dir.path().to_str().unwrap()], &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let r = &v[0];
    // closed forms: V = abc, m = ρV, I_xx = m (b² + c²) / 12 about the centroid
    let (a, bb, c) = (0.05, 0.04, 0.03);
    let m = 7800.0 * a * bb * c;
    assert!((r["volume_m3"].as_f64().unwrap() / (a * bb * c) - 1.0).abs() < 1e-6);
    assert!((r["mass_kg"].as_f64().unwrap() / m - 1.0).abs() < 1e-6);
    let ixx = r["inertia_about_centroid_kgm2"][0][0].as_f64().unwrap();
    assert!(
        (ixx / (m * (bb * bb + c * c) / 12.0) - 1.0).abs() < 1e-6,
        "{ixx}"
    );
    assert!((r["centroid_m"][0].as_f64().unwrap() - 0.01).abs() < 1e-9);
    for key in ["l1_m", "i_zz_kgm2", "i_xx_kgm2", "crank_bore_radius_m"] {
        assert!(r[key].is_null(), "{key}: {}", r[key]);
    }
    let warnings = r["warnings"].to_string();
    assert!(
        warnings.contains("no mechanism-frame properties") && warnings.contains("inside material"),
        "{warnings}"
    );
    // the table shows the mass and "—" for the rod figures
    let table = rodstudy(&["mass", dir.path().to_str().unwrap()], &[]);
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(
        text.contains("| box | 0.468000 |") && text.contains("| — |"),
        "{text}"
    );
    // the study needs the pins in bores: refused with the message of before
    let out_dir = tempfile::tempdir().unwrap();
    let study = rodstudy(
        &[
            "study",
            "--skip-fem",
            "--designs",
            dir.path().to_str().unwrap(),
            "--out",
            out_dir.path().to_str().unwrap(),
        ],
        &[],
    );
    assert!(!study.status.success());
    let msg = String::from_utf8_lossy(&study.stderr);
    assert!(msg.contains("lies inside material, not in a bore"), "{msg}");
}

/// `dynamics table-5-1 --json` says its scene in every row.
#[test]
fn table_5_1_json_rows_name_their_scene() {
    for (args, gravity) in [
        (&["dynamics", "table-5-1", "--json"][..], true),
        (
            &["dynamics", "table-5-1", "--json", "--no-gravity"][..],
            false,
        ),
    ] {
        let o = rodstudy(args, &[]);
        assert!(o.status.success());
        let rows: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let rows = rows.as_array().unwrap();
        assert_eq!(rows.len(), 5);
        for r in rows {
            assert_eq!(r["gravity"], gravity);
            let w = r["omega_rad_s"].as_f64().unwrap();
            assert!((w - 40.0 * std::f64::consts::PI).abs() < 1e-12);
            assert!(r["computed_peak_n"].as_f64().unwrap() > 1000.0);
        }
    }
}

/// `pipeline SCRIPT` runs a script of pipeline/ by its name, never a path elsewhere.
#[test]
fn pipeline_runs_only_its_own_scripts() {
    for script in ["../Cargo.toml", "/etc/passwd", "make_designs"] {
        let o = rodstudy(&["pipeline", script], &[]);
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(
            o.status.code() == Some(2) && e.contains("a Python script in pipeline/"),
            "{script}: {e}"
        );
    }
}
