//! A step's contact pairs solved on its factorised system: the rows of every `*CONTACT PAIR`
//! ([`crate::fem::contact::node_to_surface`]), the compliance from the step's factor (one solve
//! per contact row, the factor reused), the complementarity problem, and the contact forces that
//! the step's loads then take in.

use serde::Serialize;

use super::model::{ContactLaw, Model};
use crate::fem::constraints::Reduction;
use crate::fem::contact::node_to_surface::{Law, contact_rows, solve_node_to_surface};
use crate::fem::error::{FemError, Result};
use crate::fem::shape::TET10_FACES;
use crate::fem::solver::CholeskyFactor;

/// The contact of a step, as the JSON reports it.
#[derive(Clone, Debug, Serialize)]
pub struct ContactOut {
    /// Slave nodes (deck ids) with a contact row.
    pub nodes: Vec<i64>,
    /// Their contact pressure (the mortar pressure λ_b; 0 where open).
    pub pressure: Vec<f64>,
    /// Rows in contact (λ > 0).
    pub active: usize,
    /// Σ λ_b W_b: the total normal contact force.
    pub normal_force: f64,
    /// Active-set iterations.
    pub iterations: usize,
}

/// The 6-node faces of element-face surface `name`.
fn faces(model: &Model, name: &str) -> Vec<[usize; 6]> {
    model.element_surfaces[name]
        .iter()
        .map(|&(e, f)| std::array::from_fn(|a| model.elements[e].nodes[TET10_FACES[f][a]]))
        .collect()
}

/// The contact forces (3 per node) of the model's contact pairs, given the displacements `u0`
/// of the step's loads without contact, its constraints and factor.
pub fn contact_forces(
    model: &Model,
    reduction: &Reduction,
    factor: &CholeskyFactor,
    u0: &[f64],
) -> Result<(Vec<f64>, ContactOut)> {
    // the pairing reaches as far as the model is large
    let (lo, hi) = model.nodes.iter().fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(lo, hi), p| {
            (
                std::array::from_fn(|j| lo[j].min(p[j])),
                std::array::from_fn(|j| hi[j].max(p[j])),
            )
        },
    );
    let reach = (0..3).map(|j| hi[j] - lo[j]).fold(0.0, f64::max);
    let mut rows = Vec::new();
    let mut laws = Vec::new();
    for pair in &model.contact_pairs {
        let law = match model.interactions[&pair.interaction].0 {
            Some(ContactLaw::Linear { k }) => Law::Linear(k),
            _ => Law::Hard,
        };
        let r = contact_rows(
            &model.nodes,
            &faces(model, &pair.slave),
            &faces(model, &pair.master),
            reach,
        );
        if r.is_empty() {
            return Err(FemError::Parse {
                path: pair.file.clone(),
                line: pair.line,
                message: format!(
                    "no node of slave surface {} faces master surface {}: check the pair's \
                     order (slave, master) and the surfaces",
                    pair.slave, pair.master
                ),
            });
        }
        laws.extend(std::iter::repeat_n(law, r.len()));
        rows.extend(r);
    }
    let n = u0.len();
    let mut solve = |forces: Vec<Vec<f64>>| -> Result<Vec<Vec<f64>>> {
        let m = reduction.n_eq();
        let mut rhs = vec![0.0; m * forces.len()];
        for (k, f) in forces.iter().enumerate() {
            rhs[k * m..(k + 1) * m].copy_from_slice(&reduction.restrict(f));
        }
        factor.solve_in_place(&mut rhs, forces.len());
        Ok((0..forces.len())
            .map(|k| {
                let mut u = reduction.expand(&rhs[k * m..(k + 1) * m]);
                for (d, v) in u.iter_mut().enumerate() {
                    *v -= reduction.offset(d);
                }
                u
            })
            .collect())
    };
    let sol = solve_node_to_surface(&rows, &laws, u0, &mut solve)?;
    debug_assert_eq!(sol.forces.len(), n);
    let out = ContactOut {
        nodes: rows.iter().map(|r| model.node_ids[r.node]).collect(),
        pressure: sol.pressure.clone(),
        active: sol.pressure.iter().filter(|p| **p > 0.0).count(),
        normal_force: rows
            .iter()
            .zip(&sol.pressure)
            .map(|(r, p)| r.weight * p)
            .sum(),
        iterations: sol.iterations,
    };
    Ok((sol.forces, out))
}
