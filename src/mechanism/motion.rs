//! Prescribed motion laws φ(t) for driving constraints.

use super::error::{DynamicsError, Result, finite};

/// Value and first two time derivatives of a prescribed angle at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotionSample {
    /// φ (rad).
    pub phi: f64,
    /// φ̇ (rad/s).
    pub omega: f64,
    /// φ̈ (rad/s²).
    pub alpha: f64,
}

/// A prescribed crank motion φ(t), with φ̇(t) and φ̈(t) in closed form.
#[derive(Clone, Copy, Debug)]
pub enum CrankMotion {
    /// φ = φ₀ + ω t (the `driven` scene: ω = 40π rad/s).
    ConstantSpeed {
        /// φ(0) (rad).
        phi0_rad: f64,
        /// ω (rad/s).
        omega_rad_s: f64,
    },
    /// φ = φ₀ + ω₀ t + ½ α t².
    ConstantAcceleration {
        /// φ(0) (rad).
        phi0_rad: f64,
        /// φ̇(0) (rad/s).
        omega0_rad_s: f64,
        /// φ̈ (rad/s²).
        alpha_rad_s2: f64,
    },
    /// φ = φ₀ + ω t + a sin(ν t): a speed ripple, a general non-uniform motion.
    Harmonic {
        /// φ(0) (rad).
        phi0_rad: f64,
        /// Mean speed ω (rad/s).
        omega_rad_s: f64,
        /// Ripple amplitude a (rad).
        amplitude_rad: f64,
        /// Ripple circular frequency ν (rad/s).
        frequency_rad_s: f64,
    },
    /// Any law given as a function t ↦ (φ, φ̇, φ̈); the caller guarantees that
    /// the three are consistent derivatives.
    Custom(fn(f64) -> MotionSample),
}

impl CrankMotion {
    /// Constant speed from φ = 0.
    pub fn constant_speed(omega_rad_s: f64) -> CrankMotion {
        CrankMotion::ConstantSpeed {
            phi0_rad: 0.0,
            omega_rad_s,
        }
    }

    /// φ(t), φ̇(t), φ̈(t).
    pub fn sample(&self, t: f64) -> MotionSample {
        match *self {
            CrankMotion::ConstantSpeed {
                phi0_rad,
                omega_rad_s,
            } => MotionSample {
                phi: phi0_rad + omega_rad_s * t,
                omega: omega_rad_s,
                alpha: 0.0,
            },
            CrankMotion::ConstantAcceleration {
                phi0_rad,
                omega0_rad_s,
                alpha_rad_s2,
            } => MotionSample {
                phi: phi0_rad + omega0_rad_s * t + 0.5 * alpha_rad_s2 * t * t,
                omega: omega0_rad_s + alpha_rad_s2 * t,
                alpha: alpha_rad_s2,
            },
            CrankMotion::Harmonic {
                phi0_rad,
                omega_rad_s,
                amplitude_rad,
                frequency_rad_s,
            } => {
                let (s, c) = (frequency_rad_s * t).sin_cos();
                MotionSample {
                    phi: phi0_rad + omega_rad_s * t + amplitude_rad * s,
                    omega: omega_rad_s + amplitude_rad * frequency_rad_s * c,
                    alpha: -amplitude_rad * frequency_rad_s * frequency_rad_s * s,
                }
            }
            CrankMotion::Custom(f) => f(t),
        }
    }

    /// Refuse non-finite parameters (a `Custom` law is checked when sampled).
    pub fn validate(&self) -> Result<()> {
        match *self {
            CrankMotion::ConstantSpeed {
                phi0_rad,
                omega_rad_s,
            } => {
                finite("phi0_rad", phi0_rad)?;
                finite("omega_rad_s", omega_rad_s)?;
            }
            CrankMotion::ConstantAcceleration {
                phi0_rad,
                omega0_rad_s,
                alpha_rad_s2,
            } => {
                finite("phi0_rad", phi0_rad)?;
                finite("omega0_rad_s", omega0_rad_s)?;
                finite("alpha_rad_s2", alpha_rad_s2)?;
            }
            CrankMotion::Harmonic {
                phi0_rad,
                omega_rad_s,
                amplitude_rad,
                frequency_rad_s,
            } => {
                finite("phi0_rad", phi0_rad)?;
                finite("omega_rad_s", omega_rad_s)?;
                finite("amplitude_rad", amplitude_rad)?;
                finite("frequency_rad_s", frequency_rad_s)?;
            }
            CrankMotion::Custom(_) => {}
        }
        Ok(())
    }

    /// Sample and refuse non-finite values (for `Custom` laws).
    pub fn checked_sample(&self, t: f64) -> Result<MotionSample> {
        let s = self.sample(t);
        if s.phi.is_finite() && s.omega.is_finite() && s.alpha.is_finite() {
            Ok(s)
        } else {
            Err(DynamicsError::NonFinite {
                t_s: t,
                what: "prescribed motion",
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_derivatives(m: CrankMotion) {
        let h = 1e-5;
        for &t in &[0.0, 0.013, 0.37, 1.2] {
            let s = m.sample(t);
            let (p, q) = (m.sample(t + h), m.sample(t - h));
            let w = (p.phi - q.phi) / (2.0 * h);
            let a = (p.omega - q.omega) / (2.0 * h);
            assert!((w - s.omega).abs() < 1e-6 * (1.0 + s.omega.abs()), "{m:?}");
            assert!((a - s.alpha).abs() < 1e-5 * (1.0 + s.alpha.abs()), "{m:?}");
        }
    }

    #[test]
    fn derivatives_are_consistent() {
        check_derivatives(CrankMotion::constant_speed(40.0 * std::f64::consts::PI));
        check_derivatives(CrankMotion::ConstantAcceleration {
            phi0_rad: 0.2,
            omega0_rad_s: 10.0,
            alpha_rad_s2: 300.0,
        });
        check_derivatives(CrankMotion::Harmonic {
            phi0_rad: 0.1,
            omega_rad_s: 100.0,
            amplitude_rad: 0.05,
            frequency_rad_s: 200.0,
        });
        assert!(
            CrankMotion::ConstantSpeed {
                phi0_rad: f64::NAN,
                omega_rad_s: 1.0
            }
            .validate()
            .is_err()
        );
    }
}
