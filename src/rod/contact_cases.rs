//! The static cases with the pin force entering through contact (`[fem] bore_load = "contact"`):
//! each case of [`STATIC_CASES`] solved by the kernel's frictionless contact
//! ([`crate::fem::contact::solve_contact`]), pin A a rigid cylinder of radius r_A − c_A carrying
//! the case's force (its translation unknown), so that the same post-processing as for the
//! prescribed spreads ([`super::solve::rod_fields`]: peaks, recovery, error estimate, judged
//! region) runs on its displacement.
//!
//! How bore B holds the rod depends on the case:
//! - a force along A→B ([`CaseDirection::AlongRod`]) passes through pin B's axis: pin B is a fixed
//!   rigid cylinder of radius r_B − c_B in contact with its bore, and the rotation about it, which
//!   frictionless contact leaves free, is held by a support whose reaction is refused unless ~0
//!   ([`crate::fem::contact::Restraint`]);
//! - a force across the rod ([`CaseDirection::AcrossRod`]) has a moment about B that only the
//!   rod's inertia balances in the engine; the static case clamps bore B (all DOFs of its nodes)
//!   as the thesis does, and only pin A is in contact.
//!
//! c_A, c_B are [`BoreSpec::clearance_a_m`], [`BoreSpec::clearance_b_m`] (by default
//! [`super::bores::default_clearance_m`] of the bore found; negative: an interference).
//! On a half model the pin force is halved and u_z = 0 on the symmetry plane (`held`), which also
//! holds the sliding along the pins.

use std::time::Instant;

use crate::fem::element::QuadratureChoice;

use super::bores::{BoreSpec, BoreSurface, default_clearance_m};
use super::cases::{CaseDirection, STATIC_CASES};
use super::pin_model::PinModel;
use super::records::PinContactRecord;
use crate::fem::contact::{
    ContactProblem, ContactSolution, ContactTolerances, Cylinder, PinElasticity, PinMotion,
    diameter_change, solve_contact,
};
use crate::fem::error::{FemError, Result};
use crate::fem::load::SurfaceLoad;
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;
use crate::fem::mesh::mirror::MirroredMesh;
use crate::fem::statics::{SolveStats, StaticSolution, Timings};

/// The radial clearances of pins A and B (m) of `bores` in the bores found.
pub fn clearances_m(bores: &BoreSpec, loaded: &BoreSurface, fixed: &BoreSurface) -> [f64; 2] {
    [
        bores
            .clearance_a_m
            .unwrap_or_else(|| default_clearance_m(loaded.radius_m)),
        bores
            .clearance_b_m
            .unwrap_or_else(|| default_clearance_m(fixed.radius_m)),
    ]
}

/// A pin in `bore` with radial clearance `clearance` (m), moving as `motion`, rigid or elastic
/// (`elastic`).
pub fn pin_in(
    bore: &BoreSurface,
    axis: [f64; 3],
    clearance: f64,
    motion: PinMotion,
    elastic: Option<PinElasticity>,
) -> Result<Cylinder> {
    let radius = bore.radius_m - clearance;
    if !(clearance.is_finite() && radius > 0.0) {
        return Err(FemError::InvalidInput(format!(
            "contact load: a radial clearance of {:.4} mm leaves no pin in a bore of radius {:.4} mm",
            clearance * 1e3,
            bore.radius_m * 1e3
        )));
    }
    Ok(Cylinder {
        axis_point_m: bore.centre_m,
        axis,
        radius_m: radius,
        faces: bore.faces.clone(),
        // the gap from the bore's radius: a faceted wall's midside nodes lie inside it
        nominal_bore_radius_m: Some(bore.radius_m),
        motion,
        elastic,
    })
}

/// One case's contact solve: the record of the pins and the nodal fields of the contact.
pub struct ContactCase {
    pub record: PinContactRecord,
    /// Contact pressure at each node of the mesh (smoothed over the faces; 0 off the bore walls), Pa.
    pub pressure_pa: Vec<f64>,
    /// Gap between the bore wall and its pin at each node (0 off the bore walls), m.
    pub gap_m: Vec<f64>,
}

impl ContactCase {
    /// The contact of a half model's case on the whole mesh `m`: the nodal fields of the images.
    pub(super) fn mirrored(self, m: &MirroredMesh) -> Self {
        let on_whole = |v: &[f64]| m.source.iter().map(|&s| v[s]).collect();
        ContactCase {
            pressure_pa: on_whole(&self.pressure_pa),
            gap_m: on_whole(&self.gap_m),
            record: self.record,
        }
    }

    fn new(
        mesh: &TetMesh,
        problem: &ContactProblem,
        solution: &ContactSolution,
        clearances_m: [f64; 2],
        seconds: f64,
    ) -> Result<Self> {
        let a = &solution.cylinders[0];
        let b = solution.cylinders.get(1);
        let force = match problem.cylinders[0].motion {
            PinMotion::Force(f) => f,
            PinMotion::Fixed => [1.0, 0.0, 0.0],
        };
        let ovality = diameter_change(mesh, &problem.cylinders[0], &solution.displacements, force)?;
        let mut pressure_pa = vec![0.0; mesh.n_nodes()];
        let mut gap_m = vec![0.0; mesh.n_nodes()];
        for c in &solution.cylinders {
            for (k, &nd) in c.nodes.iter().enumerate() {
                pressure_pa[nd] = c.smoothed_pressure_pa[k];
                gap_m[nd] = c.gap_m[k];
            }
        }
        let m = solution.restraint.moment_nm;
        Ok(ContactCase {
            record: PinContactRecord {
                pins: PinModel::Rigid,
                clearance_a_um: clearances_m[0] * 1e6,
                clearance_b_um: clearances_m[1] * 1e6,
                arc_a_deg: a.arc_deg,
                arc_a_ends_deg: a.arc_ends_deg,
                peak_pressure_a_mpa: a.peak_pressure_pa * 1e-6,
                peak_pressure_a_at_deg: a.peak_angle_deg,
                arc_b_deg: b.map(|b| b.arc_deg),
                peak_pressure_b_mpa: b.map(|b| b.peak_pressure_pa * 1e-6),
                ovality_a_along_um: ovality.along_m * 1e6,
                ovality_a_across_um: ovality.across_m * 1e6,
                penetration_max_um: solution.check.penetration_max_m * 1e6,
                max_tensile_pressure_mpa: solution.check.max_tensile_pressure_pa * 1e-6,
                restraint_moment_nm: (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt(),
                iterations: solution.iterations,
                seconds,
            },
            pressure_pa,
            gap_m,
        })
    }
}

/// The cases of [`STATIC_CASES`] under contact, as the static solution [`super::solve::rod_fields`]
/// post-processes: `cases` (direction, force per case), the bores found, the pin axis; pin loads
/// scaled by `load_share`, the DOFs `held` fixed besides (a half model's plane). Returns the
/// static solution, the contact pin loads as surface loads, and each case's contact solve.
#[allow(clippy::too_many_arguments)]
pub(super) fn contact_solutions(
    mesh: &TetMesh,
    material: &Material,
    bores: &BoreSpec,
    quadrature: QuadratureChoice,
    cases: &[([f64; 3], f64)],
    (loaded, fixed, axis): (&BoreSurface, &BoreSurface, [f64; 3]),
    load_share: f64,
    held: &[usize],
) -> Result<(StaticSolution, Vec<SurfaceLoad>, Vec<ContactCase>)> {
    let [c_a, c_b] = clearances_m(bores, loaded, fixed);
    let elastic = bores.pin_elasticity(material)?;
    let n = mesh.n_dofs();
    let mut displacements = Vec::with_capacity(cases.len());
    let mut reactions = Vec::with_capacity(cases.len());
    let mut residual_rel = Vec::with_capacity(cases.len());
    let mut loads = Vec::with_capacity(cases.len());
    let mut solves = Vec::with_capacity(cases.len());
    let mut timings = Timings::default();
    let mut equations = 0;
    for (def, (dir, force)) in STATIC_CASES.iter().zip(cases) {
        let t = Instant::now();
        let pin_force = dir.map(|v| v * force * load_share);
        let pin_b = def.direction == CaseDirection::AlongRod;
        let mut cylinders = vec![pin_in(
            loaded,
            axis,
            c_a,
            PinMotion::Force(pin_force),
            elastic,
        )?];
        let mut prescribed: Vec<(usize, f64)> = held.iter().map(|&d| (d, 0.0)).collect();
        if pin_b {
            cylinders.push(pin_in(fixed, axis, c_b, PinMotion::Fixed, elastic)?);
        } else {
            let on_plane: std::collections::HashSet<usize> = held.iter().copied().collect();
            prescribed.extend(
                fixed
                    .nodes
                    .iter()
                    .flat_map(|&nd| (0..3).map(move |j| 3 * nd + j))
                    .filter(|d| !on_plane.contains(d))
                    .map(|d| (d, 0.0)),
            );
        }
        let problem = ContactProblem {
            mesh,
            material: *material,
            quadrature,
            prescribed,
            loads: Vec::new(),
            cylinders,
            tolerances: ContactTolerances::default(),
        };
        let solution = solve_contact(&problem).map_err(|e| {
            FemError::Problem(format!(
                "case {}: the contact of the pins with their bores (radial clearances {:.4} mm at \
                 A, {:.4} mm at B): {e}",
                def.name,
                c_a * 1e3,
                c_b * 1e3
            ))
        })?;
        let forces = solution.contact_forces[0].clone();
        let mut resultant_n = [0.0; 3];
        for (d, f) in forces.iter().enumerate() {
            resultant_n[d % 3] += f;
        }
        let contact = &solution.cylinders[0];
        loads.push(SurfaceLoad {
            forces,
            area_m2: loaded.area_m2,
            traction_pa: [contact.peak_pressure_pa, 0.0, 0.0],
            resultant_n,
            resultant_error_rel: solution.check.resultant_error_rel,
        });
        // what holds the rod: pin B's contact, the clamp, the plane, the free-motion support
        let mut r = solution.reactions.clone();
        if pin_b {
            for (ri, fb) in r.iter_mut().zip(&solution.contact_forces[1]) {
                *ri += fb;
            }
        }
        reactions.push(r);
        displacements.push(solution.displacements.clone());
        residual_rel.push(solution.check.equilibrium_residual_rel);
        equations = equations.max(solution.equations);
        timings.assembly_s += solution.timings.assembly_s;
        timings.factorisation_s += solution.timings.factorisation_s;
        timings.solve_s += t.elapsed().as_secs_f64()
            - solution.timings.assembly_s
            - solution.timings.factorisation_s;
        let mut case = ContactCase::new(
            mesh,
            &problem,
            &solution,
            [c_a, c_b],
            t.elapsed().as_secs_f64(),
        )?;
        case.record.pins = bores.pins;
        solves.push(case);
    }
    let stats = SolveStats {
        dofs: n,
        equations,
        ..SolveStats::default()
    };
    Ok((
        StaticSolution {
            displacements,
            reactions,
            residual_rel,
            stats,
            timings,
        },
        loads,
        solves,
    ))
}
