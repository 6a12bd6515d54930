//! The `[material]` section: the rod material's strengths for the two fatigue factors.
//!
//! **The local (FKM) factor**, the one the ranking and the criterion use
//! ([`crate::fatigue`], FKM guideline "Analytical Strength Assessment", 6th ed. 2012, ch. 4):
//! tensile strength R_m = `ultimate_mpa`, yield strength R_p = `yield_mpa`, the FKM material group
//! `material_group` (its constants: f_W,σ, f_W,τ, a_M, b_M, a_R,σ, R_m,N,min, a_G, b_G), the fatigue
//! limit σ_W,zd = f_W,σ · R_m unless `fatigue_limit_mpa` gives a tested one, the surface roughness
//! R_z = `surface_roughness_um` (default 200 µm: FKM's indicative value for rolled, forged and cast
//! skin after DIN 4768; quadco.engineering, "Surface roughness factor K_R", Table 2), the surface
//! treatment `surface_treatment` (K_V of FKM Table 4.3.7, default none), the overload case
//! `overload` (default `"constant_ratio"`, F2: a rod's inertia and gas loads scale mean and
//! amplitude together) and the FKM safety factors `j_s` (loads, 1), `j_f` (fatigue strength, 1.5:
//! steel, no regular inspection, severe consequences; FKM Table 4.5.1, the default of Altair
//! HyperLife's FKM parameters too) and `j_g` (castings, 1).
//!
//! **The Goodman (or Gerber) factor**, kept beside it as the textbook interface: S_ut =
//! `ultimate_mpa`, S_e = `endurance_mpa` (Budynas–Nisbett, *Shigley's Mechanical Engineering
//! Design*, 10th ed., eq. 6-8: S'e = 0.5 Sut, no Marin factors), `mean_stress`.
//!
//! Defaults: S355 (EN 10025-2, 3–100 mm): R_m = 470 MPa, R_p = 355 MPa, the thesis' steel.

use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};

use crate::fatigue::{
    FatigueMaterial, LocalSettings, MaterialGroup, OverloadCase, SafetyFactors, SurfaceFactors,
    SurfaceTreatment,
};
use crate::rod::fatigue::MeanStress;

/// Fatigue strengths of the rod's material (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MaterialConfig {
    /// Tensile strength R_m (S_ut), MPa.
    pub ultimate_mpa: f64,
    /// The Goodman factor's endurance limit S_e, MPa.
    pub endurance_mpa: f64,
    /// The mean-stress correction of the Goodman factor: `"goodman"` (default) or `"gerber"`
    /// ([`crate::rod::fatigue::MeanStress`]); the default is not written into `results.json`.
    #[serde(skip_serializing_if = "MeanStress::is_goodman")]
    pub mean_stress: MeanStress,
    /// Yield strength R_p, MPa.
    pub yield_mpa: f64,
    /// FKM material group (`"steel"`, `"case_hardening_steel"`, `"stainless_steel"`,
    /// `"forging_steel"`, `"cast_steel"`, `"nodular_cast_iron"`, `"malleable_cast_iron"`,
    /// `"grey_cast_iron"`, `"wrought_aluminium"`, `"cast_aluminium"`).
    pub material_group: MaterialGroup,
    /// A tested fatigue limit in fully reversed tension–compression, MPa (absent: FKM's estimate
    /// f_W,σ · R_m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fatigue_limit_mpa: Option<f64>,
    /// Mean roughness depth R_z of the surface, µm (forged skin: 200; machined 100; ground 12.5;
    /// polished 0).
    pub surface_roughness_um: f64,
    /// Surface treatment (`"none"`, `"shot_peened"`, `"cold_rolled"`, `"nitrided"`,
    /// `"case_hardened"`, `"induction_hardened"`).
    pub surface_treatment: SurfaceTreatment,
    /// Overload case: `"constant_ratio"` (F2) or `"constant_mean"` (F1).
    pub overload: OverloadCase,
    /// FKM safety factor on the loads j_S.
    pub j_s: f64,
    /// FKM safety factor on the fatigue strength j_F.
    pub j_f: f64,
    /// FKM safety factor of castings j_G.
    pub j_g: f64,
}

impl Default for MaterialConfig {
    fn default() -> Self {
        let safety = SafetyFactors::default();
        MaterialConfig {
            ultimate_mpa: 470.0,
            endurance_mpa: 235.0,
            mean_stress: MeanStress::Goodman,
            yield_mpa: 355.0,
            material_group: MaterialGroup::Steel,
            fatigue_limit_mpa: None,
            surface_roughness_um: crate::fatigue::factors::FORGED_SKIN_RZ_M * 1e6,
            surface_treatment: SurfaceTreatment::None,
            overload: OverloadCase::ConstantRatio,
            j_s: safety.load,
            j_f: safety.material,
            j_g: safety.casting,
        }
    }
}

impl MaterialConfig {
    /// The settings of the local (FKM) assessment. The surface treatment's K_V is its notched
    /// value: the critical points of a rod are fillets and bores.
    pub fn local_settings(&self) -> LocalSettings {
        LocalSettings {
            material: FatigueMaterial {
                group: self.material_group,
                tensile_strength_pa: self.ultimate_mpa * 1e6,
                yield_strength_pa: self.yield_mpa * 1e6,
                fatigue_limit_pa: self.fatigue_limit_mpa.map(|v| v * 1e6),
            },
            surface: SurfaceFactors {
                roughness_rz_m: self.surface_roughness_um * 1e-6,
                treatment_factor: self.surface_treatment.factor(true),
                ..SurfaceFactors::default()
            },
            overload: self.overload,
            safety: SafetyFactors {
                load: self.j_s,
                material: self.j_f,
                casting: self.j_g,
            },
        }
    }

    /// Checks the section's values, naming the key.
    pub(super) fn check(&self) -> Result<()> {
        for (key, v) in [
            ("material.ultimate_mpa", self.ultimate_mpa),
            ("material.endurance_mpa", self.endurance_mpa),
            ("material.yield_mpa", self.yield_mpa),
        ] {
            if !(v.is_finite() && v > 0.0) {
                bail!("`{key}` must be a positive number, got {v}");
            }
            if v > super::MAX_STRENGTH_MPA {
                bail!(
                    "`{key}` = {v:e} is out of range: it must be at most {:e} MPa",
                    super::MAX_STRENGTH_MPA
                );
            }
        }
        if self.endurance_mpa >= self.ultimate_mpa {
            bail!("`material.endurance_mpa` must be below `material.ultimate_mpa`");
        }
        if self.yield_mpa > self.ultimate_mpa {
            bail!(
                "`material.yield_mpa` ({}) must not exceed `material.ultimate_mpa` ({}): the yield strength R_p lies below the tensile strength R_m",
                self.yield_mpa,
                self.ultimate_mpa
            );
        }
        if let Some(s) = self.fatigue_limit_mpa
            && !(s.is_finite() && s > 0.0 && s < self.ultimate_mpa)
        {
            bail!(
                "`material.fatigue_limit_mpa` must lie between 0 and `material.ultimate_mpa` ({}), got {s}; leave it out for FKM's estimate f_W,σ · R_m",
                self.ultimate_mpa
            );
        }
        let rz = self.surface_roughness_um;
        if !(rz.is_finite() && (0.0..=1000.0).contains(&rz)) {
            bail!(
                "`material.surface_roughness_um` is R_z in µm and must lie in [0, 1000] (polished 0, ground 12.5, machined 100, forged skin 200), got {rz}"
            );
        }
        for (key, v) in [
            ("material.j_s", self.j_s),
            ("material.j_f", self.j_f),
            ("material.j_g", self.j_g),
        ] {
            if !(v.is_finite() && (1.0..=super::MAX_FACTOR).contains(&v)) {
                bail!(
                    "`{key}` is an FKM safety factor and must lie in [1, {}] (a factor below 1 credits strength the part does not have), got {v}",
                    super::MAX_FACTOR
                );
            }
        }
        let k_r = self.local_settings();
        let c = k_r.material.constants();
        let k = crate::fatigue::factors::roughness_factor(
            k_r.surface.roughness_rz_m,
            k_r.material.tensile_strength_pa,
            c.a_r,
            c.r_m_n_min_pa,
        );
        if k <= 0.0 {
            bail!(
                "`material.surface_roughness_um` = {rz} with R_m = {} MPa gives a roughness factor K_R = {k:.3} ≤ 0: outside FKM's formula; give a smaller R_z",
                self.ultimate_mpa
            );
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_thesis_steel_and_fkm_safety() {
        let s = MaterialConfig::default().local_settings();
        assert_eq!(s.material.tensile_strength_pa, 470e6);
        assert_eq!(s.material.yield_strength_pa, 355e6);
        assert_eq!(s.material.fatigue_limit_pa, None);
        // R_z of a forged skin, 200 µm (through µm and back: one rounding)
        assert!((s.surface.roughness_rz_m - 200e-6).abs() < 1e-18);
        assert_eq!(s.safety.total(), 1.5);
        assert!(MaterialConfig::default().check().is_ok());
    }

    #[test]
    fn bad_values_are_refused_by_key() {
        let bad = |text: &str| {
            let c: MaterialConfig = toml::from_str(text).unwrap();
            c.check().unwrap_err().to_string()
        };
        assert!(bad("yield_mpa = 500.0").contains("material.yield_mpa"));
        assert!(bad("j_f = 0.8").contains("material.j_f"));
        assert!(bad("surface_roughness_um = -1.0").contains("surface_roughness_um"));
        assert!(bad("fatigue_limit_mpa = 600.0").contains("fatigue_limit_mpa"));
        let e = toml::from_str::<MaterialConfig>("material_group = \"titanium\"").unwrap_err();
        assert!(e.to_string().contains("material_group"), "{e}");
        let t: MaterialConfig =
            toml::from_str("surface_treatment = \"shot_peened\"\noverload = \"constant_mean\"")
                .unwrap();
        assert_eq!(t.local_settings().surface.treatment_factor, 1.1);
        assert_eq!(t.local_settings().overload, OverloadCase::ConstantMean);
    }
}
