//! Counted, capped access to the system: every solver evaluates `f` and `∂f/∂y` through this.

use super::norm::all_finite;
use super::{FailureKind, JacobianSource, OdeSystem, SolverError, SolverOptions, Stats};
use nalgebra::{DMatrix, DVector};

/// Wraps an [`OdeSystem`], counts evaluations and enforces the caps of [`SolverOptions`].
pub(crate) struct Evaluator<'a, S: OdeSystem + ?Sized> {
    sys: &'a S,
    method: &'static str,
    pub(crate) stats: Stats,
    max_steps: u64,
    max_rhs_evals: u64,
    jacobian: JacobianSource,
    /// Time reached (for error reports).
    pub(crate) t: f64,
    fd_y: DVector<f64>,
    fd_f0: DVector<f64>,
    fd_f1: DVector<f64>,
}

impl<'a, S: OdeSystem + ?Sized> Evaluator<'a, S> {
    pub(crate) fn new(sys: &'a S, method: &'static str, opts: &SolverOptions, t0: f64) -> Self {
        let n = sys.dim();
        Self {
            sys,
            method,
            stats: Stats::default(),
            max_steps: opts.max_steps,
            max_rhs_evals: opts.max_rhs_evals,
            jacobian: opts.jacobian,
            t: t0,
            fd_y: DVector::zeros(n),
            fd_f0: DVector::zeros(n),
            fd_f1: DVector::zeros(n),
        }
    }

    /// A failure report at the current time.
    pub(crate) fn fail(&self, kind: FailureKind) -> SolverError {
        SolverError {
            method: self.method,
            kind,
            t: self.t,
            stats: self.stats,
        }
    }

    /// `f(t, y)`; fails on the evaluation cap. Non-finite output is returned as is: callers
    /// decide whether to reject the step or stop (see [`Self::rhs_finite`]).
    pub(crate) fn rhs(
        &mut self,
        t: f64,
        y: &DVector<f64>,
        out: &mut DVector<f64>,
    ) -> Result<(), SolverError> {
        self.charge_rhs()?;
        self.sys.rhs(t, y, out);
        Ok(())
    }

    /// `f(t, y)`, failing with [`FailureKind::NonFinite`] if `y` or `f` is not finite.
    pub(crate) fn rhs_finite(
        &mut self,
        t: f64,
        y: &DVector<f64>,
        out: &mut DVector<f64>,
    ) -> Result<(), SolverError> {
        if !all_finite(y) {
            return Err(self.fail(FailureKind::NonFinite));
        }
        self.rhs(t, y, out)?;
        if !all_finite(out) {
            return Err(self.fail(FailureKind::NonFinite));
        }
        Ok(())
    }

    /// `∂f/∂y` at `(t, y)`: analytic if available and allowed, else forward differences with
    /// `δ_j = sqrt(eps) · max(|y_j|, 1e-5 · scale_floor)` (`f0 = f(t, y)` if the caller has it).
    pub(crate) fn jacobian(
        &mut self,
        t: f64,
        y: &DVector<f64>,
        f0: Option<&DVector<f64>>,
        jac: &mut DMatrix<f64>,
    ) -> Result<(), SolverError> {
        self.stats.jac_evals += 1;
        if self.jacobian == JacobianSource::Auto && self.sys.jacobian(t, y, jac) {
            if jac.iter().all(|v| v.is_finite()) {
                return Ok(());
            }
            return Err(self.fail(FailureKind::NonFinite));
        }
        let n = y.len();
        match f0 {
            Some(f) => self.fd_f0.copy_from(f),
            None => {
                self.charge_rhs()?;
                self.sys.rhs(t, y, &mut self.fd_f0);
            }
        }
        self.fd_y.copy_from(y);
        let sqrt_eps = f64::EPSILON.sqrt();
        for j in 0..n {
            let yj = y[j];
            self.fd_y[j] = yj + sqrt_eps * yj.abs().max(1e-5);
            let delta = self.fd_y[j] - yj;
            self.charge_rhs()?;
            self.sys.rhs(t, &self.fd_y, &mut self.fd_f1);
            for i in 0..n {
                jac[(i, j)] = (self.fd_f1[i] - self.fd_f0[i]) / delta;
            }
            self.fd_y[j] = yj;
        }
        if jac.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(self.fail(FailureKind::NonFinite))
        }
    }

    /// Counts one right-hand-side evaluation against the cap.
    fn charge_rhs(&mut self) -> Result<(), SolverError> {
        if self.stats.rhs_evals >= self.max_rhs_evals {
            return Err(self.fail(FailureKind::EvalLimit {
                max_rhs_evals: self.max_rhs_evals,
            }));
        }
        self.stats.rhs_evals += 1;
        Ok(())
    }

    /// `∂f/∂t` at `(t, y)` by a forward difference (zero for autonomous systems).
    pub(crate) fn time_derivative(
        &mut self,
        t: f64,
        y: &DVector<f64>,
        f0: &DVector<f64>,
        out: &mut DVector<f64>,
    ) -> Result<(), SolverError> {
        if self.sys.is_autonomous() {
            out.fill(0.0);
            return Ok(());
        }
        let dt = f64::EPSILON.sqrt() * t.abs().max(1e-5);
        let t1 = t + dt;
        let dt = t1 - t;
        self.rhs(t1, y, out)?;
        for i in 0..y.len() {
            out[i] = (out[i] - f0[i]) / dt;
        }
        Ok(())
    }

    /// Fails if the cap on steps is used up; call before attempting a new step.
    pub(crate) fn check_step_budget(&self) -> Result<(), SolverError> {
        if self.stats.steps >= self.max_steps {
            return Err(self.fail(FailureKind::StepLimit {
                max_steps: self.max_steps,
            }));
        }
        Ok(())
    }

    /// Counts an accepted step ending at `t_new`.
    pub(crate) fn accept_step(&mut self, t_new: f64) {
        self.stats.steps += 1;
        self.t = t_new;
    }

    /// Counts a rejected step attempt.
    pub(crate) fn reject_step(&mut self) {
        self.stats.rejected_steps += 1;
    }
}
