//! Bogacki–Shampine 3(2), the method of MATLAB's ode23.
//!
//! P. Bogacki, L. F. Shampine, "A 3(2) pair of Runge–Kutta formulas", Appl. Math. Lett. 2
//! (1989) 321–325. Four stages, FSAL, local extrapolation (3rd-order result propagated):
//!
//! `k1 = f(t, y)`, `k2 = f(t + h/2, y + h/2 k1)`, `k3 = f(t + 3h/4, y + 3h/4 k2)`,
//! `y_new = y + h (2/9 k1 + 1/3 k2 + 4/9 k3)`, `k4 = f(t + h, y_new)`,
//! error `h (−5/72 k1 + 1/12 k2 + 1/9 k3 − 1/8 k4)`; step factor `0.9 err^(-1/3)` in `[0.2, 5]`.
//! Dense output: cubic Hermite interpolation of `(y, k1)` and `(y_new, k4)` (3rd order, as ode23).

use super::control::{check_underflow, clamp_to_end, factor, initial_step, max_step};
use super::eval::Evaluator;
use super::grid::Recorder;
use super::method::{check_input, invalid};
use super::norm::{Weights, all_finite};
use super::{OdeSystem, OutputGrid, Solution, SolverError, SolverOptions};
use nalgebra::DVector;

const NAME: &str = "rk23";

/// Cubic Hermite interpolation on `[t, t + h]` at `θ`: writes into `out`.
pub(crate) fn hermite(
    theta: f64,
    h: f64,
    y0: &DVector<f64>,
    f0: &DVector<f64>,
    y1: &DVector<f64>,
    f1: &DVector<f64>,
    out: &mut DVector<f64>,
) {
    let t2 = theta * theta;
    let t3 = t2 * theta;
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = t3 - 2.0 * t2 + theta;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = t3 - t2;
    for i in 0..out.len() {
        out[i] = h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i];
    }
}

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
    let mut ev = Evaluator::new(sys, NAME, opts, t0);
    let mut rec = Recorder::new(grid, y0);
    let h_max = max_step(opts, t_end - t0);
    let (mut k1, mut k2, mut k3, mut k4) = (
        DVector::zeros(n),
        DVector::zeros(n),
        DVector::zeros(n),
        DVector::zeros(n),
    );
    let mut y = y0.clone();
    let mut y_new = DVector::zeros(n);
    let mut ys = DVector::zeros(n);
    let mut err = DVector::zeros(n);
    ev.rhs_finite(t0, &y, &mut k1)?;
    let mut h = initial_step(&mut ev, t0, &y, &k1, 2, t_end - t0, opts)?;
    let mut t = t0;
    let mut rejected_last = false;
    loop {
        ev.check_step_budget()?;
        check_underflow(&ev, t, h)?;
        let (h_step, t_new, last) = clamp_to_end(t, h, t_end);
        ys.copy_from(&y);
        ys.axpy(0.5 * h_step, &k1, 1.0);
        ev.rhs(t + 0.5 * h_step, &ys, &mut k2)?;
        ys.copy_from(&y);
        ys.axpy(0.75 * h_step, &k2, 1.0);
        ev.rhs(t + 0.75 * h_step, &ys, &mut k3)?;
        for i in 0..n {
            y_new[i] = y[i] + h_step * (2.0 / 9.0 * k1[i] + 1.0 / 3.0 * k2[i] + 4.0 / 9.0 * k3[i]);
        }
        ev.rhs(t_new, &y_new, &mut k4)?;
        for i in 0..n {
            err[i] = h_step
                * (-5.0 / 72.0 * k1[i] + 1.0 / 12.0 * k2[i] + 1.0 / 9.0 * k3[i]
                    - 1.0 / 8.0 * k4[i]);
        }
        let en = weights.norm(&err, &y, &y_new);
        if !en.is_finite() || !all_finite(&y_new) || !all_finite(&k4) {
            ev.reject_step();
            h = 0.2 * h_step;
            rejected_last = true;
            continue;
        }
        if en > 1.0 {
            ev.reject_step();
            h = h_step * factor(en, 3.0, 0.9, 0.2, 1.0);
            rejected_last = true;
            continue;
        }
        rec.record(t, t_new, &y_new, |theta, out| {
            hermite(theta, h_step, &y, &k1, &y_new, &k4, out)
        });
        ev.accept_step(t_new);
        if last {
            break;
        }
        let fac_max = if rejected_last { 1.0 } else { 5.0 };
        h = (h_step * factor(en, 3.0, 0.9, 0.2, fac_max)).min(h_max);
        rejected_last = false;
        t = t_new;
        std::mem::swap(&mut y, &mut y_new);
        std::mem::swap(&mut k1, &mut k4);
    }
    Ok(rec.finish(ev.stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::FailureKind;
    use crate::integrators::tests_common::{Decay, Oscillator, max_error};

    #[test]
    fn decay_within_tolerance() {
        let grid = OutputGrid::new(0.0, 2.0, 0.01).unwrap();
        let y0 = DVector::from_vec(vec![1.0]);
        for tol in [1e-4, 1e-6, 1e-8] {
            let sol = solve(
                &Decay { lambda: 1.0 },
                &y0,
                &grid,
                &SolverOptions::absolute(tol),
            )
            .unwrap();
            let e = max_error(&sol, |t| vec![(-t).exp()]);
            assert!(e < 10.0 * tol, "tol {tol}: error {e}");
        }
    }

    #[test]
    fn oscillator_steps_scale_like_tol_to_the_third_root() {
        let sys = Oscillator { omega: 2.0 };
        let grid = OutputGrid::new(0.0, 10.0, 0.01).unwrap();
        let y0 = DVector::from_vec(vec![1.0, 0.0]);
        let run = |tol: f64| {
            let sol = solve(&sys, &y0, &grid, &SolverOptions::absolute(tol)).unwrap();
            (
                max_error(&sol, |t| sys.exact(t).to_vec()),
                sol.stats.steps as f64,
            )
        };
        let (e1, n1) = run(1e-5);
        let (e2, n2) = run(1e-8);
        assert!(e2 < e1 && e2 < 1e-6, "{e1} {e2}");
        let ratio = n2 / n1; // 1000^(1/3) = 10
        assert!(ratio > 7.0 && ratio < 13.0, "step ratio {ratio}");
    }

    #[test]
    fn stiff_problem_hits_the_step_cap() {
        let grid = OutputGrid::new(0.0, 10.0, 1.0).unwrap();
        let y0 = DVector::from_vec(vec![1.0]);
        let opts = SolverOptions {
            max_steps: 500,
            ..SolverOptions::absolute(1e-6)
        };
        let err = solve(&Decay { lambda: 1e6 }, &y0, &grid, &opts).unwrap_err();
        assert_eq!(err.kind, FailureKind::StepLimit { max_steps: 500 });
        assert!(err.t < 1e-2);
    }
}
