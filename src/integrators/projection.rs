//! Post-step projection onto an invariant manifold (coordinate projection).
//!
//! Hairer, Lubich & Wanner, *Geometric Numerical Integration*, 2nd ed., §IV.4, Algorithm 4.2:
//! after each accepted step of a one-step method, the new value `ỹ_{n+1}` is replaced by the
//! nearest point `y_{n+1}` of the manifold, and the next step starts from there. The
//! projection changes `ỹ_{n+1}` by `O(local error)`, so the order of the method is kept, and
//! the invariants hold to the projection's tolerance for all times instead of drifting.
//! Used by [`rk45::solve_projected`](super::rk45::solve_projected), where the interplay with
//! the dense output is documented.

use nalgebra::DVector;

/// A projection of states onto an invariant manifold.
pub trait StepProjection {
    /// Replaces `y` (a state at time `t`) by its projection onto the manifold; `Err` with the
    /// reason when the projection fails (e.g. its Newton iteration does not converge).
    fn project(&mut self, t: f64, y: &mut DVector<f64>) -> Result<(), String>;
}
