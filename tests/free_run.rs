//! Scene `free` (thesis ch. 4): exact reference, integrators, work–precision sweep and the
//! hard cases of the spec (near toggle, l ≤ r, I_red ≤ 0, 100 s run, stiff gas spring).

use rodstudy::free_run::{
    CrankSliderData, FreeRunError, FreeRunOptions, FreeScene, GasSpring, Method, ModelError,
    ReducedModel, ReferenceError, SweepConfig, exact_reference_with_tol, run_all, run_free,
    work_precision_sweep,
};
use rodstudy::integrators::FailureKind;

fn opts(scene: FreeScene, atol: f64) -> FreeRunOptions {
    FreeRunOptions {
        scene,
        atol,
        ..FreeRunOptions::default()
    }
}

#[test]
fn reference_agrees_with_tight_rk45() {
    let scene = FreeScene::thesis();
    let reference = scene.reference().unwrap();
    assert_eq!(reference.t.len(), 10_001);
    let run = run_free(Method::Rk45, &opts(scene, 1e-12)).unwrap();
    let (ep, ew) = reference.max_errors(&run.phi, &run.omega);
    assert!(ep < 5e-12, "max |Δφ| = {ep:e}");
    assert!(ew < 5e-10, "max |Δω| = {ew:e}");
    // φ(1 s) of the thesis scene
    assert!(
        (reference.phi[10_000] - 21.267_647_407_399).abs() < 1e-11,
        "{}",
        reference.phi[10_000]
    );
}

#[test]
fn reference_is_self_consistent() {
    let scene = FreeScene::thesis();
    let model = scene.model().unwrap();
    let grid = scene.grid().unwrap();
    let r = scene.reference().unwrap();
    // (the energy E(φ_k, φ̇_k) is not checked here: φ̇ is built from the energy integral, so it
    // would hold by construction)
    // 1. quadrature converged: a 100× tighter panel threshold changes nothing
    let tight = exact_reference_with_tol(&model, &scene.loads, 0.0, 0.0, &grid, 1e-13).unwrap();
    let (dp, dw) = r.max_errors(&tight.phi, &tight.omega);
    assert!(dp < 5e-14 && dw < 1e-12, "{dp:e} {dw:e}");
    // 2. φ̇ from the energy integral = dφ/dt of the inverted t(φ) (6th-order differences)
    let h = scene.dt_out;
    let c = [1.0 / 60.0, -3.0 / 20.0, 3.0 / 4.0];
    let mut worst: f64 = 0.0;
    for k in 3..r.phi.len() - 3 {
        let d = (c[0] * (r.phi[k + 3] - r.phi[k - 3])
            + c[1] * (r.phi[k + 2] - r.phi[k - 2])
            + c[2] * (r.phi[k + 1] - r.phi[k - 1]))
            / h;
        worst = worst.max((d - r.omega[k]).abs());
    }
    assert!(worst < 1e-9, "dφ/dt vs φ̇: {worst:e}");
    // 4. singular start: φ = ½ α0 t² (1 + F p42'(0) t² / (12 I_red(0)) + O(t⁴)), α0 = M / I_red(0);
    //    the O(t⁴) coefficient is ≈ 170 here
    let i0 = model.i_red(0.0);
    let alpha0 = scene.loads.torque / i0;
    let c1 = model.kinematics().at(0.0).dp42;
    for k in 1..=10 {
        let t = r.t[k];
        let ratio = r.phi[k] / (0.5 * alpha0 * t * t) - 1.0;
        let series = scene.loads.piston_force * c1 * t * t / (12.0 * i0);
        assert!(
            (ratio - series).abs() < 300.0 * t.powi(4) + 1e-12,
            "t = {t}: {ratio:e} vs {series:e}"
        );
    }
}

/// The long-horizon table's projected rows (`integrators --t-end 100`): RK45 with the energy
/// projection is run after the plain methods, labelled, kept out of the plain method's rows, and
/// far closer to the exact reference than plain RK45 at the same tolerance (at 100 s 1,800×,
/// docs/free-run.md; over 10 s measured here).
#[test]
fn the_sweep_runs_rk45_with_the_energy_projection_as_its_own_rows() {
    let scene = FreeScene::long_run(10.0, 1e-3);
    let cfg = SweepConfig {
        repeats: 1,
        methods: vec![Method::Rk45],
        tolerances: vec![1e-7, 1e-8, 1e-9],
        projected_methods: vec![Method::Rk45],
        ..SweepConfig::default()
    };
    let wp = work_precision_sweep(&scene, &cfg).unwrap();
    assert_eq!(wp.rows.len(), 6);
    let plain = wp.rows_of(Method::Rk45);
    let projected = wp.rows_of_variant(Method::Rk45, true);
    assert_eq!((plain.len(), projected.len()), (3, 3));
    assert!(plain.iter().all(|r| !r.project_energy));
    assert!(wp.is_monotone_variant(Method::Rk45, true));
    for (p, q) in plain.iter().zip(&projected) {
        assert_eq!(p.value, q.value);
        let (ep, eq) = (p.max_err_phi_rad.unwrap(), q.max_err_phi_rad.unwrap());
        assert!(
            eq * 10.0 < ep,
            "atol {:e}: projected {eq:e}, plain {ep:e}",
            p.value
        );
        // one evaluation more per step (the projected state's first stage)
        assert!(q.rhs_evals > p.rhs_evals);
    }
    let md = wp.to_markdown();
    assert_eq!(
        md.matches("| rk45 + energy projection |").count(),
        3,
        "{md}"
    );
}

#[test]
fn work_precision_sweep_meets_targets() {
    let scene = FreeScene::thesis();
    let cfg = SweepConfig {
        repeats: 1,
        methods: Method::REDUCED.to_vec(),
        ..SweepConfig::default()
    };
    let wp = work_precision_sweep(&scene, &cfg).unwrap();
    assert_eq!(wp.rows.len(), 4 + 5 * 9);
    for m in Method::REDUCED {
        let rows = wp.rows_of(m);
        assert!(
            rows.iter().all(|r| r.failure.is_none()),
            "{m} failed: {rows:?}"
        );
        assert!(wp.is_monotone(m), "{m}: error not monotone in tolerance");
        let last = rows.last().unwrap();
        assert!(
            last.rhs_evals > rows[0].rhs_evals,
            "{m}: work must grow as tolerance shrinks"
        );
        if m.is_implicit() {
            assert!(last.jac_evals >= 1);
        } else {
            assert_eq!(last.jac_evals, 0);
        }
    }
    assert!(
        wp.best_phi_error() <= 1e-10,
        "best max |Δφ| = {:e}",
        wp.best_phi_error()
    );
    // the fixed-step method converges at first order (error ∝ Δt)
    let ia = wp.rows_of(Method::InitialAcceleration);
    for w in ia.windows(2) {
        let ratio = w[0].max_err_phi_rad.unwrap() / w[1].max_err_phi_rad.unwrap();
        assert!(
            (8.0..12.0).contains(&ratio),
            "initial-acceleration error ratio per decade {ratio}"
        );
    }
    // rk45's error tracks its absolute tolerance (local extrapolation): measured 0.37–12.3× tol
    // over atol 1e-4 … 1e-12 (reports/work_precision.md)
    for r in wp.rows_of(Method::Rk45) {
        let q = r.max_err_phi_rad.unwrap() / r.value;
        assert!(
            (0.3..15.0).contains(&q),
            "rk45 at {:e}: error/tol = {q}",
            r.value
        );
    }
    let json = serde_json::to_string(&wp).unwrap();
    assert!(json.contains("\"method\":\"trbdf2\"") && json.contains("max_err_phi_rad"));
    assert!(wp.to_markdown().lines().count() == 2 + wp.rows.len());
}

#[test]
fn run_free_result_and_names() {
    let r = run_free(Method::Bdf, &FreeRunOptions::default()).unwrap();
    assert_eq!(r.method, Method::Bdf);
    assert_eq!(r.t.len(), 10_001);
    assert_eq!(r.phi.len(), 10_001);
    assert_eq!(r.omega.len(), 10_001);
    assert_eq!(r.t[0], 0.0);
    assert_eq!(*r.t.last().unwrap(), 1.0);
    assert!((r.t[5000] - 0.5).abs() < 1e-15);
    // φ(1 s), φ̇(1 s) against the energy-integral reference (independent of any integrator), to
    // BDF's default tolerance (atol 1e-8 on φ)
    let reference = FreeScene::thesis().reference().unwrap();
    let (phi_ref, omega_ref) = (
        *reference.phi.last().unwrap(),
        *reference.omega.last().unwrap(),
    );
    assert!(
        (r.phi_rad - phi_ref).abs() < 1e-6 && (r.omega_rad_s - omega_ref).abs() < 1e-4,
        "{} vs {phi_ref}, {} vs {omega_ref}",
        r.phi_rad,
        r.omega_rad_s
    );
    assert!(r.steps > 0 && r.rhs_evals > r.steps && r.jac_evals >= 1 && r.cpu_s > 0.0);
    assert!(r.warnings.is_empty() && r.energy_drift_rel.unwrap() < 1e-6);
    let json = serde_json::to_value(&r).unwrap();
    assert_eq!(json["method"], "bdf");
    for name in [
        "initial-acceleration",
        "rk45",
        "rk23",
        "bdf",
        "rosenbrock",
        "trbdf2",
    ] {
        assert_eq!(name.parse::<Method>().unwrap().to_string(), name);
    }
    assert_eq!("dae-index1".parse::<Method>().unwrap(), Method::DaeIndex1);
    assert_eq!(
        "dae-genalpha".parse::<Method>().unwrap(),
        Method::DaeGenAlpha
    );
}

#[test]
fn caps_are_typed_errors() {
    let o = FreeRunOptions {
        max_rhs_evals: 500,
        ..FreeRunOptions::default()
    };
    match run_free(Method::Rk45, &o) {
        Err(FreeRunError::Solver(e)) => {
            assert_eq!(e.kind, FailureKind::EvalLimit { max_rhs_evals: 500 });
            assert!(e.is_limit() && e.t > 0.0 && e.t < 1.0);
            assert!(
                e.to_string()
                    .contains("limit of 500 right-hand-side evaluations"),
                "{e}"
            );
        }
        other => panic!("expected an evaluation-limit error, got {other:?}"),
    }
    let o = FreeRunOptions {
        max_steps: 10,
        ..FreeRunOptions::default()
    };
    for m in Method::ALL {
        let e = run_free(m, &o).unwrap_err();
        assert!(
            matches!(e, FreeRunError::Solver(ref s) if s.kind == FailureKind::StepLimit { max_steps: 10 }),
            "{m}: {e}"
        );
    }
}

#[test]
fn near_toggle_keeps_error_estimates_honest() {
    // l/r = 1.02: p32' and p42' become steep around φ = 90°
    let toggle = FreeScene::near_toggle(1.02);
    let nominal = FreeScene::thesis();
    let ref_t = toggle.reference().unwrap();
    let ref_n = nominal.reference().unwrap();
    for m in Method::ALL.into_iter().filter(|m| !m.is_fixed_step()) {
        for tol in [1e-6, 1e-8] {
            let rt = run_free(m, &opts(toggle, tol)).unwrap();
            let rn = run_free(m, &opts(nominal, tol)).unwrap();
            let (et, _) = ref_t.max_errors(&rt.phi, &rt.omega);
            let (en, _) = ref_n.max_errors(&rn.phi, &rn.omega);
            match m {
                // local extrapolation / BDF: error a small multiple of the tolerance
                Method::Rk45 | Method::Rk23 | Method::Bdf => {
                    assert!(et < 30.0 * tol, "{m} at {tol:e}: {et:e}")
                }
                // second order, error per step: global error ~ tol^(2/3) as on the nominal
                // geometry; near toggle it must not be worse than there by more than 5×
                _ => assert!(et < 5.0 * en, "{m} at {tol:e}: {et:e} vs nominal {en:e}"),
            }
            assert!(rt.warnings.is_empty(), "{m}: {:?}", rt.warnings);
        }
    }
    // the fixed-step method completes but its energy check flags it
    let o = FreeRunOptions {
        fixed_step: 1e-3,
        ..opts(toggle, 1e-6)
    };
    let r = run_free(Method::InitialAcceleration, &o).unwrap();
    assert!(r.energy_drift_rel.unwrap() > 1e-2);
    assert!(
        r.warnings
            .iter()
            .any(|w| w.contains("fixed step too large")),
        "{:?}",
        r.warnings
    );
}

#[test]
fn rod_not_longer_than_crank_is_refused() {
    for ratio in [1.0, 0.8] {
        let scene = FreeScene::near_toggle(ratio);
        let e = run_free(
            Method::Rk45,
            &FreeRunOptions {
                scene,
                ..FreeRunOptions::default()
            },
        )
        .unwrap_err();
        assert!(
            matches!(e, FreeRunError::Model(ModelError::RodTooShort { .. })),
            "{e}"
        );
        assert!(e.to_string().contains("crank cannot turn"));
    }
    assert!(ReducedModel::new(CrankSliderData::thesis_ch3().with_rod_ratio(1.02)).is_ok());
}

#[test]
fn non_positive_reduced_inertia_is_refused_naming_phi() {
    let thesis = ReducedModel::new(CrankSliderData::thesis_ch3()).unwrap();
    assert!((thesis.rod.i_kor + 0.031881341820528).abs() < 1e-14);
    assert!(ReducedModel::new(CrankSliderData::thesis_ch3().with_i_kor(-0.32)).is_ok());
    for i_kor in [-0.33, -0.4] {
        let data = CrankSliderData::thesis_ch3().with_i_kor(i_kor);
        match ReducedModel::new(data) {
            Err(ModelError::NonPositiveInertia { phi_rad, i_red, .. }) => {
                assert!(i_red <= 0.0);
                assert!(
                    phi_rad.sin().abs() < 1e-6,
                    "minimum at a dead centre, got φ = {phi_rad}"
                );
            }
            other => panic!("expected refusal, got {other:?}"),
        }
        let scene = FreeScene {
            data,
            ..FreeScene::thesis()
        };
        let e = run_free(
            Method::Rk45,
            &FreeRunOptions {
                scene,
                ..FreeRunOptions::default()
            },
        )
        .unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("≤ 0 at φ = 0.000°") && msg.contains("refusing to integrate"),
            "{msg}"
        );
    }
}

/// Over 100 s (φ → 1.8e5 rad, 29 000 turns) the error against the energy-integral
/// reference falls with the tolerance instead of being set by round-off. RK45 at atol 1e-10
/// (rtol 0) measured max |Δφ| = 1.087e-5 rad on this 0.01 s grid (1.0895e-5 on the CLI's
/// 1e-4 s grid; 8.917e-6 rad at 100 s, a step point), max |Δφ̇| = 1.452e-2 rad/s,
/// 16,946,799 steps, 321,579 rejected (with plain sums of the increments: 6.1e-4 rad, 0.38 M
/// rejected); at 1e-9 9.0e-5, at 1e-11 1.4e-6, at 1e-12 2.4e-7 rad (`docs/free-run.md`). The
/// error is 1.1e5 × the tolerance (the tolerance is per step), so the run warns.
///
/// What the error is: the method's energy drift. A state off the exact trajectory by an
/// energy error δE reaches each angle with φ̇ off by δE/(I_red φ̇), i.e. late, so
/// `δφ(T) = φ̇(T) ∫ δE(t) / (I_red φ̇²) dt`; that integral over the run's energy error on the
/// grid gives the measured δφ(100 s) to 0.1 % (8.910e-6 vs 8.917e-6 rad): the error is the
/// accumulated truncation error in the energy, not a timing (along-the-orbit) error, the
/// dense output or round-off (a random ±1 ulp on every stage state moved it by 0.5 %).
#[test]
fn long_run_100s_error_falls_with_the_tolerance() {
    let scene = FreeScene::long_run(100.0, 0.01);
    let reference = scene.reference().unwrap();
    let o = FreeRunOptions {
        rtol: 0.0,
        ..opts(scene, 1e-10)
    }
    .with_caps_for_duration();
    let mut r = run_free(Method::Rk45, &o).unwrap();
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    let (ep, ew) = r.check_against_reference(&reference, &o);
    let end = r.phi_rad - reference.phi.last().unwrap();
    assert!(
        ep < 1.2e-5 && end > 8.0e-6 && end < 1.0e-5,
        "max |Δφ| {ep:e}, at 100 s {end:e}"
    );
    assert!(ew < 1.6e-2, "max |Δω| {ew:e}");
    // round-off no longer fights the step control: few rejections (plain sums: 0.38 M)
    assert!(r.rejected_steps < 400_000, "{} rejected", r.rejected_steps);
    assert!(
        r.warnings.len() == 1 && r.warnings[0].contains("× the tolerance"),
        "{:?}",
        r.warnings
    );
    // the error is the energy drift: φ̇(T) ∫ δE / (I_red φ̇²) dt reproduces δφ(T)
    let model = scene.model().unwrap();
    let energy = |p: f64, w: f64| model.energy(&scene.loads, p, w);
    let mut late = 0.0;
    for k in 1..reference.t.len() {
        let (p, w) = (reference.phi[k], reference.omega[k]);
        let de = energy(r.phi[k], r.omega[k]) - energy(p, w);
        late += de / (model.i_red(p) * w * w) * scene.dt_out;
    }
    let predicted = reference.omega.last().unwrap() * late;
    assert!(
        (predicted / end - 1.0).abs() < 0.02,
        "δφ(100 s) {end:e}, from the energy drift {predicted:e}"
    );
}

/// With the energy projection (`--project-energy`: φ̇ put back onto the
/// energy integral at the step's φ after every step, `EnergyProjection`) the drift that sets
/// the error above is gone, and RK45 at atol 1e-10 ends well within 1e-6 rad of the exact φ
/// over 100 s, at the same step count: measured max |Δφ| 6.2e-9 rad on the CLI's 1e-4 s grid
/// (1.1e-5 rad without), falling 10× per decade of atol (8.0e-7, 6.5e-8, 6.2e-9 at 1e-8, 1e-9,
/// 1e-10). The energy left on the grid is the rounding of E's −M·φ term.
#[test]
fn long_run_100s_with_the_energy_projection_is_within_1e_6_rad() {
    let scene = FreeScene::long_run(100.0, 0.01);
    let reference = scene.reference().unwrap();
    let o = FreeRunOptions {
        rtol: 0.0,
        project_energy: true,
        ..opts(scene, 1e-10)
    }
    .with_caps_for_duration();
    let mut r = run_free(Method::Rk45, &o).unwrap();
    let (ep, ew) = r.check_against_reference(&reference, &o);
    let end = r.phi_rad - reference.phi.last().unwrap();
    eprintln!(
        "projected: max |Δφ| {ep:e}, at 100 s {end:e}, max |Δω| {ew:e}, {} steps",
        r.steps
    );
    assert!(
        ep < 1e-8 && end.abs() < 1e-8,
        "max |Δφ| {ep:e}, at 100 s {end:e}"
    );
    assert!(ew < 1.5e-5, "max |Δω| {ew:e}");
    assert!(
        r.energy_projections >= r.steps,
        "{} projections",
        r.energy_projections
    );
    assert!(
        r.energy_drift_max_j.unwrap() < 1e-9,
        "{:e} J",
        r.energy_drift_max_j.unwrap()
    );
    // each projection corrects φ̇ by a step's local error, not by the accumulated drift
    assert!(r.energy_projection_max_change_rad_s < 1e-6);
}

/// The projection is RK45's, on conservative loads: other methods and damped loads are
/// refused with the reason.
#[test]
fn the_energy_projection_is_refused_where_it_does_not_apply() {
    let o = FreeRunOptions {
        project_energy: true,
        ..opts(FreeScene::thesis(), 1e-8)
    };
    let e = run_free(Method::Bdf, &o).unwrap_err().to_string();
    assert!(e.contains("rk45 only"), "{e}");
    let mut damped = o;
    damped.scene.loads.spring = Some(GasSpring {
        k: 1e3,
        x0: 0.1,
        c: 2.0,
    });
    let e = run_free(Method::Rk45, &damped).unwrap_err().to_string();
    assert!(e.contains("conservative"), "{e}");
}

/// The energy-integral reference itself is far more accurate than the errors it
/// measures at 100 s: a 10× looser panel threshold moves it by at most 1.6e-9 rad
/// (measured 1.57e-9 rad, 2.0e-10 rad at 100 s), against RK45's 1.1e-5 rad at atol 1e-10.
#[test]
fn long_run_100s_reference_is_converged() {
    let scene = FreeScene::long_run(100.0, 0.01);
    let model = scene.model().unwrap();
    let grid = scene.grid().unwrap();
    let r = scene.reference().unwrap();
    let loose = exact_reference_with_tol(&model, &scene.loads, 0.0, 0.0, &grid, 1e-10).unwrap();
    let (dp, dw) = r.max_errors(&loose.phi, &loose.omega);
    assert!(dp < 3e-9 && dw < 4e-6, "{dp:e} {dw:e}");
}

/// A tolerance below what f64 resolves is raised to the floor κ·ε·|y_i| with a
/// warning, and the run stays cheap and accurate instead of fighting round-off: RK45 at atol
/// 1e-16 over 1 s measured 5,785 steps (floored on 5,766), 5 rejected, max |Δφ| = 1.4e-14 rad
/// (at 1e-12: 2,104 steps, 8.2e-13 rad).
#[test]
fn tolerance_below_the_f64_resolution_is_floored_with_a_warning() {
    let scene = FreeScene::thesis();
    let reference = scene.reference().unwrap();
    let o = FreeRunOptions {
        rtol: 0.0,
        ..opts(scene, 1e-16)
    };
    let mut r = run_free(Method::Rk45, &o).unwrap();
    assert!(
        r.warnings.iter().any(|w| w.contains("f64 resolution")),
        "{:?}",
        r.warnings
    );
    let (ep, _) = r.check_against_reference(&reference, &o);
    assert!(ep < 5e-13, "max |Δφ| {ep:e}");
    assert!(
        r.rejected_steps * 5 < r.steps,
        "{} of {}",
        r.rejected_steps,
        r.steps
    );
}

#[test]
fn long_run_100s_absolute_tolerance_keeps_energy() {
    // φ grows to ≈ 1.8e5 rad (≈ 29 000 revolutions); purely absolute control
    let scene = FreeScene::long_run(100.0, 0.01);
    // atol = 1e-5 keeps the test short (1.8e6 steps); at 1e-6 (2.8e6 steps) the drift is 0.5 J
    let o = FreeRunOptions {
        max_steps: 3_000_000,
        max_rhs_evals: 20_000_000,
        ..opts(scene, 1e-5)
    };
    let r = run_free(Method::Rk45, &o).unwrap();
    // exact φ(100 s) = 180408.41063 rad (energy-integral reference)
    assert!(
        (r.phi_rad / 180_408.410_63 - 1.0).abs() < 1e-4,
        "φ(100 s) = {}",
        r.phi_rad
    );
    let rel = r.energy_drift_rel.unwrap();
    assert!(
        rel < 1e-4,
        "energy drift {:e} J, relative {rel:e}",
        r.energy_drift_max_j.unwrap()
    );
    assert!(r.warnings.is_empty());
}

#[test]
fn relative_tolerance_on_phi_loosens_the_control() {
    // 10 s (φ ≈ 1840 rad): rtol·|φ| is 1840× looser than the same number as atol
    let scene = FreeScene::long_run(10.0, 0.01);
    let reference = scene.reference().unwrap();
    let abs = run_free(Method::Rk45, &opts(scene, 1e-8)).unwrap();
    let rel = run_free(
        Method::Rk45,
        &FreeRunOptions {
            rtol: 1e-8,
            atol: 1e-12,
            ..opts(scene, 1e-8)
        },
    )
    .unwrap();
    let (ea, _) = reference.max_errors(&abs.phi, &abs.omega);
    let (er, _) = reference.max_errors(&rel.phi, &rel.omega);
    assert!(
        ea < 1e-5 && er > 100.0 * ea,
        "absolute {ea:e}, relative {er:e}"
    );
    assert!(rel.energy_drift_rel.unwrap() > 100.0 * abs.energy_drift_rel.unwrap());
}

#[test]
fn long_run_slow_methods_stop_at_their_cap() {
    // the other methods need 3–20 million steps for 100 s at 1e-6: with a cap they stop
    // quickly and say where; the fixed-step method finishes but is flagged
    let scene = FreeScene::long_run(100.0, 0.01);
    let o = FreeRunOptions {
        max_steps: 50_000,
        ..opts(scene, 1e-6)
    };
    let adaptive: Vec<Method> = Method::REDUCED
        .into_iter()
        .filter(|m| !m.is_fixed_step())
        .collect();
    for c in run_all(&adaptive, &o).unwrap() {
        assert!(
            !c.completed && c.t_reached > 0.5 && c.t_reached < 100.0,
            "{c:?}"
        );
        assert!(
            c.failure
                .as_ref()
                .unwrap()
                .contains("step limit of 50000 steps"),
            "{c:?}"
        );
    }
    // 1e6 fixed steps of 1e-4 s (the default cap): completes, but φ(100 s) is far off and
    // the energy check says so
    let o = FreeRunOptions {
        fixed_step: 1e-4,
        ..opts(scene, 1e-6)
    };
    let r = run_free(Method::InitialAcceleration, &o).unwrap();
    assert!(
        r.phi_rad < 1.0e5 && r.energy_drift_rel.unwrap() > 0.1,
        "{} {:?}",
        r.phi_rad,
        r.energy_drift_rel
    );
    assert!(!r.warnings.is_empty());
}

#[test]
fn stiff_gas_spring_explicit_methods_stop_implicit_finish() {
    // k = 1e8 N/m, c = 1e7 N·s/m at mid-stroke: modes ≈ −5.8e5 and −10 1/s
    let scene = FreeScene::stiff_spring(1e8, 1e7);
    let o = FreeRunOptions {
        max_steps: 20_000,
        fixed_step: 1e-4,
        ..opts(scene, 1e-8)
    };
    // the explicit methods crawl and are stopped by the step cap (time is not asserted here:
    // `rodstudy integrators` and the benchmarks measure it)
    let out = run_all(&Method::REDUCED, &o).unwrap();
    // static equilibrium: M + (F − k (x − x0)) p42 = 0 with p42(90°) = r
    let r = scene.data.r;
    let dphi_eq = (scene.loads.torque / r + scene.loads.piston_force) / (1e8 * r);
    let mut implicit = vec![];
    for c in &out {
        match c.method {
            Method::InitialAcceleration => {
                assert!(
                    !c.completed && c.failure.as_ref().unwrap().contains("blew up"),
                    "{c:?}"
                )
            }
            Method::Rk45 | Method::Rk23 => {
                assert!(
                    !c.completed && c.failure.as_ref().unwrap().contains("step limit"),
                    "{c:?}"
                )
            }
            _ => {
                assert!(c.completed && c.steps < 1000, "{c:?}");
                let d = c.phi_end_rad.unwrap() - scene.phi0;
                assert!(
                    (d / dphi_eq - 1.0).abs() < 1e-3,
                    "{}: {d:e} vs {dphi_eq:e}",
                    c.method
                );
                implicit.push(d);
            }
        }
    }
    assert_eq!(implicit.len(), 3);
    let spread = implicit.iter().fold(f64::MIN, |a, &b| a.max(b))
        - implicit.iter().fold(f64::MAX, |a, &b| a.min(b));
    assert!(spread < 1e-9, "implicit methods disagree by {spread:e} rad");
    // no energy integral with damping: the reference refuses
    assert!(matches!(
        scene.reference(),
        Err(FreeRunError::Reference(ReferenceError::NonConservative))
    ));
}

#[test]
fn gravity_switch() {
    // with gravity the torque amplitude g (m2 e + m_A r) ≈ 1.54 N·m exceeds M = 1 N·m: the crank
    // first swings backwards, so the forward-only energy reference refuses, clearly
    let mut scene = FreeScene::thesis();
    scene.loads.gravity = true;
    let model = scene.model().unwrap();
    assert!((model.gravity_lever() * 9.81 - 1.54).abs() < 0.01);
    assert!(matches!(
        scene.reference(),
        Err(FreeRunError::Reference(
            ReferenceError::NotStartingForward { .. }
        ))
    ));
    let r = run_free(Method::Rk45, &opts(scene, 1e-10)).unwrap();
    assert!(r.phi[100] < 0.0, "swings backwards first");
    assert!(
        r.energy_drift_max_j.unwrap() < 1e-8,
        "energy incl. gravity potential is conserved"
    );
    // started fast enough, the reference works with gravity too and agrees with rk45
    scene.omega0 = 20.0;
    let reference = scene.reference().unwrap();
    let r = run_free(Method::Rk45, &opts(scene, 1e-11)).unwrap();
    let (ep, _) = reference.max_errors(&r.phi, &r.omega);
    assert!(ep < 1e-9, "{ep:e}");
}
