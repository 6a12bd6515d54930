//! Work counters every solver reports.

use serde::Serialize;
use std::fmt;

/// Counters of one solver run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Stats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected step attempts (error test or Newton failure).
    pub rejected_steps: u64,
    /// Right-hand-side evaluations, including those spent on finite-difference Jacobians.
    pub rhs_evals: u64,
    /// Jacobian evaluations (analytic or finite-difference).
    pub jac_evals: u64,
    /// LU decompositions of iteration matrices.
    pub lu_decompositions: u64,
    /// Newton iterations (implicit methods).
    pub newton_iters: u64,
    /// Accepted steps on which a tolerance was below the f64 resolution of the state and was
    /// raised to the floor `κ·ε·|y_i|` ([`TOL_FLOOR_KAPPA`](super::TOL_FLOOR_KAPPA)).
    pub floored_steps: u64,
}

impl fmt::Display for Stats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} steps, {} rejected, {} RHS evals, {} Jacobians, {} LU",
            self.steps, self.rejected_steps, self.rhs_evals, self.jac_evals, self.lu_decompositions
        )
    }
}
