//! From the material's fatigue limit to the component fatigue limit at one surface point: the
//! support factor of the stress gradient, the roughness, size, surface-treatment and coating
//! factors, the design factor K_WK and σ_WK (FKM guideline, 6th ed. 2012, §4.3, local stresses).
//!
//! **Support factor** (FKM 6th ed. §4.3.1.3, eq. 4.3.12 with Table 4.3.4; McKelvey, Lee & Barkey
//! 2012, eq. 34): with the related stress gradient χ* (per mm) and R_m in MPa,
//!
//!   n_σ = 1 + χ*·mm · 10^−(a_G − 0.5 + R_m/b_G)        for χ* ≤ 0.1 mm⁻¹,
//!   n_σ = 1 + √(χ*·mm) · 10^−(a_G + R_m/b_G)            for 0.1 < χ* ≤ 1 mm⁻¹,
//!   n_σ = 1 + ⁴√(χ*·mm) · 10^−(a_G + R_m/b_G)           for 1 < χ* ≤ 100 mm⁻¹
//!
//! (the branches meet: 0.1 · 10^0.5 = √0.1 and √1 = ⁴√1). χ* ≤ 0 (a stress that grows inward, or
//! none) gives n_σ = 1; χ* is capped at 100 mm⁻¹, the end of the table. The shear support factor
//! n_τ is the same function of the shear gradient χ*_τ. The newer support concept of the 7th
//! edition (n = n_st · n_vm · n_bm, with the highly stressed surface) is not used: it needs the
//! stressed area, and the gradient form is the one every tool manual documents.
//!
//! **Roughness factor** (FKM §4.3.1.4, eq. 4.3.15–16; quadco.engineering after FKM):
//!
//!   K_R,σ = 1 − a_R,σ · lg(R_z/µm) · lg(2 R_m / R_m,N,min),
//!   K_R,τ = 1 − f_W,τ · a_R,σ · lg(R_z/µm) · lg(2 R_m / R_m,N,min),
//!
//! 1 for a polished surface (R_z ≤ 1 µm). Forged or rolled skin: R_z = 200 µm (the indicative value
//! for rolled, forged and cast skin of DIN 4768 that FKM uses), the default here.
//!
//! **Size factor** (technological, FKM §4.2.1, eq. 4.2.4; acts on R_m and so on σ_W,zd):
//!
//!   K_d,m = (1 − 0.7686 a_d,m lg(d_eff/7.5 mm)) / (1 − 0.7686 a_d,m lg(d_eff,N,m/7.5 mm))
//!
//! for d_eff > d_eff,N,m, else 1. For FKM's "steel in general" a_d,m = 0.15 and d_eff,N,m = 40 mm
//! ([`SizeEffect::structural_steel`]); a forging's d_eff is the thickness of the section at
//! heat treatment. Off by default: the tensile strength is then the part's own.
//!
//! **Design factor** for local stresses (FKM §4.3.1, eq. 4.3.1 and 4.3.2; the nominal-stress form
//! has K_f in place of 1/n):
//!
//!   K_WK,σ = (1/n_σ) · (1 + (1/K̃_f) · (1/K_R,σ − 1)) · 1/(K_V · K_S · K_NL,E),
//!   K_WK,τ = (1/n_τ) · (1 + (1/K̃_f) · (1/K_R,τ − 1)) · 1/(K_V · K_S),
//!
//! with K̃_f the estimated fatigue notch factor (FKM: K̃_f = 2 when the local approach gives no
//! nominal stress, the default here; 1 for an unnotched part), K_V the surface-treatment factor
//! (Table 4.3.7: 1 untreated; e.g. shot peening 1.1–1.2 unnotched, 1.1–1.5 notched; see
//! [`SurfaceTreatment`]), K_S the coating factor (1 except anodised aluminium), K_NL,E the factor
//! of the non-linear elastic behaviour (1 except grey cast iron). The component fatigue limits:
//!
//!   σ_WK = σ_W,zd / K_WK,σ,        τ_WK = τ_W,s / K_WK,τ.

use serde::{Deserialize, Serialize};

use super::material::FatigueMaterial;

/// Related stress gradient of the table's upper end, 1/m (100 mm⁻¹).
pub const CHI_STAR_MAX_PER_M: f64 = 100e3;

/// The default R_z of a forged (or rolled) skin, m: 200 µm.
pub const FORGED_SKIN_RZ_M: f64 = 200e-6;

/// The support factor n(χ*) of a related stress gradient `chi_star_per_m` (1/m) for tensile
/// strength `r_m_pa` and group constants `a_g`, `b_g_pa` (see the module documentation).
pub fn support_factor(chi_star_per_m: f64, r_m_pa: f64, a_g: f64, b_g_pa: f64) -> f64 {
    // χ* ≤ 0 or NaN: no support
    if chi_star_per_m.is_nan() || chi_star_per_m <= 0.0 {
        return 1.0;
    }
    let chi_mm = (chi_star_per_m.min(CHI_STAR_MAX_PER_M)) * 1e-3;
    let e = a_g + r_m_pa / b_g_pa;
    if chi_mm <= 0.1 {
        1.0 + chi_mm * 10f64.powf(-(e - 0.5))
    } else if chi_mm <= 1.0 {
        1.0 + chi_mm.sqrt() * 10f64.powf(-e)
    } else {
        1.0 + chi_mm.sqrt().sqrt() * 10f64.powf(-e)
    }
}

/// K_R,σ of roughness `rz_m` (m) for tensile strength `r_m_pa`, constants `a_r`, `r_m_n_min_pa`;
/// multiply `a_r` by f_W,τ for K_R,τ. 1 for R_z ≤ 1 µm.
pub fn roughness_factor(rz_m: f64, r_m_pa: f64, a_r: f64, r_m_n_min_pa: f64) -> f64 {
    let rz_um = rz_m * 1e6;
    if rz_um <= 1.0 {
        return 1.0;
    }
    1.0 - a_r * rz_um.log10() * (2.0 * r_m_pa / r_m_n_min_pa).log10()
}

/// The technological size effect on R_m (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SizeEffect {
    /// Effective diameter of the section at heat treatment, m.
    pub effective_diameter_m: f64,
    /// a_d,m of the material group.
    pub a_d: f64,
    /// d_eff,N,m: the diameter R_m,N holds for, m.
    pub reference_diameter_m: f64,
}

impl SizeEffect {
    /// FKM's steel in general (a_d,m = 0.15, d_eff,N,m = 40 mm) at `effective_diameter_m`.
    pub fn structural_steel(effective_diameter_m: f64) -> Self {
        SizeEffect {
            effective_diameter_m,
            a_d: 0.15,
            reference_diameter_m: 0.040,
        }
    }

    /// K_d,m (1 when the section is not larger than the reference).
    pub fn factor(&self) -> f64 {
        size_factor(
            self.effective_diameter_m,
            self.a_d,
            self.reference_diameter_m,
        )
    }
}

/// K_d,m = (1 − 0.7686 a_d lg(d_eff/7.5 mm)) / (1 − 0.7686 a_d lg(d_N/7.5 mm)) for d_eff > d_N.
pub fn size_factor(d_eff_m: f64, a_d: f64, d_n_m: f64) -> f64 {
    if d_eff_m <= d_n_m {
        return 1.0;
    }
    let f = |d: f64| 1.0 - 0.7686 * a_d * (d / 7.5e-3).log10();
    f(d_eff_m) / f(d_n_m)
}

/// Surface treatments of FKM Table 4.3.7 (steel, specimens of 8–25 mm), as presets of K_V: the
/// lower end of each range, so the preset never credits more than FKM does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SurfaceTreatment {
    /// No treatment: K_V = 1.
    None,
    /// Shot peening: 1.1 (unnotched and notched).
    ShotPeened,
    /// Cold rolling: 1.1 unnotched, 1.3 notched.
    ColdRolled,
    /// Nitriding: 1.1 unnotched, 1.3 notched.
    Nitrided,
    /// Case hardening: 1.1 unnotched, 1.2 notched.
    CaseHardened,
    /// Induction or flame hardening: 1.2 unnotched, 1.5 notched.
    InductionHardened,
}

impl SurfaceTreatment {
    /// K_V of the treatment on an unnotched or a notched part.
    pub fn factor(self, notched: bool) -> f64 {
        let (plain, notch) = match self {
            SurfaceTreatment::None => (1.0, 1.0),
            SurfaceTreatment::ShotPeened => (1.1, 1.1),
            SurfaceTreatment::ColdRolled => (1.1, 1.3),
            SurfaceTreatment::Nitrided => (1.1, 1.3),
            SurfaceTreatment::CaseHardened => (1.1, 1.2),
            SurfaceTreatment::InductionHardened => (1.2, 1.5),
        };
        if notched { notch } else { plain }
    }
}

/// The surface and the part: what lowers or raises σ_W,zd besides the gradient.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SurfaceFactors {
    /// Mean roughness depth R_z, m (default: forged skin, 200 µm).
    pub roughness_rz_m: f64,
    /// Surface-treatment factor K_V (1: untreated).
    pub treatment_factor: f64,
    /// Coating factor K_S (1 except anodised aluminium).
    pub coating_factor: f64,
    /// Factor of the non-linear elastic behaviour K_NL,E (1 except grey cast iron).
    pub nonlinear_elastic_factor: f64,
    /// Estimated fatigue notch factor K̃_f of the design factor (FKM: 2 in the local approach).
    pub estimated_notch_factor: f64,
    /// Technological size effect on R_m (`None`: R_m is the part's own).
    pub size: Option<SizeEffect>,
}

impl Default for SurfaceFactors {
    /// Forged skin (R_z 200 µm), untreated, uncoated, K̃_f = 2, no size effect.
    fn default() -> Self {
        SurfaceFactors {
            roughness_rz_m: FORGED_SKIN_RZ_M,
            treatment_factor: 1.0,
            coating_factor: 1.0,
            nonlinear_elastic_factor: 1.0,
            estimated_notch_factor: 2.0,
            size: None,
        }
    }
}

/// Every number of the chain from σ_W,zd to σ_WK at one point, SI.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LocalStrength {
    /// Technological size factor K_d,m.
    pub k_d_m: f64,
    /// Tensile strength of the part K_d,m · R_m,N, Pa.
    pub r_m_pa: f64,
    /// σ_W,zd of the part, Pa.
    pub sigma_w_zd_pa: f64,
    /// τ_W,s of the part, Pa.
    pub tau_w_s_pa: f64,
    /// Related stress gradient of the normal stress, 1/m.
    pub chi_star_sigma_per_m: f64,
    /// Related stress gradient of the shear stress, 1/m.
    pub chi_star_tau_per_m: f64,
    /// Support factor n_σ.
    pub n_sigma: f64,
    /// Support factor n_τ.
    pub n_tau: f64,
    /// Roughness factor K_R,σ.
    pub k_r_sigma: f64,
    /// Roughness factor K_R,τ.
    pub k_r_tau: f64,
    /// Design factor K_WK,σ.
    pub k_wk_sigma: f64,
    /// Design factor K_WK,τ.
    pub k_wk_tau: f64,
    /// Component fatigue limit σ_WK, Pa.
    pub sigma_wk_pa: f64,
    /// Component fatigue limit τ_WK, Pa.
    pub tau_wk_pa: f64,
}

/// The component fatigue limits at a point with related stress gradients `chi_star_sigma_per_m`,
/// `chi_star_tau_per_m` (1/m), for `material` and `surface` (see the module documentation).
pub fn local_strength(
    material: &FatigueMaterial,
    surface: &SurfaceFactors,
    chi_star_sigma_per_m: f64,
    chi_star_tau_per_m: f64,
) -> LocalStrength {
    let c = material.constants();
    let k_d_m = surface.size.map_or(1.0, |s| s.factor());
    let r_m = k_d_m * material.tensile_strength_pa;
    let sigma_w_zd = material.tension_fatigue_limit_pa(k_d_m);
    let tau_w_s = material.shear_fatigue_limit_pa(k_d_m);
    let n_sigma = support_factor(chi_star_sigma_per_m, r_m, c.a_g, c.b_g_pa);
    let n_tau = support_factor(chi_star_tau_per_m, r_m, c.a_g, c.b_g_pa);
    let k_r_sigma = roughness_factor(surface.roughness_rz_m, r_m, c.a_r, c.r_m_n_min_pa);
    let k_r_tau = roughness_factor(
        surface.roughness_rz_m,
        r_m,
        c.f_w_tau * c.a_r,
        c.r_m_n_min_pa,
    );
    let kf = surface.estimated_notch_factor;
    let k_wk_sigma = (1.0 / n_sigma) * (1.0 + (1.0 / kf) * (1.0 / k_r_sigma - 1.0))
        / (surface.treatment_factor * surface.coating_factor * surface.nonlinear_elastic_factor);
    let k_wk_tau = (1.0 / n_tau) * (1.0 + (1.0 / kf) * (1.0 / k_r_tau - 1.0))
        / (surface.treatment_factor * surface.coating_factor);
    LocalStrength {
        k_d_m,
        r_m_pa: r_m,
        sigma_w_zd_pa: sigma_w_zd,
        tau_w_s_pa: tau_w_s,
        chi_star_sigma_per_m,
        chi_star_tau_per_m,
        n_sigma,
        n_tau,
        k_r_sigma,
        k_r_tau,
        k_wk_sigma,
        k_wk_tau,
        sigma_wk_pa: sigma_w_zd / k_wk_sigma,
        tau_wk_pa: tau_w_s / k_wk_tau,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn support_factor_branches_meet_and_grow() {
        let (rm, ag, bg) = (470e6, 0.5, 2700e6);
        let e = 10f64.powf(-(ag + 470.0 / 2700.0));
        // at 0.1 and 1 mm⁻¹ the neighbouring branches agree
        for chi_mm in [0.1, 1.0] {
            let below = support_factor(chi_mm * 1e3 * (1.0 - 1e-12), rm, ag, bg);
            let above = support_factor(chi_mm * 1e3 * (1.0 + 1e-12), rm, ag, bg);
            assert!((below - above).abs() < 1e-9, "{chi_mm}: {below} {above}");
        }
        // χ* = 1 mm⁻¹: n = 1 + 10^−(a_G + R_m/b_G)
        assert!((support_factor(1e3, rm, ag, bg) - (1.0 + e)).abs() < 1e-12);
        // no gradient, no support; monotone
        assert_eq!(support_factor(0.0, rm, ag, bg), 1.0);
        assert_eq!(support_factor(-5.0, rm, ag, bg), 1.0);
        let mut last = 1.0;
        for k in 1..160 {
            // up to 96 mm⁻¹, below the cap
            let n = support_factor(k as f64 * 600.0, rm, ag, bg);
            assert!(n > last);
            last = n;
        }
    }

    #[test]
    fn roughness_factor_matches_the_worked_example() {
        // quadco.engineering's FKM example: R_m 600 MPa, machined R_z 100 µm, steel → 0.79
        let k = roughness_factor(100e-6, 600e6, 0.22, 400e6);
        assert!((k - (1.0 - 0.22 * 2.0 * 3f64.log10())).abs() < 1e-12);
        assert!((k - 0.79).abs() < 0.005);
        assert_eq!(roughness_factor(0.5e-6, 600e6, 0.22, 400e6), 1.0);
    }

    #[test]
    fn size_factor_is_one_up_to_the_reference_and_falls_beyond() {
        let s = SizeEffect::structural_steel(0.030);
        assert_eq!(s.factor(), 1.0);
        let s = SizeEffect::structural_steel(0.100);
        let f = |d: f64| 1.0 - 0.7686 * 0.15 * (d / 7.5).log10();
        assert!((s.factor() - f(100.0) / f(40.0)).abs() < 1e-12);
        assert!(s.factor() < 1.0);
    }

    #[test]
    fn unnotched_polished_untreated_is_the_material_limit() {
        let m = FatigueMaterial::default();
        let s = SurfaceFactors {
            roughness_rz_m: 0.0,
            estimated_notch_factor: 1.0,
            ..SurfaceFactors::default()
        };
        let l = local_strength(&m, &s, 0.0, 0.0);
        assert_eq!(l.k_wk_sigma, 1.0);
        assert_eq!(l.sigma_wk_pa, 235e6);
        assert!((l.tau_wk_pa - 0.577 * 235e6).abs() < 1e-6);
    }
}
