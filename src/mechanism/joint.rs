//! [`Joint`], the closed set of joints of the multibody core — revolute
//! (thesis eq. 2.17–2.19), translational (eq. 2.28–2.29) and driving — and its
//! static dispatch of [`ConstraintEquations`] to the joint types (Φ, D, ν, γ,
//! thesis eq. 3.25–3.38).

use super::body::{BodyId, Pose, Twist};
use super::constraint::{ConstraintEquations, JacobianBlocks};
use super::driving::Driving;
use super::revolute::Revolute;
use super::translational::Translational;

/// Any joint of the multibody core.
#[derive(Clone, Debug)]
pub enum Joint {
    /// Revolute (pin) joint, 2 equations.
    Revolute(Revolute),
    /// Translational (prismatic) joint, 2 equations.
    Translational(Translational),
    /// Driving constraint on an angle, 1 equation.
    Driving(Driving),
}

impl Joint {
    /// Short name of the joint type, for messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Joint::Revolute(_) => "revolute",
            Joint::Translational(_) => "translational",
            Joint::Driving(_) => "driving",
        }
    }
}

// Static dispatch (no trait objects on the hot path).
macro_rules! dispatch {
    ($self:ident, $j:ident => $e:expr) => {
        match $self {
            Joint::Revolute($j) => $e,
            Joint::Translational($j) => $e,
            Joint::Driving($j) => $e,
        }
    };
}

impl ConstraintEquations for Joint {
    #[inline]
    fn equations(&self) -> usize {
        dispatch!(self, j => j.equations())
    }
    #[inline]
    fn bodies(&self) -> (BodyId, BodyId) {
        dispatch!(self, j => j.bodies())
    }
    fn is_angle_row(&self, k: usize) -> bool {
        dispatch!(self, j => j.is_angle_row(k))
    }
    #[inline]
    fn phi(&self, pi: &Pose, pj: &Pose, t: f64) -> [f64; 2] {
        dispatch!(self, j => j.phi(pi, pj, t))
    }
    #[inline]
    fn jacobian(&self, pi: &Pose, pj: &Pose, t: f64) -> JacobianBlocks {
        dispatch!(self, j => j.jacobian(pi, pj, t))
    }
    #[inline]
    fn nu(&self, t: f64) -> [f64; 2] {
        dispatch!(self, j => j.nu(t))
    }
    #[inline]
    fn gamma(&self, pi: &Pose, pj: &Pose, vi: &Twist, vj: &Twist, t: f64) -> [f64; 2] {
        dispatch!(self, j => j.gamma(pi, pj, vi, vj, t))
    }
}
