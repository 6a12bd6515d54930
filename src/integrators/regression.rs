//! Regression test: rows of the work–precision table (`reports/work_precision.csv`, scene
//! `free` of thesis ch. 4) pinned as recorded before the adaptive methods were given their
//! shared loop ([`super::adaptive`]) and the crate its one dense LU. A change of any
//! counter, or of an error beyond rounding, is a change of behaviour.

use super::{SolverOptions, solve};
use crate::free_run::{CrankOde, FreeRunOptions, FreeScene, Method, run_free};
use nalgebra::DVector;

/// One pinned row: method, `atol`, accepted steps, RHS evaluations, Jacobians, LU
/// decompositions, `max |φ − φ_ref|` \[rad\], `max |φ̇ − φ̇_ref|` [rad/s].
type Row = (Method, f64, u64, u64, u64, u64, f64, f64);

#[rustfmt::skip]
const ROWS: [Row; 12] = [
    (Method::Rk45, 1e-6, 145, 1100, 0, 0, 3.7533633800990174e-7, 1.483533321078312e-5),
    (Method::Rk45, 1e-9, 537, 3470, 0, 0, 8.05552957672262e-10, 3.224225508802192e-8),
    (Method::Rk23, 1e-6, 1583, 4880, 0, 0, 7.200539300811215e-6, 1.1126766396074572e-4),
    (Method::Rk23, 1e-9, 15719, 47216, 0, 0, 9.081468022031913e-9, 1.39602320814447e-7),
    (Method::Bdf, 1e-6, 670, 1409, 1, 103, 2.082157810079366e-5, 3.465268912634656e-4),
    (Method::Bdf, 1e-9, 2102, 4440, 1, 341, 6.970480725954076e-8, 1.1062853317866939e-6),
    (Method::Rosenbrock, 1e-6, 2290, 4604, 2290, 2301, 1.3928128122842054e-5, 2.709400043343635e-4),
    (Method::Rosenbrock, 1e-9, 22863, 45730, 22863, 22864, 1.528372486347962e-7, 2.912186985781773e-6),
    (Method::TrBdf2, 1e-6, 2076, 9137, 1, 226, 1.5447235020715766e-4, 2.116404003523087e-3),
    (Method::TrBdf2, 1e-9, 21183, 92700, 1, 275, 1.5587491901669637e-6, 2.1253436713664087e-5),
    // rk45 with the post-step projection (rk45::solve_projected) on the multibody DAE
    (Method::DaeIndex1, 1e-6, 117, 988, 0, 0, 3.927525018099232e-6, 6.764216581700566e-5),
    (Method::DaeIndex1, 1e-9, 444, 3235, 0, 0, 1.8951560321056604e-9, 6.15145623328317e-8),
];

/// Rejected steps and Newton iterations at `atol = 1e-6` (not in the table).
const REJECTED_1E6: [(Method, u64, u64); 5] = [
    (Method::Rk45, 38, 0),
    (Method::Rk23, 43, 0),
    (Method::Bdf, 28, 1407),
    (Method::Rosenbrock, 11, 0),
    (Method::TrBdf2, 104, 9135),
];

/// Runs `method` as the sweep does (`rtol = 0`, `atol = tol`, the sweep's caps).
fn run(method: Method, tol: f64) -> crate::free_run::FreeRunResult {
    let opts = FreeRunOptions {
        scene: FreeScene::thesis(),
        rtol: 0.0,
        atol: tol,
        omega_rtol: None,
        omega_atol: None,
        fixed_step: tol,
        max_steps: 1_000_000,
        max_rhs_evals: 10_000_000,
        ..FreeRunOptions::default()
    };
    run_free(method, &opts).unwrap_or_else(|e| panic!("{} at {tol:e}: {e}", method.name()))
}

#[test]
fn work_precision_rows_are_unchanged() {
    let reference = FreeScene::thesis().reference().unwrap();
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs();
    for (method, tol, steps, rhs, jac, lu, e_phi, e_omega) in ROWS {
        let r = run(method, tol);
        let name = format!("{} at {tol:e}", method.name());
        assert_eq!(
            (r.steps, r.rhs_evals, r.jac_evals, r.lu_decompositions),
            (steps, rhs, jac, lu),
            "{name}: steps, RHS evaluations, Jacobians, LU"
        );
        let (ep, ew) = reference.max_errors(&r.phi, &r.omega);
        assert!(
            close(ep, e_phi) && close(ew, e_omega),
            "{name}: errors {ep:e}, {ew:e}, pinned {e_phi:e}, {e_omega:e}"
        );
    }
}

#[test]
fn rejections_and_newton_iterations_are_unchanged() {
    let scene = FreeScene::thesis();
    let model = scene.model().unwrap();
    let sys = CrankOde {
        model: &model,
        loads: scene.loads,
    };
    let y0 = DVector::from_vec(vec![scene.phi0, scene.omega0]);
    let grid = scene.grid().unwrap();
    for (method, rejected, newton) in REJECTED_1E6 {
        let ode = method.ode_method().unwrap();
        let sol = solve(ode, &sys, &y0, &grid, &SolverOptions::absolute(1e-6)).unwrap();
        assert_eq!(
            (sol.stats.rejected_steps, sol.stats.newton_iters),
            (rejected, newton),
            "{}",
            method.name()
        );
    }
}
