//! Integration tests of the dynamics stage (`rodstudy::mechanism`): the
//! multibody core against the closed-form Newton–Euler oracle over full
//! scenes, the thesis' Table 5.1, the study helpers, and the hard cases.

mod common;

use common::{guess, raw_crank_slider};
use nalgebra::{SVector, Vector2};
use rodstudy::mechanism::table_5_1::{DESIGN_2_L1_M, THESIS_OMEGA_RAD_S};
use rodstudy::mechanism::{
    BodyId, CrankMotion, CrankSlider, DrivenScene, DynamicsError, L1Fit, MechanismParams, Method,
    MultibodyBuilder, MultibodySystem, RodInertia, TABLE_5_1, bench_driven, compare_results,
    driven_scene, l1_for_peak_force, peak_pin_force, peak_sensitivity, table_5_1_check,
    tdc_peak_formula,
};

/// The five Table 5.1 rods with the spec's l1 (design 2: 72 mm) and I_zz of
/// our choice (the thesis' values are long-axis moments, see the spec).
fn table_rods() -> Vec<RodInertia> {
    let izz = [0.018, 0.024, 0.021, 0.019, 0.016];
    TABLE_5_1
        .iter()
        .zip(izz)
        .map(|(row, i)| RodInertia::new(row.mass_kg, row.l1_m.unwrap_or(DESIGN_2_L1_M), i))
        .collect()
}

fn assert_methods_agree(
    params: &MechanismParams,
    rod: &RodInertia,
    scene: &DrivenScene,
    tol: f64,
) -> f64 {
    let reference =
        driven_scene(params, rod, scene, Method::ClosedForm).expect("closed form solves");
    let test = driven_scene(params, rod, scene, Method::Multibody).expect("multibody solves");
    let a = compare_results(&test, &reference).expect("same grid");
    assert!(
        a.max_rel_diff <= tol && a.max_rel_diff_f_b <= tol && a.max_rel_diff_torque <= tol,
        "rod {rod:?}, gravity {}: {a:?}",
        params.gravity
    );
    // each refines its peak on its own model: they agree to the same tolerance
    assert!(
        (test.peak_pin_force_n - reference.peak_pin_force_n).abs()
            <= tol * reference.peak_pin_force_n,
        "refined peaks {} vs {} N",
        test.peak_pin_force_n,
        reference.peak_pin_force_n
    );
    assert!(
        (test.grid_peak_pin_force_n - reference.grid_peak_pin_force_n).abs()
            <= tol * reference.grid_peak_pin_force_n
    );
    a.max_rel_diff
}

// ---------------------------------------------------------------------------
// multibody core against the closed form

#[test]
fn multibody_matches_closed_form_over_full_scene_for_table_5_1_rods() {
    let scene = DrivenScene::default();
    let mut worst = 0.0f64;
    for gravity in [true, false] {
        let params = MechanismParams::default().with_gravity(gravity);
        for rod in table_rods() {
            worst = worst.max(assert_methods_agree(&params, &rod, &scene, 1e-9));
        }
    }
    println!("table rods, full 5000-step scenes: max relative difference {worst:.3e}");
}

#[test]
fn multibody_matches_closed_form_with_transverse_offset() {
    let scene = DrivenScene::default();
    for gravity in [true, false] {
        for offset in [0.004, -0.0025] {
            let params = MechanismParams::builder()
                .gravity(gravity)
                .piston_force_n(-250.0)
                .build()
                .expect("params");
            let rod = RodInertia::new(3.0420019180, 0.07176, 0.02).with_offset(offset);
            assert_methods_agree(&params, &rod, &scene, 1e-9);
        }
    }
    // the offset is honoured: it changes the force history
    let p = MechanismParams::default();
    let a = driven_scene(
        &p,
        &RodInertia::new(3.0, 0.07, 0.02),
        &scene,
        Method::ClosedForm,
    )
    .expect("solves");
    let b = driven_scene(
        &p,
        &RodInertia::new(3.0, 0.07, 0.02).with_offset(0.004),
        &scene,
        Method::ClosedForm,
    )
    .expect("solves");
    let d = a
        .fa_y_n
        .iter()
        .zip(&b.fa_y_n)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(d > 1.0, "offset must change F_A (max change {d} N)");
}

#[test]
fn near_toggle_rod_ratio_1_05_is_solved_exactly() {
    let scene = DrivenScene::default();
    for gravity in [true, false] {
        let params = MechanismParams::builder()
            .centre_distance_m(1.05 * 0.046)
            .gravity(gravity)
            .build()
            .expect("l/r = 1.05 is a valid mechanism");
        for rod in [
            RodInertia::new(3.0, 0.02, 0.02),
            RodInertia::new(2.5, 0.03, 0.015).with_offset(0.003),
        ] {
            let d = assert_methods_agree(&params, &rod, &scene, 1e-9);
            println!("l/r = 1.05, gravity {gravity}: max relative difference {d:.3e}");
            let r = driven_scene(&params, &rod, &scene, Method::Multibody).expect("solves");
            assert!(r.fa_abs_n.iter().all(|f| f.is_finite()));
            // near toggle the peak leaves TDC (~270 deg) and falls between samples
            assert!(r.peak_pin_force_n > r.grid_peak_pin_force_n);
        }
    }
}

#[test]
fn general_crank_motion_multibody_matches_closed_form() {
    let params = MechanismParams::builder()
        .piston_force_n(120.0)
        .build()
        .expect("params");
    let rod = RodInertia::new(3.4571018109, 0.07505, 0.021).with_offset(0.002);
    let model = CrankSlider::new(&params, &rod).expect("model");
    for motion in [
        CrankMotion::ConstantAcceleration {
            phi0_rad: 0.3,
            omega0_rad_s: 20.0,
            alpha_rad_s2: 900.0,
        },
        CrankMotion::Harmonic {
            phi0_rad: -0.2,
            omega_rad_s: 125.0,
            amplitude_rad: 0.15,
            frequency_rad_s: 250.0,
        },
    ] {
        let sys = model.multibody(motion).expect("model");
        let mut tracker = sys.tracker(model.assembly_guess(motion.sample(0.0).phi));
        let mut scale = 0.0f64;
        let mut worst = [0.0f64; 5];
        for k in 0..=400 {
            let t = 0.1 * k as f64 / 400.0;
            let sol = tracker.solve_at(t).expect("solves");
            let mb = model.loads_from_multibody(&sys, sol);
            let cf = model.closed_form(motion.sample(t));
            scale = scale.max(cf.f_a.norm());
            worst[0] = worst[0].max((mb.f_a - cf.f_a).norm());
            worst[1] = worst[1].max((mb.f_b - cf.f_b).norm());
            worst[2] = worst[2].max((mb.f_o - cf.f_o).norm());
            worst[3] = worst[3].max((mb.piston_normal_n - cf.piston_normal_n).abs());
            worst[4] = worst[4].max((mb.crank_torque_nm - cf.crank_torque_nm).abs() / 0.046);
            assert!(mb.slide_moment_nm.abs() < 1e-9 * scale.max(1.0));
        }
        for w in worst {
            assert!(w <= 1e-9 * scale, "{motion:?}: {worst:?} vs scale {scale}");
        }
    }
}

#[test]
fn joint_reactions_of_the_core_are_the_pin_loads() {
    let params = MechanismParams::default();
    let rod = RodInertia::new(2.8775347239, 0.07231, 0.019);
    let model = CrankSlider::new(&params, &rod).expect("model");
    let sys: MultibodySystem<9> = model
        .multibody(CrankMotion::constant_speed(THESIS_OMEGA_RAD_S))
        .expect("model");
    let sol = sys
        .analyze(0.0123, &model.assembly_guess(1.5))
        .expect("assembles from a rough guess");
    let reactions = sys.reactions(&sol);
    assert_eq!(reactions.len(), 5);
    let cf = model.closed_form(CrankMotion::constant_speed(THESIS_OMEGA_RAD_S).sample(0.0123));
    let a = &reactions[1];
    assert!(a.joint.starts_with("A"));
    // on the rod (body j) the force of the crank; on the crank the opposite force
    assert!((a.on_j.fx_n - cf.f_a.x).abs() < 1e-8 && (a.on_j.fy_n - cf.f_a.y).abs() < 1e-8);
    assert!((a.on_i.fx_n + a.on_j.fx_n).abs() < 1e-9 && (a.on_i.fy_n + a.on_j.fy_n).abs() < 1e-9);
    let drive = &reactions[4];
    assert!(
        (drive.on_j.torque_nm - cf.crank_torque_nm).abs()
            < 1e-8 * cf.crank_torque_nm.abs().max(1.0)
    );
}

// ---------------------------------------------------------------------------
// Table 5.1, the TDC formula, l1 fit and sensitivities

#[test]
fn table_5_1_rows_1_3_4_5_within_0_1_percent() {
    let rows = table_5_1_check(&MechanismParams::default(), 0.02).expect("table");
    for row in &rows {
        println!(
            "design {}: computed {:.2} N vs thesis {:.0} N, rel. error {:?}; {}",
            row.design,
            row.computed_peak_n,
            row.thesis_peak_n,
            row.rel_error,
            row.l1_fit.explanation()
        );
        match row.design {
            2 => assert!(row.rel_error.is_none()),
            _ => {
                // measured within 4e-6 (the thesis prints the peaks to 1 N)
                let e = row.rel_error.expect("reachable row");
                assert!(e.abs() < 4e-5, "design {}: {e}", row.design);
            }
        }
    }
}

#[test]
fn table_5_1_row_2_is_unreachable_with_lower_bound() {
    let params = MechanismParams::default();
    let rod = RodInertia::new(TABLE_5_1[1].mass_kg, DESIGN_2_L1_M, 0.02);
    match l1_for_peak_force(&params, &rod, 5244.0, THESIS_OMEGA_RAD_S).expect("fit") {
        L1Fit::BelowMinimum { min_peak_n, .. } => {
            assert!((min_peak_n - 7481.0).abs() < 1.0, "{min_peak_n}");
        }
        other => panic!("row 2 must be unreachable, got {other:?}"),
    }
    let e = l1_for_peak_force(&params, &rod, 5244.0, THESIS_OMEGA_RAD_S)
        .expect("fit")
        .explanation();
    assert!(e.contains("7481"), "{e}");
    // above the l1 = l bound
    let hi = l1_for_peak_force(&params, &rod, 20_000.0, THESIS_OMEGA_RAD_S).expect("fit");
    assert!(matches!(hi, L1Fit::AboveMaximum { .. }));
}

#[test]
fn l1_fit_reproduces_the_spec_l1_column() {
    for gravity in [false, true] {
        let params = MechanismParams::default().with_gravity(gravity);
        for row in TABLE_5_1.iter().filter(|r| r.l1_m.is_some()) {
            let spec_l1 = row.l1_m.unwrap_or_default();
            let rod = RodInertia::new(row.mass_kg, 0.0, 0.02);
            let fit = l1_for_peak_force(&params, &rod, row.peak_force_n, THESIS_OMEGA_RAD_S)
                .expect("fit");
            let l1 = fit.l1_m().expect("reachable");
            // the spec's column is rounded to 0.01 mm (and matches the gravity-free formula);
            // gravity moves the fit by ~0.007 mm
            let tol = if gravity { 0.013e-3 } else { 0.0051e-3 };
            assert!(
                (l1 - spec_l1).abs() < tol,
                "design {} gravity {gravity}: {l1} vs {spec_l1}",
                row.design
            );
            let check = peak_pin_force(
                &params,
                &RodInertia::new(row.mass_kg, l1, 0.02),
                THESIS_OMEGA_RAD_S,
            )
            .expect("peak")
            .force_n;
            assert!((check - row.peak_force_n).abs() < 1e-6, "{check}");
        }
    }
}

#[test]
fn tdc_formula_and_the_gravity_effect() {
    for rod in table_rods() {
        let on = MechanismParams::default();
        let off = on.with_gravity(false);
        let formula = tdc_peak_formula(&off, &rod, THESIS_OMEGA_RAD_S);
        let p_off = peak_pin_force(&off, &rod, THESIS_OMEGA_RAD_S).expect("peak");
        let p_on = peak_pin_force(&on, &rod, THESIS_OMEGA_RAD_S).expect("peak");
        assert!(
            (p_off.force_n - formula).abs() < 1e-9 * formula,
            "{} vs {formula}",
            p_off.force_n
        );
        // (golden section locates the flat top to ~sqrt(eps) in angle)
        assert!(
            p_off.crank_angle_deg.min(360.0 - p_off.crank_angle_deg) < 1e-5,
            "{}",
            p_off.crank_angle_deg
        );
        let dg = p_on.force_n - p_off.force_n;
        assert!(dg > 0.01 && dg < 0.04, "gravity changes the peak by {dg} N");
        // the peak stays within a hundredth of a degree of TDC
        let a = p_on.crank_angle_deg.min(360.0 - p_on.crank_angle_deg);
        assert!(a < 0.01, "{}", p_on.crank_angle_deg);
    }
}

#[test]
fn peak_sensitivity_izz_vanishes_and_mass_l1_match_the_formula() {
    for rod in table_rods() {
        let off = peak_sensitivity(
            &MechanismParams::default().with_gravity(false),
            &rod,
            THESIS_OMEGA_RAD_S,
        )
        .expect("sensitivity");
        assert!(off.d_izz_n_per_kgm2.abs() < 1e-4, "{off:?}");
        assert!(
            (off.d_mass_n_per_kg / off.formula_d_mass_n_per_kg - 1.0).abs() < 1e-7,
            "{off:?}"
        );
        assert!(
            (off.d_l1_n_per_m / off.formula_d_l1_n_per_m - 1.0).abs() < 1e-7,
            "{off:?}"
        );
        let on = peak_sensitivity(&MechanismParams::default(), &rod, THESIS_OMEGA_RAD_S)
            .expect("sensitivity");
        // gravity: a 0.02 kg m^2 change of I_zz moves the peak by less than 1e-3 N
        assert!(on.d_izz_n_per_kgm2.abs() * 0.02 < 1e-3, "{on:?}");
        assert!(
            (on.d_mass_n_per_kg / on.formula_d_mass_n_per_kg - 1.0).abs() < 2e-4,
            "{on:?}"
        );
        assert!(
            (on.d_l1_n_per_m / on.formula_d_l1_n_per_m - 1.0).abs() < 2e-4,
            "{on:?}"
        );
    }
}

// ---------------------------------------------------------------------------
// the driven scene: grid, peak refinement, output

#[test]
fn driven_scene_grid_peak_and_output() {
    let params = MechanismParams::default();
    let rod = RodInertia::new(3.0420019180, 0.07176, 0.02);
    let r =
        driven_scene(&params, &rod, &DrivenScene::default(), Method::default()).expect("solves");
    assert_eq!(r.method, Method::ClosedForm);
    assert_eq!(r.samples, 5001);
    assert_eq!(r.t_s.len(), 5001);
    assert_eq!((r.t_s[0], r.t_s[5000]), (0.0, 5.0));
    assert!((r.dt_s - 1e-3).abs() < 1e-18);
    // sign convention: at TDC the crank pulls the rod back towards O
    assert!(r.fa_x_n[0] < 0.0 && r.fb_x_n[0] < 0.0);
    // the grid contains TDC: the grid peak is there and within 1e-7 of the true peak
    assert_eq!(r.grid_peak_time_s, 0.0);
    assert_eq!(r.grid_peak_crank_angle_deg, 0.0);
    assert!(r.peak_pin_force_n >= r.grid_peak_pin_force_n);
    assert!((r.peak_pin_force_n - r.grid_peak_pin_force_n) / r.peak_pin_force_n < 1e-7);
    assert!(r.peak_time_s >= 0.0 && r.peak_time_s < 0.05);
    assert!(r.peak_crank_angle_deg >= 0.0 && r.peak_crank_angle_deg < 360.0);
    let json = serde_json::to_value(&r).expect("serializes");
    for key in [
        "t_s",
        "phi_rad",
        "fa_x_n",
        "fa_abs_n",
        "fb_abs_n",
        "crank_torque_nm",
        "peak_pin_force_n",
        "grid_peak_pin_force_n",
    ] {
        assert!(json.get(key).is_some(), "missing {key}");
    }
    assert_eq!(json["method"], "closed_form");
}

#[test]
fn peak_refinement_finds_the_true_maximum_between_samples() {
    // phi0 = 0.05 rad: no sample at TDC any more
    let params = MechanismParams::default().with_gravity(false);
    let rod = RodInertia::new(2.4794531840, 0.06561, 0.016);
    let scene = DrivenScene {
        phi0_rad: 0.05,
        ..DrivenScene::default()
    };
    for method in [Method::ClosedForm, Method::Multibody] {
        let r = driven_scene(&params, &rod, &scene, method).expect("solves");
        let formula = tdc_peak_formula(&params, &rod, scene.omega_rad_s);
        assert!(
            r.peak_pin_force_n > r.grid_peak_pin_force_n + 1.0,
            "{} vs {}",
            r.peak_pin_force_n,
            r.grid_peak_pin_force_n
        );
        assert!((r.peak_pin_force_n - formula).abs() < 1e-9 * formula);
        let a = r.peak_crank_angle_deg.min(360.0 - r.peak_crank_angle_deg);
        assert!(a < 1e-5, "{}", r.peak_crank_angle_deg);
        // first TDC after phi0 = 0.05 rad
        let t_tdc = (std::f64::consts::TAU - 0.05) / scene.omega_rad_s;
        assert!(
            (r.peak_time_s - t_tdc).abs() < 1e-9,
            "{} vs {t_tdc}",
            r.peak_time_s
        );
    }
    // a scene shorter than one revolution: the maximum over the covered arc
    let short = DrivenScene {
        duration_s: 0.02,
        steps: 20,
        phi0_rad: 0.5,
        ..DrivenScene::default()
    };
    let r = driven_scene(&params, &rod, &short, Method::ClosedForm).expect("solves");
    assert!(r.peak_pin_force_n >= r.grid_peak_pin_force_n && r.peak_time_s <= 0.02);
}

#[test]
fn hundredfold_speed_scales_the_force_by_1e4() {
    let params = MechanismParams::default().with_gravity(false);
    let rod = RodInertia::new(3.0420019180, 0.07176, 0.02).with_offset(0.002);
    let slow = DrivenScene {
        duration_s: 0.1,
        steps: 400,
        ..DrivenScene::default()
    };
    let fast = DrivenScene {
        omega_rad_s: 100.0 * slow.omega_rad_s,
        duration_s: slow.duration_s / 100.0,
        ..slow
    };
    for method in [Method::ClosedForm, Method::Multibody] {
        let a = driven_scene(&params, &rod, &slow, method).expect("solves");
        let b = driven_scene(&params, &rod, &fast, method).expect("solves");
        for k in 0..a.samples {
            let d = (b.fa_x_n[k] - 1e4 * a.fa_x_n[k]).hypot(b.fa_y_n[k] - 1e4 * a.fa_y_n[k]);
            assert!(
                d <= 1e-9 * 1e4 * a.fa_abs_n[k],
                "{method:?} sample {k}: {d}"
            );
        }
        assert!((b.peak_pin_force_n / a.peak_pin_force_n - 1e4).abs() < 1e-9 * 1e4);
    }
}

// ---------------------------------------------------------------------------
// hard cases: refused or reported, never a NaN

#[test]
fn l_not_greater_than_r_is_refused_at_model_build() {
    for l in [0.046, 0.03] {
        let e = MechanismParams::builder()
            .centre_distance_m(l)
            .build()
            .unwrap_err();
        assert!(matches!(e, DynamicsError::CrankCannotTurn { .. }), "{e:?}");
        assert!(e.to_string().contains("cannot turn"), "{e}");
        let p = MechanismParams {
            centre_distance_m: l,
            ..MechanismParams::default()
        };
        let rod = RodInertia::new(3.0, 0.07, 0.02);
        assert!(matches!(
            CrankSlider::new(&p, &rod),
            Err(DynamicsError::CrankCannotTurn { .. })
        ));
        for method in [Method::ClosedForm, Method::Multibody] {
            assert!(matches!(
                driven_scene(&p, &rod, &DrivenScene::default(), method),
                Err(DynamicsError::CrankCannotTurn { .. })
            ));
        }
    }
}

#[test]
fn invalid_inputs_are_refused_with_typed_errors() {
    let p = MechanismParams::default();
    let good = RodInertia::new(3.0, 0.07, 0.02);
    let bad_rods = [
        RodInertia::new(0.0, 0.07, 0.02),
        RodInertia::new(-3.0, 0.07, 0.02),
        RodInertia::new(3.0, f64::NAN, 0.02),
        RodInertia::new(3.0, 0.07, 0.0),
        RodInertia::new(3.0, 0.07, 0.02).with_offset(f64::INFINITY),
    ];
    for rod in bad_rods {
        let e = CrankSlider::new(&p, &rod).unwrap_err();
        assert!(matches!(e, DynamicsError::InvalidParameter { .. }), "{e:?}");
        assert!(e.to_string().contains("rod."), "{e}");
    }
    assert!(
        MechanismParams::builder()
            .crank_mass_kg(-1.0)
            .build()
            .is_err()
    );
    assert!(
        MechanismParams::builder()
            .piston_mass_kg(0.0)
            .build()
            .is_err()
    );
    assert!(
        MechanismParams::builder()
            .crank_radius_m(f64::NAN)
            .build()
            .is_err()
    );
    assert!(
        MechanismParams::builder()
            .crank_inertia_o_kgm2(0.0)
            .build()
            .is_err()
    );
    let scenes = [
        DrivenScene {
            steps: 0,
            ..DrivenScene::default()
        },
        DrivenScene {
            duration_s: -1.0,
            ..DrivenScene::default()
        },
        DrivenScene {
            omega_rad_s: f64::NAN,
            ..DrivenScene::default()
        },
        DrivenScene {
            omega_rad_s: 0.0,
            ..DrivenScene::default()
        },
    ];
    for s in scenes {
        assert!(matches!(
            driven_scene(&p, &good, &s, Method::ClosedForm),
            Err(DynamicsError::InvalidScene(_))
        ));
    }
    // a prescribed motion that turns non-finite is an error, not a NaN
    let model = CrankSlider::new(&p, &good).expect("model");
    let sys = model
        .multibody(CrankMotion::Custom(|t| rodstudy::mechanism::MotionSample {
            phi: if t > 0.01 { f64::NAN } else { t },
            omega: 1.0,
            alpha: 0.0,
        }))
        .expect("model");
    let mut tracker = sys.tracker(model.assembly_guess(0.0));
    assert!(tracker.solve_at(0.0).is_ok());
    let e = tracker.solve_at(0.02).unwrap_err();
    assert!(matches!(e, DynamicsError::NonFinite { .. }), "{e:?}");
}

#[test]
fn redundant_constraint_set_is_refused_naming_joint_and_time() {
    // two identical pins at O (and no slide): nine equations, rank eight
    let sys = raw_crank_slider(0.05, 0.16, CrankMotion::constant_speed(1.0), true, 0.0);
    let e = sys.analyze(0.3, &guess(0.05, 0.16)).unwrap_err();
    match &e {
        DynamicsError::SingularJacobian { t_s, joint, .. } => {
            assert_eq!(*t_s, 0.3);
            assert_eq!(joint, "O duplicate");
        }
        other => panic!("expected a singular Jacobian, got {other:?}"),
    }
    let msg = e.to_string();
    assert!(
        msg.contains("t = 0.3 s") && msg.contains("'O duplicate'"),
        "{msg}"
    );
}

#[test]
fn surplus_equations_are_refused_naming_joint() {
    let mut b = MultibodyBuilder::new();
    let crank = b.add_body("crank", 8.0, 0.015);
    b.add_revolute(
        "O",
        BodyId::Ground,
        Vector2::zeros(),
        crank,
        Vector2::zeros(),
    )
    .add_driving(
        "drive",
        BodyId::Ground,
        crank,
        CrankMotion::constant_speed(1.0),
    )
    .add_revolute(
        "O again",
        BodyId::Ground,
        Vector2::zeros(),
        crank,
        Vector2::zeros(),
    );
    let e = b.build::<3>().unwrap_err();
    assert!(
        matches!(
            e,
            DynamicsError::ConstraintCount {
                equations: 5,
                coordinates: 3,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("'O again'"), "{e}");
}

#[test]
fn inconsistent_constraints_are_refused_naming_joint_and_time() {
    // the slide line y = 0.5 m is out of reach of a 0.05 + 0.16 m linkage
    let sys = raw_crank_slider(0.05, 0.16, CrankMotion::constant_speed(1.0), false, 0.5);
    let e = sys.analyze(0.0, &guess(0.05, 0.16)).unwrap_err();
    assert!(
        matches!(e, DynamicsError::NoConvergence { t_s, .. } if t_s == 0.0),
        "{e:?}"
    );
    let msg = e.to_string();
    assert!(msg.contains("t = 0 s") && msg.contains("joint '"), "{msg}");
}

#[test]
fn toggle_position_is_an_error_naming_the_time_not_a_nan() {
    let (r, l) = (0.05, 0.05);
    // (a) l = r assembled exactly at the toggle phi = 90 deg (rod vertical, B on O)
    let h = std::f64::consts::FRAC_PI_2;
    let sys = raw_crank_slider(
        r,
        l,
        CrankMotion::ConstantSpeed {
            phi0_rad: h,
            omega_rad_s: 1.0,
        },
        false,
        0.0,
    );
    let at_toggle = SVector::<f64, 9>::from_column_slice(&[
        0.0,
        r / 2.0,
        h,
        0.0,
        r - l / 2.0,
        -h,
        0.0,
        0.0,
        0.0,
    ]);
    let e = sys.analyze(0.0, &at_toggle).unwrap_err();
    assert!(
        matches!(e, DynamicsError::SingularJacobian { t_s, .. } if t_s == 0.0),
        "{e:?}"
    );
    // (b) l = r driven through the toggle: the sample at t = 0.25 s is phi = 90 deg
    let sys = raw_crank_slider(
        r,
        l,
        CrankMotion::constant_speed(std::f64::consts::TAU),
        false,
        0.0,
    );
    let mut tracker = sys.tracker(guess(r, l));
    let mut failure = None;
    for k in 0..=100 {
        let t = 0.01 * k as f64;
        match tracker.solve_at(t) {
            Ok(s) => assert!(s.lambda.iter().all(|v| v.is_finite())),
            Err(e) => {
                failure = Some(e);
                break;
            }
        }
    }
    let e = failure.expect("the toggle must be reported");
    assert!(
        matches!(e, DynamicsError::SingularJacobian { t_s, .. } if t_s == 0.25),
        "{e:?}"
    );
    assert!(e.to_string().contains("t = 0.25 s"), "{e}");
}

#[test]
fn locking_during_the_motion_is_reported_at_the_locking_time() {
    // l < r: the crank locks at sin(phi) = l/r; driven at 1 rad/s it gets there at t = asin(0.8) s
    let (r, l) = (0.05, 0.04);
    let sys = raw_crank_slider(r, l, CrankMotion::constant_speed(1.0), false, 0.0);
    let mut tracker = sys.tracker(guess(r, l));
    let t_lock = (l / r).asin();
    let mut failure = None;
    for k in 0..200 {
        let t = 0.01 * k as f64;
        match tracker.solve_at(t) {
            Ok(s) => assert!(s.lambda.iter().all(|v| v.is_finite())),
            Err(e) => {
                failure = Some(e);
                break;
            }
        }
    }
    let e = failure.expect("the locking position must be reported");
    let t = match e {
        DynamicsError::NoConvergence { t_s, .. } | DynamicsError::SingularJacobian { t_s, .. } => {
            t_s
        }
        ref other => panic!("unexpected error {other:?}"),
    };
    assert!(
        (t - t_lock).abs() < 1e-3,
        "reported at {t} s, locks at {t_lock} s: {e}"
    );
}

// ---------------------------------------------------------------------------
// bench

#[test]
fn bench_reports_times_and_agreement() {
    let scene = DrivenScene {
        duration_s: 0.5,
        steps: 500,
        ..DrivenScene::default()
    };
    let b = bench_driven(
        &MechanismParams::default(),
        &RodInertia::new(3.0, 0.07, 0.02),
        &scene,
        3,
    )
    .expect("bench");
    assert_eq!(b.samples, 501);
    assert!(b.closed_form_scene_s > 0.0 && b.multibody_scene_s > 0.0);
    assert!(b.max_rel_diff < 1e-9);
    assert!(serde_json::to_string(&b).is_ok());
    assert!(
        bench_driven(
            &MechanismParams::default(),
            &RodInertia::new(3.0, 0.07, 0.02),
            &scene,
            0
        )
        .is_err()
    );
}
