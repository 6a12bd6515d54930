//! The modified Rosenbrock 2(3) pair of MATLAB's ode23s.
//!
//! L. F. Shampine, M. W. Reichelt, "The MATLAB ODE Suite", SIAM J. Sci. Comput. 18 (1997)
//! 1–22, §3 (Rosenbrock theory: Hairer & Wanner, *Solving ODEs II*, §IV.7). With
//! `d = 1/(2 + √2)`, `e32 = 6 + √2`, `W = I − h d J`, `J = ∂f/∂y(t, y)`, `T = ∂f/∂t(t, y)`:
//!
//! - `F0 = f(t, y)`,                     `k1 = W⁻¹ (F0 + h d T)`
//! - `F1 = f(t + h/2, y + h/2 k1)`,      `k2 = W⁻¹ (F1 − k1) + k1`
//! - `y_new = y + h k2`,                  `F2 = f(t + h, y_new)`
//! - `k3 = W⁻¹ [F2 − e32 (k2 − F1) − 2 (k1 − F0) + h d T]`
//! - error `h/6 (k1 − 2 k2 + k3)`, step factor `0.8 err^(-1/3)` in `[0.5, 5]` on rejection /
//!   `≤ 5` on acceptance (as ode23s).
//!
//! The second-order formula is a W-method (its order does not depend on `J` being exact) and is
//! L-stable; F2 is reused as F0 of the next step (FSAL). `J` is evaluated once per step (as
//! ode23s does), `T` by a forward difference unless the system declares itself autonomous.
//! Dense output: `y(t + θh) = y + h [θ(1−θ)/(1−2d) k1 + θ(θ−2d)/(1−2d) k2]`.

use super::adaptive::{AdaptiveStepper, Attempt, Step, integrate};
use super::control::Controller;
use super::eval::Evaluator;
use super::newton::iteration_matrix;
use super::norm::{Weights, all_finite};
use super::{OdeSystem, OutputGrid, Solution, SolverError, SolverOptions};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::SQRT_2;

/// `d = 1/(2 + √2)`, `e32 = 6 + √2`.
const D: f64 = 1.0 / (2.0 + SQRT_2);
const E32: f64 = 6.0 + SQRT_2;

/// Integrates with error control `opts.rtol`, `opts.atol`.
pub fn solve<S: OdeSystem + ?Sized>(
    sys: &S,
    y0: &DVector<f64>,
    grid: &OutputGrid,
    opts: &SolverOptions,
) -> Result<Solution, SolverError> {
    integrate::<Rosenbrock23, _>(sys, y0, grid, opts, None)
}

/// `J`, `T` at the start of the step, stages `k1 … k3`, derivatives `F0 … F2`
/// (`F0 = f(t_n, y_n)`, `F2 = f(t_{n+1}, y_{n+1})`) and scratch.
struct Rosenbrock23 {
    jac: DMatrix<f64>,
    tder: DVector<f64>,
    /// Time at which `jac` and `tder` were evaluated.
    jac_current_at: f64,
    k: [DVector<f64>; 3],
    f: [DVector<f64>; 3],
    ys: DVector<f64>,
    err: DVector<f64>,
}

impl AdaptiveStepper for Rosenbrock23 {
    const NAME: &'static str = "rosenbrock";
    const START_ORDER: u32 = 2;
    /// ode23s: `0.8 err^(-1/3)`, at least 0.5 on rejection.
    const CONTROL: Controller = Controller {
        exponent: 3.0,
        safety: 0.8,
        fac_min: 0.5,
    };

    fn new(n: usize, _weights: &Weights) -> Self {
        Self {
            jac: DMatrix::zeros(n, n),
            tder: DVector::zeros(n),
            jac_current_at: f64::NAN,
            k: std::array::from_fn(|_| DVector::zeros(n)),
            f: std::array::from_fn(|_| DVector::zeros(n)),
            ys: DVector::zeros(n),
            err: DVector::zeros(n),
        }
    }

    fn derivative_mut(&mut self) -> &mut DVector<f64> {
        &mut self.f[0]
    }

    /// `J` and `T` once per step.
    fn begin_step<S: OdeSystem + ?Sized>(
        &mut self,
        ev: &mut Evaluator<'_, S>,
        t: f64,
        y: &DVector<f64>,
    ) -> Result<(), SolverError> {
        if self.jac_current_at != t {
            ev.jacobian(t, y, Some(&self.f[0]), &mut self.jac)?;
            ev.time_derivative(t, y, &self.f[0], &mut self.tder)?;
            self.jac_current_at = t;
        }
        Ok(())
    }

    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        ev: &mut Evaluator<'_, S>,
        weights: &Weights,
        step: &Step,
        y: &DVector<f64>,
        y_new: &mut DVector<f64>,
        dy: &mut DVector<f64>,
    ) -> Result<Attempt, SolverError> {
        let Step { t, h, t_new, .. } = *step;
        ev.stats.lu_decompositions += 1;
        let Some(w) = iteration_matrix(&self.jac, h * D) else {
            return Ok(Attempt::Failed {
                shrink: Some(0.5),
                cap_growth: true,
            });
        };
        let hd = h * D;
        let ([k1, k2, k3], [f0, f1, f2]) = (&mut self.k, &mut self.f);
        let (tder, ys, err) = (&self.tder, &mut self.ys, &mut self.err);
        k1.copy_from(f0);
        k1.axpy(hd, tder, 1.0);
        let mut ok = w.solve_mut(k1);
        ys.copy_from(y);
        ys.axpy(0.5 * h, k1, 1.0);
        ev.rhs(t + 0.5 * h, ys, f1)?;
        k2.copy_from(f1);
        *k2 -= &*k1;
        ok &= w.solve_mut(k2);
        *k2 += &*k1;
        for i in 0..y.len() {
            dy[i] = h * k2[i];
            y_new[i] = y[i] + dy[i];
        }
        ev.rhs(t_new, y_new, f2)?;
        for i in 0..y.len() {
            k3[i] = f2[i] - E32 * (k2[i] - f1[i]) - 2.0 * (k1[i] - f0[i]) + hd * tder[i];
        }
        ok &= w.solve_mut(k3);
        for i in 0..y.len() {
            err[i] = h / 6.0 * (k1[i] - 2.0 * k2[i] + k3[i]);
        }
        let en = weights.norm(err, y, y_new);
        Ok(Attempt::checked(
            en,
            ok && all_finite(y_new) && all_finite(f2),
        ))
    }

    fn interpolate(
        &self,
        theta: f64,
        h: f64,
        y: &DVector<f64>,
        _y_new: &DVector<f64>,
        out: &mut DVector<f64>,
    ) {
        let denom = 1.0 - 2.0 * D;
        let a = theta * (1.0 - theta) / denom;
        let b = theta * (theta - 2.0 * D) / denom;
        let [k1, k2, _] = &self.k;
        for i in 0..out.len() {
            out[i] = y[i] + h * (a * k1[i] + b * k2[i]);
        }
    }

    fn accept(&mut self) {
        self.f.swap(0, 2);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::tests_common::{Decay, Oscillator, ProtheroRobinson, max_error};

    #[test]
    fn oscillator_steps_scale_like_tol_to_the_third_root() {
        let sys = Oscillator { omega: 2.0 };
        let grid = OutputGrid::new(0.0, 5.0, 0.01).unwrap();
        let y0 = DVector::from_vec(vec![1.0, 0.0]);
        let run = |tol: f64| {
            let sol = solve(&sys, &y0, &grid, &SolverOptions::absolute(tol)).unwrap();
            (
                max_error(&sol, |t| sys.exact(t).to_vec()),
                sol.stats.steps as f64,
            )
        };
        // second order without local extrapolation: global error ~ tol^(2/3)
        let (e1, n1) = run(1e-5);
        let (e2, n2) = run(1e-8);
        assert!(
            e2 < e1 && e1 < 20.0 * 1e-5f64.powf(2.0 / 3.0) && e2 < 20.0 * 1e-8f64.powf(2.0 / 3.0),
            "{e1} {e2}"
        );
        let ratio = n2 / n1;
        assert!(ratio > 7.0 && ratio < 13.0, "step ratio {ratio}");
    }

    #[test]
    fn stiff_decay_is_l_stable() {
        let grid = OutputGrid::new(0.0, 10.0, 0.5).unwrap();
        let y0 = DVector::from_vec(vec![1.0]);
        let sol = solve(
            &Decay { lambda: 1e8 },
            &y0,
            &grid,
            &SolverOptions::absolute(1e-6),
        )
        .unwrap();
        assert!(sol.stats.steps < 300, "{}", sol.stats);
        assert!(sol.last()[0].abs() < 1e-8);
    }

    #[test]
    fn prothero_robinson_nonautonomous() {
        // stiff limit: the local error drops to O(h²) (order reduction, estimated honestly),
        // so ~2000 steps at 1e-6, independent of λ; an explicit method would need ~1e6
        let sys = ProtheroRobinson { lambda: 1e6 };
        let grid = OutputGrid::new(0.0, 3.0, 0.01).unwrap();
        let y0 = DVector::from_vec(vec![0.0]);
        let sol = solve(&sys, &y0, &grid, &SolverOptions::absolute(1e-6)).unwrap();
        let e = max_error(&sol, |t| vec![t.sin()]);
        assert!(e < 1e-5, "error {e}");
        assert!(sol.stats.steps < 5000, "{}", sol.stats);
    }
}
