//! The material's side of the local fatigue strength: the FKM material group and its constants,
//! the tensile and yield strength, and the fatigue limit of the polished specimen in
//! tension–compression.
//!
//! **Fatigue limit** (FKM guideline "Analytical Strength Assessment of Components", 6th ed. 2012,
//! §4.2, eq. 4.2.3 and Table 4.2.1; the same in the 7th ed. 2020):
//!
//!   σ_W,zd = f_W,σ · R_m,        τ_W,s = f_W,τ · σ_W,zd,
//!
//! with R_m the tensile strength of the part (R_m = K_d,m · R_m,N, the technological size factor
//! applied to the standard value, see [`super::factors::size_factor`]). f_W,σ and f_W,τ are the
//! group constants below. A fatigue limit from a test or a data sheet can replace f_W,σ · R_m,N
//! ([`FatigueMaterial::fatigue_limit_pa`]): that is what the default does, so that the default
//! reproduces the thesis' steel (S355: R_m = 470 MPa, S_e = 0.5 R_m = 235 MPa, the polished
//! rotating-beam estimate of Budynas–Nisbett, *Shigley's Mechanical Engineering Design*, 10th ed.,
//! eq. 6-8). FKM's own estimate for that steel would be 0.45 · 470 = 211.5 MPa.
//!
//! **Group constants.** One row per FKM material group, from the tables of the 6th edition as
//! reproduced in the public literature: f_W,σ, f_W,τ (Table 4.2.1); the constants of the
//! mean-stress sensitivity a_M, b_M (Table 4.6.1, [`super::haigh`]); of the roughness factor a_R,σ
//! and R_m,N,min (Table 4.3.9; also quadco.engineering, "Surface roughness factor K_R", after FKM);
//! of the support factor a_G, b_G (Table 4.3.4, [`super::factors::support_factor`]). Secondary
//! source for all four tables: S. A. McKelvey, Y.-L. Lee, M. E. Barkey, "Stress-based uniaxial
//! fatigue analysis using methods described in FKM-guideline", J. Fail. Anal. and Preven. 12
//! (2012) 445–484.

use serde::{Deserialize, Serialize};

/// The FKM material groups (the rows of FKM Tables 4.2.1, 4.3.4, 4.3.9, 4.6.1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MaterialGroup {
    /// Steel other than the groups below (structural, quenched-and-tempered): the default.
    #[default]
    Steel,
    /// Case-hardening steel.
    CaseHardeningSteel,
    /// Stainless steel.
    StainlessSteel,
    /// Forging steel.
    ForgingSteel,
    /// Cast steel (GS).
    CastSteel,
    /// Nodular (ductile) cast iron (GJS).
    NodularCastIron,
    /// Malleable cast iron (GJM).
    MalleableCastIron,
    /// Grey cast iron, lamellar graphite (GJL).
    GreyCastIron,
    /// Wrought aluminium alloy.
    WroughtAluminium,
    /// Cast aluminium alloy.
    CastAluminium,
}

/// The constants of one material group (SI: stresses in Pa).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroupConstants {
    /// f_W,σ: fatigue limit in tension–compression over R_m.
    pub f_w_sigma: f64,
    /// f_W,τ: shear fatigue limit over the tension–compression one.
    pub f_w_tau: f64,
    /// a_M of the mean-stress sensitivity M_σ = a_M · 10⁻³ · R_m/MPa + b_M.
    pub a_m: f64,
    /// b_M of the mean-stress sensitivity.
    pub b_m: f64,
    /// a_R,σ of the roughness factor.
    pub a_r: f64,
    /// R_m,N,min of the roughness factor, Pa.
    pub r_m_n_min_pa: f64,
    /// a_G of the support factor.
    pub a_g: f64,
    /// b_G of the support factor, Pa.
    pub b_g_pa: f64,
}

const MPA: f64 = 1e6;

impl MaterialGroup {
    /// Every group, in table order.
    pub const ALL: [MaterialGroup; 10] = [
        MaterialGroup::Steel,
        MaterialGroup::CaseHardeningSteel,
        MaterialGroup::StainlessSteel,
        MaterialGroup::ForgingSteel,
        MaterialGroup::CastSteel,
        MaterialGroup::NodularCastIron,
        MaterialGroup::MalleableCastIron,
        MaterialGroup::GreyCastIron,
        MaterialGroup::WroughtAluminium,
        MaterialGroup::CastAluminium,
    ];

    /// The group's constants (FKM 6th ed. Tables 4.2.1, 4.3.4, 4.3.9, 4.6.1).
    pub fn constants(self) -> GroupConstants {
        // (f_W,σ, f_W,τ, a_M, b_M, a_R,σ, R_m,N,min MPa, a_G, b_G MPa)
        let (f_w_sigma, f_w_tau, a_m, b_m, a_r, r_min, a_g, b_g) = match self {
            MaterialGroup::Steel => (0.45, 0.577, 0.35, -0.1, 0.22, 400.0, 0.50, 2700.0),
            MaterialGroup::CaseHardeningSteel => {
                (0.40, 0.577, 0.35, -0.1, 0.22, 400.0, 0.50, 2700.0)
            }
            MaterialGroup::StainlessSteel => (0.40, 0.577, 0.35, -0.1, 0.22, 400.0, 0.40, 2400.0),
            MaterialGroup::ForgingSteel => (0.40, 0.577, 0.35, -0.1, 0.22, 400.0, 0.50, 2700.0),
            MaterialGroup::CastSteel => (0.34, 0.577, 0.35, 0.05, 0.20, 400.0, 0.25, 2000.0),
            MaterialGroup::NodularCastIron => (0.34, 0.65, 0.35, 0.08, 0.16, 400.0, 0.05, 3200.0),
            MaterialGroup::MalleableCastIron => {
                (0.30, 0.75, 0.35, 0.13, 0.12, 350.0, -0.05, 3200.0)
            }
            MaterialGroup::GreyCastIron => (0.30, 0.85, 0.0, 0.5, 0.06, 100.0, -0.05, 3200.0),
            MaterialGroup::WroughtAluminium => (0.30, 0.577, 1.0, -0.04, 0.22, 133.0, 0.05, 850.0),
            MaterialGroup::CastAluminium => (0.30, 0.75, 1.0, 0.2, 0.20, 133.0, -0.05, 3200.0),
        };
        GroupConstants {
            f_w_sigma,
            f_w_tau,
            a_m,
            b_m,
            a_r,
            r_m_n_min_pa: r_min * MPA,
            a_g,
            b_g_pa: b_g * MPA,
        }
    }
}

/// The strength data of a part's material, SI (Pa).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FatigueMaterial {
    /// FKM material group.
    pub group: MaterialGroup,
    /// Tensile strength R_m (standard value R_m,N of the semi-finished product), Pa.
    pub tensile_strength_pa: f64,
    /// Yield strength R_p (R_p0.2 or R_eH), Pa.
    pub yield_strength_pa: f64,
    /// Fatigue limit of the polished specimen in tension–compression, Pa: `None` for FKM's
    /// estimate f_W,σ · R_m.
    pub fatigue_limit_pa: Option<f64>,
}

impl Default for FatigueMaterial {
    /// The thesis' steel: S355, R_m = 470 MPa, R_p = 355 MPa (EN 10025-2), S_e = 235 MPa.
    fn default() -> Self {
        FatigueMaterial {
            group: MaterialGroup::Steel,
            tensile_strength_pa: 470e6,
            yield_strength_pa: 355e6,
            fatigue_limit_pa: Some(235e6),
        }
    }
}

impl FatigueMaterial {
    /// A material with FKM's estimate of the fatigue limit (f_W,σ · R_m).
    pub fn fkm(group: MaterialGroup, tensile_strength_pa: f64, yield_strength_pa: f64) -> Self {
        FatigueMaterial {
            group,
            tensile_strength_pa,
            yield_strength_pa,
            fatigue_limit_pa: None,
        }
    }

    /// The group's constants.
    pub fn constants(&self) -> GroupConstants {
        self.group.constants()
    }

    /// σ_W,zd of the part, Pa: (given limit or f_W,σ · R_m,N) · K_d,m, with `k_d_m` the
    /// technological size factor (1 when R_m is the part's own strength).
    pub fn tension_fatigue_limit_pa(&self, k_d_m: f64) -> f64 {
        let specimen = self
            .fatigue_limit_pa
            .unwrap_or(self.constants().f_w_sigma * self.tensile_strength_pa);
        specimen * k_d_m
    }

    /// τ_W,s = f_W,τ · σ_W,zd, Pa.
    pub fn shear_fatigue_limit_pa(&self, k_d_m: f64) -> f64 {
        self.constants().f_w_tau * self.tension_fatigue_limit_pa(k_d_m)
    }

    /// Checks 0 < R_p ≤ R_m, finite, and 0 < σ_W,zd < R_m when given.
    pub fn validate(&self) -> Result<(), String> {
        let (rm, rp) = (self.tensile_strength_pa, self.yield_strength_pa);
        if !(rm.is_finite() && rm > 0.0 && rp.is_finite() && rp > 0.0 && rp <= rm) {
            return Err(format!(
                "need 0 < R_p <= R_m, got R_p = {:.1} MPa, R_m = {:.1} MPa",
                rp / MPA,
                rm / MPA
            ));
        }
        if let Some(s) = self.fatigue_limit_pa
            && !(s.is_finite() && s > 0.0 && s < rm)
        {
            return Err(format!(
                "the fatigue limit must lie in (0, R_m), got {:.1} MPa",
                s / MPA
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_the_thesis_steel() {
        let m = FatigueMaterial::default();
        assert_eq!(m.tension_fatigue_limit_pa(1.0), 235e6);
        assert_eq!(m.tensile_strength_pa, 470e6);
        assert!(m.validate().is_ok());
        // FKM's estimate for the same steel: 0.45 R_m
        let f = FatigueMaterial::fkm(MaterialGroup::Steel, 470e6, 355e6);
        assert!((f.tension_fatigue_limit_pa(1.0) - 211.5e6).abs() < 1e-3);
        assert!((f.shear_fatigue_limit_pa(1.0) - 0.577 * 211.5e6).abs() < 1e-3);
    }

    #[test]
    fn every_group_has_sane_constants() {
        for g in MaterialGroup::ALL {
            let c = g.constants();
            assert!(c.f_w_sigma > 0.0 && c.f_w_sigma < 1.0, "{g:?}");
            assert!(c.f_w_tau >= 0.577 && c.f_w_tau < 1.0, "{g:?}");
            assert!(c.r_m_n_min_pa > 0.0 && c.b_g_pa > 0.0, "{g:?}");
        }
        assert!(
            FatigueMaterial::fkm(MaterialGroup::Steel, 400e6, 500e6)
                .validate()
                .is_err()
        );
    }
}
