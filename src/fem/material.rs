//! Isotropic linear elastic material (Hooke's law in Lamé form).
//!
//! Stress and strain tensors are stored as `[xx, yy, zz, xy, yz, zx]` (the component order ParaView
//! uses for symmetric tensors); strains are tensor components (not engineering shears).

use serde::{Deserialize, Serialize};

use super::error::{FemError, Result};

/// Isotropic linear elastic material, SI units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Young's modulus E, Pa.
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio ν.
    pub poisson_ratio: f64,
}

impl Default for Material {
    /// Steel as in SPEC Stage 3: E = 210 GPa, ν = 0.3.
    fn default() -> Self {
        Material::STEEL
    }
}

impl Material {
    /// Steel, E = 210 GPa, ν = 0.3 (SPEC Stage 3).
    pub const STEEL: Material = Material {
        youngs_modulus_pa: 210e9,
        poisson_ratio: 0.3,
    };

    /// Checks E > 0 and -1 < ν < 0.5 (finite).
    pub fn validate(&self) -> Result<()> {
        let (e, nu) = (self.youngs_modulus_pa, self.poisson_ratio);
        if !(e.is_finite() && e > 0.0) {
            return Err(FemError::InvalidInput(format!(
                "Young's modulus must be > 0, got {e}"
            )));
        }
        if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
            return Err(FemError::InvalidInput(format!(
                "Poisson's ratio must be in (-1, 0.5), got {nu}"
            )));
        }
        Ok(())
    }

    /// Lamé constants (λ, μ).
    pub fn lame(&self) -> (f64, f64) {
        let (e, nu) = (self.youngs_modulus_pa, self.poisson_ratio);
        let mu = e / (2.0 * (1.0 + nu));
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        (lambda, mu)
    }

    /// Shear modulus G = μ.
    pub fn shear_modulus(&self) -> f64 {
        self.lame().1
    }

    /// σ = λ tr(ε) I + 2 μ ε, both as `[xx, yy, zz, xy, yz, zx]` tensor components.
    pub fn stress(&self, strain: &[f64; 6]) -> [f64; 6] {
        let (lambda, mu) = self.lame();
        let tr = strain[0] + strain[1] + strain[2];
        [
            lambda * tr + 2.0 * mu * strain[0],
            lambda * tr + 2.0 * mu * strain[1],
            lambda * tr + 2.0 * mu * strain[2],
            2.0 * mu * strain[3],
            2.0 * mu * strain[4],
            2.0 * mu * strain[5],
        ]
    }
}

/// Von Mises equivalent stress of `[xx, yy, zz, xy, yz, zx]`.
pub fn von_mises(s: &[f64; 6]) -> f64 {
    let d = (s[0] - s[1]).powi(2) + (s[1] - s[2]).powi(2) + (s[2] - s[0]).powi(2);
    (0.5 * d + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5])).sqrt()
}
