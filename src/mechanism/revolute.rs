//! Revolute (pin) joint — thesis §2.3.1, eq. (2.17)–(2.19); Nikravesh 1988,
//! planar revolute joint.
//!
//! Point Pᵢ of body i and point Pⱼ of body j coincide:
//!
//! Φ^(r,2) = rⱼᴾ − rᵢᴾ = rⱼ + Aⱼ s'ⱼᴾ − rᵢ − Aᵢ s'ᵢᴾ = 0            (2.17–2.19)
//!
//! Jacobian (thesis eq. 3.33), with sᴾ = A s'ᴾ and B s'ᴾ = rot90(sᴾ):
//!
//! D_i = [−I₂, −rot90(sᵢᴾ)],   D_j = [I₂, rot90(sⱼᴾ)]
//!
//! Velocity right-hand side ν = 0 (time-independent), acceleration right-hand
//! side (thesis eq. 3.37–3.38, γ = −Ḋ ċ):
//!
//! γ = sⱼᴾ φ̇ⱼ² − sᵢᴾ φ̇ᵢ²
//!
//! Reaction: with M c̈ = h + Dᵀλ (thesis eq. 3.27) the two multipliers λ =
//! (λ_x, λ_y) *are* the global force that body i exerts on body j at P; body i
//! receives −λ (its generalized forces are D_jᵀλ = (λ, sⱼᴾ × λ) and
//! D_iᵀλ = (−λ, −sᵢᴾ × λ), moments about each body's reference point).

use nalgebra::Vector2;

use super::body::{BodyId, Pose, Twist, rot90};
use super::constraint::{ConstraintEquations, JacobianBlocks};

/// Revolute joint between body i and body j.
#[derive(Clone, Debug, PartialEq)]
pub struct Revolute {
    /// Body i (may be the ground).
    pub body_i: BodyId,
    /// s'ᵢᴾ: the joint point in body i's frame (global coordinates for ground).
    pub point_i: Vector2<f64>,
    /// Body j.
    pub body_j: BodyId,
    /// s'ⱼᴾ: the joint point in body j's frame (global coordinates for ground).
    pub point_j: Vector2<f64>,
}

impl ConstraintEquations for Revolute {
    fn equations(&self) -> usize {
        2
    }

    fn bodies(&self) -> (BodyId, BodyId) {
        (self.body_i, self.body_j)
    }

    fn is_angle_row(&self, _k: usize) -> bool {
        false
    }

    #[inline]
    fn phi(&self, pi: &Pose, pj: &Pose, _t: f64) -> [f64; 2] {
        let d = pj.point(self.point_j) - pi.point(self.point_i);
        [d.x, d.y]
    }

    #[inline]
    fn jacobian(&self, pi: &Pose, pj: &Pose, _t: f64) -> JacobianBlocks {
        let bi = rot90(pi.rotate(self.point_i));
        let bj = rot90(pj.rotate(self.point_j));
        JacobianBlocks {
            di: [[-1.0, 0.0, -bi.x], [0.0, -1.0, -bi.y]],
            dj: [[1.0, 0.0, bj.x], [0.0, 1.0, bj.y]],
        }
    }

    #[inline]
    fn nu(&self, _t: f64) -> [f64; 2] {
        [0.0, 0.0]
    }

    #[inline]
    fn gamma(&self, pi: &Pose, pj: &Pose, vi: &Twist, vj: &Twist, _t: f64) -> [f64; 2] {
        let g = pj.rotate(self.point_j) * (vj.w * vj.w) - pi.rotate(self.point_i) * (vi.w * vi.w);
        [g.x, g.y]
    }
}

#[cfg(test)]
mod tests {
    use super::super::constraint::testing::check_joint;
    use super::*;

    #[test]
    fn jacobian_and_gamma_match_finite_differences() {
        let j = Revolute {
            body_i: BodyId::Moving(0),
            point_i: Vector2::new(0.041, 0.002),
            body_j: BodyId::Moving(1),
            point_j: Vector2::new(-0.072, -0.003),
        };
        check_joint(
            &j,
            [0.01, 0.02, 0.7],
            [0.1, -0.03, -0.3],
            [0.4, -1.1, 50.0],
            [-2.0, 0.7, -30.0],
        );
        let g = Revolute {
            body_i: BodyId::Ground,
            point_i: Vector2::new(0.01, -0.02),
            body_j: BodyId::Moving(0),
            point_j: Vector2::new(-0.005, 0.0),
        };
        check_joint(
            &g,
            [0.0; 3],
            [0.02, 0.01, 1.3],
            [0.0; 3],
            [1.0, -0.5, 125.0],
        );
    }

    #[test]
    fn residual_vanishes_when_points_coincide() {
        let j = Revolute {
            body_i: BodyId::Moving(0),
            point_i: Vector2::new(1.0, 0.0),
            body_j: BodyId::Moving(1),
            point_j: Vector2::new(-0.5, 0.0),
        };
        // body i at origin turned 90 deg: P at (0, 1); body j at (0, 1.5) turned 90 deg: P at (0, 1)
        let f = j.phi(
            &Pose::new(0.0, 0.0, std::f64::consts::FRAC_PI_2),
            &Pose::new(0.0, 1.5, std::f64::consts::FRAC_PI_2),
            0.0,
        );
        assert!(f[0].abs() < 1e-15 && f[1].abs() < 1e-15);
    }
}
