//! What a contact solution must meet ([`ContactTolerances`]) and the figures of its check
//! ([`ContactCheck`], worked out by [`super::check`]): equilibrium, the pin force's resultant,
//! complementarity, penetration, no tensile pressure, the free motions' support carrying nothing.

use crate::fem::error::{FemError, Result};

/// Limits a solution must meet, else the solve is refused ([`super::check`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactTolerances {
    /// Largest penetration of a wall node into its pin, relative to the gap scale (the largest
    /// initial gap or radial displacement of a wall node relative to its pin).
    pub penetration_rel: f64,
    /// |Σ contact forces of a force-driven pin − its force| / |force|.
    pub resultant_rel: f64,
    /// Weighted gaps recomputed from the displacement: |G| on the active rows and −G on the
    /// inactive ones, relative to the largest |free gap|; and the residual of K u = f.
    pub complementarity_rel: f64,
    /// The reaction of the support that holds the motions contact leaves free (rotation about
    /// a lone fixed pin, sliding along it), relative to the load scale (force) and the load
    /// scale × body size (moment). `None`: reported, not enforced (loads that are not in
    /// balance about the pin, e.g. a transverse pin force without the body's inertia).
    pub free_mode_reaction_rel: Option<f64>,
}

impl Default for ContactTolerances {
    fn default() -> Self {
        ContactTolerances {
            penetration_rel: 0.05,
            resultant_rel: 1e-10,
            complementarity_rel: 1e-8,
            free_mode_reaction_rel: Some(1e-8),
        }
    }
}

/// The figures of a check (all relative figures are ≥ 0).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactCheck {
    /// |r| at the free DOFs / |f + f_c|.
    pub equilibrium_residual_rel: f64,
    /// Largest |resultant − force| / |force| over the force-driven pins.
    pub resultant_error_rel: f64,
    /// Largest complementarity violation on the weighted gaps, relative to the largest
    /// ∫ψ_b × gap scale.
    pub complementarity_rel: f64,
    /// Largest penetration, m.
    pub penetration_max_m: f64,
    /// Largest penetration / gap scale.
    pub penetration_rel: f64,
    /// Largest tensile pressure (max −λ, 0 if none), Pa.
    pub max_tensile_pressure_pa: f64,
    /// The free-motion support's reaction, relative ([`Restraint::reaction_rel`]).
    pub free_mode_reaction_rel: f64,
    /// The gap scale: the largest initial gap or radial motion of a wall node relative to its
    /// pin, m.
    pub gap_scale_m: f64,
    /// The load scale: Σ_b |λ_b c_b| (every wall node's contact force) + |Σ other loads|, N.
    pub load_scale_n: f64,
}

impl ContactCheck {
    /// Refuses a solution outside `tol`.
    pub fn verify(&self, tol: &ContactTolerances) -> Result<()> {
        let mut bad = Vec::new();
        if !within(self.equilibrium_residual_rel, tol.complementarity_rel) {
            bad.push(format!(
                "equilibrium residual {:.2e} > {:.0e}",
                self.equilibrium_residual_rel, tol.complementarity_rel
            ));
        }
        if !within(self.resultant_error_rel, tol.resultant_rel) {
            bad.push(format!(
                "pin force resultant error {:.2e} > {:.0e}",
                self.resultant_error_rel, tol.resultant_rel
            ));
        }
        if !within(self.complementarity_rel, tol.complementarity_rel) {
            bad.push(format!(
                "complementarity violation {:.2e} > {:.0e}",
                self.complementarity_rel, tol.complementarity_rel
            ));
        }
        if !within(self.penetration_rel, tol.penetration_rel) {
            bad.push(format!(
                "penetration {:.3e} m = {:.2e} of the gap scale > {:.0e}",
                self.penetration_max_m, self.penetration_rel, tol.penetration_rel
            ));
        }
        if !within(self.max_tensile_pressure_pa, 0.0) {
            bad.push(format!(
                "tensile contact pressure {:.3e} Pa",
                self.max_tensile_pressure_pa
            ));
        }
        if let Some(t) = tol.free_mode_reaction_rel
            && !within(self.free_mode_reaction_rel, t)
        {
            bad.push(format!(
                "the support of the free motions carries {:.2e} of the load (> {t:.0e}): the \
                 loads are not in balance about the pin that holds the body",
                self.free_mode_reaction_rel
            ));
        }
        if bad.is_empty() {
            Ok(())
        } else {
            Err(FemError::Check(format!("contact: {}", bad.join("; "))))
        }
    }
}

/// v ≤ limit, false for NaN.
fn within(v: f64, limit: f64) -> bool {
    v <= limit
}
