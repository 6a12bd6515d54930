//! Test problems with known solutions (unit tests only).

use super::OdeSystem;
use nalgebra::{DMatrix, DVector};

/// `y' = -λ y`, `y(0) = 1`: `y = exp(-λ t)`.
pub(crate) struct Decay {
    pub(crate) lambda: f64,
}

impl OdeSystem for Decay {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, y: &DVector<f64>, d: &mut DVector<f64>) {
        d[0] = -self.lambda * y[0];
    }
    fn jacobian(&self, _t: f64, _y: &DVector<f64>, j: &mut DMatrix<f64>) -> bool {
        j[(0, 0)] = -self.lambda;
        true
    }
    fn is_autonomous(&self) -> bool {
        true
    }
}

/// `q̈ = -ω² q` as `y = [q, q̇]`, `y(0) = [1, 0]`: `q = cos ωt`, `q̇ = -ω sin ωt`.
pub(crate) struct Oscillator {
    pub(crate) omega: f64,
}

impl Oscillator {
    pub(crate) fn exact(&self, t: f64) -> [f64; 2] {
        [(self.omega * t).cos(), -self.omega * (self.omega * t).sin()]
    }
}

impl OdeSystem for Oscillator {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &DVector<f64>, d: &mut DVector<f64>) {
        d[0] = y[1];
        d[1] = -self.omega * self.omega * y[0];
    }
    fn jacobian(&self, _t: f64, _y: &DVector<f64>, j: &mut DMatrix<f64>) -> bool {
        j[(0, 0)] = 0.0;
        j[(0, 1)] = 1.0;
        j[(1, 0)] = -self.omega * self.omega;
        j[(1, 1)] = 0.0;
        true
    }
    fn is_autonomous(&self) -> bool {
        true
    }
}

/// Prothero–Robinson: `y' = -λ (y - sin t) + cos t`, `y(0) = 0`: `y = sin t` (stiff for
/// large λ, non-autonomous, no analytic Jacobian so finite differences are exercised).
pub(crate) struct ProtheroRobinson {
    pub(crate) lambda: f64,
}

impl OdeSystem for ProtheroRobinson {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, t: f64, y: &DVector<f64>, d: &mut DVector<f64>) {
        d[0] = -self.lambda * (y[0] - t.sin()) + t.cos();
    }
}

/// Max-norm distance between a solution and an exact solution on its grid.
pub(crate) fn max_error(sol: &super::Solution, exact: impl Fn(f64) -> Vec<f64>) -> f64 {
    let mut e: f64 = 0.0;
    for (k, &t) in sol.t.iter().enumerate() {
        let ex = exact(t);
        for (a, b) in sol.y_at(k).iter().zip(ex.iter()) {
            e = e.max((a - b).abs());
        }
    }
    e
}
