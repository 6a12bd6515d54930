//! The cycle with the pins in contact at the instants that matter. Contact is not superposable
//! (the arc depends on the load), so the linear cycle ([`super::combine`]) cannot carry it; instead
//! the rod is solved directly with contact at a few instants: peak compression (largest F_A,x on
//! the rod, towards B), peak tension (most negative F_A,x), peak force across the rod (largest
//! |F_A,y|) and the linear cycle's worst instant, and its judged peak compared with the linear
//! cycle's at the same instant.
//!
//! All instants share one factorisation of K ([`ContactSystem`]); a mirror-symmetric rod is solved
//! on its half model (u_z = 0 on the plane, half the loads) and mirrored for the stresses.
//!
//! At an instant the rod carries the d'Alembert body force ρ (g − a_P) (the four body-force unit
//! loads of [`super::unit_cases`] combined with the instant's coefficients), pin A a rigid cylinder
//! of radius r_A − c_A with the crank's force F_A on it, and is held by pin B, a fixed rigid
//! cylinder of radius r_B − c_B, in contact with bore B (where the linear cycle fixes all of bore
//! B's DOFs). The loads are in balance by the dynamics on the mesh's own mass properties, so the
//! support of the rotation about pin B that frictionless contact leaves free carries ~0; its
//! moment is reported relative to |F_A| × the centre distance.

use serde::{Deserialize, Serialize};

use super::CycleInstant;
use super::unit_cases::{CycleOptions, coefficients};
use crate::fem::body_force::{BodyShape, body_force_load};
use crate::fem::boundary::{boundary_faces, norm};
use crate::fem::contact::{ContactProblem, ContactSystem, ContactTolerances, PinMotion};
use crate::fem::error::{FemError, Result};
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;
use crate::fem::mesh::mirror::mirror;
use crate::fem::stress::{peak_nodal, stress_field};
use crate::mechanism::RodFrameInstant;
use crate::rod::bores::{BoreSpec, BoreSurface, find_bores};
use crate::rod::contact_cases::{clearances_m, pin_in};
use crate::rod::fatigue::signed_von_mises;
use crate::rod::half_model::mirror_plane_tolerance;
use crate::rod::judged::{Bands, judged_nodes};

/// One instant solved with contact, beside the linear cycle's figure at the same instant.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactInstant {
    /// Why this instant: "peak compression", "peak tension", "peak transverse", "worst linear"
    /// (several, joined, where they coincide).
    pub reason: String,
    pub crank_angle_deg: f64,
    /// The pin force on the rod at A, rod frame, N.
    pub f_a_on_rod_n: [f64; 2],
    /// The judged peak of the linear cycle (uniform or cosine bore load, bore B fixed), MPa.
    pub linear_mpa: f64,
    /// The judged peak with the pins in contact, MPa, and where (rod frame, mm).
    pub contact_mpa: f64,
    pub contact_at_mm: [f64; 3],
    /// (contact − linear) / linear.
    pub change_rel: f64,
    /// The contact arcs on bores A and B, degrees, and their peak pressures, MPa.
    pub arc_a_deg: f64,
    pub arc_b_deg: f64,
    pub peak_pressure_a_mpa: f64,
    pub peak_pressure_b_mpa: f64,
    /// |moment| of the support of the rotation about pin B / (|F_A| × centre distance).
    pub restraint_moment_rel: f64,
}

/// The instants solved with contact, and the signed von Mises stress (Pa) of each at every node
/// of the mesh (the nodally averaged tensor's, [`crate::rod::fatigue::signed_von_mises`]), for the
/// fatigue factor with contact ([`super::contact_fatigue`]).
#[derive(Clone, Debug)]
pub struct ContactInstants {
    pub instants: Vec<ContactInstant>,
    pub signed_von_mises_pa: Vec<Vec<f64>>,
    /// The instants that could not be solved, each with why (the others are solved).
    pub failed: Vec<String>,
}

/// Instants of the cycle closer than this (degrees of crank angle, across the cycle's end too) are
/// one for the choice of [`instants_that_matter`]: the linear worst 1° after the peak tension at
/// top dead centre is the same load.
pub const SAME_INSTANT_DEG: f64 = 3.0;

/// The instants of `instants` that matter for contact, with the reasons: the linear cycle's worst
/// instant `linear_worst`, peak compression, peak force across the rod and peak tension (only
/// where F_A,x < 0 somewhere); an instant within [`SAME_INSTANT_DEG`] of one chosen before is that
/// one (its reasons joined); in crank-angle order.
pub fn instants_that_matter(
    instants: &[RodFrameInstant],
    linear_worst: usize,
) -> Vec<(usize, String)> {
    let arg = |key: &dyn Fn(&RodFrameInstant) -> f64| {
        (0..instants.len())
            .max_by(|&a, &b| key(&instants[a]).total_cmp(&key(&instants[b])))
            .unwrap_or(0)
    };
    let mut picked: Vec<(usize, &str)> = vec![
        (linear_worst, "worst linear"),
        (arg(&|i| i.f_a_on_rod_n[0]), "peak compression"),
        (arg(&|i| i.f_a_on_rod_n[1].abs()), "peak transverse"),
    ];
    let tension = arg(&|i| -i.f_a_on_rod_n[0]);
    if instants
        .get(tension)
        .is_some_and(|i| i.f_a_on_rod_n[0] < 0.0)
    {
        picked.push((tension, "peak tension"));
    }
    let mut out: Vec<(usize, String)> = Vec::new();
    let angle = |k: usize| instants.get(k).map_or(f64::NAN, |i| i.crank_angle_deg);
    let span = if instants.iter().any(|i| i.crank_angle_deg >= 360.0) {
        720.0
    } else {
        360.0
    };
    for (k, why) in picked {
        // an instant within SAME_INSTANT_DEG of one already chosen is that one
        let near = |j: usize| {
            let d = (angle(j) - angle(k)).abs().rem_euclid(span);
            d.min(span - d) <= SAME_INSTANT_DEG
        };
        match out.iter_mut().find(|(j, _)| near(*j)) {
            Some((_, reasons)) => {
                reasons.push_str(", ");
                reasons.push_str(why);
            }
            None => out.push((k, why.to_string())),
        }
    }
    out.sort_by(|a, b| {
        instants[a.0]
            .crank_angle_deg
            .total_cmp(&instants[b.0].crank_angle_deg)
    });
    out
}

/// Solves the rod `mesh` with contact at each instant of `which` (indices into `instants`, with
/// reasons), against the linear cycle's `history`. On a half model ([`CycleOptions::half_model`])
/// the half is solved (half the loads, u_z = 0 on the plane) and mirrored; the instants share one
/// factorised system ([`ContactSystem`]): only the loads and the pin force change between them.
pub fn contact_instants(
    mesh: &TetMesh,
    material: &Material,
    bores: &BoreSpec,
    options: &CycleOptions,
    instants: &[RodFrameInstant],
    history: &[CycleInstant],
    which: &[(usize, String)],
) -> Result<ContactInstants> {
    if which.is_empty() {
        return Ok(ContactInstants {
            instants: Vec::new(),
            signed_von_mises_pa: Vec::new(),
            failed: Vec::new(),
        });
    }
    // the mesh solved: the half model with its plane held, or the whole
    let half = match &options.half_model {
        Some(h) => {
            let half = h.half_of(mesh)?;
            let m = mirror(&half, h.plane_z_m(), mirror_plane_tolerance(&half))?;
            if m.whole.n_nodes() != mesh.n_nodes() {
                return Err(FemError::InvalidInput(format!(
                    "the half model mirrors into {} nodes, the cycle's mesh has {}",
                    m.whole.n_nodes(),
                    mesh.n_nodes()
                )));
            }
            Some((half, m))
        }
        None => None,
    };
    let solved = half.as_ref().map_or(mesh, |(h, _)| h);
    let share = if half.is_some() { 0.5 } else { 1.0 };
    let held: Vec<(usize, f64)> = half.as_ref().map_or(Vec::new(), |(_, m)| {
        m.plane_nodes.iter().map(|&n| (3 * n + 2, 0.0)).collect()
    });
    let (loaded, fixed) = find_bores(solved, &boundary_faces(solved)?, bores)?;
    let axis = bores.unit_axis()?;
    let [c_a, c_b] = clearances_m(bores, &loaded, &fixed);
    let elastic = bores.pin_elasticity(material)?;
    let body: Vec<Vec<f64>> = [
        BodyShape::UniformX,
        BodyShape::UniformY,
        BodyShape::Centrifugal,
        BodyShape::AngularAccel,
    ]
    .into_iter()
    .map(|shape| body_force_load(solved, options.density_kg_m3, shape))
    .collect();
    // the judged region on the whole mesh, as the linear cycle's
    let (_, fixed_whole) = find_bores(mesh, &boundary_faces(mesh)?, bores)?;
    let bands = Bands {
        fixed_faces: &fixed_whole.faces,
        fixed_band_m: options.fixed_band_m,
        singular_edges_m: &options.singular_edges_m,
        singular_band_m: options.singular_band_m,
    };
    let judged = judged_nodes(mesh, &bands).judged;
    let centre_distance = norm(std::array::from_fn(|j| {
        fixed.centre_m[j] - loaded.centre_m[j]
    }));
    let problem_at = |inst: &RodFrameInstant| -> Result<ContactProblem<'_>> {
        let c = coefficients(inst);
        let mut loads = vec![0.0; solved.n_dofs()];
        for (b, coeff) in body.iter().zip(&c[2..]) {
            for (l, v) in loads.iter_mut().zip(b) {
                *l += coeff * v;
            }
        }
        let f_a = [
            share * inst.f_a_on_rod_n[0],
            share * inst.f_a_on_rod_n[1],
            0.0,
        ];
        Ok(ContactProblem {
            mesh: solved,
            material: *material,
            quadrature: options.quadrature,
            prescribed: held.clone(),
            loads,
            cylinders: vec![
                pin_in(&loaded, axis, c_a, PinMotion::Force(f_a), elastic)?,
                pin_in(&fixed, axis, c_b, PinMotion::Fixed, elastic)?,
            ],
            tolerances: ContactTolerances {
                free_mode_reaction_rel: None,
                ..ContactTolerances::default()
            },
        })
    };
    let instant = |k: usize| {
        instants.get(k).ok_or_else(|| {
            FemError::InvalidInput(format!("contact instant {k} is not in the cycle"))
        })
    };
    let system = ContactSystem::new(&problem_at(instant(which[0].0)?)?)?;
    let open_side = open_side_of(&loaded, axis, bores.loaded_arc_deg, solved);
    let solved: Vec<Result<(ContactInstant, Vec<f64>)>> = which
        .iter()
        .map(|(k, reason)| {
            let inst = instant(*k)?;
            let problem = problem_at(inst)?;
            let s = system.solve(&problem).map_err(|e| {
                FemError::Problem(format!(
                    "φ = {:.0}° ({reason}): {e}{}",
                    inst.crank_angle_deg,
                    open_side(inst.f_a_on_rod_n)
                ))
            })?;
            let u = match &half {
                Some((_, m)) => m.mirror_vector(&s.displacements),
                None => s.displacements.clone(),
            };
            let stress = stress_field(mesh, material, &u)?;
            let peak = peak_nodal(mesh, &stress.von_mises_averaged(), Some(&judged));
            let linear = history
                .get(*k)
                .ok_or_else(|| {
                    FemError::InvalidInput(format!("contact instant {k} has no linear figure"))
                })?
                .max_von_mises_away_from_fixed_mpa;
            let m = s.restraint.moment_nm;
            let f_a = [inst.f_a_on_rod_n[0], inst.f_a_on_rod_n[1], 0.0];
            let contact_mpa = peak.value * 1e-6;
            let signed = stress.averaged.iter().map(signed_von_mises).collect();
            let record = ContactInstant {
                reason: reason.clone(),
                crank_angle_deg: inst.crank_angle_deg,
                f_a_on_rod_n: inst.f_a_on_rod_n,
                linear_mpa: linear,
                contact_mpa,
                contact_at_mm: peak.location_m.map(|v| v * 1e3),
                change_rel: (contact_mpa - linear) / linear,
                arc_a_deg: s.cylinders[0].arc_deg,
                arc_b_deg: s.cylinders[1].arc_deg,
                peak_pressure_a_mpa: s.cylinders[0].peak_pressure_pa * 1e-6,
                peak_pressure_b_mpa: s.cylinders[1].peak_pressure_pa * 1e-6,
                restraint_moment_rel: norm(m)
                    / (share * norm(f_a) * centre_distance).max(f64::MIN_POSITIVE),
            };
            Ok((record, signed))
        })
        .collect();
    let mut out = ContactInstants {
        instants: Vec::new(),
        signed_von_mises_pa: Vec::new(),
        failed: Vec::new(),
    };
    for r in solved {
        match r {
            Ok((record, signed)) => {
                out.instants.push(record);
                out.signed_von_mises_pa.push(signed);
            }
            Err(e) => out.failed.push(e.to_string()),
        }
    }
    Ok(out)
}

/// For a partial bore A (`arc_deg` < 360: a big end without its cap), what to add to a failed
/// instant's message: how far the pin force points from the middle of the arc that exists (the
/// mean direction of the wall's nodes from the axis), beside the arc's half width; empty for a
/// full bore.
fn open_side_of<'a>(
    bore: &'a BoreSurface,
    axis: [f64; 3],
    arc_deg: f64,
    mesh: &'a TetMesh,
) -> impl Fn([f64; 2]) -> String + 'a {
    let mut middle = [0.0; 3];
    for &n in &bore.nodes {
        let x = mesh.nodes()[n];
        let d: [f64; 3] = std::array::from_fn(|j| x[j] - bore.centre_m[j]);
        let along = (0..3).map(|j| d[j] * axis[j]).sum::<f64>();
        let r: [f64; 3] = std::array::from_fn(|j| d[j] - along * axis[j]);
        let l = norm(r).max(f64::MIN_POSITIVE);
        for j in 0..3 {
            middle[j] += r[j] / l;
        }
    }
    move |f: [f64; 2]| {
        let (lf, lm) = (f[0].hypot(f[1]), norm(middle));
        if arc_deg >= 360.0 || lf == 0.0 || lm == 0.0 {
            return String::new();
        }
        let cos = (f[0] * middle[0] + f[1] * middle[1]) / (lf * lm);
        format!(
            "; bore A is a partial bore of {arc_deg:.0}° (a big end without its cap) and the pin \
             force ({:.0}, {:.0}) N points {:.0}° from the middle of its arc (which reaches \
             ±{:.0}°): a force towards the open side needs the cap",
            f[0],
            f[1],
            cos.clamp(-1.0, 1.0).acos().to_degrees(),
            arc_deg / 2.0
        )
    }
}
