//! The system interface the solvers integrate.

use nalgebra::{DMatrix, DVector};

/// A first-order system `y' = f(t, y)` of fixed dimension.
///
/// Second-order mechanical systems are written in the layout `y = [q; q̇]`,
/// `f = [q̇; q̈]`, which the thesis' initial-acceleration method relies on
/// (the thesis, eq. 4.15, orders them `[φ̇, φ]`; the layout here puts positions first).
pub trait OdeSystem {
    /// State dimension `n`.
    fn dim(&self) -> usize;

    /// Right-hand side: writes `f(t, y)` into `dydt` (length `n`).
    fn rhs(&self, t: f64, y: &DVector<f64>, dydt: &mut DVector<f64>);

    /// Analytic Jacobian `∂f/∂y` (n × n). Return `false` (the default) when there is none:
    /// the implicit solvers then use forward differences.
    fn jacobian(&self, _t: f64, _y: &DVector<f64>, _jac: &mut DMatrix<f64>) -> bool {
        false
    }

    /// `true` if `f` does not depend on `t` explicitly (lets the Rosenbrock method skip `∂f/∂t`).
    fn is_autonomous(&self) -> bool {
        false
    }
}
