//! LU of the iteration matrices `I - γ h J` of the implicit methods.

use nalgebra::{DMatrix, DVector, Dyn, LU};

/// LU factors of `I - c J`.
pub(crate) struct IterationMatrix {
    lu: LU<f64, Dyn, Dyn>,
}

impl IterationMatrix {
    /// Factors `I - c J`; `None` if singular or not finite.
    pub(crate) fn new(jac: &DMatrix<f64>, c: f64) -> Option<Self> {
        let n = jac.nrows();
        let mut m = jac * (-c);
        for i in 0..n {
            m[(i, i)] += 1.0;
        }
        if !m.iter().all(|v| v.is_finite()) {
            return None;
        }
        let lu = m.lu();
        if !lu.is_invertible() {
            return None;
        }
        Some(Self { lu })
    }

    /// Solves in place; `false` if the result is not finite.
    pub(crate) fn solve_mut(&self, b: &mut DVector<f64>) -> bool {
        self.lu.solve_mut(b) && b.iter().all(|v| v.is_finite())
    }
}
