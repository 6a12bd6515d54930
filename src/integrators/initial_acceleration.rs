//! The thesis' "initial acceleration" method (metoda počátečního zrychlení), §4.1.1.
//!
//! For a second-order system `q̈ = a(t, q, q̇)` (state `y = [q; q̇]`, `f = [q̇; a]`), each step
//! freezes the acceleration at its value at the start of the step (eq. 4.5) and integrates the
//! kinematics exactly over the step `τ ∈ [0, Δt]`:
//!
//! - eq. 4.8/4.9:  `q̇(τ) = q̇_k + q̈_k τ`,           `q̇_{k+1} = q̇_k + q̈_k Δt`
//! - eq. 4.12/4.13: `q(τ) = q_k + q̇_k τ + ½ q̈_k τ²`, `q_{k+1} = q_k + q̇_k Δt + ½ q̈_k Δt²`
//!
//! (the thesis prints eq. 4.8 as `φ̇_0 + φ̇_0 τ`, a misprint for `φ̇_0 + φ̈_0 τ`, as eq. 4.9–4.10
//! show). It is an explicit first-order Taylor method (global error `O(Δt)`), with no error
//! estimate; the thesis uses `Δt = 1e-7 s` for t ∈ [0, 1] s. Dense output is the step's own
//! polynomial, eq. 4.8 and 4.12. A blow-up is reported as [`FailureKind::NonFinite`].

use super::eval::Evaluator;
use super::grid::Recorder;
use super::input::{check_input, invalid};
use super::{FailureKind, OdeSystem, OutputGrid, Solution, SolverError, SolverOptions};
use nalgebra::DVector;

const NAME: &str = "initial-acceleration";

/// Integrates with the fixed step `opts.h` (required). The last step is shortened to end at
/// `grid.t_end()`; step `k` starts at `t0 + k·Δt` (no accumulated rounding in `t`).
pub fn solve<S: OdeSystem + ?Sized>(
    sys: &S,
    y0: &DVector<f64>,
    grid: &OutputGrid,
    opts: &SolverOptions,
) -> Result<Solution, SolverError> {
    let t0 = grid.t0;
    check_input(sys, y0, opts).map_err(|m| invalid(NAME, t0, m))?;
    let n = y0.len();
    if !n.is_multiple_of(2) {
        return Err(invalid(
            NAME,
            t0,
            format!("state dimension {n} is odd: need y = [q; q̇]"),
        ));
    }
    let Some(dt) = opts.h else {
        return Err(invalid(NAME, t0, "the fixed step h is required".into()));
    };
    let m = n / 2;
    let t_end = grid.t_end();
    let n_steps = ((t_end - t0) / dt * (1.0 - 1e-12)).ceil().max(1.0) as u64;
    let mut ev = Evaluator::new(sys, NAME, opts, t0);
    let mut rec = Recorder::new(grid, y0);
    let mut y = y0.clone();
    let mut f = DVector::zeros(n);
    let mut y_new = DVector::zeros(n);
    for k in 0..n_steps {
        ev.check_step_budget()?;
        let t = t0 + k as f64 * dt;
        let t_new = if k + 1 == n_steps {
            t_end
        } else {
            t0 + (k + 1) as f64 * dt
        };
        let h = t_new - t;
        // eq. 4.5: the acceleration at the start of the step
        ev.rhs_finite(t, &y, &mut f)?;
        for i in 0..m {
            let (q, v, a) = (y[i], y[m + i], f[m + i]);
            y_new[i] = q + v * h + 0.5 * a * h * h; // eq. 4.13
            y_new[m + i] = v + a * h; // eq. 4.9
        }
        if !y_new.iter().all(|v| v.is_finite()) {
            return Err(ev.fail(FailureKind::NonFinite));
        }
        rec.record(t, t_new, &y_new, |theta, out| {
            let tau = theta * h;
            for i in 0..m {
                let (q, v, a) = (y[i], y[m + i], f[m + i]);
                out[i] = q + v * tau + 0.5 * a * tau * tau; // eq. 4.12
                out[m + i] = v + a * tau; // eq. 4.8
            }
        });
        ev.accept_step(t_new);
        std::mem::swap(&mut y, &mut y_new);
    }
    Ok(rec.finish(ev.stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::tests_common::Oscillator;

    fn err_at_end(h: f64) -> f64 {
        let sys = Oscillator { omega: 2.0 };
        let grid = OutputGrid::new(0.0, 1.0, 0.1).unwrap();
        let y0 = DVector::from_vec(vec![1.0, 0.0]);
        let sol = solve(&sys, &y0, &grid, &SolverOptions::fixed_step(h)).unwrap();
        let exact = sys.exact(1.0);
        (sol.last()[0] - exact[0])
            .abs()
            .max((sol.last()[1] - exact[1]).abs())
    }

    #[test]
    fn first_order_convergence_on_harmonic_oscillator() {
        let e1 = err_at_end(1e-3);
        let e2 = err_at_end(5e-4);
        let p = (e1 / e2).log2();
        assert!((p - 1.0).abs() < 0.05, "observed order {p}");
    }

    #[test]
    fn free_fall_is_exact() {
        // q̈ = −g: the frozen acceleration is exact, so the method is exact.
        struct Fall;
        impl OdeSystem for Fall {
            fn dim(&self) -> usize {
                2
            }
            fn rhs(&self, _t: f64, y: &DVector<f64>, d: &mut DVector<f64>) {
                d[0] = y[1];
                d[1] = -9.81;
            }
        }
        let grid = OutputGrid::new(0.0, 1.0, 0.25).unwrap();
        let y0 = DVector::from_vec(vec![0.0, 3.0]);
        let sol = solve(&Fall, &y0, &grid, &SolverOptions::fixed_step(0.1)).unwrap();
        for (k, &t) in sol.t.iter().enumerate() {
            let q = 3.0 * t - 0.5 * 9.81 * t * t;
            assert!((sol.y_at(k)[0] - q).abs() < 1e-13, "t = {t}");
        }
        assert_eq!(sol.stats.steps, 10);
        assert_eq!(sol.stats.rhs_evals, 10);
    }

    #[test]
    fn blow_up_is_reported() {
        // q̈ = −1e8 q with Δt = 1e-2: |amplification| ≈ 1e4 per step, overflows quickly.
        let sys = Oscillator { omega: 1e4 };
        let grid = OutputGrid::new(0.0, 10.0, 1.0).unwrap();
        let y0 = DVector::from_vec(vec![1.0, 0.0]);
        let err = solve(&sys, &y0, &grid, &SolverOptions::fixed_step(1e-2)).unwrap_err();
        assert_eq!(err.kind, FailureKind::NonFinite);
        assert!(err.to_string().contains("blew up"));
    }

    #[test]
    fn step_cap_is_reported() {
        let sys = Oscillator { omega: 1.0 };
        let grid = OutputGrid::new(0.0, 1.0, 0.5).unwrap();
        let y0 = DVector::from_vec(vec![1.0, 0.0]);
        let opts = SolverOptions {
            max_steps: 100,
            ..SolverOptions::fixed_step(1e-3)
        };
        let err = solve(&sys, &y0, &grid, &opts).unwrap_err();
        assert_eq!(err.kind, FailureKind::StepLimit { max_steps: 100 });
        assert_eq!(err.stats.steps, 100);
    }
}
