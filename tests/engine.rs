//! The engine: the `[engine]` settings and the pressure trace, the gas force
//! in both solution methods over the four-stroke cycle, the quasi-static statics of the slider,
//! the example configuration, and that the default stays the thesis' rig.

use rodstudy::config::{EngineConfig, StudyConfig};
use rodstudy::mechanism::{
    CrankSlider, DrivenScene, GasForce, MechanismParams, Method, MotionSample, RodInertia,
    compare_results, driven_scene, driven_scene_with_gas, piston_area_m2,
};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn example_config() -> StudyConfig {
    StudyConfig::read(&repo().join("pipeline/examples/engine.toml")).expect("example config")
}

fn tempdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rodstudy-engine-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

// ---------------------------------------------------------------------------
// settings

/// Reference: serde's `deny_unknown_fields` and typed fields, as for the other sections (the
/// sidecars refuse the same way).
#[test]
fn unknown_keys_and_wrong_types_are_refused() {
    let e = toml::from_str::<StudyConfig>("[engine]\nbore_mm = 82.0\n").unwrap_err();
    assert!(e.to_string().contains("unknown field `bore_mm`"), "{e}");
    let e = toml::from_str::<StudyConfig>("[engine]\ncrank_radius_mm = \"46\"\n").unwrap_err();
    assert!(e.to_string().contains("crank_radius_mm"), "{e}");
    let e = toml::from_str::<StudyConfig>("[engine]\npressure_trace = 3\n").unwrap_err();
    assert!(e.to_string().contains("pressure_trace"), "{e}");
    // out-of-range values are refused on reading
    let dir = tempdir("range");
    let file = dir.join("bad.toml");
    write(&file, "[engine]\ncylinder_bore_mm = -82.0\n");
    let e = format!("{:#}", StudyConfig::read(&file).unwrap_err());
    assert!(e.contains("engine.cylinder_bore_mm"), "{e}");
}

/// Reference: the pressure trace's rules (cover 0–720, monotone angles, no negative
/// absolute pressure), each message naming the file and the line.
#[test]
fn bad_traces_are_refused_naming_file_and_line() {
    let dir = tempdir("traces");
    let cases = [
        (
            "crank_angle_deg,pressure_bar\n0,1\n360,0\n700,1\n",
            "line 4",
            "cover the cycle",
        ),
        (
            "crank_angle_deg,pressure_bar\n0,1\n360,0\n350,0\n720,1\n",
            "line 4",
            "monotone",
        ),
        (
            "# a comment\ncrank_angle_deg,pressure_bar\n0,1\n360,-2\n720,1\n",
            "line 4",
            "negative absolute pressure",
        ),
    ];
    for (k, (text, line, what)) in cases.iter().enumerate() {
        let trace = dir.join(format!("trace{k}.csv"));
        write(&trace, text);
        let config = dir.join(format!("engine{k}.toml"));
        write(
            &config,
            &format!("[engine]\npressure_trace = \"trace{k}.csv\"\n"),
        );
        let e = format!("{:#}", StudyConfig::read(&config).unwrap_err());
        assert!(
            e.contains(&format!("trace{k}.csv")) && e.contains(line) && e.contains(what),
            "{text:?}: {e}"
        );
    }
    // a missing file names itself
    let config = dir.join("missing.toml");
    write(&config, "[engine]\npressure_trace = \"nowhere.csv\"\n");
    let e = format!("{:#}", StudyConfig::read(&config).unwrap_err());
    assert!(e.contains("nowhere.csv"), "{e}");
}

/// Reference: the `[engine]` settings: "a relative path is relative to the config file".
#[test]
fn a_relative_trace_path_is_resolved_against_the_config_folder() {
    let dir = tempdir("relative");
    write(
        &dir.join("sub/traces/flat.csv"),
        "crank_angle_deg,pressure_bar\n0,10\n720,10\n",
    );
    let config = dir.join("sub/engine.toml");
    write(
        &config,
        "[engine]\ncylinder_bore_mm = 100.0\npressure_trace = \"traces/flat.csv\"\n",
    );
    let c = StudyConfig::read(&config).expect("reads");
    let path = c.engine.pressure_trace.expect("trace").as_path();
    assert_eq!(path, dir.join("sub/traces/flat.csv"));
    let gas = c.engine.gas_force().unwrap().expect("gas force");
    // 10 bar on a 100 mm bore: 1e6 Pa · π 0.05² m²
    let expected = 1e6 * std::f64::consts::PI * 0.05 * 0.05;
    assert!((gas.at(1.234) - expected).abs() < 1e-9 * expected);
    // the trace is serialized with the engine; the default engine is not
    let json = serde_json::to_string(&c).unwrap();
    assert!(
        json.contains("\"engine\"") && json.contains("flat.csv"),
        "{json}"
    );
}

/// Reference: the spec's defaults (SPEC "The mechanism"): the default engine is the thesis' rig
/// to the bit, and it is not written into results.json (so the default study is unchanged).
#[test]
fn the_default_engine_is_the_thesis_rig_and_is_not_serialized() {
    let e = EngineConfig::default();
    for gravity in [true, false] {
        let p = e.mechanism(0.179, gravity);
        let expected = MechanismParams {
            centre_distance_m: 0.179,
            ..MechanismParams::default()
        }
        .with_gravity(gravity);
        assert_eq!(p, expected);
    }
    let json = serde_json::to_string(&StudyConfig::default()).unwrap();
    assert!(!json.contains("engine"), "{json}");
    assert!(e.gas_force().unwrap().is_none());
    // a changed engine is used, in SI
    let c: StudyConfig =
        toml::from_str("[engine]\ncrank_radius_mm = 40.0\npiston_mass_kg = 0.5\n").unwrap();
    let p = c.engine.mechanism(0.15, true);
    assert_eq!(p.crank_radius_m, 0.04);
    assert_eq!(p.piston_mass_kg, 0.5);
    assert!(serde_json::to_string(&c).unwrap().contains("\"engine\""));
}

// ---------------------------------------------------------------------------
// the two methods with gas force

/// Reference: the closed-form Newton–Euler of the crank–slider against the general multibody
/// core (the gas force an applied load in h, thesis eq. 3.31), ≤ 1e-9 as without gas force
/// (SPEC "Stage 2").
#[test]
fn closed_form_and_multibody_agree_with_gas_force_over_the_cycle() {
    let config = example_config();
    let gas = config
        .engine
        .gas_force()
        .unwrap()
        .expect("the example has a trace");
    let rods = [
        RodInertia::thesis_original(),
        RodInertia::new(3.0420019180, 0.07176, 0.018).with_offset(0.0015),
    ];
    for gravity in [true, false] {
        let params = config.engine.mechanism(0.18, gravity);
        for rod in &rods {
            // finer than the default 100 steps over the cycle: every 1.8°
            let scene = DrivenScene {
                steps: 400,
                ..DrivenScene::default().four_stroke()
            };
            assert!(
                (scene.duration_s * scene.omega_rad_s - 4.0 * std::f64::consts::PI).abs() < 1e-12
            );
            let a = driven_scene_with_gas(
                &params,
                rod,
                Some(Arc::clone(&gas)),
                &scene,
                Method::ClosedForm,
            )
            .unwrap();
            let b = driven_scene_with_gas(
                &params,
                rod,
                Some(Arc::clone(&gas)),
                &scene,
                Method::Multibody,
            )
            .unwrap();
            let ag = compare_results(&b, &a).unwrap();
            eprintln!("gravity {gravity}, rod m3 = {}: {ag:?}", rod.mass_kg);
            assert!(
                ag.max_rel_diff_to_peak <= 1e-9
                    && ag.max_rel_diff_f_b <= 1e-9
                    && ag.max_rel_diff_torque <= 1e-9,
                "{ag:?}"
            );
            let rel = |x: f64, y: f64| (x - y).abs() / y.abs().max(1.0);
            assert!(rel(b.peak_pin_force_n, a.peak_pin_force_n) <= 1e-9);
            assert!(rel(b.axial.compression.force_n, a.axial.compression.force_n) <= 1e-9);
            assert!(rel(b.axial.tension.force_n, a.axial.tension.force_n) <= 1e-9);
            assert!(
                (b.axial.compression.crank_angle_deg - a.axial.compression.crank_angle_deg).abs()
                    < 1e-3
            );
            let (ga, gb) = (
                a.gas_force_n.as_ref().unwrap(),
                b.gas_force_n.as_ref().unwrap(),
            );
            let gmax = gas.max_n();
            for k in 0..ga.len() {
                assert!((ga[k] - gb[k]).abs() <= 1e-9 * gmax);
                let axial_diff = (a.rod_axial_n[k] - b.rod_axial_n[k]).abs();
                assert!(axial_diff <= 1e-9 * a.axial.compression.force_n);
            }
            // the firing compression dominates, the angles lie in [0, 720)
            assert!(a.axial.compression.force_n > 2.0 * a.axial.tension.force_n);
            for angle in [
                a.peak_crank_angle_deg,
                a.axial.compression.crank_angle_deg,
                a.axial.tension.crank_angle_deg,
            ] {
                assert!((0.0..720.0).contains(&angle), "{angle}");
            }
        }
    }
}

/// Reference: statics of the slider. Quasi-static (ω → 0), without gravity, with a constant
/// gauge pressure p, the rod is a two-force member: its axial force is F_gas / cos ψ
/// (compression, F_gas = p A), and by virtual work the drive torque balances the gas:
/// T φ̇ + F_piston ẋ_B = 0 with F_piston = −F_gas along x and ẋ_B = −p42 φ̇ (thesis eq. 2.11),
/// so T = −F_gas p42 (the gas delivers +F_gas dx/dφ to the crank, the drive absorbs it).
#[test]
fn quasi_static_constant_pressure_is_the_statics_of_the_slider() {
    let p_pa = 40e5;
    let bore = 0.082;
    let f_gas = p_pa * piston_area_m2(bore);
    let gas = Arc::new(GasForce::constant(f_gas));
    let params = MechanismParams::default().with_gravity(false);
    let rod = RodInertia::new(3.0, 0.072, 0.02).with_offset(0.001);
    let omega = 1e-4;
    let scene = DrivenScene {
        omega_rad_s: omega,
        duration_s: 4.0 * std::f64::consts::PI / omega,
        steps: 720,
        ..DrivenScene::default()
    };
    let (r, l) = (params.crank_radius_m, params.centre_distance_m);
    for method in [Method::ClosedForm, Method::Multibody] {
        let run =
            driven_scene_with_gas(&params, &rod, Some(Arc::clone(&gas)), &scene, method).unwrap();
        for k in 0..run.samples {
            let phi = run.phi_rad[k];
            let sin_psi = r / l * phi.sin();
            let cos_psi = (1.0 - sin_psi * sin_psi).sqrt();
            let axial = f_gas / cos_psi;
            assert!(
                (run.rod_axial_n[k] - axial).abs() <= 1e-9 * axial,
                "{method:?} φ = {phi}: {} vs {axial}",
                run.rod_axial_n[k]
            );
            // the pin force is along the rod: |F_A| = axial
            assert!((run.fa_abs_n[k] - axial).abs() <= 1e-9 * axial);
            let p42 = r * phi.sin() + r * r * phi.sin() * phi.cos() / (l * cos_psi);
            let torque = -f_gas * p42;
            assert!(
                (run.crank_torque_nm[k] - torque).abs() <= 1e-9 * f_gas * r,
                "{method:?} φ = {phi}: {} vs {torque}",
                run.crank_torque_nm[k]
            );
        }
        // largest compression at φ = 90° or 270° (largest ψ), where cos ψ = √(1 − (r/l)²)
        let most = f_gas / (1.0 - (r / l) * (r / l)).sqrt();
        assert!((run.axial.compression.force_n - most).abs() <= 1e-9 * most);
        assert_eq!(run.axial.tension.force_n, 0.0);
    }
    // the same model at one instant, straight from the closed form
    let model = CrankSlider::new(&params, &rod)
        .unwrap()
        .with_gas_force(Some(gas));
    let loads = model.closed_form(MotionSample {
        phi: 0.0,
        omega: 0.0,
        alpha: 0.0,
    });
    assert!((loads.f_a.x - f_gas).abs() < 1e-9 * f_gas && loads.f_a.y.abs() < 1e-9 * f_gas);
}

/// Reference: without a trace nothing changes (the gas force is absent, the scene is the
/// configured one, the history has no gas column).
#[test]
fn without_a_trace_the_scene_is_todays() {
    let params = MechanismParams::default();
    let rod = RodInertia::thesis_original();
    let scene = DrivenScene {
        duration_s: 0.1,
        steps: 100,
        ..DrivenScene::default()
    };
    let a = driven_scene(&params, &rod, &scene, Method::ClosedForm).unwrap();
    let b = driven_scene_with_gas(&params, &rod, None, &scene, Method::ClosedForm).unwrap();
    assert_eq!(a, b);
    assert!(a.gas_force_n.is_none());
    assert!(a.peak_crank_angle_deg < 360.0);
    // inertia alone: tension at top dead centre equals the |F_A| peak there (F_A along the rod)
    assert!((a.axial.tension.force_n - a.peak_pin_force_n).abs() < 1e-3 * a.peak_pin_force_n);
}

// ---------------------------------------------------------------------------
// the example and the command line

fn rodstudy(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .args(args)
        .current_dir(repo())
        .output()
        .expect("runs")
}

/// Reference: the `[engine]` fields and the example's physics: 64 bar on an 82 mm
/// bore is 33.7 kN of gas force, so tens of kN of compression; the tension is the inertia at
/// exhaust top dead centre (360°), about the thesis' 7 kN.
#[test]
fn the_example_prints_compression_and_tension() {
    let out = rodstudy(&[
        "dynamics",
        "driven",
        "designs/design1.stl",
        "--config",
        "pipeline/examples/engine.toml",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let d = &v[0];
    let num = |k: &str| d[k].as_f64().unwrap_or_else(|| panic!("{k} in {d}"));
    let compression = num("peak_compression_n");
    assert!((10e3..60e3).contains(&compression), "{compression}");
    let gas = num("peak_compression_gas_force_n");
    assert!((25e3..40e3).contains(&gas), "{gas}");
    let at = num("peak_compression_crank_angle_deg");
    assert!((0.0..40.0).contains(&at), "{at}");
    let tension = num("peak_tension_n");
    assert!((3e3..15e3).contains(&tension), "{tension}");
    let at = num("peak_tension_crank_angle_deg");
    assert!((340.0..380.0).contains(&at), "{at}");
    assert!(num("peak_tension_gas_force_n").abs() < 1e3);
    assert!((num("duration_s") * num("omega_rad_s") - 4.0 * std::f64::consts::PI).abs() < 1e-9);

    // the CSV keeps its columns and adds gas_force_n
    let dir = tempdir("csv");
    let csv = dir.join("h.csv");
    let out = rodstudy(&[
        "dynamics",
        "driven",
        "designs/design1.stl",
        "--config",
        "pipeline/examples/engine.toml",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let text = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(
        text.lines().next().unwrap(),
        "design,t_s,phi_rad,fa_x_n,fa_y_n,fa_abs_n,fb_x_n,fb_y_n,fb_abs_n,crank_torque_nm,gas_force_n"
    );
    assert_eq!(text.lines().count(), 1 + 101);
}

/// Reference: the done-criterion "the default study is byte-identical": without `--config`
/// the summary has none of the engine fields and the CSV none of the gas column.
#[test]
fn the_default_prints_todays_fields() {
    let dir = tempdir("default");
    let csv = dir.join("h.csv");
    let out = rodstudy(&[
        "dynamics",
        "driven",
        "designs/design1.stl",
        "--json",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(!text.contains("peak_compression") && !text.contains("peak_tension"));
    let header = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(
        header.lines().next().unwrap(),
        "design,t_s,phi_rad,fa_x_n,fa_y_n,fa_abs_n,fb_x_n,fb_y_n,fb_abs_n,crank_torque_nm"
    );
}

/// Reference: the cache's rule (`src/study/cache.rs`): a changed setting or input reruns a design.
/// The engine and the trace's bytes are in the key; the default engine leaves the key as before
/// (the configuration serializes identically).
#[test]
fn the_cache_key_follows_the_engine_and_the_trace() {
    use rodstudy::study::cache::design_key;
    let stl = repo().join("designs/design1.stl");
    let default = design_key(&stl, &StudyConfig::default()).unwrap();
    let dir = tempdir("cache");
    let trace = dir.join("t.csv");
    write(&trace, "crank_angle_deg,pressure_bar\n0,10\n720,10\n");
    let config_file = dir.join("e.toml");
    write(&config_file, "[engine]\npressure_trace = \"t.csv\"\n");
    let engine = StudyConfig::read(&config_file).unwrap();
    let with_trace = design_key(&stl, &engine).unwrap();
    assert_ne!(default, with_trace);
    write(&trace, "crank_angle_deg,pressure_bar\n0,20\n720,20\n");
    assert_ne!(design_key(&stl, &engine).unwrap(), with_trace);
    let mut bore = engine;
    bore.engine.cylinder_bore_mm = 90.0;
    assert_ne!(
        design_key(&stl, &bore).unwrap(),
        design_key(&stl, &engine).unwrap()
    );
}

/// The `cycle --json` record of design 1 on a fixed 8 mm mesh with `config` (a path relative to
/// the repository, or none).
fn cycle_json(config: Option<&Path>, out: &Path) -> serde_json::Value {
    let mut args = vec![
        "cycle".to_string(),
        "designs/design1.stl".into(),
        "--size".into(),
        "8".into(),
        "--json".into(),
        "--out".into(),
        out.to_str().unwrap().into(),
    ];
    if let Some(c) = config {
        args.push("--config".into());
        args.push(c.to_str().unwrap().into());
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let run = rodstudy(&args);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_slice(&run.stdout).unwrap()
}

/// Reference: the cycle over 720° with the gas force (Gerber as a choice) and
/// item 3 (the cosine bore load in the cycle). The gas force's peak is the trace's 64 bar on
/// the 82 mm bore; equilibrium at B holds to round-off with the gas force too; the worst instant
/// is at firing; the fatigue factor falls from today's (inertia only) to single digits; Gerber
/// credits the tensile mean, so its factor is at least Goodman's.
#[test]
fn the_engine_cycle_spans_720_degrees_with_the_gas_force() {
    let dir = tempdir("cycle720");
    let today = cycle_json(None, &dir.join("today"));
    let engine = cycle_json(
        Some(Path::new("pipeline/examples/engine.toml")),
        &dir.join("engine"),
    );
    let num = |v: &serde_json::Value, k: &str| v[k].as_f64().unwrap_or_else(|| panic!("{k}"));
    assert!(today.get("cycle_span_deg").is_none());
    assert_eq!(num(&engine, "cycle_span_deg"), 720.0);
    assert_eq!(num(&engine, "instants"), 720.0);
    let history = engine["history"].as_array().unwrap();
    let last = history.last().unwrap()["crank_angle_deg"].as_f64().unwrap();
    assert!((last - 719.0).abs() < 1e-9, "{last}");
    let trace = example_config().engine.pressure_trace().unwrap().unwrap();
    let area = std::f64::consts::PI * 0.082f64.powi(2) / 4.0;
    let peak_gas = trace.peak().0 * 1e5 * area;
    let got = num(&engine, "peak_gas_force_n");
    assert!(
        (got - peak_gas).abs() < 1e-6 * peak_gas,
        "{got} vs {peak_gas}"
    );
    assert!(num(&engine, "reaction_mismatch_rel") < 1e-9);
    let at = num(&engine, "crank_angle_of_max_deg");
    assert!((0.0..40.0).contains(&at), "worst instant at {at}°");
    let (n_today, n_engine) = (
        num(&today, "fatigue_safety_factor"),
        num(&engine, "fatigue_safety_factor"),
    );
    assert!(
        n_engine < 10.0 && n_engine < 0.5 * n_today,
        "{n_engine} vs {n_today}"
    );
    assert!(engine["method"].as_str().unwrap().contains("four-stroke"));

    // Gerber: a config beside a copy of the trace
    let gerber_dir = tempdir("gerber");
    let cfg = std::fs::read_to_string(repo().join("pipeline/examples/engine.toml")).unwrap();
    write(
        &gerber_dir.join("engine.toml"),
        &format!("{cfg}\n[material]\nmean_stress = \"gerber\"\n"),
    );
    std::fs::copy(
        repo().join("pipeline/examples/wiebe_gasoline.csv"),
        gerber_dir.join("wiebe_gasoline.csv"),
    )
    .unwrap();
    let gerber = cycle_json(Some(&gerber_dir.join("engine.toml")), &dir.join("gerber"));
    assert_eq!(gerber["mean_stress"], "gerber");
    assert!(gerber["method"].as_str().unwrap().contains("Gerber"));
    let n_gerber = num(&gerber, "fatigue_safety_factor");
    assert!(n_gerber >= n_engine, "{n_gerber} < {n_engine}");
    // the same stresses: only the criterion differs
    assert_eq!(
        num(&gerber, "max_von_mises_over_cycle_mpa"),
        num(&engine, "max_von_mises_over_cycle_mpa")
    );
}

/// Reference: the engine study's stage 3 (SPEC stage 3): the F_x case carries
/// the peak pin force, the F_y case the largest pin force across the rod over the cycle (the gas
/// force acts along the rod), which the dynamics reports as `peak_transverse_n`.
#[test]
fn the_engine_fy_case_carries_the_largest_transverse_pin_force() {
    let out = rodstudy(&[
        "dynamics",
        "driven",
        "designs/design1.stl",
        "--config",
        "pipeline/examples/engine.toml",
        "--json",
    ]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let d = &v[0];
    let transverse = d["peak_transverse_n"].as_f64().unwrap();
    let peak = d["peak_pin_force_n"].as_f64().unwrap();
    // inertia and the slider's reaction: a few kN, far below the firing peak
    assert!(
        transverse > 500.0 && transverse < 0.3 * peak,
        "{transverse} vs {peak}"
    );
    let dir = tempdir("fy");
    let out = rodstudy(&[
        "fem",
        "designs/design1.stl",
        "--size",
        "8",
        "--config",
        "pipeline/examples/engine.toml",
        "--json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let f: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let fem = &f["fem"];
    let fx = fem["fx"]["force_n"].as_f64().unwrap();
    let fy = fem["fy"]["force_n"].as_f64().unwrap();
    assert!((fx - peak).abs() < 1e-9 * peak, "{fx} vs {peak}");
    assert!(
        (fy - transverse).abs() < 1e-9 * transverse,
        "{fy} vs {transverse}"
    );
}
