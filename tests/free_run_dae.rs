//! Scene `free` through the multibody core as a DAE (thesis §3.2): the stabilised index-1
//! form with RK45 (`dae-index1`) and the index-3 form with generalized-α (`dae-genalpha`),
//! against the exact energy-integral reference of the reduced model; constraint drift with
//! and without stabilisation; the long run; caps.

use rodstudy::free_run::dae::Stabilization;
use rodstudy::free_run::{
    FreeRunError, FreeRunOptions, FreeScene, Method, SweepConfig, run_all, run_free,
    work_precision_sweep,
};
use rodstudy::integrators::FailureKind;

fn index1(scene: FreeScene, atol: f64, stabilization: Stabilization) -> FreeRunOptions {
    let mut o = FreeRunOptions {
        scene,
        atol,
        ..FreeRunOptions::default()
    };
    o.dae.stabilization = stabilization;
    o
}

fn genalpha(scene: FreeScene, h: f64) -> FreeRunOptions {
    FreeRunOptions {
        scene,
        fixed_step: h,
        ..FreeRunOptions::default()
    }
}

#[test]
fn index1_with_projection_gives_the_reduced_models_phi() {
    let scene = FreeScene::thesis();
    let reference = scene.reference().unwrap();
    let r = run_free(
        Method::DaeIndex1,
        &index1(scene, 1e-12, Stabilization::Projection),
    )
    .unwrap();
    let (ep, ew) = reference.max_errors(&r.phi, &r.omega);
    // measured 2.3e-12 rad and 6.4e-11 rad/s
    assert!(ep < 1e-10 && ew < 1e-9, "max |Δφ| {ep:e}, max |Δω| {ew:e}");
    assert_eq!((r.t.len(), r.method), (10_001, Method::DaeIndex1));
    assert!(r.model.contains("index-1") && r.model.contains("projection"));
    // on the manifold to the projection tolerance (1e-13 L) at every output point
    let d = r.constraint_drift_max.unwrap();
    assert!(d.position < 1e-12 && d.velocity < 1e-12, "{d:?}");
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    assert!(r.energy_drift_rel.unwrap() < 1e-10);
    assert!(r.steps > 100 && r.rhs_evals > 6 * r.steps && r.jac_evals == 0);
    // every evaluation of c̈ solves the block system by one LU (eq. 3.38)
    assert_eq!(r.lu_decompositions, r.rhs_evals);
    let json = serde_json::to_value(&r).unwrap();
    assert_eq!(json["method"], "dae-index1");
    assert!(json["constraint_drift_max"]["position"].as_f64().unwrap() < 1e-12);
    // the reduced model's result carries no constraint drift
    let reduced = run_free(Method::Rk45, &FreeRunOptions::default()).unwrap();
    assert!(reduced.constraint_drift_max.is_none());
}

#[test]
fn genalpha_converges_at_second_order_to_the_same_phi() {
    let scene = FreeScene::thesis();
    let reference = scene.reference().unwrap();
    let mut errors = Vec::new();
    for h in [4e-4, 2e-4, 1e-4, 5e-5] {
        let r = run_free(Method::DaeGenAlpha, &genalpha(scene, h)).unwrap();
        let (ep, ew) = reference.max_errors(&r.phi, &r.omega);
        let d = r.constraint_drift_max.unwrap();
        // the index-3 form holds Φ = 0 at its steps (h ≤ 1e-4: every output point is a step;
        // at 4e-4 and 2e-4 the points between steps are Hermite-interpolated, O(h⁴)) and lets
        // D ċ drift by O(h²)
        assert!(
            d.position < if h <= 1e-4 { 1e-12 } else { 1e-8 },
            "{h}: {d:?}"
        );
        assert!(d.velocity > 1e-9 && d.velocity < 1e3 * h * h, "{h}: {d:?}");
        assert_eq!(r.steps, (1.0 / h).round() as u64);
        assert!(r.jac_evals >= r.steps && r.lu_decompositions >= r.steps);
        errors.push((h, ep, ew));
    }
    for w in errors.windows(2) {
        let (rp, rw) = (w[0].1 / w[1].1, w[0].2 / w[1].2);
        assert!((3.6..4.4).contains(&rp), "φ error ratio {rp}: {errors:?}");
        assert!((3.6..4.4).contains(&rw), "ω error ratio {rw}: {errors:?}");
    }
    // measured 3.0e-5 rad at h = 1e-4 s, 7.5e-6 at 5e-5 (3.0e-7 at 1e-5 in the sweep)
    assert!(errors[2].1 < 5e-5 && errors[3].1 < 1e-5, "{errors:?}");
}

#[test]
fn constraint_drift_with_and_without_stabilisation() {
    let scene = FreeScene::thesis();
    let reference = scene.reference().unwrap();
    let run = |s| run_free(Method::DaeIndex1, &index1(scene, 1e-8, s)).unwrap();
    let projected = run(Stabilization::Projection);
    let baumgarte = run(Stabilization::Baumgarte {
        alpha: 50.0,
        beta: 50.0,
    });
    let off = run(Stabilization::Off);
    let (p, b, o) = (
        projected.constraint_drift_max.unwrap(),
        baumgarte.constraint_drift_max.unwrap(),
        off.constraint_drift_max.unwrap(),
    );
    // measured over 1 s at atol 1e-8: |Φ| 1e-14 / 1.8e-10 / 3.1e-9 m, |D ċ| 7e-16 / 1.2e-8 /
    // 4.0e-8 m/s
    assert!(p.position < 1e-12 && p.velocity < 1e-12, "{p:?}");
    assert!(
        o.position > 1e3 * p.position && o.velocity > 1e3 * p.velocity,
        "{o:?}"
    );
    assert!(b.position < o.position && b.position > p.position, "{b:?}");
    // all three still follow the exact φ(t) to a small multiple of the tolerance
    for r in [&projected, &baumgarte, &off] {
        let (ep, _) = reference.max_errors(&r.phi, &r.omega);
        assert!(ep < 1e-7, "{}: {ep:e}", r.model);
    }
    assert!(off.model.contains("without stabilisation"));
    assert!(baumgarte.model.contains("Baumgarte"));
}

#[test]
fn long_run_drift_is_reported() {
    // 10 s (φ ≈ 1840 rad, ω up to ≈ 370 rad/s), atol 1e-5 to stay fast
    let scene = FreeScene::long_run(10.0, 0.01);
    let reference = scene.reference().unwrap();
    let projected = run_free(
        Method::DaeIndex1,
        &index1(scene, 1e-5, Stabilization::Projection),
    )
    .unwrap();
    let off = run_free(Method::DaeIndex1, &index1(scene, 1e-5, Stabilization::Off)).unwrap();
    let (p, o) = (
        projected.constraint_drift_max.unwrap(),
        off.constraint_drift_max.unwrap(),
    );
    // measured: projection 9.6e-15 m; unstabilised the joints open by 5.0 mm (|D ċ| 1.4e-3)
    assert!(p.position < 1e-12 && p.velocity < 1e-12, "{p:?}");
    assert!(o.position > 1e-3 && o.velocity > 1e-4, "{o:?}");
    assert!(projected.warnings.is_empty(), "{:?}", projected.warnings);
    assert!(
        off.warnings.iter().any(|w| w.contains("constraint drift")),
        "{:?}",
        off.warnings
    );
    // φ(t) is governed by the (loose) tolerance here: measured 4.4e-2 and 5.1e-2 rad
    for r in [&projected, &off] {
        let (ep, _) = reference.max_errors(&r.phi, &r.omega);
        assert!(ep < 0.1, "{}: {ep:e}", r.model);
    }
    // 100 s under a step cap: a typed error that says how far each form got
    let o = FreeRunOptions {
        max_steps: 5_000,
        fixed_step: 1e-4,
        ..index1(
            FreeScene::long_run(100.0, 0.01),
            1e-6,
            Stabilization::Projection,
        )
    };
    let out = run_all(&Method::DAE, &o).unwrap();
    for c in &out {
        assert!(
            !c.completed && c.t_reached > 0.1 && c.t_reached < 100.0,
            "{c:?}"
        );
        assert!(
            c.failure
                .as_ref()
                .unwrap()
                .contains("step limit of 5000 steps"),
            "{c:?}"
        );
    }
}

#[test]
fn caps_and_refusals_are_typed_errors() {
    let scene = FreeScene::thesis();
    for m in Method::DAE {
        let o = FreeRunOptions {
            max_rhs_evals: 500,
            ..genalpha(scene, 1e-4)
        };
        match run_free(m, &o) {
            Err(FreeRunError::Solver(e)) => {
                assert_eq!(e.kind, FailureKind::EvalLimit { max_rhs_evals: 500 });
                assert!(e.t > 0.0 && e.t < 1.0, "{m}: {e}");
            }
            other => panic!("{m}: expected an evaluation-limit error, got {other:?}"),
        }
    }
    // a Newton cap the index-3 form cannot meet at a huge step
    let mut o = genalpha(scene, 0.2);
    o.dae.max_newton_iters = 2;
    let e = run_free(Method::DaeGenAlpha, &o).unwrap_err();
    assert!(
        matches!(e, FreeRunError::Solver(ref s) if matches!(s.kind, FailureKind::NoConvergence { .. })),
        "{e}"
    );
    let mut o = genalpha(scene, 1e-4);
    o.dae.rho_inf = 1.0;
    assert!(run_free(Method::DaeGenAlpha, &o).is_err());
    // the gas spring is not in the multibody model: refused clearly, an outcome in tables
    let spring = FreeScene::stiff_spring(1e8, 1e7);
    let e = run_free(
        Method::DaeIndex1,
        &index1(spring, 1e-6, Stabilization::Projection),
    )
    .unwrap_err();
    assert!(matches!(e, FreeRunError::SceneNotSupported(_)), "{e}");
    let out = run_all(
        &Method::DAE,
        &index1(spring, 1e-6, Stabilization::Projection),
    )
    .unwrap();
    assert!(
        out.iter()
            .all(|c| !c.completed && c.failure.as_ref().unwrap().contains("gas spring"))
    );
    // l ≤ r is refused before any model is built
    let e = run_free(
        Method::DaeGenAlpha,
        &genalpha(FreeScene::near_toggle(1.0), 1e-4),
    )
    .unwrap_err();
    assert!(e.to_string().contains("crank cannot turn"), "{e}");
}

#[test]
fn near_toggle_and_gravity() {
    // l/r = 1.02: the index-1 form keeps its error at the tolerance (measured 1.9e-8 at 1e-8)
    let toggle = FreeScene::near_toggle(1.02);
    let reference = toggle.reference().unwrap();
    let r = run_free(
        Method::DaeIndex1,
        &index1(toggle, 1e-8, Stabilization::Projection),
    )
    .unwrap();
    let (ep, _) = reference.max_errors(&r.phi, &r.omega);
    assert!(ep < 3e-7, "{ep:e}");
    // gravity on (no forward-only reference): the multibody model agrees with the reduced one
    let mut g = FreeScene::thesis();
    g.loads.gravity = true;
    let a = run_free(
        Method::DaeIndex1,
        &index1(g, 1e-10, Stabilization::Projection),
    )
    .unwrap();
    let b = run_free(
        Method::Rk45,
        &FreeRunOptions {
            scene: g,
            atol: 1e-11,
            ..FreeRunOptions::default()
        },
    )
    .unwrap();
    let d = a
        .phi
        .iter()
        .zip(&b.phi)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(d < 1e-8, "{d:e}");
    assert!(
        a.phi[100] < 0.0,
        "swings backwards first, as the reduced model"
    );
}

#[test]
fn work_precision_sweep_includes_the_dae_forms() {
    let cfg = SweepConfig {
        methods: Method::DAE.to_vec(),
        tolerances: vec![1e-6, 1e-8, 1e-10],
        genalpha_steps: vec![4e-4, 2e-4, 1e-4],
        repeats: 1,
        ..SweepConfig::default()
    };
    let wp = work_precision_sweep(&FreeScene::thesis(), &cfg).unwrap();
    assert_eq!(wp.rows.len(), 6);
    for m in Method::DAE {
        assert!(wp.is_monotone(m), "{m}");
        for r in wp.rows_of(m) {
            assert!(
                r.failure.is_none() && r.constraint_drift_max.is_some(),
                "{r:?}"
            );
        }
    }
    let rows = wp.rows_of(Method::DaeIndex1);
    assert!(rows.iter().all(|r| r.setting == "atol"));
    for r in &rows {
        let q = r.max_err_phi_rad.unwrap() / r.value;
        // measured 1.9–17.6× tol over atol 1e-4 … 1e-12 (reports/work_precision.md)
        assert!(
            (1.5..20.0).contains(&q),
            "dae-index1 at {:e}: error/tol {q}",
            r.value
        );
    }
    assert!(
        wp.rows_of(Method::DaeGenAlpha)
            .iter()
            .all(|r| r.setting == "step")
    );
    let md = wp.to_markdown();
    assert!(
        md.contains("| dae-index1 | atol = 1e-8 |")
            && md.contains("| dae-genalpha | step = 1e-4 |"),
        "{md}"
    );
}
