//! A pin force entering the rod through frictionless contact ([`crate::fem::contact`]): pin A a
//! rigid cylinder of radius r_A − c_A carrying the force F (its translation unknown), pin B a
//! fixed rigid cylinder of radius r_B − c_B holding the rod (r the bore radius found on the mesh,
//! c the clearance; c < 0 is an interference). The rotation about pin B and the sliding along the
//! pins, which frictionless contact leaves free, are held by a support whose reaction is reported
//! ([`crate::fem::contact::Restraint`]) and refused unless ~0 (unless the tolerances given say
//! otherwise: a force across the rod has a moment about B that only the rod's inertia balances).
//!
//! The judged peak is the static cases' ([`super::solve::rod_fields`]): the nodally averaged von
//! Mises stress over the nodes outside the bands around bore B and the sharp edges
//! ([`super::judged::judged_nodes`], the same [`RodOptions`] bands), so that it compares with the
//! uniform and cosine load models like for like.

use super::bores::{BoreSpec, BoreSurface, find_bores};
use super::contact_cases::pin_in;
use super::judged::{Bands, DEFAULT_FIXED_BAND_M, DEFAULT_SINGULAR_BAND_M, judged_nodes};
use super::solve::RodOptions;
use crate::fem::boundary::{boundary_faces, norm};
use crate::fem::contact::{
    ContactSolution, ContactTolerances, CylinderContact, DiameterChange, PinElasticity, PinMotion,
    Restraint, diameter_change, solve_contact,
};
use crate::fem::error::{FemError, Result};
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;
use crate::fem::stress::{Peak, StressField, peak_nodal, stress_field};

/// The pins of a contact solve.
#[derive(Clone, Debug, PartialEq)]
pub struct PinContact {
    /// The force of pin A on the rod, N (rod frame).
    pub force_n: [f64; 3],
    /// Radial clearance of pin A in bore A, m (negative: interference).
    pub clearance_a_m: f64,
    /// Radial clearance of pin B in bore B, m (negative: interference).
    pub clearance_b_m: f64,
    /// Acceptance limits of the contact solution.
    pub tolerances: ContactTolerances,
    /// `None`: rigid pins; else both pins' elasticity ([`crate::fem::contact::elastic_pin`]).
    pub elastic: Option<PinElasticity>,
}

/// The rod loaded through its pins.
#[derive(Clone, Debug)]
pub struct RodContact {
    /// Displacements, 3 per node, m.
    pub displacements: Vec<f64>,
    /// The stress field.
    pub stress: StressField,
    /// The judged peak: nodally averaged von Mises over the judged nodes, Pa.
    pub judged_peak: Peak,
    /// The judged nodes ([`super::judged::judged_nodes`]).
    pub judged: Vec<bool>,
    /// Contact on bore A (arc, peak pressure, pin translation, …).
    pub bore_a: CylinderContact,
    /// Contact on bore B.
    pub bore_b: CylinderContact,
    /// Bore A's diameter change along the force and across it, m.
    pub ovality_a: DiameterChange,
    /// The bores found.
    pub loaded: BoreSurface,
    pub fixed: BoreSurface,
    /// The support of the motions contact leaves free, and its reaction.
    pub restraint: Restraint,
    /// The whole contact solution (checks, iterations, timings).
    pub solution: ContactSolution,
}

/// Solves the rod `mesh` (whole, not a half model) with pin A carrying `pins.force_n` and pin B
/// fixed, both in contact with their bores (found by [`find_bores`] from `bores`).
pub fn solve_rod_contact(
    mesh: &TetMesh,
    material: &Material,
    bores: &BoreSpec,
    pins: &PinContact,
    options: &RodOptions,
) -> Result<RodContact> {
    if options.mirror_plane_z_m.is_some() {
        return Err(FemError::InvalidInput(
            "contact load: a half model is not supported, solve the whole rod".into(),
        ));
    }
    let f = norm(pins.force_n);
    if !(f.is_finite() && f > 0.0) {
        return Err(FemError::InvalidInput(format!(
            "contact load: pin force {:?} N has no magnitude",
            pins.force_n
        )));
    }
    let axis = bores.unit_axis()?;
    let boundary = boundary_faces(mesh)?;
    let (loaded, fixed) = find_bores(mesh, &boundary, bores)?;
    let cylinders = vec![
        pin_in(
            &loaded,
            axis,
            pins.clearance_a_m,
            PinMotion::Force(pins.force_n),
            pins.elastic,
        )?,
        pin_in(
            &fixed,
            axis,
            pins.clearance_b_m,
            PinMotion::Fixed,
            pins.elastic,
        )?,
    ];
    let problem = crate::fem::contact::ContactProblem {
        mesh,
        material: *material,
        quadrature: options.quadrature,
        prescribed: Vec::new(),
        loads: Vec::new(),
        cylinders,
        tolerances: pins.tolerances,
    };
    let solution = solve_contact(&problem)?;
    let u = &solution.displacements;
    let ovality_a = diameter_change(mesh, &problem.cylinders[0], u, pins.force_n)?;
    let bands = Bands {
        fixed_faces: &fixed.faces,
        fixed_band_m: options.fixed_band_m.unwrap_or(DEFAULT_FIXED_BAND_M),
        singular_edges_m: &options.singular_edges_m,
        singular_band_m: options.singular_band_m.unwrap_or(DEFAULT_SINGULAR_BAND_M),
    };
    let judged = judged_nodes(mesh, &bands).judged;
    let stress = stress_field(mesh, material, u)?;
    let judged_peak = peak_nodal(mesh, &stress.von_mises_averaged(), Some(&judged));
    Ok(RodContact {
        displacements: u.clone(),
        stress,
        judged_peak,
        judged,
        bore_a: solution.cylinders[0].clone(),
        bore_b: solution.cylinders[1].clone(),
        ovality_a,
        loaded,
        fixed,
        restraint: solution.restraint.clone(),
        solution,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::mesh::structured::{TwoEyePlate, two_eye_plate};
    use crate::rod::pin_load::BoreLoad;
    use crate::rod::solve::solve_rod_fields;

    /// The two-eye plate (curved walls), pin A pushing along AB.
    fn plate() -> (TetMesh, BoreSpec) {
        let p = TwoEyePlate {
            curved: true,
            n_side: 6,
            ..TwoEyePlate::default()
        };
        let mesh = two_eye_plate(&p).unwrap();
        let spec = BoreSpec {
            loaded_centre_m: [0.0; 3],
            fixed_centre_m: [p.length, 0.0, 0.0],
            ..BoreSpec::default()
        };
        (mesh, spec)
    }

    #[test]
    fn the_pin_carries_its_force_and_the_judged_peak_grows_with_the_clearance_from_the_cosine_loads()
     {
        let (mesh, spec) = plate();
        let material = Material::STEEL;
        let options = RodOptions::default();
        let force = 20e3;
        // the cosine bearing pressure on the pressed half, bore B clamped, same judged region
        let cosine = BoreSpec {
            bore_load: BoreLoad::Cosine,
            ..spec.clone()
        };
        let st = solve_rod_fields(&mesh, &material, &cosine, force, &options).unwrap();
        let fx = &st.result.cases["fx"];
        assert_eq!(fx.direction, [1.0, 0.0, 0.0]);
        let cos_peak = fx.max_von_mises_away_from_fixed_mpa * 1e6;
        // measured on this mesh: −13.3 % (0), +10.7 % (5 µm, the peak then at the small eye,
        // which pin B loads by contact where the static cases clamp it), +100 % (50 µm: arc
        // 18°, a bearing pressure concentrated on a few nodes)
        let (mut last_arc, mut last_peak) = (f64::INFINITY, 0.0);
        for (clearance, band) in [(0.0, 0.2), (5e-6, 0.2), (50e-6, f64::INFINITY)] {
            let pins = PinContact {
                force_n: [force, 0.0, 0.0],
                clearance_a_m: clearance,
                clearance_b_m: clearance,
                tolerances: ContactTolerances::default(),
                elastic: None,
            };
            let c = solve_rod_contact(&mesh, &material, &spec, &pins, &options).unwrap();
            // contact resultant = pin force (by construction of the force pin, [`solve_contact`]);
            // pin B reacts it
            for j in 0..3 {
                assert!((c.bore_a.resultant_n[j] - pins.force_n[j]).abs() <= 1e-10 * force);
                assert!((c.bore_b.resultant_n[j] + pins.force_n[j]).abs() <= 1e-8 * force);
            }
            assert!(c.restraint.reaction_rel < 1e-8, "{:?}", c.restraint);
            let rel = c.judged_peak.value / cos_peak - 1.0;
            eprintln!(
                "clearance {clearance:.0e} m: judged peak {:.4e} Pa vs cosine {cos_peak:.4e} \
                 ({:+.2} %) at {:?}; arc A {:.1}°, peak pressure {:.3e} Pa, ovality {:?}, \
                 {} iterations",
                c.judged_peak.value,
                100.0 * rel,
                c.judged_peak.location_m,
                c.bore_a.arc_deg,
                c.bore_a.peak_pressure_pa,
                c.ovality_a,
                c.solution.iterations
            );
            // the arc narrows as the clearance grows (Persson 1964), centred on the force
            assert!(c.bore_a.arc_deg < last_arc && c.bore_a.arc_deg < 180.0);
            last_arc = c.bore_a.arc_deg;
            // and the judged peak grows, from within 20 % of the cosine load's
            assert!(c.judged_peak.value > last_peak);
            last_peak = c.judged_peak.value;
            assert!(rel.abs() < band, "{clearance}: {rel}");
            // the judged region is the static cases'
            assert_eq!(c.judged, st.away_from_fixed);
        }
    }

    #[test]
    fn a_clearance_that_leaves_no_pin_is_refused() {
        let (mesh, spec) = plate();
        let pins = PinContact {
            force_n: [1e3, 0.0, 0.0],
            clearance_a_m: 1.0,
            clearance_b_m: 0.0,
            tolerances: ContactTolerances::default(),
            elastic: None,
        };
        let r = solve_rod_contact(
            &mesh,
            &Material::STEEL,
            &spec,
            &pins,
            &RodOptions::default(),
        );
        assert!(r.is_err());
    }
}
