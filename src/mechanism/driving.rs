//! Driving constraint on an angle — a prescribed motion, Nikravesh 1988
//! (kinematic driver constraints); the thesis prescribes the crank rotation
//! 40πt in ADAMS (ch. 5.2).
//!
//! Φ^(d,1) = φⱼ − φᵢ − f(t) = 0        (body i is usually the ground, φᵢ ≡ 0)
//!
//! D: φᵢ: −1, φⱼ: +1;   ν = −Φ_t = ḟ(t);   γ = −Φ_tt = f̈(t).
//!
//! Reaction: the multiplier λ is the *driving torque* that body i applies to
//! body j (D_jᵀλ = (0, 0, λ)); body i receives −λ. For the crank–slider this is
//! the torque the drive must supply to the crank.

use super::body::{BodyId, Pose, Twist};
use super::constraint::{ConstraintEquations, JacobianBlocks};
use super::motion::CrankMotion;

/// Prescribed relative angle φⱼ − φᵢ = f(t).
#[derive(Clone, Debug)]
pub struct Driving {
    /// Reference body i (usually the ground).
    pub body_i: BodyId,
    /// Driven body j.
    pub body_j: BodyId,
    /// The law f(t).
    pub motion: CrankMotion,
}

impl ConstraintEquations for Driving {
    fn equations(&self) -> usize {
        1
    }

    fn bodies(&self) -> (BodyId, BodyId) {
        (self.body_i, self.body_j)
    }

    fn is_angle_row(&self, _k: usize) -> bool {
        true
    }

    #[inline]
    fn phi(&self, pi: &Pose, pj: &Pose, t: f64) -> [f64; 2] {
        [pj.phi - pi.phi - self.motion.sample(t).phi, 0.0]
    }

    #[inline]
    fn jacobian(&self, _pi: &Pose, _pj: &Pose, _t: f64) -> JacobianBlocks {
        JacobianBlocks {
            di: [[0.0, 0.0, -1.0], [0.0; 3]],
            dj: [[0.0, 0.0, 1.0], [0.0; 3]],
        }
    }

    #[inline]
    fn nu(&self, t: f64) -> [f64; 2] {
        [self.motion.sample(t).omega, 0.0]
    }

    #[inline]
    fn gamma(&self, _pi: &Pose, _pj: &Pose, _vi: &Twist, _vj: &Twist, t: f64) -> [f64; 2] {
        [self.motion.sample(t).alpha, 0.0]
    }
}

#[cfg(test)]
mod tests {
    use super::super::constraint::testing::check_joint;
    use super::*;

    fn harmonic() -> Driving {
        Driving {
            body_i: BodyId::Ground,
            body_j: BodyId::Moving(0),
            motion: CrankMotion::Harmonic {
                phi0_rad: 0.3,
                omega_rad_s: 20.0,
                amplitude_rad: 0.1,
                frequency_rad_s: 15.0,
            },
        }
    }

    #[test]
    fn time_derivatives_match_finite_differences() {
        let d = harmonic();
        let pj = Pose::new(0.0, 0.0, 1.0);
        let h = 1e-5;
        for &t in &[0.0, 0.1, 0.77] {
            // Phi_t by central differences; nu = -Phi_t
            let phi_t = (d.phi(&Pose::GROUND, &pj, t + h)[0] - d.phi(&Pose::GROUND, &pj, t - h)[0])
                / (2.0 * h);
            assert!((d.nu(t)[0] + phi_t).abs() < 1e-6);
            // Phi_tt; gamma = -Phi_tt
            let f = |s: f64| d.phi(&Pose::GROUND, &pj, s)[0];
            let phi_tt = (f(t + h) - 2.0 * f(t) + f(t - h)) / (h * h);
            let g = d.gamma(&Pose::GROUND, &pj, &Twist::ZERO, &Twist::ZERO, t)[0];
            assert!(
                (g + phi_tt).abs() < 1e-3 * (1.0 + g.abs()),
                "{g} vs {}",
                -phi_tt
            );
        }
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let d = Driving {
            body_i: BodyId::Moving(1),
            body_j: BodyId::Moving(0),
            motion: CrankMotion::constant_speed(3.0),
        };
        check_joint(
            &d,
            [0.1, 0.2, 0.3],
            [0.0, 0.1, 1.0],
            [1.0, 2.0, 3.0],
            [0.5, 0.2, 3.0],
        );
    }
}
