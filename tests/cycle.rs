//! `rodstudy cycle`: stress over one revolution with inertia relief, on a committed design with a
//! fixed 5 mm mesh. The JSON fields are the interface; the figures are checked against each other
//! and against independent relations (equilibrium with the dynamics at every instant, the Goodman
//! line, the static F_x case at the same force).

use std::process::Command;

#[test]
fn cycle_json_reports_the_history_the_maximum_and_the_fatigue_factor() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .arg("cycle")
        .arg(root.join("designs/design2.stl"))
        .args(["--size", "5", "--json", "--out"])
        .arg(out.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let history = j["history"].as_array().unwrap();
    assert_eq!(history.len(), 360);
    for (k, h) in history.iter().enumerate() {
        // equally spaced from crank angle 0 exactly
        let angle = h["crank_angle_deg"].as_f64().unwrap();
        assert!((angle - k as f64).abs() < 1e-9, "{angle}");
        assert!(h["time_s"].as_f64().unwrap() >= 0.0);
    }
    // equilibrium: the reaction of the fixed bore equals the piston pin's force of the dynamics
    // (the loads use the mesh's own mass properties); measured ~1e-13 of the peak force
    let peak = j["peak_pin_force_n"].as_f64().unwrap();
    assert!(j["reaction_mismatch_rel"].as_f64().unwrap() < 1e-6);
    for h in history {
        for c in 0..3 {
            let r = h["reaction_b_n"][c].as_f64().unwrap();
            let f = h["dynamics_f_b_n"][c].as_f64().unwrap();
            assert!((r - f).abs() < 1e-6 * peak, "{h}");
        }
    }
    // the mesh's mass is the STL's within the discretisation (straight-sided faceted bores)
    let (mesh_m, stl_m) = (
        j["mesh_mass_kg"].as_f64().unwrap(),
        j["stl_mass_kg"].as_f64().unwrap(),
    );
    assert!((mesh_m / stl_m - 1.0).abs() < 5e-3, "{mesh_m} vs {stl_m}");
    // the maximum over the cycle is the history's maximum, at its crank angle
    let (k_max, s_max) = history
        .iter()
        .enumerate()
        .map(|(k, h)| (k, h["max_von_mises_away_from_fixed_mpa"].as_f64().unwrap()))
        .fold((0, 0.0), |b, x| if x.1 > b.1 { x } else { b });
    assert_eq!(j["max_von_mises_over_cycle_mpa"].as_f64(), Some(s_max));
    assert_eq!(
        j["crank_angle_of_max_deg"].as_f64(),
        history[k_max]["crank_angle_deg"].as_f64()
    );
    // the fatigue factor sits on the Goodman line of its own alternating and mean stress
    let (sa, sm) = (
        j["fatigue_alternating_mpa"].as_f64().unwrap(),
        j["fatigue_mean_mpa"].as_f64().unwrap(),
    );
    let (se, sut) = (
        j["endurance_mpa"].as_f64().unwrap(),
        j["ultimate_mpa"].as_f64().unwrap(),
    );
    let n = j["fatigue_safety_factor"].as_f64().unwrap();
    let goodman = if sm >= 0.0 {
        1.0 / (sa / se + sm / sut)
    } else {
        se / sa
    };
    assert!((n - goodman).abs() < 1e-9 * goodman, "{n} vs {goodman}");
    // alternating stress at the critical node is at most the cycle's maximum
    assert!(sa <= s_max + 1e-9 && sa > 0.0);
    for key in ["location_of_max_mm", "fatigue_location_mm"] {
        assert_eq!(j[key].as_array().unwrap().len(), 3, "{key}");
    }
    assert!(j["method"].as_str().unwrap().contains("Goodman"));
    // the stage costs at most 1.5× the static two-case stage on the same mesh is a benchmark
    // figure (README); here only that both times were measured
    assert!(j["static_stage_s"].as_f64().unwrap() > 0.0);
    for f in ["cycle.vtu", "von_mises_cycle.svg"] {
        assert!(out.path().join(f).is_file(), "{f}");
    }
}
