//! TR-BDF2, the method of MATLAB's ode23tb.
//!
//! M. E. Hosea, L. F. Shampine, "Analysis and implementation of TR-BDF2", Appl. Numer. Math.
//! 20 (1996) 21–37 (original: Bank et al. 1985). With `γ = 2 − √2`, `d = γ/2`, `w = √2/4`,
//! one step is a trapezoidal stage to `t + γh` followed by a BDF2 stage to `t + h`,
//! written as an ESDIRK (c = (0, γ, 1)):
//!
//! - TR:   `z_γ = y_n + d h (f_n + f(t + γh, z_γ))`
//! - BDF2: `y_{n+1} = y_n + h (w f_n + w f_γ + d f(t + h, y_{n+1}))`
//!   (equivalently `y_{n+1} − d h f_{n+1} = ((1+√2) z_γ − (√2−1) y_n)/2`).
//!
//! Both stages share the iteration matrix `W = I − d h J` (one LU per step size; `J` reused
//! across steps and refreshed only when Newton fails). The error of the second-order result is
//! estimated against the embedded third-order weights `((1−w)/3, (3w+1)/3, d/3)`:
//! `est = h ((√2−1)/3 f_n − 1/3 f_γ + γ/3 f_{n+1})`. As in ode23tb, the error is
//! `max(‖W⁻¹ est‖, ‖est‖/16)`: the filtered estimate keeps stiff components from inflating it
//! (cf. Hairer & Wanner, *Solving ODEs II*, eq. IV.8.20), the bound by the raw one keeps it
//! from hiding a real error at large `hλ`. Step factor `0.9 err^(-1/3)` in `[0.2, 5]`,
//! reduced when Newton needed many iterations; the step is kept when the factor is within
//! 20 % of 1 (so the LU can be reused). Stage derivatives are taken from the stage equations
//! (`f_γ = (z_γ − y_n)/(d h) − f_n` etc.), so `f_{n+1}` serves as `f_n` of the next step.
//! Dense output: cubic Hermite through `(y_n, f_n)`, `(y_{n+1}, f_{n+1})`.

use super::adaptive::{AdaptiveStepper, Attempt, Step, integrate};
use super::control::Controller;
use super::eval::Evaluator;
use super::hermite::hermite;
use super::newton::{IterationMatrix, Newton, iteration_matrix};
use super::norm::{Weights, rms_norm};
use super::{OdeSystem, OutputGrid, Solution, SolverError, SolverOptions};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::SQRT_2;

const NEWTON_MAXITER: usize = 5;
/// `γ = 2 − √2`, `d = γ/2`, `w = √2/4`.
const GAMMA: f64 = 2.0 - SQRT_2;
const D: f64 = GAMMA / 2.0;
const W: f64 = SQRT_2 / 4.0;
/// Weights of the error estimate.
const E: [f64; 3] = [(SQRT_2 - 1.0) / 3.0, -1.0 / 3.0, GAMMA / 3.0];

/// Integrates with error control `opts.rtol`, `opts.atol`.
pub fn solve<S: OdeSystem + ?Sized>(
    sys: &S,
    y0: &DVector<f64>,
    grid: &OutputGrid,
    opts: &SolverOptions,
) -> Result<Solution, SolverError> {
    integrate::<TrBdf2, _>(sys, y0, grid, opts, None)
}

/// The Jacobian and its iteration matrix, Newton state, stages.
struct TrBdf2 {
    newton: Newton,
    jac: DMatrix<f64>,
    /// `W = I − d h J` for the `d h` it was factored with.
    lu: Option<(f64, IterationMatrix)>,
    /// `J` was evaluated at the start of the current step.
    current_jac: bool,
    /// Newton failed with an old `J`: re-evaluate it before the next attempt.
    refresh_jac: bool,
    /// Newton iterations of the last successful attempt (larger of the two stages).
    iters: usize,
    /// `f_n`, `z_γ`, `f_γ`, `f_{n+1}`, then scratch.
    fn_: DVector<f64>,
    zg: DVector<f64>,
    fg: DVector<f64>,
    f_new: DVector<f64>,
    base: DVector<f64>,
    scale: DVector<f64>,
    est: DVector<f64>,
}

impl AdaptiveStepper for TrBdf2 {
    const NAME: &'static str = "trbdf2";
    const START_ORDER: u32 = 2;
    const CONTROL: Controller = Controller {
        exponent: 3.0,
        safety: 0.9,
        fac_min: 0.2,
    };

    fn new(n: usize, weights: &Weights) -> Self {
        let tol_ref = weights.reference_tol();
        let kappa = (10.0 * f64::EPSILON / tol_ref).max(0.03f64.min(tol_ref.sqrt()));
        let z = || DVector::zeros(n);
        Self {
            newton: Newton::new(n, NEWTON_MAXITER, kappa),
            jac: DMatrix::zeros(n, n),
            lu: None,
            current_jac: false,
            refresh_jac: false,
            iters: 0,
            fn_: z(),
            zg: z(),
            fg: z(),
            f_new: z(),
            base: z(),
            scale: z(),
            est: z(),
        }
    }

    fn derivative_mut(&mut self) -> &mut DVector<f64> {
        &mut self.fn_
    }

    /// The first Jacobian; later ones only when Newton fails.
    fn start<S: OdeSystem + ?Sized>(
        &mut self,
        ev: &mut Evaluator<'_, S>,
        t0: f64,
        y0: &DVector<f64>,
    ) -> Result<(), SolverError> {
        ev.jacobian(t0, y0, Some(&self.fn_), &mut self.jac)
    }

    fn begin_step<S: OdeSystem + ?Sized>(
        &mut self,
        _ev: &mut Evaluator<'_, S>,
        _t: f64,
        _y: &DVector<f64>,
    ) -> Result<(), SolverError> {
        self.current_jac = false;
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
        let Step { t, h, t_new, h_req } = *step;
        if self.refresh_jac {
            ev.jacobian(t, y, Some(&self.fn_), &mut self.jac)?;
            self.current_jac = true;
            self.refresh_jac = false;
        }
        let n = y.len();
        let dh = D * h;
        // the factorisation is kept while the requested step is unchanged (the exact step
        // differs from it by the rounding of t + h; simplified Newton does not mind)
        let dh_req = D * h_req;
        if self.lu.as_ref().is_none_or(|(c, _)| *c != dh_req) {
            ev.stats.lu_decompositions += 1;
            self.lu = iteration_matrix(&self.jac, dh_req).map(|m| (dh_req, m));
        }
        let Self {
            newton,
            fn_,
            zg,
            fg,
            base,
            scale,
            ..
        } = self;
        weights.fill_scale(scale, y);
        let mut iters = None;
        if let Some((_, wm)) = self.lu.as_ref() {
            // in increment form (Newton's unknowns and `base` relative to y_n, see
            // `Newton::solve`), so that the step's increment keeps its own precision
            // TR stage, predictor: explicit Euler
            for i in 0..n {
                base[i] = dh * fn_[i];
                zg[i] = GAMMA * h * fn_[i];
            }
            let o1 = newton.solve(ev, wm, t + GAMMA * h, base, dh, y, zg, scale)?;
            if o1.converged {
                for i in 0..n {
                    fg[i] = (zg[i] - base[i]) / dh;
                }
                // BDF2 stage, predictor: quadratic through (y_n, f_n) and z_γ
                for i in 0..n {
                    base[i] = h * W * (fn_[i] + fg[i]);
                    let c2 = (zg[i] - GAMMA * h * fn_[i]) / (GAMMA * GAMMA);
                    dy[i] = h * fn_[i] + c2;
                }
                let o2 = newton.solve(ev, wm, t_new, base, dh, y, dy, scale)?;
                for i in 0..n {
                    y_new[i] = y[i] + dy[i];
                }
                iters = o2.converged.then_some(o1.iters.max(o2.iters));
            }
        }
        let Some(iters) = iters else {
            self.lu = None;
            // first failure of the step: retry it with a fresh Jacobian, then halve it
            self.refresh_jac = !self.current_jac;
            let shrink = self.current_jac.then_some(0.5);
            return Ok(Attempt::Failed {
                shrink,
                cap_growth: false,
            });
        };
        self.iters = iters;
        for i in 0..n {
            self.f_new[i] = (dy[i] - self.base[i]) / dh;
            self.est[i] = h * (E[0] * self.fn_[i] + E[1] * self.fg[i] + E[2] * self.f_new[i]);
        }
        let (est, scale) = (&mut self.est, &mut self.scale);
        weights.fill_scale2(scale, y, y_new);
        let raw = rms_norm(est, scale);
        let filtered = self.lu.as_ref().is_some_and(|(_, wm)| wm.solve_mut(est));
        let en = if filtered {
            rms_norm(est, scale).max(raw / 16.0)
        } else {
            f64::INFINITY
        };
        Ok(Attempt::Estimated(en))
    }

    fn interpolate(
        &self,
        theta: f64,
        h: f64,
        y: &DVector<f64>,
        y_new: &DVector<f64>,
        out: &mut DVector<f64>,
    ) {
        hermite(theta, h, y, &self.fn_, y_new, &self.f_new, out)
    }

    fn accept(&mut self) {
        std::mem::swap(&mut self.fn_, &mut self.f_new);
    }

    /// Safety factor lowered when Newton needed many iterations; the step is kept when the
    /// factor is within 20 % of 1 (so the LU can be reused).
    fn accept_factor(&self, err: f64, fac_max: f64) -> f64 {
        let safety =
            0.9 * (2 * NEWTON_MAXITER + 1) as f64 / (2 * NEWTON_MAXITER + self.iters) as f64;
        let fac = Controller {
            safety,
            ..Self::CONTROL
        }
        .factor(err, fac_max);
        if (0.8..=1.2).contains(&fac) { 1.0 } else { fac }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::tests_common::{Decay, Oscillator, ProtheroRobinson, max_error};

    #[test]
    fn oscillator_error_follows_tolerance() {
        let sys = Oscillator { omega: 2.0 };
        let grid = OutputGrid::new(0.0, 5.0, 0.01).unwrap();
        let y0 = DVector::from_vec(vec![1.0, 0.0]);
        let mut last = f64::INFINITY;
        let mut steps = vec![];
        for tol in [1e-5, 1e-8] {
            let sol = solve(&sys, &y0, &grid, &SolverOptions::absolute(tol)).unwrap();
            let e = max_error(&sol, |t| sys.exact(t).to_vec());
            // second order without local extrapolation: global error ~ tol^(2/3)
            assert!(
                e < 20.0 * tol.powf(2.0 / 3.0) && e < last,
                "tol {tol}: error {e}"
            );
            last = e;
            steps.push(sol.stats.steps as f64);
        }
        let ratio = steps[1] / steps[0];
        assert!(ratio > 7.0 && ratio < 13.0, "step ratio {ratio}");
    }

    #[test]
    fn stiff_decay_takes_few_steps() {
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
        let sys = ProtheroRobinson { lambda: 1e6 };
        let grid = OutputGrid::new(0.0, 3.0, 0.01).unwrap();
        let y0 = DVector::from_vec(vec![0.0]);
        let sol = solve(&sys, &y0, &grid, &SolverOptions::absolute(1e-6)).unwrap();
        let e = max_error(&sol, |t| vec![t.sin()]);
        assert!(e < 2e-5, "error {e}");
        assert!(sol.stats.steps < 2000, "{}", sol.stats);
    }
}
