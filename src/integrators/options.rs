//! Solver settings shared by all methods.

use serde::{Deserialize, Serialize};

/// Where the implicit solvers take `∂f/∂y` from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum JacobianSource {
    /// The system's analytic Jacobian if it has one, else forward differences.
    #[default]
    Auto,
    /// Always forward differences (`n` extra right-hand-side evaluations per Jacobian).
    FiniteDifference,
}

/// Settings of one solver run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SolverOptions {
    /// Relative tolerance (`0` for purely absolute control).
    pub rtol: f64,
    /// Absolute tolerance, same for every component, in the state's units.
    pub atol: f64,
    /// Per-component relative tolerances (length = dimension), overriding `rtol`.
    pub rtol_components: Option<Vec<f64>>,
    /// Per-component absolute tolerances (length = dimension), overriding `atol`.
    pub atol_components: Option<Vec<f64>>,
    /// Step size of fixed-step methods \[s\]; initial step of adaptive ones if set.
    pub h: Option<f64>,
    /// Largest step an adaptive method may take \[s\].
    pub h_max: Option<f64>,
    /// Cap on accepted steps.
    pub max_steps: u64,
    /// Cap on right-hand-side evaluations.
    pub max_rhs_evals: u64,
    /// Jacobian source for the implicit methods.
    pub jacobian: JacobianSource,
}

impl Default for SolverOptions {
    fn default() -> Self {
        Self {
            rtol: 1e-6,
            atol: 1e-9,
            rtol_components: None,
            atol_components: None,
            h: None,
            h_max: None,
            max_steps: 1_000_000,
            max_rhs_evals: 10_000_000,
            jacobian: JacobianSource::Auto,
        }
    }
}

impl SolverOptions {
    /// Purely absolute error control with tolerance `atol` (`rtol = 0`).
    pub fn absolute(atol: f64) -> Self {
        Self {
            rtol: 0.0,
            atol,
            ..Self::default()
        }
    }

    /// Fixed step `h` (for fixed-step methods).
    pub fn fixed_step(h: f64) -> Self {
        Self {
            h: Some(h),
            ..Self::default()
        }
    }

    /// Checks that the settings make sense.
    pub(crate) fn validate(&self) -> Result<(), String> {
        if !(self.rtol >= 0.0 && self.atol >= 0.0 && self.rtol.is_finite() && self.atol.is_finite())
        {
            return Err(format!(
                "tolerances must be finite and ≥ 0 (rtol {}, atol {})",
                self.rtol, self.atol
            ));
        }
        if self.rtol >= 1.0
            || self
                .rtol_components
                .as_ref()
                .is_some_and(|r| r.iter().any(|x| *x >= 1.0))
        {
            return Err(format!(
                "rtol {} ≥ 1 controls nothing (an error as large as the solution passes): give a \
                 relative tolerance below 1, e.g. 1e-6",
                self.rtol
            ));
        }
        if self.rtol == 0.0 && self.atol == 0.0 && self.atol_components.is_none() {
            return Err("rtol and atol cannot both be zero".into());
        }
        for v in [&self.rtol_components, &self.atol_components]
            .into_iter()
            .flatten()
        {
            if v.iter().any(|x| !(x.is_finite() && *x >= 0.0)) {
                return Err(format!(
                    "per-component tolerances must be finite and ≥ 0, got {v:?}"
                ));
            }
        }
        if let Some(a) = &self.atol_components {
            let r = self
                .rtol_components
                .clone()
                .unwrap_or_else(|| vec![self.rtol; a.len()]);
            if a.iter().zip(&r).any(|(a, r)| *a == 0.0 && *r == 0.0) {
                return Err("a component has rtol = atol = 0".into());
            }
        }
        if let Some(h) = self.h
            && !(h > 0.0 && h.is_finite())
        {
            return Err(format!("step size must be positive and finite, got {h}"));
        }
        if let Some(h) = self.h_max
            && (h.is_nan() || h <= 0.0)
        {
            return Err(format!("h_max must be positive, got {h}"));
        }
        if self.max_steps == 0 || self.max_rhs_evals == 0 {
            return Err("step and evaluation caps must be positive".into());
        }
        Ok(())
    }
}
