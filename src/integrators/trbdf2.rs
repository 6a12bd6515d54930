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

use super::control::{check_underflow, clamp_to_end, initial_step, max_step};
use super::eval::Evaluator;
use super::grid::Recorder;
use super::lu::IterationMatrix;
use super::method::{check_input, invalid};
use super::newton::Newton;
use super::norm::{Weights, rms_norm};
use super::rk23::hermite;
use super::{OdeSystem, OutputGrid, Solution, SolverError, SolverOptions};
use nalgebra::{DMatrix, DVector};

const NAME: &str = "trbdf2";
const NEWTON_MAXITER: usize = 5;

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
    let s2 = 2f64.sqrt();
    let gamma = 2.0 - s2;
    let d = gamma / 2.0;
    let w = s2 / 4.0;
    let (e1, e2, e3) = ((s2 - 1.0) / 3.0, -1.0 / 3.0, gamma / 3.0);
    let tol_ref = weights.reference_tol();
    let kappa = (10.0 * f64::EPSILON / tol_ref).max(0.03f64.min(tol_ref.sqrt()));
    let mut newton = Newton::new(n, NEWTON_MAXITER, kappa);

    let mut ev = Evaluator::new(sys, NAME, opts, t0);
    let mut rec = Recorder::new(grid, y0);
    let h_max = max_step(opts, t_end - t0);
    let mut y = y0.clone();
    let mut fn_ = DVector::zeros(n);
    ev.rhs_finite(t0, &y, &mut fn_)?;
    let mut h = initial_step(&mut ev, t0, &y, &fn_, 2, t_end - t0, opts)?;
    let mut jac = DMatrix::zeros(n, n);
    ev.jacobian(t0, &y, Some(&fn_), &mut jac)?;
    let mut lu: Option<(f64, IterationMatrix)> = None;

    let (mut zg, mut fg) = (DVector::zeros(n), DVector::zeros(n));
    let (mut y_new, mut f_new) = (DVector::zeros(n), DVector::zeros(n));
    let mut base = DVector::zeros(n);
    let mut scale = DVector::zeros(n);
    let mut est = DVector::zeros(n);
    let mut t = t0;
    let mut rejected_last = false;
    loop {
        ev.check_step_budget()?;
        let mut current_jac = false;
        let (t_new, h_step, last, en, iters) = loop {
            check_underflow(&ev, t, h)?;
            let (h_step, t_new, last) = clamp_to_end(t, h, t_end);
            let dh = d * h_step;
            if lu.as_ref().is_none_or(|(c, _)| *c != dh) {
                ev.stats.lu_decompositions += 1;
                lu = IterationMatrix::new(&jac, dh).map(|m| (dh, m));
            }
            weights.fill_scale(&mut scale, &y);
            let mut ok = false;
            let mut iters = 0;
            if let Some((_, wm)) = lu.as_ref() {
                // TR stage, predictor: explicit Euler
                base.copy_from(&y);
                base.axpy(dh, &fn_, 1.0);
                zg.copy_from(&y);
                zg.axpy(gamma * h_step, &fn_, 1.0);
                let o1 =
                    newton.solve(&mut ev, wm, t + gamma * h_step, &base, dh, &mut zg, &scale)?;
                if o1.converged {
                    for i in 0..n {
                        fg[i] = (zg[i] - base[i]) / dh;
                    }
                    // BDF2 stage, predictor: quadratic through (y_n, f_n) and z_γ
                    for i in 0..n {
                        base[i] = y[i] + h_step * w * (fn_[i] + fg[i]);
                        let c2 = (zg[i] - y[i] - gamma * h_step * fn_[i]) / (gamma * gamma);
                        y_new[i] = y[i] + h_step * fn_[i] + c2;
                    }
                    let o2 = newton.solve(&mut ev, wm, t_new, &base, dh, &mut y_new, &scale)?;
                    ok = o2.converged;
                    iters = o1.iters.max(o2.iters);
                }
            }
            if !ok {
                ev.reject_step();
                if !current_jac {
                    ev.jacobian(t, &y, Some(&fn_), &mut jac)?;
                    current_jac = true;
                    lu = None;
                } else {
                    h = 0.5 * h_step;
                    lu = None;
                }
                continue;
            }
            for i in 0..n {
                f_new[i] = (y_new[i] - base[i]) / dh;
                est[i] = h_step * (e1 * fn_[i] + e2 * fg[i] + e3 * f_new[i]);
            }
            weights.fill_scale2(&mut scale, &y, &y_new);
            let raw = rms_norm(&est, &scale);
            let filtered = lu.as_ref().is_some_and(|(_, wm)| wm.solve_mut(&mut est));
            let en = if filtered {
                rms_norm(&est, &scale).max(raw / 16.0)
            } else {
                f64::INFINITY
            };
            if !en.is_finite() || en > 1.0 {
                ev.reject_step();
                let fac = if en.is_finite() {
                    (0.9 * en.powf(-1.0 / 3.0)).max(0.2)
                } else {
                    0.2
                };
                h = h_step * fac;
                rejected_last = true;
                continue;
            }
            break (t_new, h_step, last, en, iters);
        };
        rec.record(t, t_new, &y_new, |theta, out| {
            hermite(theta, h_step, &y, &fn_, &y_new, &f_new, out)
        });
        ev.accept_step(t_new);
        if last {
            break;
        }
        let safety = 0.9 * (2 * NEWTON_MAXITER + 1) as f64 / (2 * NEWTON_MAXITER + iters) as f64;
        let fac_max = if rejected_last { 1.0 } else { 5.0 };
        let fac = if en == 0.0 {
            fac_max
        } else {
            (safety * en.powf(-1.0 / 3.0)).clamp(0.2, fac_max)
        };
        // keep the LU when the step would change by less than 20 %
        if !(0.8..=1.2).contains(&fac) {
            h = (h_step * fac).min(h_max);
        } else {
            h = h_step.min(h_max);
        }
        rejected_last = false;
        t = t_new;
        std::mem::swap(&mut y, &mut y_new);
        std::mem::swap(&mut fn_, &mut f_new);
    }
    Ok(rec.finish(ev.stats))
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
