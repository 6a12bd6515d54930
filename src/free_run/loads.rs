//! Applied loads of the free-running crank (thesis §4.2) and the stiff hard-case addition.

use serde::{Deserialize, Serialize};

/// Standard gravity [m/s²] (SPEC: along −y when enabled).
pub const G: f64 = 9.81;

/// A linear gas spring with damping on the piston: force along +x
/// `F_s = −k (x − x0) − c ẋ` \[N\], added to the piston force.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GasSpring {
    /// Stiffness `k` [N/m].
    pub k: f64,
    /// Unstretched piston travel `x0` \[m\].
    pub x0: f64,
    /// Damping `c` [N·s/m].
    pub c: f64,
}

/// Loads on the mechanism.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Loads {
    /// Crank torque `M` [N·m] (positive in the sense of increasing φ).
    pub torque: f64,
    /// Piston force `F` \[N\] in the direction of increasing `x`.
    pub piston_force: f64,
    /// Gravity `g` along −y (the piston slides along x, so it acts on the crank and rod only).
    ///
    /// Off for the thesis' `free` scene: the reduced moment of eq. 3.22 has no gravity term,
    /// and with gravity the torque amplitude `g (m2 e + m_A r) ≈ 1.5 N·m` would exceed
    /// `M = 1 N·m`, so the crank would first swing backwards — not the run of thesis §4.2.
    pub gravity: bool,
    /// Optional stiff gas spring (hard case; not in the thesis).
    pub spring: Option<GasSpring>,
}

impl Loads {
    /// The thesis' ch. 4 loads: `M = 1 N·m`, `F = 15 N`, no gravity, no spring.
    pub fn thesis_ch4() -> Self {
        Self {
            torque: 1.0,
            piston_force: 15.0,
            gravity: false,
            spring: None,
        }
    }

    /// `true` if every load derives from a potential (no damping), so the energy integral
    /// holds.
    pub fn is_conservative(&self) -> bool {
        self.spring.is_none_or(|s| s.c == 0.0)
    }
}
