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

    /// The period `P` of component `i` if `f` is periodic in it (`f(t, y + P e_i) = f(t, y)`
    /// for every `y`, e.g. an angle on which the right-hand side depends only through sin and
    /// cos). The solvers then carry that component as whole periods plus a remainder in
    /// `[0, P)` and evaluate `f` at the remainder, which keeps its precision however far the
    /// angle grows (see `turns.rs`); the output is the full value. Default: none.
    fn period(&self, _i: usize) -> Option<f64> {
        None
    }

    /// `true` if `f` does not depend on `t` explicitly (lets the Rosenbrock method skip `∂f/∂t`).
    fn is_autonomous(&self) -> bool {
        false
    }
}
