//! The reduced equation of motion as a first-order system (thesis eq. 4.14–4.16).

use super::loads::Loads;
use super::reduced::ReducedModel;
use crate::integrators::OdeSystem;
use nalgebra::{DMatrix, DVector};

/// `y = [φ, φ̇]`, `y' = [φ̇, φ̈(φ, φ̇)]` with `φ̈` from eq. 4.1 (the thesis, eq. 4.15–4.16,
/// orders the state `[φ̇, φ]`; positions first here, the layout the initial-acceleration
/// method uses). Analytic Jacobian `[[0, 1], [∂φ̈/∂φ, ∂φ̈/∂φ̇]]`.
#[derive(Debug, Clone, Copy)]
pub struct CrankOde<'a> {
    /// The reduced model.
    pub model: &'a ReducedModel,
    /// Loads.
    pub loads: Loads,
}

impl OdeSystem for CrankOde<'_> {
    fn dim(&self) -> usize {
        2
    }

    fn rhs(&self, _t: f64, y: &DVector<f64>, dydt: &mut DVector<f64>) {
        dydt[0] = y[1];
        dydt[1] = self.model.acceleration(&self.loads, y[0], y[1]);
    }

    fn jacobian(&self, _t: f64, y: &DVector<f64>, jac: &mut DMatrix<f64>) -> bool {
        let (a_phi, a_w) = self.model.acceleration_partials(&self.loads, y[0], y[1]);
        jac[(0, 0)] = 0.0;
        jac[(0, 1)] = 1.0;
        jac[(1, 0)] = a_phi;
        jac[(1, 1)] = a_w;
        true
    }

    fn is_autonomous(&self) -> bool {
        true
    }

    /// φ: the mechanism, its loads (crank torque, piston force, gas spring on the piston
    /// travel, gravity through sin/cos φ) and so `φ̈` repeat every turn.
    fn period(&self, i: usize) -> Option<f64> {
        (i == 0).then_some(std::f64::consts::TAU)
    }
}
