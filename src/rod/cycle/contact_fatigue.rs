//! The fatigue factor with the pins in contact. Contact does not superpose, so the cycle's
//! per-node signed von Mises history cannot be formed at every instant; the instants solved with
//! contact ([`super::contact_instants`]) include peak tension and peak compression, where the
//! signed von Mises of most nodes takes its extremes. At each judged node
//!
//! σ_max = max_k σ_k, σ_min = min_k σ_k over the contact instants k, σ_a = (σ_max − σ_min)/2,
//! σ_m = (σ_max + σ_min)/2, n = 1 / (σ_a/S_e + σ_m/S_ut) (Goodman; Gerber as configured,
//! [`crate::rod::fatigue`]),
//!
//! and the smallest n over the judged nodes is compared with the same formula on the linear
//! cycle's stresses at the same instants (the load model's effect alone), and that with the
//! linear cycle's factor over every instant (what the few instants miss of the cycle).

use serde::{Deserialize, Serialize};

use super::unit_cases::CycleOptions;
use crate::fem::error::{FemError, Result};
use crate::rod::fatigue::amplitude_and_mean;

/// The fatigue factor from the contact instants, beside the linear cycle's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactFatigue {
    /// The smallest factor over the judged nodes of the signed von Mises range spanned by the
    /// contact instants, and where (rod frame, mm).
    pub contact_factor: f64,
    pub contact_at_mm: [f64; 3],
    /// The same from the linear cycle's stresses at the same instants.
    pub linear_factor_at_instants: f64,
    /// The linear cycle's factor over every instant (`fatigue_safety_factor`).
    pub linear_factor: f64,
    /// contact_factor / linear_factor_at_instants − 1: how contact moves the factor.
    pub change_rel: f64,
    /// linear_factor_at_instants / linear_factor − 1: what the instants miss of the linear cycle
    /// (≥ 0: fewer instants span a smaller range).
    pub instants_vs_cycle_rel: f64,
    /// The instants (crank angles, degrees).
    pub crank_angles_deg: Vec<f64>,
}

/// The smallest fatigue factor over the `judged` nodes of the signed von Mises cycles
/// `signed[k][n]` (instant k, node n, Pa), and its node.
pub fn smallest_factor(
    signed: &[Vec<f64>],
    judged: &[bool],
    options: &CycleOptions,
) -> Result<(f64, usize)> {
    let mut best: Option<(f64, usize)> = None;
    for (n, _) in judged.iter().enumerate().filter(|(_, j)| **j) {
        let (lo, hi) = signed
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
                (lo.min(s[n]), hi.max(s[n]))
            });
        let (sa, sm) = amplitude_and_mean(lo, hi);
        let f =
            options
                .mean_stress
                .safety_factor(sa, sm, options.endurance_pa, options.ultimate_pa);
        if best.is_none_or(|b| f < b.0) {
            best = Some((f, n));
        }
    }
    best.ok_or_else(|| FemError::InvalidInput("no judged node for the fatigue factor".into()))
}

/// [`ContactFatigue`] from the contact instants' signed von Mises `contact` and the linear
/// cycle's at the same instants `linear` (per instant, per node, Pa), `linear_factor` the linear
/// cycle's factor over every instant.
pub fn contact_fatigue(
    contact: &[Vec<f64>],
    linear: &[Vec<f64>],
    judged: &[bool],
    options: &CycleOptions,
    linear_factor: f64,
    nodes: &[[f64; 3]],
    crank_angles_deg: Vec<f64>,
) -> Result<ContactFatigue> {
    if contact.is_empty() || contact.len() != linear.len() {
        return Err(FemError::InvalidInput(
            "the fatigue factor with contact needs the linear cycle at the same instants".into(),
        ));
    }
    let (c, node) = smallest_factor(contact, judged, options)?;
    let (l, _) = smallest_factor(linear, judged, options)?;
    Ok(ContactFatigue {
        contact_factor: c,
        contact_at_mm: nodes[node].map(|v| v * 1e3),
        linear_factor_at_instants: l,
        linear_factor,
        change_rel: c / l - 1.0,
        instants_vs_cycle_rel: l / linear_factor - 1.0,
        crank_angles_deg,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::element::QuadratureChoice;
    use crate::rod::fatigue::MeanStress;

    fn options() -> CycleOptions {
        CycleOptions {
            density_kg_m3: 7850.0,
            fixed_band_m: 0.0,
            singular_edges_m: Vec::new(),
            singular_band_m: 0.0,
            endurance_pa: 200e6,
            ultimate_pa: 400e6,
            mean_stress: MeanStress::default(),
            quadrature: QuadratureChoice::Auto,
            direction_step_deg: 5.0,
            half_model: None,
        }
    }

    /// Node 0 swings ±50 MPa (Goodman n = S_e/σ_a = 4), node 1 from 0 to 100 MPa (σ_a = σ_m =
    /// 50 MPa: n = 1/(50/200 + 50/400) = 8/3), node 2 ±150 MPa but not judged.
    #[test]
    fn the_factor_is_goodmans_at_the_worst_judged_node() {
        let contact = vec![vec![50e6, 0.0, 150e6], vec![-50e6, 100e6, -150e6]];
        let linear = vec![vec![25e6, 0.0, 0.0], vec![-25e6, 100e6, 0.0]];
        let judged = [true, true, false];
        let nodes = [[0.0; 3], [1e-3, 0.0, 0.0], [2e-3, 0.0, 0.0]];
        let f = contact_fatigue(
            &contact,
            &linear,
            &judged,
            &options(),
            2.0,
            &nodes,
            vec![0.0, 180.0],
        )
        .unwrap();
        assert!(
            (f.linear_factor_at_instants - 8.0 / 3.0).abs() < 1e-12,
            "{f:?}"
        );
        assert!((f.contact_factor - 8.0 / 3.0).abs() < 1e-12, "{f:?}");
        assert_eq!(f.contact_at_mm, [1.0, 0.0, 0.0]);
        assert!((f.instants_vs_cycle_rel - (4.0 / 3.0 - 1.0)).abs() < 1e-12);
        // contact raising node 0 to ±80 MPa makes it the worst: n = 200/80
        let contact = vec![vec![80e6, 0.0, 0.0], vec![-80e6, 100e6, 0.0]];
        let f = contact_fatigue(
            &contact,
            &linear,
            &judged,
            &options(),
            2.0,
            &nodes,
            vec![0.0, 180.0],
        )
        .unwrap();
        assert!((f.contact_factor - 2.5).abs() < 1e-12 && f.contact_at_mm[0] == 0.0);
        assert!((f.change_rel - 2.5 / (8.0 / 3.0) + 1.0).abs() < 1e-12);
    }
}
