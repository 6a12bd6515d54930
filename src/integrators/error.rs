//! Typed solver failures.

use super::Stats;
use serde::Serialize;
use std::fmt;

/// Why a solver stopped before the end of the interval.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum FailureKind {
    /// The cap on accepted steps was reached.
    StepLimit {
        /// The cap.
        max_steps: u64,
    },
    /// The cap on right-hand-side evaluations was reached.
    EvalLimit {
        /// The cap.
        max_rhs_evals: u64,
    },
    /// The step size fell below the resolution of `t`.
    StepSizeUnderflow {
        /// The step that was too small \[s\].
        h: f64,
    },
    /// A state or derivative became NaN or infinite (e.g. a fixed-step method blew up).
    NonFinite,
    /// Inconsistent input (dimensions, tolerances, step size, interval).
    InvalidInput(String),
    /// A Newton iteration of a fixed-step implicit method did not converge within its cap.
    NoConvergence {
        /// Iterations spent on the step.
        iterations: usize,
        /// Scaled size of the last Newton increment (1 = the convergence tolerance).
        increment: f64,
    },
    /// An iteration matrix was singular (e.g. a mechanism at a toggle position).
    SingularMatrix,
    /// A post-step projection onto an invariant manifold failed (with its reason).
    Projection(String),
}

impl fmt::Display for FailureKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::StepLimit { max_steps } => write!(f, "step limit of {max_steps} steps reached"),
            Self::EvalLimit { max_rhs_evals } => {
                write!(
                    f,
                    "limit of {max_rhs_evals} right-hand-side evaluations reached"
                )
            }
            Self::StepSizeUnderflow { h } => write!(f, "step size underflow (h = {h:e} s)"),
            Self::NonFinite => write!(f, "non-finite state or derivative (solution blew up)"),
            Self::InvalidInput(msg) => write!(f, "invalid input: {msg}"),
            Self::NoConvergence {
                iterations,
                increment,
            } => write!(
                f,
                "Newton iteration did not converge in {iterations} iterations (last increment \
                 {increment:.2e} × tolerance)"
            ),
            Self::SingularMatrix => write!(f, "singular iteration matrix"),
            Self::Projection(msg) => {
                write!(f, "projection onto the invariant manifold failed: {msg}")
            }
        }
    }
}

/// A solver failure: what happened, where, and the work done up to then.
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[error("{method}: {kind} at t = {t} s ({stats})")]
pub struct SolverError {
    /// Name of the solver.
    pub method: &'static str,
    /// The cause.
    pub kind: FailureKind,
    /// Time reached.
    pub t: f64,
    /// Work done until the failure.
    pub stats: Stats,
}

impl SolverError {
    /// `true` for the step or evaluation cap (the solver was slow, not wrong).
    pub fn is_limit(&self) -> bool {
        matches!(
            self.kind,
            FailureKind::StepLimit { .. } | FailureKind::EvalLimit { .. }
        )
    }
}
