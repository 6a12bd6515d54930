//! The acceptance test of a contact solution, recomputed from its displacement field and
//! pressures alone (not from the solver's intermediate quantities):
//!
//! - equilibrium: the residual r = K u − f − f_c (f_c = Σ_b λ_b D_ba e_a, element by element,
//!   without the assembled matrix) vanishes at every DOF that is neither prescribed nor part of
//!   the support of the free motions, relative to |f + f_c|;
//! - the support's reaction (r at its DOFs) as a force and a moment: ~0 when the loads are in
//!   balance on the free motions;
//! - each force-driven pin's contact resultant Σ_b λ_b c_b equals its force;
//! - complementarity on the weighted gaps G_b = Σ_a D_ba g_a: G_b = 0 where λ_b > 0, G_b ≥ 0
//!   where λ_b = 0, no λ_b < 0 (no tensile contact pressure);
//! - the nodal gaps g_a: the largest penetration max(−g_a) (the weighted gaps are the
//!   constraint, so a node at the edge of the contact zone may dip slightly into the pin).

use rayon::prelude::*;

use super::acceptance::ContactCheck;
use super::cylinder::PinMotion;
use super::problem::{ContactProblem, Restraint};
use super::weights::Wall;
use crate::fem::boundary::{cross, norm};
use crate::fem::element::element_stiffness;
use crate::fem::error::{FemError, Result};

/// Checks the displacements `u` (3 per node), the wall pressures `pressure` (per cylinder, per
/// wall node, Pa), the pin translations `pins` (m) and each elastic pin's deflection towards its
/// axis at its wall nodes (`deflection`, m; empty for a rigid pin) of `problem`, with the support
/// of the free motions on `support` (DOFs). Returns the figures, the support's reaction and the reactions
/// K u − f − f_c at the prescribed DOFs and the support's (3 per node, zero elsewhere); it does
/// not judge them ([`ContactCheck::verify`] does).
pub fn check(
    problem: &ContactProblem,
    u: &[f64],
    pressure: &[Vec<f64>],
    pins: &[[f64; 3]],
    deflection: &[Vec<f64>],
    support: &[usize],
) -> Result<(ContactCheck, Restraint, Vec<f64>)> {
    let mesh = problem.mesh;
    let n = mesh.n_dofs();
    if u.len() != n
        || pressure.len() != problem.cylinders.len()
        || pins.len() != pressure.len()
        || deflection.len() != pressure.len()
    {
        return Err(FemError::InvalidInput(
            "contact check: sizes do not match the problem".into(),
        ));
    }
    let mut f = if problem.loads.is_empty() {
        vec![0.0; n]
    } else {
        problem.loads.clone()
    };
    let mut load_sum = [0.0; 3];
    for (i, v) in f.iter().enumerate() {
        load_sum[i % 3] += v;
    }
    let mut load_scale = norm(load_sum);
    let mut out = ContactCheck::default();
    let mut offset = 0;
    let mut walls = Vec::with_capacity(pressure.len());
    for (k, cyl) in problem.cylinders.iter().enumerate() {
        let wall = Wall::new(mesh, cyl, k, offset)?;
        offset += wall.len();
        let lam = &pressure[k];
        if lam.len() != wall.len() {
            return Err(FemError::InvalidInput(format!(
                "contact check: cylinder {k} has {} wall nodes, {} pressures",
                wall.len(),
                lam.len()
            )));
        }
        wall.add_forces(lam, &mut f);
        let mut res = [0.0; 3];
        for (b, l) in lam.iter().enumerate() {
            let c = wall.force_per_pressure(b);
            load_scale += l.abs() * norm(c);
            for j in 0..3 {
                res[j] += l * c[j];
            }
        }
        if let PinMotion::Force(force) = cyl.motion {
            let err = norm(std::array::from_fn(|j| res[j] - force[j])) / norm(force).max(1e-300);
            out.resultant_error_rel = out.resultant_error_rel.max(err);
        }
        walls.push(wall);
    }
    // gaps, penetration, complementarity
    let mut weighted = Vec::with_capacity(walls.len());
    for (k, wall) in walls.iter().enumerate() {
        let mut g = wall.gaps(u, pins[k]);
        if !deflection[k].is_empty() {
            if deflection[k].len() != g.len() {
                return Err(FemError::InvalidInput(format!(
                    "contact check: cylinder {k} has {} wall nodes, {} deflections",
                    g.len(),
                    deflection[k].len()
                )));
            }
            for (ga, d) in g.iter_mut().zip(&deflection[k]) {
                *ga += d;
            }
        }
        for (a, ga) in g.iter().enumerate() {
            out.gap_scale_m = out
                .gap_scale_m
                .max(wall.g0[a].abs())
                .max((ga - wall.g0[a]).abs());
            out.penetration_max_m = out.penetration_max_m.max(-ga);
        }
        for l in &pressure[k] {
            out.max_tensile_pressure_pa = out.max_tensile_pressure_pa.max(-l);
        }
        weighted.push(wall.weighted(&g));
    }
    let area_max = walls
        .iter()
        .flat_map(|w| w.area.iter().copied())
        .fold(0.0, f64::max);
    let gw = (area_max * out.gap_scale_m).max(f64::MIN_POSITIVE);
    for (k, g) in weighted.iter().enumerate() {
        for (b, gb) in g.iter().enumerate() {
            let v = if pressure[k][b] > 0.0 {
                gb.abs()
            } else {
                (-gb).max(0.0)
            };
            out.complementarity_rel = out.complementarity_rel.max(v / gw);
        }
    }
    out.penetration_rel = out.penetration_max_m / out.gap_scale_m.max(f64::MIN_POSITIVE);
    out.load_scale_n = load_scale;
    // equilibrium, element by element
    let r = internal_forces(problem, u)?;
    let mut held = vec![false; n];
    for &(d, _) in &problem.prescribed {
        held[d] = true;
    }
    for &d in support {
        held[d] = true;
    }
    let (mut num, mut den) = (0.0, 0.0);
    let mut reactions = vec![0.0; n];
    for d in 0..n {
        den += f[d] * f[d];
        if held[d] {
            reactions[d] = r[d] - f[d];
        } else {
            num += (r[d] - f[d]).powi(2);
        }
    }
    out.equilibrium_residual_rel = (num / den.max(f64::MIN_POSITIVE)).sqrt();
    // the support's reaction
    let (lo, hi) = mesh.bounding_box();
    let point = std::array::from_fn(|j| 0.5 * (lo[j] + hi[j]));
    let size = norm(std::array::from_fn(|j| hi[j] - lo[j]));
    let mut force = [0.0; 3];
    let mut moment = [0.0; 3];
    for &d in support {
        let mut fv = [0.0; 3];
        fv[d % 3] = r[d] - f[d];
        let x = mesh.nodes()[d / 3];
        let arm = std::array::from_fn(|j| x[j] - point[j]);
        let m = cross(arm, fv);
        for j in 0..3 {
            force[j] += fv[j];
            moment[j] += m[j];
        }
    }
    let scale = load_scale.max(f64::MIN_POSITIVE);
    let reaction_rel = (norm(force) / scale).max(norm(moment) / (scale * size));
    out.free_mode_reaction_rel = reaction_rel;
    Ok((
        out,
        Restraint {
            dofs: support.to_vec(),
            free_motions: 0,
            force_n: force,
            moment_nm: moment,
            point_m: point,
            reaction_rel,
        },
        reactions,
    ))
}

/// K u of the whole body (all DOFs), element by element.
fn internal_forces(problem: &ContactProblem, u: &[f64]) -> Result<Vec<f64>> {
    let mesh = problem.mesh;
    let parts: Vec<[f64; 30]> = (0..mesh.n_elements())
        .into_par_iter()
        .map(|e| {
            let x = mesh.element_coords(e);
            let ke = element_stiffness(&x, &problem.material, problem.quadrature.rule_for(&x), e)?;
            let el = &mesh.elements()[e];
            let ue = nalgebra::SVector::<f64, 30>::from_fn(|i, _| u[3 * el[i / 3] + i % 3]);
            let fe = ke * ue;
            Ok(std::array::from_fn(|i| fe[i]))
        })
        .collect::<Result<_>>()?;
    let mut r = vec![0.0; mesh.n_dofs()];
    for (el, fe) in mesh.elements().iter().zip(&parts) {
        for (i, v) in fe.iter().enumerate() {
            r[3 * el[i / 3] + i % 3] += v;
        }
    }
    Ok(r)
}
