//! The typed error of the dynamics stage.
//!
//! Every failure of the dynamics stage is one of these variants, each with a
//! human-readable [`Display`](std::fmt::Display) message that names the
//! offending parameter, or the time and the joint. No code path of this module
//! returns a NaN in place of an error: non-finite intermediate values are
//! turned into [`DynamicsError::NonFinite`].

use thiserror::Error;

/// Errors of model building, kinematic analysis and inverse dynamics.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum DynamicsError {
    /// A scalar input is out of its admissible range (non-positive mass,
    /// non-finite length, ...).
    #[error("invalid parameter {name} = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name as it appears in the structs of this module.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// Why it is refused.
        reason: String,
    },

    /// Centre distance not larger than the crank radius: the crank cannot make
    /// a full turn (for l < r it locks at sin φ = l/r, for l = r the rod
    /// reaches the toggle position ψ = 90° with B on O).
    #[error(
        "the crank cannot turn: centre distance l = {l_m} m must be larger than the crank \
         radius r = {r_m} m (for l <= r the mechanism locks at a toggle position, sin(psi) = \
         (r/l) sin(phi) reaches 1)"
    )]
    CrankCannotTurn {
        /// Centre distance (m).
        l_m: f64,
        /// Crank radius (m).
        r_m: f64,
    },

    /// The multibody model is malformed (unknown body, joint connecting a body
    /// to itself, zero slide axis, wrong coordinate count, ...).
    #[error("invalid multibody model: {0}")]
    InvalidModel(String),

    /// The constraint equations do not match the coordinates: kinematic
    /// analysis needs a zero-DOF system (as many independent equations as
    /// coordinates).
    #[error(
        "constraint count mismatch: the joints give {equations} equations for {coordinates} \
         coordinates, kinematic analysis needs a zero-DOF system{detail}"
    )]
    ConstraintCount {
        /// Number of constraint equations of all joints.
        equations: usize,
        /// Number of body coordinates (3 per moving body).
        coordinates: usize,
        /// Which joint over-/under-constrains (text starting with "; ").
        detail: String,
    },

    /// The constraint Jacobian D is singular to working precision (toggle
    /// position, or redundant constraints).
    #[error(
        "singular constraint Jacobian at t = {t_s} s: equation {equation} (row {row}) of joint \
         '{joint}' is linearly dependent on the other constraints (relative pivot {pivot_ratio:.3e} \
         below the threshold {threshold:.1e}); the mechanism is at a toggle (locking) position or \
         the constraint set is redundant"
    )]
    SingularJacobian {
        /// Time of the failing analysis (s).
        t_s: f64,
        /// Name of the joint owning the dependent equation.
        joint: String,
        /// Global row index of the dependent equation (0-based).
        row: usize,
        /// Equation number inside the joint (1-based).
        equation: usize,
        /// Smallest/largest pivot of the scaled full-pivot LU of D.
        pivot_ratio: f64,
        /// The threshold in force (see `SolverOptions::pivot_threshold`).
        threshold: f64,
    },

    /// Newton–Raphson on Φ(c, t) = 0 did not converge.
    #[error(
        "Newton-Raphson position analysis did not converge at t = {t_s} s after {iterations} \
         iterations: scaled residual {residual:.3e} m (tolerance {tolerance:.1e} m), largest in \
         joint '{joint}'; the constraints are inconsistent or the mechanism cannot reach this \
         position"
    )]
    NoConvergence {
        /// Time of the failing analysis (s).
        t_s: f64,
        /// Iterations spent.
        iterations: usize,
        /// Infinity norm of the scaled residual (angle rows times the
        /// characteristic length, so metres throughout).
        residual: f64,
        /// Convergence tolerance (m).
        tolerance: f64,
        /// Joint with the largest residual.
        joint: String,
    },

    /// A non-finite number appeared (guard; never returned as a value).
    #[error("non-finite value in {what} at t = {t_s} s")]
    NonFinite {
        /// Time (s).
        t_s: f64,
        /// Which quantity.
        what: &'static str,
    },

    /// A scene description is unusable (zero steps, non-positive duration, ...).
    #[error("invalid scene: {0}")]
    InvalidScene(String),
}

/// Result alias of this module.
pub type Result<T> = std::result::Result<T, DynamicsError>;

/// Refuse a non-finite value.
pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(DynamicsError::InvalidParameter {
            name,
            value,
            reason: "must be a finite number".into(),
        })
    }
}

/// Refuse a value that is not finite and strictly positive.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64> {
    finite(name, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(DynamicsError::InvalidParameter {
            name,
            value,
            reason: "must be strictly positive".into(),
        })
    }
}

/// Refuse a value that is not finite and non-negative.
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<f64> {
    finite(name, value)?;
    if value >= 0.0 {
        Ok(value)
    } else {
        Err(DynamicsError::InvalidParameter {
            name,
            value,
            reason: "must not be negative".into(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validators_refuse_bad_numbers() {
        assert!(finite("x", f64::NAN).is_err());
        assert!(positive("m", 0.0).is_err());
        assert!(positive("m", -1.0).is_err());
        assert!(positive("m", f64::INFINITY).is_err());
        assert!(non_negative("i", -1e-9).is_err());
        assert_eq!(non_negative("i", 0.0), Ok(0.0));
        let msg = positive("mass_kg", -2.0).unwrap_err().to_string();
        assert!(msg.contains("mass_kg") && msg.contains("positive"), "{msg}");
    }

    #[test]
    fn singular_message_names_time_and_joint() {
        let e = DynamicsError::SingularJacobian {
            t_s: 0.25,
            joint: "crank drive".into(),
            row: 8,
            equation: 1,
            pivot_ratio: 1e-17,
            threshold: 1e-8,
        };
        let s = e.to_string();
        assert!(
            s.contains("t = 0.25 s") && s.contains("'crank drive'"),
            "{s}"
        );
    }
}
