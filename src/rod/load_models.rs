//! The load model's part of the error bar: the static cases solved on the final mesh under the
//! three ways a pin's force can enter the rod ([`BoreLoad`]: the thesis' uniform traction, the
//! cosine bearing pressure, contact with rigid pins at their clearances), and how far the uniform
//! traction's judged peak is from contact's, ε_load = |P_uniform − P_contact| / P_contact
//! ([`LoadCaseResult::set_load_model_error`]).
//!
//! Contact is the reference because it is the only one of the three whose pressure follows from
//! the mechanics (no tension, no penetration, the arc set by the clearance and the load); the
//! other two prescribe it. Its own uncertainty is the clearance, which a user sets
//! (`[fem] clearance_a_mm`, `clearance_b_mm`); docs/contact.md measures how the peaks move with it.
//! The model the solution was solved under is not solved again.

use super::pin_load::BoreLoad;
use super::records::{LoadCaseResult, LoadModelPeaks};
use super::solve::{RodOptions, RodSolution};
use super::{BoreSpec, half_model::solve_rod_on};
use crate::fem::error::{FemError, Result};
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;

/// The other load models' solutions on the mesh of `solution` (`whole`, the mirrored whole of a
/// half model): each is solved as `solution` was (the same half, options and forces), under
/// `bores` with its `bore_load` replaced.
pub struct LoadModelSolutions {
    /// Per case, the peaks under each model.
    pub peaks: Vec<LoadModelPeaks>,
    /// The contact solution on the whole mesh, for the report's fields (`None`: the solution
    /// compared is itself contact's).
    pub contact: Option<(TetMesh, RodSolution)>,
    /// Why the cosine pressure could not be solved, where it could not.
    pub cosine_error: Option<String>,
}

/// Solves the cases of `solution` (on `whole`) under the load models it was not solved under, and
/// returns each case's peaks under all three.
pub fn compare_load_models(
    whole: &TetMesh,
    solution: &RodSolution,
    material: &Material,
    bores: &BoreSpec,
    force_n: f64,
    options: &RodOptions,
) -> Result<LoadModelSolutions> {
    let half = solution.result.half_model.as_ref();
    let mesh = half.map(|h| h.half_of(whole)).transpose()?;
    let options = RodOptions {
        mirror_plane_z_m: half.map(|h| h.plane_z_m()),
        keep_system: false,
        reuse_symbolic: None,
        ..options.clone()
    };
    let solved = bores.bore_load;
    let solve = |model: BoreLoad| -> Result<Option<(TetMesh, RodSolution)>> {
        if model == solved {
            return Ok(None);
        }
        let spec = BoreSpec {
            bore_load: model,
            ..bores.clone()
        };
        let m = mesh.clone().unwrap_or_else(|| whole.clone());
        solve_rod_on(m, material, &spec, force_n, &options)
            .map(Some)
            .map_err(|e| FemError::Problem(format!("the {} load model: {e}", model.name())))
    };
    let uniform = solve(BoreLoad::Uniform)?;
    // the cosine pressure needs the pressed half of the bore: a big end without its cap loaded
    // across the rod has not all of it, and the comparison goes on without that model
    let cosine = solve(BoreLoad::Cosine);
    let contact = solve(BoreLoad::Contact)?;
    let pick = |other: &Option<(TetMesh, RodSolution)>| -> Vec<LoadCaseResult> {
        other
            .as_ref()
            .map_or(&solution.result.cases.0, |(_, s)| &s.result.cases.0)
            .clone()
    };
    let (u, k) = (pick(&uniform), pick(&contact));
    let c: Vec<Option<f64>> = match &cosine {
        Ok(c) => pick(c)
            .iter()
            .map(|c| Some(c.max_von_mises_away_from_fixed_mpa))
            .collect(),
        Err(_) => vec![None; u.len()],
    };
    let peaks = u
        .iter()
        .zip(&c)
        .zip(&k)
        .map(|((u, c), k)| {
            let record = k.contact.clone().ok_or_else(|| {
                FemError::Problem(format!("case {}: the contact solve has no record", k.name))
            })?;
            Ok(LoadModelPeaks {
                uniform_mpa: u.max_von_mises_away_from_fixed_mpa,
                cosine_mpa: *c,
                contact_mpa: k.max_von_mises_away_from_fixed_mpa,
                contact_at_mm: k.max_von_mises_away_from_fixed_at_mm,
                contact_discretisation_error_rel: k.estimated_discretisation_error_rel,
                contact: record,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(LoadModelSolutions {
        peaks,
        contact,
        cosine_error: cosine.err().map(|e| e.to_string()),
    })
}
