//! Bogacki–Shampine 3(2), the method of MATLAB's ode23.
//!
//! P. Bogacki, L. F. Shampine, "A 3(2) pair of Runge–Kutta formulas", Appl. Math. Lett. 2
//! (1989) 321–325. Four stages, FSAL, local extrapolation (3rd-order result propagated):
//!
//! `k1 = f(t, y)`, `k2 = f(t + h/2, y + h/2 k1)`, `k3 = f(t + 3h/4, y + 3h/4 k2)`,
//! `y_new = y + h (2/9 k1 + 1/3 k2 + 4/9 k3)`, `k4 = f(t + h, y_new)`,
//! error `h (−5/72 k1 + 1/12 k2 + 1/9 k3 − 1/8 k4)`; step factor `0.9 err^(-1/3)` in `[0.2, 5]`.
//! Dense output: cubic Hermite interpolation of `(y, k1)` and `(y_new, k4)` (3rd order, as ode23).

use super::adaptive::{AdaptiveStepper, Attempt, Step, integrate};
use super::control::Controller;
use super::eval::Evaluator;
use super::hermite::hermite;
use super::norm::{Weights, all_finite};
use super::{OdeSystem, OutputGrid, Solution, SolverError, SolverOptions};
use nalgebra::DVector;

/// Integrates with error control `opts.rtol`, `opts.atol`.
pub fn solve<S: OdeSystem + ?Sized>(
    sys: &S,
    y0: &DVector<f64>,
    grid: &OutputGrid,
    opts: &SolverOptions,
) -> Result<Solution, SolverError> {
    integrate::<BogackiShampine, _>(sys, y0, grid, opts, None)
}

/// Stages `k1 … k4` (`k1 = f(t_n, y_n)`, `k4 = f(t_{n+1}, y_{n+1})`) and scratch.
struct BogackiShampine {
    k: [DVector<f64>; 4],
    ys: DVector<f64>,
    err: DVector<f64>,
}

impl AdaptiveStepper for BogackiShampine {
    const NAME: &'static str = "rk23";
    const START_ORDER: u32 = 2;
    const CONTROL: Controller = Controller {
        exponent: 3.0,
        safety: 0.9,
        fac_min: 0.2,
    };

    fn new(n: usize, _weights: &Weights) -> Self {
        Self {
            k: std::array::from_fn(|_| DVector::zeros(n)),
            ys: DVector::zeros(n),
            err: DVector::zeros(n),
        }
    }

    fn derivative_mut(&mut self) -> &mut DVector<f64> {
        &mut self.k[0]
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
        let ([k1, k2, k3, k4], ys, err) = (&mut self.k, &mut self.ys, &mut self.err);
        ys.copy_from(y);
        ys.axpy(0.5 * h, k1, 1.0);
        ev.rhs(t + 0.5 * h, ys, k2)?;
        ys.copy_from(y);
        ys.axpy(0.75 * h, k2, 1.0);
        ev.rhs(t + 0.75 * h, ys, k3)?;
        for i in 0..y.len() {
            dy[i] = h * (2.0 / 9.0 * k1[i] + 1.0 / 3.0 * k2[i] + 4.0 / 9.0 * k3[i]);
            y_new[i] = y[i] + dy[i];
        }
        ev.rhs(t_new, y_new, k4)?;
        for i in 0..y.len() {
            err[i] = h
                * (-5.0 / 72.0 * k1[i] + 1.0 / 12.0 * k2[i] + 1.0 / 9.0 * k3[i]
                    - 1.0 / 8.0 * k4[i]);
        }
        let en = weights.norm(err, y, y_new);
        Ok(Attempt::checked(en, all_finite(y_new) && all_finite(k4)))
    }

    fn interpolate(
        &self,
        theta: f64,
        h: f64,
        y: &DVector<f64>,
        y_new: &DVector<f64>,
        out: &mut DVector<f64>,
    ) {
        hermite(theta, h, y, &self.k[0], y_new, &self.k[3], out)
    }

    fn accept(&mut self) {
        self.k.swap(0, 3);
    }
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
