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

use super::control::{check_underflow, clamp_to_end, initial_step, max_step};
use super::eval::Evaluator;
use super::grid::Recorder;
use super::lu::IterationMatrix;
use super::method::{check_input, invalid};
use super::norm::{Weights, all_finite};
use super::{OdeSystem, OutputGrid, Solution, SolverError, SolverOptions};
use nalgebra::{DMatrix, DVector};

const NAME: &str = "rosenbrock";

/// Integrates with error control `opts.rtol`, `opts.atol`.
pub fn solve<S: OdeSystem + ?Sized>(
    sys: &S,
    y0: &DVector<f64>,
    grid: &OutputGrid,
    opts: &SolverOptions,
) -> Result<Solution, SolverError> {
    let (t0, t_end) = (grid.t0, grid.t_end());
    check_input(sys, y0, opts).map_err(|m| invalid(NAME, t0, m))?;
    let n = y0.len();
    let weights = Weights::new(opts, n);
    let d = 1.0 / (2.0 + 2f64.sqrt());
    let e32 = 6.0 + 2f64.sqrt();
    let mut ev = Evaluator::new(sys, NAME, opts, t0);
    let mut rec = Recorder::new(grid, y0);
    let h_max = max_step(opts, t_end - t0);
    let mut y = y0.clone();
    let mut f0 = DVector::zeros(n);
    ev.rhs_finite(t0, &y, &mut f0)?;
    let mut h = initial_step(&mut ev, t0, &y, &f0, 2, t_end - t0, opts)?;
    let mut jac = DMatrix::zeros(n, n);
    let mut tder = DVector::zeros(n);
    let (mut k1, mut k2, mut k3) = (DVector::zeros(n), DVector::zeros(n), DVector::zeros(n));
    let (mut f1, mut f2) = (DVector::zeros(n), DVector::zeros(n));
    let mut ys = DVector::zeros(n);
    let mut y_new = DVector::zeros(n);
    let mut err = DVector::zeros(n);
    let mut t = t0;
    let mut jac_current_at = f64::NAN;
    loop {
        ev.check_step_budget()?;
        if jac_current_at != t {
            ev.jacobian(t, &y, Some(&f0), &mut jac)?;
            ev.time_derivative(t, &y, &f0, &mut tder)?;
            jac_current_at = t;
        }
        let mut rejected = false;
        let (t_new, h_step, last, en) = loop {
            check_underflow(&ev, t, h)?;
            let (h_step, t_new, last) = clamp_to_end(t, h, t_end);
            ev.stats.lu_decompositions += 1;
            let Some(w) = IterationMatrix::new(&jac, h_step * d) else {
                ev.reject_step();
                h = 0.5 * h_step;
                rejected = true;
                continue;
            };
            let hd = h_step * d;
            k1.copy_from(&f0);
            k1.axpy(hd, &tder, 1.0);
            let mut ok = w.solve_mut(&mut k1);
            ys.copy_from(&y);
            ys.axpy(0.5 * h_step, &k1, 1.0);
            ev.rhs(t + 0.5 * h_step, &ys, &mut f1)?;
            k2.copy_from(&f1);
            k2 -= &k1;
            ok &= w.solve_mut(&mut k2);
            k2 += &k1;
            y_new.copy_from(&y);
            y_new.axpy(h_step, &k2, 1.0);
            ev.rhs(t_new, &y_new, &mut f2)?;
            for i in 0..n {
                k3[i] = f2[i] - e32 * (k2[i] - f1[i]) - 2.0 * (k1[i] - f0[i]) + hd * tder[i];
            }
            ok &= w.solve_mut(&mut k3);
            for i in 0..n {
                err[i] = h_step / 6.0 * (k1[i] - 2.0 * k2[i] + k3[i]);
            }
            let en = weights.norm(&err, &y, &y_new);
            if !ok || !en.is_finite() || !all_finite(&y_new) || !all_finite(&f2) {
                ev.reject_step();
                h = 0.2 * h_step;
                rejected = true;
                continue;
            }
            if en > 1.0 {
                ev.reject_step();
                h = h_step * (0.8 * en.powf(-1.0 / 3.0)).max(0.5);
                rejected = true;
                continue;
            }
            break (t_new, h_step, last, en);
        };
        let denom = 1.0 - 2.0 * d;
        rec.record(t, t_new, &y_new, |theta, out| {
            let a = theta * (1.0 - theta) / denom;
            let b = theta * (theta - 2.0 * d) / denom;
            for i in 0..n {
                out[i] = y[i] + h_step * (a * k1[i] + b * k2[i]);
            }
        });
        ev.accept_step(t_new);
        if last {
            break;
        }
        let grow = if en == 0.0 {
            5.0
        } else {
            (0.8 * en.powf(-1.0 / 3.0)).min(5.0)
        };
        h = if rejected {
            h_step * grow.min(1.0)
        } else {
            h_step * grow
        }
        .min(h_max);
        t = t_new;
        std::mem::swap(&mut y, &mut y_new);
        std::mem::swap(&mut f0, &mut f2);
    }
    Ok(rec.finish(ev.stats))
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
