//! Translational (prismatic) joint — thesis §2.3.2, eq. (2.28)–(2.29);
//! Nikravesh 1988, planar translational joint.
//!
//! Body j slides along the axis uᵢ fixed on body i (through point Pᵢ) without
//! rotating relative to it. With d = rⱼᴾ − rᵢᴾ and nᵢ = rot90(uᵢ) = Aᵢ rot90(u'ᵢ)
//! (the thesis' ũᵢ):
//!
//! Φ^(t,2) = [ φⱼ − φᵢ − ᶜφ ;  nᵢᵀ d ] = 0                          (2.28)
//!         = [ φⱼ − φᵢ − ᶜφ ;  −u_{i,y} d_x + u_{i,x} d_y ] = 0       (2.29)
//!
//! Jacobian (sᴾ = A s'ᴾ; ∂nᵢ/∂φᵢ = −uᵢ; nᵀ rot90(s) = s × n):
//!
//! row 1: φᵢ: −1, φⱼ: +1
//! row 2: rᵢ: −nᵢᵀ, φᵢ: −uᵢᵀd − sᵢᴾ × nᵢ;  rⱼ: nᵢᵀ, φⱼ: sⱼᴾ × nᵢ
//!
//! ν = 0; acceleration right-hand side (γ = −Ḋ ċ, thesis eq. 3.38, derived
//! without assuming φ̇ᵢ = φ̇ⱼ so that it holds at any state):
//!
//! γ₁ = 0
//! γ₂ = φ̇ᵢ² nᵢᵀd + 2 φ̇ᵢ uᵢᵀḋ + nᵢᵀ(sⱼᴾ φ̇ⱼ² − sᵢᴾ φ̇ᵢ²),
//! ḋ = ṙⱼ + rot90(sⱼᴾ) φ̇ⱼ − ṙᵢ − rot90(sᵢᴾ) φ̇ᵢ
//!
//! Reaction: body j receives the normal force nᵢ λ₂ at Pⱼ and the couple λ₁
//! (generalized force D_jᵀλ = (nᵢλ₂, λ₁ + sⱼᴾ × nᵢ λ₂)); body i receives
//! D_iᵀλ. The thesis attaches the crank–slider's slide with i = piston and
//! j = ground (eq. 2.30–2.31); with i = ground, j = piston, as used in
//! [`CrankSlider`](super::crank_slider::CrankSlider), the equations read
//! [φ₄, y₄] and only the signs of the multipliers differ.

use nalgebra::Vector2;

use super::body::{BodyId, Pose, Twist, cross, rot90};
use super::constraint::{ConstraintEquations, JacobianBlocks};

/// Translational joint: body j slides on body i.
#[derive(Clone, Debug, PartialEq)]
pub struct Translational {
    /// Body i, carrying the slide axis (may be the ground).
    pub body_i: BodyId,
    /// s'ᵢᴾ: a point of the axis in body i's frame.
    pub point_i: Vector2<f64>,
    /// u'ᵢ: unit axis direction in body i's frame (normalised on construction).
    pub axis_i: Vector2<f64>,
    /// Body j, the slider.
    pub body_j: BodyId,
    /// s'ⱼᴾ: a point of the slider on the axis, in body j's frame.
    pub point_j: Vector2<f64>,
    /// ᶜφ: the constant angle φⱼ − φᵢ (rad).
    pub angle0_rad: f64,
}

impl Translational {
    /// Build with a normalised axis; `None` if the axis is zero or not finite.
    pub fn new(
        body_i: BodyId,
        point_i: Vector2<f64>,
        axis_i: Vector2<f64>,
        body_j: BodyId,
        point_j: Vector2<f64>,
        angle0_rad: f64,
    ) -> Option<Translational> {
        let n = axis_i.norm();
        if !(n.is_finite() && n > 0.0) {
            return None;
        }
        Some(Translational {
            body_i,
            point_i,
            axis_i: axis_i / n,
            body_j,
            point_j,
            angle0_rad,
        })
    }
}

impl ConstraintEquations for Translational {
    fn equations(&self) -> usize {
        2
    }

    fn bodies(&self) -> (BodyId, BodyId) {
        (self.body_i, self.body_j)
    }

    fn is_angle_row(&self, k: usize) -> bool {
        k == 0
    }

    #[inline]
    fn phi(&self, pi: &Pose, pj: &Pose, _t: f64) -> [f64; 2] {
        let n = pi.rotate(rot90(self.axis_i));
        let d = pj.point(self.point_j) - pi.point(self.point_i);
        [pj.phi - pi.phi - self.angle0_rad, n.dot(&d)]
    }

    #[inline]
    fn jacobian(&self, pi: &Pose, pj: &Pose, _t: f64) -> JacobianBlocks {
        let u = pi.rotate(self.axis_i);
        let n = rot90(u);
        let si = pi.rotate(self.point_i);
        let sj = pj.rotate(self.point_j);
        let d = pj.r + sj - pi.r - si;
        JacobianBlocks {
            di: [[0.0, 0.0, -1.0], [-n.x, -n.y, -u.dot(&d) - cross(si, n)]],
            dj: [[0.0, 0.0, 1.0], [n.x, n.y, cross(sj, n)]],
        }
    }

    #[inline]
    fn nu(&self, _t: f64) -> [f64; 2] {
        [0.0, 0.0]
    }

    #[inline]
    fn gamma(&self, pi: &Pose, pj: &Pose, vi: &Twist, vj: &Twist, _t: f64) -> [f64; 2] {
        let u = pi.rotate(self.axis_i);
        let n = rot90(u);
        let si = pi.rotate(self.point_i);
        let sj = pj.rotate(self.point_j);
        let d = pj.r + sj - pi.r - si;
        let d_dot = vj.v + rot90(sj) * vj.w - vi.v - rot90(si) * vi.w;
        let g2 = vi.w * vi.w * n.dot(&d)
            + 2.0 * vi.w * u.dot(&d_dot)
            + n.dot(&(sj * (vj.w * vj.w) - si * (vi.w * vi.w)));
        [0.0, g2]
    }
}

#[cfg(test)]
mod tests {
    use super::super::constraint::testing::check_joint;
    use super::*;

    #[test]
    fn jacobian_and_gamma_match_finite_differences() {
        let j = Translational::new(
            BodyId::Moving(0),
            Vector2::new(0.02, -0.01),
            Vector2::new(0.6, 0.8),
            BodyId::Moving(1),
            Vector2::new(-0.03, 0.015),
            0.2,
        )
        .expect("axis");
        check_joint(
            &j,
            [0.01, 0.02, 0.7],
            [0.1, -0.03, -0.3],
            [0.4, -1.1, 5.0],
            [-2.0, 0.7, -3.0],
        );
        let g = Translational::new(
            BodyId::Ground,
            Vector2::zeros(),
            Vector2::new(1.0, 0.0),
            BodyId::Moving(2),
            Vector2::zeros(),
            0.0,
        )
        .expect("axis");
        check_joint(&g, [0.0; 3], [0.2, 0.01, 0.1], [0.0; 3], [3.0, -0.2, 2.0]);
        // ground slide along x: equations are [phi_j, y_j]
        let f = g.phi(&Pose::GROUND, &Pose::new(0.3, 0.02, 0.1), 0.0);
        assert!((f[0] - 0.1).abs() < 1e-15 && (f[1] - 0.02).abs() < 1e-15);
    }

    #[test]
    fn zero_axis_refused() {
        assert!(
            Translational::new(
                BodyId::Ground,
                Vector2::zeros(),
                Vector2::zeros(),
                BodyId::Moving(0),
                Vector2::zeros(),
                0.0
            )
            .is_none()
        );
    }
}
