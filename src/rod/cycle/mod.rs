//! Stress over one crank revolution: quasi-static FEM with inertia relief, by superposition of six
//! unit load cases solved with one factorisation.
//!
//! At each instant the rod (in its own frame: A at the origin, x̂ along A→B, ẑ the pin axis) carries
//! the crank's pin force F_A as a uniform traction on the big-end bore (as stage 3 does), its
//! d'Alembert body force ρ (g − a_P) with the rigid-body acceleration
//! a_P = a_A + α₃ ẑ × r − ω₃² r (r in-plane from A), and is held at the small-end bore B (all DOFs).
//! Then the reaction at B is the piston pin's force on the rod, F_B, by the rod's Newton–Euler
//! equations, provided the body forces integrate to the same mass and centroid the dynamics used:
//! the caller passes kinematics and pin forces computed with the mesh's own mass properties
//! ([`crate::fem::body_force::mesh_mass_properties`]).
//!
//! The load is linear in six coefficients (Zienkiewicz–Taylor–Zhu, superposition of linear
//! solutions):
//!
//! f(t) = F_Ax f_pin,x + F_Ay f_pin,y + (g − a_A)_x f_ρ,x + (g − a_A)_y f_ρ,y + ω₃² f_ρr − α₃ f_ρẑ×r
//!
//! so σ(t) = Σ c_k(t) σ_k at every node, from six solves of one Cholesky factor; the per-instant
//! cost is a 6-term combination per node.
//!
//! **Cosine bore load** (`[fem] bore_load = "cosine"`, [`crate::fem::load::cosine_pressure_with_resultant`]):
//! the pressed half of the bore turns with the force, so the pin load is no longer linear in
//! (F_x, F_y). It is linear in |F| for a fixed direction, so the pin is given one unit case per
//! direction θ_j = j Δ (rod frame, Δ = [`CycleOptions::direction_step_deg`], 5° by default: 72
//! directions, of which only those next to a force direction of the cycle are solved), and the
//! force F = |F| (cos θ, sin θ) with θ_j ≤ θ < θ_j+1 is written exactly in the two neighbouring
//! unit directions d_j, d_j+1:
//!
//! F = a d_j + b d_j+1, a = |F| sin(θ_j+1 − θ)/sin Δ, b = |F| sin(θ − θ_j)/sin Δ,
//!
//! so σ(t) = a σ_j + b σ_j+1 + (the four body-force terms): still six terms per node, all cases
//! from one factorisation, and the resultant of the combined pin load is F exactly (the reaction
//! check holds to round-off). The load shape between two directions is the blend of their cosines,
//! not the cosine about θ itself: that is the interpolation's only error, O(Δ²), measured in the
//! tests against direct solves (see [`tests`]).

pub mod contact_fatigue;
pub mod contact_instants;
pub mod local_fatigue;
mod unit_cases;

pub use local_fatigue::{LocalFatigueSolution, local_fatigue};
pub use unit_cases::*;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::fem::body_force::MeshMassProperties;
use crate::fem::error::{FemError, Result};
use crate::fem::material::von_mises;
use crate::mechanism::RodFrameInstant;
use crate::rod::fatigue::{amplitude_and_mean, signed_von_mises};

/// One instant of the cycle (rod frame; forces on the rod).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CycleInstant {
    pub crank_angle_deg: f64,
    pub time_s: f64,
    /// Max nodally averaged von Mises over the judged nodes, MPa.
    pub max_von_mises_away_from_fixed_mpa: f64,
    /// The fixed bore's reaction on the rod, N.
    pub reaction_b_n: [f64; 3],
    /// The piston pin's force on the rod from the dynamics, N.
    pub dynamics_f_b_n: [f64; 3],
}

/// The cycle's figures and per-node fields.
#[derive(Clone, Debug)]
pub struct CycleSolution {
    pub history: Vec<CycleInstant>,
    /// Per node: max von Mises over the cycle (Pa).
    pub max_von_mises_pa: Vec<f64>,
    /// Per node: the fatigue safety factor (Goodman or Gerber, [`CycleOptions::mean_stress`]) of
    /// the signed von Mises cycle (∞ where unloaded).
    pub fatigue_safety_factor: Vec<f64>,
    /// Per node: alternating and mean signed von Mises (Pa).
    pub alternating_pa: Vec<f64>,
    pub mean_pa: Vec<f64>,
    /// Index of the instant and node of the judged maximum.
    pub max_instant: usize,
    pub max_node: usize,
    /// Node of the smallest judged fatigue safety factor.
    pub fatigue_node: usize,
    /// Largest |reaction − F_B| over the instants, relative to the peak |F_A|.
    pub reaction_mismatch_rel: f64,
}

/// Combines the unit solutions over `instants`: per instant the judged maximum and the reaction,
/// per node the maximum over the cycle and the fatigue safety factor of its signed von Mises cycle.
pub fn combine(
    units: &UnitSolutions,
    instants: &[RodFrameInstant],
    options: &CycleOptions,
) -> Result<CycleSolution> {
    if instants.is_empty() {
        return Err(FemError::InvalidInput("no instant in the cycle".into()));
    }
    let coeffs: Vec<Terms> = instants
        .iter()
        .map(|i| units.terms(i))
        .collect::<Result<_>>()?;
    let nt = coeffs.len();
    let n_nodes = units.judged.len();
    // per node: (max vm, its instant), (min, max) signed vm
    struct NodeCycle {
        max_vm: f64,
        s_min: f64,
        s_max: f64,
    }
    let per_node: Vec<NodeCycle> = (0..n_nodes)
        .into_par_iter()
        .map(|n| {
            let mut c = NodeCycle {
                max_vm: 0.0,
                s_min: f64::INFINITY,
                s_max: f64::NEG_INFINITY,
            };
            for ck in &coeffs {
                let s = units.stress_at(n, ck);
                let vm = von_mises(&s);
                let sv = signed_von_mises(&s);
                c.max_vm = c.max_vm.max(vm);
                c.s_min = c.s_min.min(sv);
                c.s_max = c.s_max.max(sv);
            }
            c
        })
        .collect();
    // per instant: the judged maximum (nodes in parallel chunks, reduced in order: deterministic)
    let judged: Vec<usize> = (0..n_nodes).filter(|&n| units.judged[n]).collect();
    if judged.is_empty() {
        return Err(FemError::InvalidInput(
            "every node lies within the bands around the fixed bore and the sharp edges".into(),
        ));
    }
    let best: Vec<(f64, usize)> = coeffs
        .par_iter()
        .map(|ck| {
            judged.iter().fold((f64::NEG_INFINITY, 0), |b, &n| {
                let vm = von_mises(&units.stress_at(n, ck));
                if vm > b.0 { (vm, n) } else { b }
            })
        })
        .collect();
    let peak_force = instants
        .iter()
        .map(|i| i.f_a_on_rod_n[0].hypot(i.f_a_on_rod_n[1]))
        .fold(0.0, f64::max);
    let mut history = Vec::with_capacity(nt);
    let mut mismatch = 0.0f64;
    for (k, inst) in instants.iter().enumerate() {
        let r = units.reaction(&coeffs[k]);
        let fb = [inst.f_b_on_rod_n[0], inst.f_b_on_rod_n[1], 0.0];
        let d = ((r[0] - fb[0]).powi(2) + (r[1] - fb[1]).powi(2) + (r[2] - fb[2]).powi(2)).sqrt();
        mismatch = mismatch.max(d / peak_force.max(f64::MIN_POSITIVE));
        history.push(CycleInstant {
            crank_angle_deg: inst.crank_angle_deg,
            time_s: inst.time_s,
            max_von_mises_away_from_fixed_mpa: best[k].0 * 1e-6,
            reaction_b_n: r,
            dynamics_f_b_n: fb,
        });
    }
    let max_instant = (0..nt).fold(0, |b, k| if best[k].0 > best[b].0 { k } else { b });
    let (mut alternating, mut mean, mut factor) = (
        Vec::with_capacity(n_nodes),
        Vec::with_capacity(n_nodes),
        Vec::with_capacity(n_nodes),
    );
    for c in &per_node {
        let (sa, sm) = amplitude_and_mean(c.s_min, c.s_max);
        alternating.push(sa);
        mean.push(sm);
        factor.push(options.mean_stress.safety_factor(
            sa,
            sm,
            options.endurance_pa,
            options.ultimate_pa,
        ));
    }
    let fatigue_node = judged
        .iter()
        .copied()
        .fold(judged[0], |b, n| if factor[n] < factor[b] { n } else { b });
    Ok(CycleSolution {
        history,
        max_von_mises_pa: per_node.iter().map(|c| c.max_vm).collect(),
        fatigue_safety_factor: factor,
        alternating_pa: alternating,
        mean_pa: mean,
        max_instant,
        max_node: best[max_instant].1,
        fatigue_node,
        reaction_mismatch_rel: mismatch,
    })
}

/// The rod's inertia for the dynamics from the mesh's mass properties (mesh in the rod frame:
/// A at the origin, x̂ towards B), so that loads and reactions balance.
pub fn rod_inertia_of(mass: &MeshMassProperties) -> crate::mechanism::RodInertia {
    crate::mechanism::RodInertia::new(mass.mass_kg, mass.centroid_m[0], mass.i_zz_centroid_kgm2)
        .with_offset(mass.centroid_m[1])
}

#[cfg(test)]
mod tests;
