//! Variable-order (1–5) BDF / NDF with quasi-constant step size, the scheme of MATLAB's ode15s.
//!
//! L. F. Shampine, M. W. Reichelt, "The MATLAB ODE Suite", SIAM J. Sci. Comput. 18 (1997)
//! 1–22, §2 (and its SciPy port `scipy.integrate.BDF`); the modified-divided-difference
//! (backward-difference) representation goes back to Byrne & Hindmarsh (1975); BDF theory in
//! Hairer & Wanner, *Solving ODEs II*, §III.1 and §IV.8.
//!
//! The solution history is kept as backward differences `D_j = ∇^j y_n` for a constant step
//! `h`; the order-`k` formula (NDF with `κ_k`, BDF with `κ = 0`; Shampine & Reichelt eq. 2–3)
//!
//! `(1 − κ_k) γ_k (y_{n+1} − y⁽⁰⁾_{n+1}) + Σ_{j=1..k} γ_j ∇^j y_n = h f(t_{n+1}, y_{n+1})`,
//! `γ_j = Σ_{i=1..j} 1/i`, `y⁽⁰⁾_{n+1} = Σ_{j=0..k} ∇^j y_n`,
//!
//! is solved by simplified Newton with iteration matrix `I − h/((1−κ_k)γ_k) J` (J reused
//! across steps and refreshed only when Newton fails, as ode15s does). The local error is
//! `(κ_k γ_k + 1/(k+1)) ‖y_{n+1} − y⁽⁰⁾_{n+1}‖`. When the step changes, the differences are
//! interpolated to the new spacing (`change_d`). After `k + 1` steps of equal size the
//! orders `k − 1`, `k`, `k + 1` are compared and the one allowing the largest step is taken.
//! Dense output: the interpolating polynomial of the accepted step (degree `k`, through
//! `y_{n+1}, …, y_{n+1−k}`), evaluated before any order or step change.
//!
//! Precision over long runs: Newton iterates on the increment `y_{n+1} − y_n` (the
//! predictor `Σ_{j≥1} ∇^j y_n` and the corrector relative to `D_0 = y_n`, `f` evaluated at
//! the rounded `y_n + z`), and `D_0 ← D_0 + ∇y_{n+1}` is a compensated sum (Kahan 1965,
//! Neumaier 1974; see [`super::adaptive`]), so that a growing state keeps the precision of its
//! increments instead of losing up to half an ulp per step; periodic components are held as
//! whole periods plus a remainder (`turns.rs`).

use super::adaptive::compensated_add;
use super::control::{check_underflow, initial_step, max_step, min_step};
use super::eval::Evaluator;
use super::grid::Recorder;
use super::input::{check_input, invalid};
use super::newton::{IterationMatrix, Newton, iteration_matrix};
use super::norm::{Weights, rms_norm};
use super::turns::Turns;
use super::{OdeSystem, OutputGrid, Solution, SolverError, SolverOptions};
use nalgebra::{DMatrix, DVector};

const MAX_ORDER: usize = 5;
const NEWTON_MAXITER: usize = 4;
const MIN_FACTOR: f64 = 0.2;
const MAX_FACTOR: f64 = 10.0;

/// Which family of formulas.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Formula {
    /// Backward differentiation formulas (`κ = 0`; ADAMS' GSTIFF is a BDF code).
    Bdf,
    /// Klopfenstein–Shampine numerical differentiation formulas (ode15s default).
    Ndf,
}

/// `R` of Shampine & Reichelt for a step ratio `factor`: `R_{ij} = Π_{m=1..i} (m − 1 − factor j)/m`.
fn compute_r(order: usize, factor: f64) -> [[f64; MAX_ORDER + 1]; MAX_ORDER + 1] {
    let mut m = [[0.0; MAX_ORDER + 1]; MAX_ORDER + 1];
    m[0].iter_mut().take(order + 1).for_each(|v| *v = 1.0);
    for (i, row) in m.iter_mut().enumerate().take(order + 1).skip(1) {
        for (j, v) in row.iter_mut().enumerate().take(order + 1).skip(1) {
            *v = (i as f64 - 1.0 - factor * j as f64) / i as f64;
        }
    }
    // cumulative product down the rows
    for i in 1..=order {
        let (done, rest) = m.split_at_mut(i);
        for (v, p) in rest[0].iter_mut().zip(done[i - 1].iter()).take(order + 1) {
            *v *= p;
        }
    }
    m
}

/// Re-expresses the differences `D[0..=order]` for the step `factor · h`.
fn change_d(d: &mut [DVector<f64>], order: usize, factor: f64, tmp: &mut [DVector<f64>]) {
    let r = compute_r(order, factor);
    let u = compute_r(order, 1.0);
    let mut ru = [[0.0; MAX_ORDER + 1]; MAX_ORDER + 1];
    for i in 0..=order {
        for j in 0..=order {
            ru[i][j] = (0..=order).map(|m| r[i][m] * u[m][j]).sum();
        }
    }
    for i in 0..=order {
        tmp[i].fill(0.0);
        for m in 0..=order {
            tmp[i].axpy(ru[m][i], &d[m], 1.0);
        }
    }
    for i in 0..=order {
        d[i].copy_from(&tmp[i]);
    }
}

/// Integrates with error control `opts.rtol`, `opts.atol` (or their per-component forms).
pub fn solve<S: OdeSystem + ?Sized>(
    sys: &S,
    y0: &DVector<f64>,
    grid: &OutputGrid,
    opts: &SolverOptions,
    formula: Formula,
) -> Result<Solution, SolverError> {
    let name = match formula {
        Formula::Bdf => "bdf",
        Formula::Ndf => "ndf",
    };
    let (t0, t_end) = (grid.t0, grid.t_end());
    check_input(sys, y0, opts).map_err(|m| invalid(name, t0, m))?;
    let n = y0.len();
    let weights = Weights::new(opts, n);
    let mut ev = Evaluator::new(sys, name, opts, t0);
    let mut rec = Recorder::new(grid, y0);
    let h_max = max_step(opts, t_end - t0);

    let kappa: [f64; MAX_ORDER + 1] = match formula {
        Formula::Bdf => [0.0; MAX_ORDER + 1],
        Formula::Ndf => [0.0, -0.1850, -1.0 / 9.0, -0.0823, -0.0415, 0.0],
    };
    let mut gamma = [0.0; MAX_ORDER + 1];
    for k in 1..=MAX_ORDER {
        gamma[k] = gamma[k - 1] + 1.0 / k as f64;
    }
    let alpha: [f64; MAX_ORDER + 1] = std::array::from_fn(|k| (1.0 - kappa[k]) * gamma[k]);
    // error constant of order k: κ_k γ_k + 1/(k+1) (κ = 0 beyond the last order)
    let error_const: [f64; MAX_ORDER + 2] = std::array::from_fn(|k| {
        let kg = if k <= MAX_ORDER {
            kappa[k] * gamma[k]
        } else {
            0.0
        };
        kg + 1.0 / (k as f64 + 1.0)
    });
    let tol_ref = weights.reference_tol();
    let newton_kappa = (10.0 * f64::EPSILON / tol_ref).max(0.03f64.min(tol_ref.sqrt()));
    let mut newton = Newton::new(n, NEWTON_MAXITER, newton_kappa);

    let mut f0 = DVector::zeros(n);
    ev.rhs_finite(t0, y0, &mut f0)?;
    let mut h_abs = initial_step(&mut ev, t0, y0, &f0, 1, t_end - t0, opts)?;
    let mut jac = DMatrix::zeros(n, n);
    ev.jacobian(t0, y0, Some(&f0), &mut jac)?;

    let mut d: Vec<DVector<f64>> = (0..MAX_ORDER + 3).map(|_| DVector::zeros(n)).collect();
    let mut tmp: Vec<DVector<f64>> = (0..MAX_ORDER + 1).map(|_| DVector::zeros(n)).collect();
    d[0].copy_from(y0);
    d[1].copy_from(&(&f0 * h_abs));
    let mut order = 1usize;
    let mut n_equal_steps = 0usize;
    let mut lu: Option<IterationMatrix> = None;
    let mut t = t0;

    let mut y_pred = DVector::zeros(n);
    // predictor and corrector relative to d[0] = y_n (increment form), and the compensation
    // of d[0] (the exact y_n is d[0] + comp)
    let mut pred_inc = DVector::zeros(n);
    let mut z_inc = DVector::zeros(n);
    let mut comp = DVector::zeros(n);
    let mut y_n = DVector::zeros(n);
    // periodic components as whole periods + remainder (turns.rs)
    let mut turns = Turns::new(sys, n);
    let mut y_full = DVector::zeros(n);
    if turns.wrap(&mut d[0], &mut comp) {
        weights.set_offset(turns.offset());
    }
    let mut psi = DVector::zeros(n);
    let mut base = DVector::zeros(n);
    let mut y_new = DVector::zeros(n);
    let mut dd = DVector::zeros(n);
    let mut scale = DVector::zeros(n);
    let mut err = DVector::zeros(n);

    loop {
        ev.check_step_budget()?;
        if h_abs > h_max {
            change_d(&mut d, order, h_max / h_abs, &mut tmp);
            h_abs = h_max;
            n_equal_steps = 0;
            lu = None;
        }
        let mut current_jac = false;
        let (t_new, safety, err_norm) = loop {
            check_underflow(&ev, t, h_abs)?;
            let mut t_new = t + h_abs;
            if t_new + 0.01 * h_abs >= t_end {
                t_new = t_end;
                let f = (t_new - t) / h_abs;
                if f != 1.0 {
                    change_d(&mut d, order, f, &mut tmp);
                    n_equal_steps = 0;
                    lu = None;
                }
                h_abs = t_new - t;
                if h_abs < min_step(t) {
                    check_underflow(&ev, t, h_abs)?;
                }
            }
            pred_inc.fill(0.0);
            for dj in d.iter().take(order + 1).skip(1) {
                pred_inc += dj;
            }
            y_pred.copy_from(&d[0]);
            y_pred += &pred_inc;
            weights.fill_scale(&mut scale, &y_pred);
            psi.fill(0.0);
            for j in 1..=order {
                psi.axpy(gamma[j] / alpha[order], &d[j], 1.0);
            }
            let c = h_abs / alpha[order];
            // z = y_pred + d with z = (y_pred − psi) + c f(z), relative to y_n = d[0]
            base.copy_from(&pred_inc);
            base -= &psi;
            let mut converged = false;
            let mut iters = 0;
            loop {
                if lu.is_none() {
                    ev.stats.lu_decompositions += 1;
                    lu = iteration_matrix(&jac, c);
                }
                if let Some(w) = lu.as_ref() {
                    z_inc.copy_from(&pred_inc);
                    let out =
                        newton.solve(&mut ev, w, t_new, &base, c, &d[0], &mut z_inc, &scale)?;
                    converged = out.converged;
                    iters = out.iters;
                }
                if converged || current_jac {
                    break;
                }
                ev.jacobian(t_new, &y_pred, None, &mut jac)?;
                lu = None;
                current_jac = true;
            }
            if !converged {
                ev.reject_step();
                change_d(&mut d, order, 0.5, &mut tmp);
                h_abs *= 0.5;
                n_equal_steps = 0;
                lu = None;
                continue;
            }
            y_new.copy_from(&d[0]);
            y_new += &z_inc;
            let safety =
                0.9 * (2 * NEWTON_MAXITER + 1) as f64 / (2 * NEWTON_MAXITER + iters) as f64;
            dd.copy_from(&z_inc);
            dd -= &pred_inc;
            weights.fill_scale(&mut scale, &y_new);
            err.copy_from(&dd);
            err *= error_const[order];
            let err_norm = rms_norm(&err, &scale);
            if err_norm > 1.0 || !err_norm.is_finite() {
                ev.reject_step();
                let factor = if err_norm.is_finite() {
                    (safety * err_norm.powf(-1.0 / (order as f64 + 1.0))).max(MIN_FACTOR)
                } else {
                    MIN_FACTOR
                };
                change_d(&mut d, order, factor, &mut tmp);
                h_abs *= factor;
                n_equal_steps = 0;
                continue;
            }
            break (t_new, safety, err_norm);
        };

        // accepted: update the differences (D^{j+1} y_{n+1} = D^j y_{n+1} − D^j y_n)
        n_equal_steps += 1;
        for i in 0..n {
            d[order + 2][i] = dd[i] - d[order + 1][i];
            d[order + 1][i] = dd[i];
        }
        for i in (1..=order).rev() {
            let (lo, hi) = d.split_at_mut(i + 1);
            lo[i] += &hi[0];
        }
        y_n.copy_from(&d[0]);
        {
            let (d0, rest) = d.split_at_mut(1);
            compensated_add(&y_n, &rest[0], &mut comp, &mut d0[0]);
        }
        y_new.copy_from(&d[0]);
        turns.full(&y_new, &mut y_full);
        if weights.take_floored() {
            ev.stats.floored_steps += 1;
        }
        ev.accept_step(t_new);
        {
            let d_ref = &d;
            let offset = turns.offset();
            rec.record(t, t_new, &y_full, |theta, out| {
                out.copy_from(&d_ref[0]);
                let mut p = 1.0;
                for (j, dj) in d_ref.iter().enumerate().take(order + 1).skip(1) {
                    let m = (j - 1) as f64;
                    p *= (theta - 1.0 + m) / (m + 1.0);
                    out.axpy(p, dj, 1.0);
                }
                *out += offset;
            });
        }
        if turns.wrap(&mut d[0], &mut comp) {
            weights.set_offset(turns.offset());
        }
        t = t_new;
        if t_new >= t_end {
            break;
        }
        if n_equal_steps < order + 1 {
            continue;
        }
        // order and step selection
        let err_m = if order > 1 {
            rms_norm(&(&d[order] * error_const[order - 1]), &scale)
        } else {
            f64::INFINITY
        };
        let err_p = if order < MAX_ORDER {
            rms_norm(&(&d[order + 2] * error_const[order + 1]), &scale)
        } else {
            f64::INFINITY
        };
        let norms = [err_m, err_norm, err_p];
        let mut best = 1usize;
        let mut best_fac = 0.0;
        for (i, &e) in norms.iter().enumerate() {
            let fac = if e == 0.0 {
                f64::INFINITY
            } else {
                e.powf(-1.0 / (order as f64 + i as f64))
            };
            if fac > best_fac {
                best_fac = fac;
                best = i;
            }
        }
        order = order + best - 1;
        let factor = (safety * best_fac).min(MAX_FACTOR);
        change_d(&mut d, order, factor, &mut tmp);
        h_abs *= factor;
        n_equal_steps = 0;
        lu = None;
    }
    Ok(rec.finish(ev.stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::JacobianSource;
    use crate::integrators::tests_common::{Decay, Oscillator, ProtheroRobinson, max_error};

    #[test]
    fn step_change_keeps_the_polynomial() {
        // D for y(t) = t^3 sampled backwards from t = 1 with h = 0.1, rescaled to h = 0.05:
        // must equal the differences of the same cubic at the new spacing.
        let diffs = |h: f64| -> Vec<DVector<f64>> {
            let ys: Vec<f64> = (0..4).map(|i| (1.0 - i as f64 * h).powi(3)).collect();
            let mut out = vec![ys.clone()];
            for _ in 1..4 {
                let last = out.last().unwrap().clone();
                out.push((0..last.len() - 1).map(|i| last[i] - last[i + 1]).collect());
            }
            out.iter().map(|v| DVector::from_vec(vec![v[0]])).collect()
        };
        let mut d = diffs(0.1);
        let mut tmp: Vec<DVector<f64>> = (0..6).map(|_| DVector::zeros(1)).collect();
        change_d(&mut d, 3, 0.5, &mut tmp);
        let want = diffs(0.05);
        for j in 0..4 {
            assert!(
                (d[j][0] - want[j][0]).abs() < 1e-14,
                "D{j}: {} vs {}",
                d[j][0],
                want[j][0]
            );
        }
    }

    #[test]
    fn oscillator_error_follows_tolerance() {
        let sys = Oscillator { omega: 2.0 };
        let grid = OutputGrid::new(0.0, 5.0, 0.01).unwrap();
        let y0 = DVector::from_vec(vec![1.0, 0.0]);
        let mut last = f64::INFINITY;
        for tol in [1e-4, 1e-6, 1e-8, 1e-10] {
            let sol = solve(
                &sys,
                &y0,
                &grid,
                &SolverOptions::absolute(tol),
                Formula::Bdf,
            )
            .unwrap();
            let e = max_error(&sol, |t| sys.exact(t).to_vec());
            // BDF propagates the order-k result with error-per-step control: the global error
            // grows somewhat faster than tol (15× tol at 1e-4, 175× at 1e-10 here)
            assert!(e < 1000.0 * tol && e < last, "tol {tol}: error {e}");
            last = e;
        }
    }

    #[test]
    fn stiff_decay_takes_few_steps() {
        // an explicit method would need ~1e9 steps; here the transient is resolved, then the
        // step grows freely
        let grid = OutputGrid::new(0.0, 10.0, 0.5).unwrap();
        let y0 = DVector::from_vec(vec![1.0]);
        for formula in [Formula::Bdf, Formula::Ndf] {
            let sol = solve(
                &Decay { lambda: 1e8 },
                &y0,
                &grid,
                &SolverOptions::absolute(1e-6),
                formula,
            )
            .unwrap();
            assert!(sol.stats.steps < 300, "{:?}: {}", formula, sol.stats);
            assert!(sol.last()[0].abs() < 1e-8);
        }
    }

    #[test]
    fn prothero_robinson_with_fd_jacobian() {
        let sys = ProtheroRobinson { lambda: 1e5 };
        let grid = OutputGrid::new(0.0, 3.0, 0.01).unwrap();
        let y0 = DVector::from_vec(vec![0.0]);
        let opts = SolverOptions {
            jacobian: JacobianSource::FiniteDifference,
            ..SolverOptions::absolute(1e-7)
        };
        let sol = solve(&sys, &y0, &grid, &opts, Formula::Bdf).unwrap();
        let e = max_error(&sol, |t| vec![t.sin()]);
        assert!(e < 1e-6, "error {e}");
        assert!(sol.stats.steps < 2000, "{}", sol.stats);
        assert!(sol.stats.rhs_evals >= sol.stats.jac_evals);
    }
}
