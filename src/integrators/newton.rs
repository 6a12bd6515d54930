//! Simplified Newton iteration for one implicit stage `z = base + γh f(t, z)`, shared by BDF
//! and TR-BDF2 (Hairer & Wanner, *Solving ODEs II*, §IV.8, convergence test eq. IV.8.10–8.11;
//! the same test as ode15s and SciPy's BDF).

use super::eval::Evaluator;
use super::norm::rms_norm;
use super::{OdeSystem, SolverError};
use crate::linalg::DenseLu;
use nalgebra::{DMatrix, DVector, Dyn};

/// LU factors (partial pivoting) of an iteration matrix `W = I − c J`, by the crate's one
/// dense LU ([`DenseLu`]); [`DenseLu::solve_mut`] reports a singular `W` or a non-finite
/// result as `false`.
pub(crate) type IterationMatrix = DenseLu<Dyn>;

/// Factors `I − c J`; `None` if singular or not finite.
pub(crate) fn iteration_matrix(jac: &DMatrix<f64>, c: f64) -> Option<IterationMatrix> {
    let n = jac.nrows();
    let mut m = jac * (-c);
    for i in 0..n {
        m[(i, i)] += 1.0;
    }
    if !m.iter().all(|v| v.is_finite()) {
        return None;
    }
    let lu = DenseLu::Partial(m.lu());
    lu.is_invertible().then_some(lu)
}

/// Work vectors and settings of the iteration.
pub(crate) struct Newton {
    /// Iteration limit.
    pub(crate) max_iter: usize,
    /// Convergence tolerance κ in the scaled norm (a fraction of the error tolerance).
    pub(crate) kappa: f64,
    f: DVector<f64>,
    dz: DVector<f64>,
    /// `offset + z` (the evaluation point in increment form).
    at: DVector<f64>,
}

/// Result of one Newton solve.
pub(crate) struct NewtonOutcome {
    pub(crate) converged: bool,
    pub(crate) iters: usize,
}

impl Newton {
    pub(crate) fn new(n: usize, max_iter: usize, kappa: f64) -> Self {
        Self {
            max_iter,
            kappa,
            f: DVector::zeros(n),
            dz: DVector::zeros(n),
            at: DVector::zeros(n),
        }
    }

    /// Iterates `z ← z + W⁻¹ (base + gh f(t, offset + z) − z)` with `W = I − gh J` already
    /// factored. With `offset = y_n` the unknown is the increment `z = y_{n+1} − y_n` (and
    /// `base` is given relative to `y_n` too): the increment is then kept to its own
    /// precision, not to an ulp of `y`, so that the caller can add it to the state by
    /// compensated summation ([`super::adaptive`]); `f` is evaluated at the rounded
    /// `offset + z`. The round-off level of the convergence test is that of `offset + z`.
    /// Stops when the predicted remaining error `ρ/(1−ρ) ‖Δz‖` is below κ, when `‖Δz‖` is at
    /// roundoff level, or fails when the iteration diverges (`ρ ≥ 1`), would not converge
    /// within the limit, or meets a non-finite value (the caller then shrinks the step).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn solve<S: OdeSystem + ?Sized>(
        &mut self,
        ev: &mut Evaluator<'_, S>,
        w: &IterationMatrix,
        t: f64,
        base: &DVector<f64>,
        gh: f64,
        offset: &DVector<f64>,
        z: &mut DVector<f64>,
        scale: &DVector<f64>,
    ) -> Result<NewtonOutcome, SolverError> {
        let n = z.len();
        let floor = 20.0
            * f64::EPSILON
            * (0..n)
                .map(|i| (offset[i] + z[i]).abs() / scale[i])
                .fold(0.0, f64::max);
        let mut norm_old = f64::NAN;
        for k in 0..self.max_iter {
            ev.stats.newton_iters += 1;
            if !z.iter().all(|v| v.is_finite()) {
                return Ok(NewtonOutcome {
                    converged: false,
                    iters: k + 1,
                });
            }
            for i in 0..n {
                self.at[i] = offset[i] + z[i];
            }
            ev.rhs(t, &self.at, &mut self.f)?;
            if !self.f.iter().all(|v| v.is_finite()) {
                return Ok(NewtonOutcome {
                    converged: false,
                    iters: k + 1,
                });
            }
            for i in 0..n {
                self.dz[i] = base[i] + gh * self.f[i] - z[i];
            }
            if !w.solve_mut(&mut self.dz) {
                return Ok(NewtonOutcome {
                    converged: false,
                    iters: k + 1,
                });
            }
            let norm = rms_norm(&self.dz, scale);
            let rate = norm / norm_old;
            if norm > floor
                && rate.is_finite()
                && (rate >= 1.0
                    || rate.powi((self.max_iter - k) as i32) / (1.0 - rate) * norm > self.kappa)
            {
                return Ok(NewtonOutcome {
                    converged: false,
                    iters: k + 1,
                });
            }
            *z += &self.dz;
            if norm <= floor || (rate.is_finite() && rate / (1.0 - rate) * norm < self.kappa) {
                return Ok(NewtonOutcome {
                    converged: true,
                    iters: k + 1,
                });
            }
            norm_old = norm;
        }
        Ok(NewtonOutcome {
            converged: false,
            iters: self.max_iter,
        })
    }
}
