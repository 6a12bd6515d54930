//! Unit tests of the multibody core against independent checks: finite
//! differences of Φ, the assembled block system of thesis eq. 3.38, the power
//! balance of the inverse dynamics, the balance of the joint reactions, and the
//! builder's refusals.

use super::super::constraint::ConstraintEquations;
use super::super::error::DynamicsError;
use super::super::linkage::{CrankSliderLinkage, test_rig};
use super::super::motion::CrankMotion;
use super::*;
use nalgebra::SMatrix;

/// A crank–slider with an offset rod centroid, a crank centroid off O, a
/// piston force and gravity: the test rig of [`test_rig`] on the core.
fn crank_slider(motion: CrankMotion) -> MultibodySystem<9> {
    let mut b = test_rig(0.05, 0.16, 0.01, 0.06, 0.004).builder(["O", "A", "B", "slide"]);
    b.add_driving("drive", BodyId::Ground, CrankSliderLinkage::CRANK, motion)
        .add_load(AppliedLoad::Force {
            body: CrankSliderLinkage::PISTON,
            point: Vector2::zeros(),
            force: Vector2::new(-150.0, 0.0),
        })
        .add_load(AppliedLoad::Torque {
            body: CrankSliderLinkage::ROD,
            torque_nm: 0.7,
        })
        .gravity(Vector2::new(0.0, -9.81));
    b.build::<9>().expect("valid model")
}

fn guess() -> SVector<f64, 9> {
    SVector::<f64, 9>::from_column_slice(&[0.01, 0.0, 0.0, 0.11, 0.004, 0.0, 0.21, 0.0, 0.0])
}

#[test]
fn system_jacobian_matches_finite_differences() {
    let sys = crank_slider(CrankMotion::constant_speed(10.0));
    let q =
        SVector::<f64, 9>::from_column_slice(&[0.01, 0.02, 0.3, 0.1, 0.01, -0.2, 0.2, 0.003, 0.05]);
    let d = sys.jacobian(&q, 0.1);
    let h = 1e-6;
    for c in 0..9 {
        let mut qp = q;
        let mut qm = q;
        qp[c] += h;
        qm[c] -= h;
        let col = (sys.constraints(&qp, 0.1) - sys.constraints(&qm, 0.1)) / (2.0 * h);
        for r in 0..9 {
            assert!((col[r] - d[(r, c)]).abs() < 1e-8, "D[{r},{c}]");
        }
    }
}

#[test]
fn block_system_of_eq_3_38_is_satisfied() {
    let sys = crank_slider(CrankMotion::Harmonic {
        phi0_rad: 0.4,
        omega_rad_s: 60.0,
        amplitude_rad: 0.2,
        frequency_rad_s: 90.0,
    });
    let sol = sys.analyze(0.0, &guess()).expect("assembles");
    let t = sol.t;
    let d = sys.jacobian(&sol.q, t);
    let h = sys.applied_forces(&sol.q);
    let g = sys.gamma(&sol.q, &sol.qd, t);
    // assemble [M -D^T; D 0] [qdd; lambda] = [h; gamma] and solve it directly
    let mut a = SMatrix::<f64, 18, 18>::zeros();
    let mut rhs = SVector::<f64, 18>::zeros();
    for i in 0..9 {
        a[(i, i)] = sys.mass_diagonal()[i];
        rhs[i] = h[i];
        rhs[9 + i] = g[i];
        for j in 0..9 {
            a[(i, 9 + j)] = -d[(j, i)];
            a[(9 + i, j)] = d[(i, j)];
        }
    }
    let x = a.lu().solve(&rhs).expect("regular block system");
    let scale = sol.lambda.amax();
    for i in 0..9 {
        assert!((x[i] - sol.qdd[i]).abs() < 1e-9 * (1.0 + sol.qdd.amax()));
        assert!((x[9 + i] - sol.lambda[i]).abs() < 1e-9 * scale);
    }
    // and the position / velocity equations hold
    assert!(sys.constraints(&sol.q, t).amax() < 1e-13);
    assert!((d * sol.qd - sys.velocity_rhs(t)).amax() < 1e-10);
}

#[test]
fn power_balance_drive_torque_times_speed_equals_energy_rate() {
    // independent check of the inverse dynamics: P_drive + P_loads = d/dt (T + V),
    // with d/dt by central differences of the *positions/velocities* only
    let motion = CrankMotion::Harmonic {
        phi0_rad: 0.1,
        omega_rad_s: 50.0,
        amplitude_rad: 0.3,
        frequency_rad_s: 70.0,
    };
    let sys = crank_slider(motion);
    let drive = sys.joint_index("drive").expect("drive");
    let row = sys.joints()[drive].row;
    let mut tr = sys.tracker(guess());
    let energy = |s: &KinematicSolution<9>| sys.kinetic_energy(&s.qd) + sys.potential_energy(&s.q);
    let dt = 1e-5;
    for k in 0..40 {
        let t = 0.0031 * k as f64 + 0.002;
        let em2 = energy(tr.solve_at(t - 2.0 * dt).expect("solves"));
        let em1 = energy(tr.solve_at(t - dt).expect("solves"));
        let s = *tr.solve_at(t).expect("solves");
        let ep1 = energy(tr.solve_at(t + dt).expect("solves"));
        let ep2 = energy(tr.solve_at(t + 2.0 * dt).expect("solves"));
        let de = (em2 - 8.0 * em1 + 8.0 * ep1 - ep2) / (12.0 * dt);
        let p_drive = s.lambda[row] * motion.sample(t).omega;
        // loads: piston force -150 N along x at piston; torque 0.7 N m on the rod
        let p_loads = -150.0 * s.qd[6] + 0.7 * s.qd[5];
        let scale = p_drive.abs().max(1.0);
        assert!(
            (p_drive + p_loads - de).abs() < 1e-6 * scale,
            "t = {t}: drive {p_drive} loads {p_loads} dE/dt {de}"
        );
    }
}

#[test]
fn reactions_balance_each_body() {
    let sys = crank_slider(CrankMotion::constant_speed(100.0));
    let sol = sys.analyze(0.0, &guess()).expect("assembles");
    let h = sys.applied_forces(&sol.q);
    let mut total = SVector::<f64, 9>::zeros();
    for (k, nj) in sys.joints().iter().enumerate() {
        let r = sys.reaction(k, &sol).expect("joint");
        let (bi, bj) = nj.joint.bodies();
        for (b, f) in [(bi, r.on_i), (bj, r.on_j)] {
            if let Some(o) = b.offset() {
                total[o] += f.fx_n;
                total[o + 1] += f.fy_n;
                total[o + 2] += f.torque_nm;
            }
        }
    }
    // M qdd = h + sum of reactions
    let m = sys.mass_diagonal();
    for i in 0..9 {
        assert!((m[i] * sol.qdd[i] - h[i] - total[i]).abs() < 1e-9 * (1.0 + total.amax()));
    }
    // revolute A: action = -reaction
    let a = sys.reaction(1, &sol).expect("A");
    assert!((a.on_i.fx_n + a.on_j.fx_n).abs() < 1e-12 && (a.on_i.fy_n + a.on_j.fy_n).abs() < 1e-12);
}

#[test]
fn count_and_model_errors() {
    let mut b = MultibodyBuilder::new();
    let c = b.add_body("c", 1.0, 0.1);
    b.add_revolute("O", BodyId::Ground, Vector2::zeros(), c, Vector2::zeros());
    let e = b.build::<3>().unwrap_err();
    assert!(
        matches!(
            e,
            DynamicsError::ConstraintCount {
                equations: 2,
                coordinates: 3,
                ..
            }
        ),
        "{e}"
    );
    b.add_driving("drive", BodyId::Ground, c, CrankMotion::constant_speed(1.0));
    assert!(b.build::<3>().is_ok());
    assert!(matches!(
        b.build::<6>(),
        Err(DynamicsError::InvalidModel(_))
    ));
    b.add_revolute(
        "again",
        BodyId::Ground,
        Vector2::zeros(),
        c,
        Vector2::zeros(),
    );
    let e = b.build::<3>().unwrap_err().to_string();
    assert!(e.contains("'again'"), "{e}");
    let mut b = MultibodyBuilder::new();
    let c = b.add_body("c", -1.0, 0.1);
    b.add_revolute("O", BodyId::Ground, Vector2::zeros(), c, Vector2::zeros())
        .add_driving("d", BodyId::Ground, c, CrankMotion::constant_speed(1.0));
    let e = b.build::<3>().unwrap_err().to_string();
    assert!(e.contains("mass_kg") && e.contains("'c'"), "{e}");
    let mut b = MultibodyBuilder::new();
    let c = b.add_body("c", 1.0, 0.1);
    b.add_revolute("self", c, Vector2::zeros(), c, Vector2::zeros())
        .add_driving("d", BodyId::Ground, c, CrankMotion::constant_speed(1.0));
    assert!(matches!(
        b.build::<3>(),
        Err(DynamicsError::InvalidModel(_))
    ));
}
