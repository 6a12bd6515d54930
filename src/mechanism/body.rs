//! Bodies, body coordinates and planar vector helpers.
//!
//! Each moving body i carries the three *body coordinates* of thesis eq.
//! (2.13)/(2.16), c_i = [x_i, y_i, φ_i]ᵀ: the global position of its reference
//! point (always the centroid here, so that the mass matrix is diagonal, eq.
//! (3.29)) and the angle φ_i of its body frame ξ_i η_i against the global
//! frame. A point P fixed on body i with body-frame coordinates s'ᴾ = (ξᴾ, ηᴾ)
//! is at
//!
//! rᴾ = r_i + A_i s'ᴾ,  A_i = [[cos φ_i, −sin φ_i], [sin φ_i, cos φ_i]]
//!
//! (thesis eq. 2.18; Nikravesh 1988, planar kinematics). Its derivative with
//! respect to φ_i is B_i s'ᴾ = rot90(A_i s'ᴾ), where rot90 turns a vector by
//! +90°.
//!
//! **Ground** (body 1 of the thesis) is handled *implicitly*: it has no
//! coordinates, its frame coincides with the global frame (x = y = φ = 0), and
//! joints that attach to it simply have no Jacobian columns for it. Points on
//! the ground are given in global coordinates. This keeps the coordinate vector
//! at 3 × (moving bodies), the 9 coordinates of thesis eq. (2.14).

use nalgebra::Vector2;

/// Reference to a body of a multibody system.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BodyId {
    /// The fixed frame (thesis body 1), without coordinates.
    Ground,
    /// Moving body with index `k`: coordinates are `q[3k], q[3k+1], q[3k+2]`.
    Moving(usize),
}

impl BodyId {
    /// Index of the first coordinate of this body, `None` for the ground.
    pub fn offset(self) -> Option<usize> {
        match self {
            BodyId::Ground => None,
            BodyId::Moving(k) => Some(3 * k),
        }
    }
}

/// Mass properties of one moving body. The reference point of the body
/// coordinates is the centroid, so its block of the mass matrix is
/// diag(m, m, I) (thesis eq. 3.29).
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Display name (used in messages).
    pub name: String,
    /// Mass (kg), strictly positive.
    pub mass_kg: f64,
    /// Moment of inertia about the centroid, about the axis normal to the
    /// plane of motion (kg·m²), non-negative.
    pub inertia_kgm2: f64,
}

/// Planar cross product a × b = a_x b_y − a_y b_x (z component).
#[inline]
pub fn cross(a: Vector2<f64>, b: Vector2<f64>) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Rotate a vector by +90°: rot90(a) = (−a_y, a_x); equals B A⁻¹ a of
/// Nikravesh's notation (dA/dφ = rot90 ∘ A).
#[inline]
pub fn rot90(a: Vector2<f64>) -> Vector2<f64> {
    Vector2::new(-a.y, a.x)
}

/// Position, angle and rotation of one body at one configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Global position of the reference point (m).
    pub r: Vector2<f64>,
    /// Angle φ (rad).
    pub phi: f64,
    /// cos φ.
    pub cos: f64,
    /// sin φ.
    pub sin: f64,
}

impl Pose {
    /// The ground frame.
    pub const GROUND: Pose = Pose {
        r: Vector2::new(0.0, 0.0),
        phi: 0.0,
        cos: 1.0,
        sin: 0.0,
    };

    /// Pose of a body from its coordinates.
    pub fn new(x: f64, y: f64, phi: f64) -> Pose {
        let (sin, cos) = phi.sin_cos();
        Pose {
            r: Vector2::new(x, y),
            phi,
            cos,
            sin,
        }
    }

    /// A s': a body-frame vector expressed in the global frame.
    #[inline]
    pub fn rotate(&self, local: Vector2<f64>) -> Vector2<f64> {
        Vector2::new(
            self.cos * local.x - self.sin * local.y,
            self.sin * local.x + self.cos * local.y,
        )
    }

    /// rᴾ = r + A s'ᴾ, the global position of a body-fixed point.
    #[inline]
    pub fn point(&self, local: Vector2<f64>) -> Vector2<f64> {
        self.r + self.rotate(local)
    }
}

/// Velocity of one body: (ẋ, ẏ) of the reference point and φ̇.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Twist {
    /// Velocity of the reference point (m/s).
    pub v: Vector2<f64>,
    /// Angular velocity (rad/s).
    pub w: f64,
}

impl Twist {
    /// The ground does not move.
    pub const ZERO: Twist = Twist {
        v: Vector2::new(0.0, 0.0),
        w: 0.0,
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_and_rot90_are_consistent() {
        let p = Pose::new(1.0, 2.0, 0.7);
        let s = Vector2::new(0.3, -0.2);
        // derivative of A s' with respect to phi equals rot90(A s')
        let h = 1e-6;
        let d = (Pose::new(1.0, 2.0, 0.7 + h).rotate(s) - Pose::new(1.0, 2.0, 0.7 - h).rotate(s))
            / (2.0 * h);
        let e = rot90(p.rotate(s));
        assert!((d - e).norm() < 1e-9);
        assert!((cross(s, rot90(s)) - s.norm_squared()).abs() < 1e-15);
        assert_eq!(Pose::GROUND.point(s), s);
        assert_eq!(BodyId::Moving(2).offset(), Some(6));
        assert_eq!(BodyId::Ground.offset(), None);
    }
}
