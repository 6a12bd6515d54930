//! Regression test: rows of the work–precision table (`reports/work_precision.csv`, scene
//! `free` of thesis ch. 4) pinned to recorded values: the counters and errors of each adaptive
//! method on the shared loop ([`super::adaptive`]) with the crate's one dense LU. A change of any
//! counter, or of an error beyond rounding, is a change of behaviour.

use super::{SolverOptions, solve};
use crate::free_run::{CrankOde, FreeRunOptions, FreeScene, Method, run_free};
use nalgebra::DVector;

/// One pinned row: method, `atol`, accepted steps, RHS evaluations, Jacobians, LU
/// decompositions, `max |φ − φ_ref|` \[rad\], `max |φ̇ − φ̇_ref|` [rad/s].
type Row = (Method, f64, u64, u64, u64, u64, f64, f64);

#[rustfmt::skip]
const ROWS: [Row; 12] = [
    (Method::Rk45, 1e-6, 145, 1100, 0, 0, 3.7533634333897226e-07, 1.4835333324469957e-05),
    (Method::Rk45, 1e-9, 537, 3470, 0, 0, 8.055671685269772e-10, 3.224216982289363e-08),
    (Method::Rk23, 1e-6, 1583, 4880, 0, 0, 7.200539297258501e-06, 0.0001112676638257426),
    (Method::Rk23, 1e-9, 15719, 47216, 0, 0, 9.081233542929112e-09, 1.3959903100158044e-07),
    (Method::Bdf, 1e-6, 670, 1409, 1, 103, 2.082157629601511e-05, 0.000346526861292773),
    (Method::Bdf, 1e-9, 2102, 4440, 1, 341, 6.970286747787213e-08, 1.10624360871725e-06),
    (Method::Rosenbrock, 1e-6, 2290, 4604, 2290, 2301, 1.3928128137052909e-05, 0.0002709400047535837),
    (Method::Rosenbrock, 1e-9, 22863, 45730, 22863, 22864, 1.5283672283317173e-07, 2.912181223280186e-06),
    (Method::TrBdf2, 1e-6, 2076, 9137, 1, 226, 0.00015447234952148392, 0.0021164039953234237),
    (Method::TrBdf2, 1e-9, 21183, 92700, 1, 275, 1.5587499753166867e-06, 2.1253444131730248e-05),
    // rk45 with the post-step projection (rk45::solve_projected) on the multibody DAE
    (Method::DaeIndex1, 1e-6, 117, 988, 0, 988, 3.927525018099232e-06, 6.764216563226455e-05),
    (Method::DaeIndex1, 1e-9, 444, 3235, 0, 3235, 1.8951951119561272e-09, 6.151490339334487e-08),
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
