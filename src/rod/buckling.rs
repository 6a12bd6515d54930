//! Linear buckling of the rod: the F_x case of stage 3 ([`super::solve::rod_fx_case`]:
//! bore B fixed, the pin force on bore A towards B, a compression) handed to the general
//! eigen-solver of [`crate::fem::buckling`]; and the same with the pin load that contact gives
//! ([`rod_buckling_contact`]), for the load model's effect on the buckling factor.

use super::bores::BoreSpec;
use super::contact_cases::{clearances_m, pin_in};
use super::solve::rod_fx_case;
use crate::fem::buckling::{
    BucklingOptions, BucklingProblem, BucklingSolution, solve_buckling, solve_buckling_with,
};
use crate::fem::contact::{ContactProblem, ContactTolerances, PinMotion, solve_contact};
use crate::fem::element::QuadratureChoice;
use crate::fem::error::Result;
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;
use crate::fem::statics::FactorisedSystem;

/// Linear buckling of a rod under the compressive F_x case of stage 3 ([`rod_fx_case`]): bore B
/// fixed, bore A loaded by the pin load of resultant `compression_n` along A→B (towards the
/// fixed bore: compression). λ₁ · `compression_n` is the linear buckling load. `system`: the
/// factorised K of stage 3's static cases on this mesh ([`super::solve::RodOptions::keep_system`]),
/// used instead of assembling and factorising K again (the same supports, so the same K).
pub fn rod_buckling(
    mesh: &TetMesh,
    material: &Material,
    bores: &BoreSpec,
    compression_n: f64,
    quadrature: QuadratureChoice,
    options: &BucklingOptions,
    system: Option<&FactorisedSystem>,
) -> Result<BucklingSolution> {
    let case = rod_fx_case(mesh, bores, compression_n)?;
    let problem = BucklingProblem {
        mesh,
        material: *material,
        fixed_dofs: case.fixed_dofs,
        load: case.load,
        quadrature,
    };
    solve_on(&problem, options, system)
}

/// The buckling problem on the factorised `system` when given, else factorised here.
fn solve_on(
    problem: &BucklingProblem,
    options: &BucklingOptions,
    system: Option<&FactorisedSystem>,
) -> Result<BucklingSolution> {
    match system {
        Some(system) => solve_buckling_with(problem, system, options),
        None => solve_buckling(problem, options),
    }
}

/// [`rod_buckling`] with the compression entering bore A through contact: pin A a rigid cylinder
/// of radius r_A − c_A pressed towards B with `compression_n`, bore B clamped as in the buckling
/// case ([`crate::fem::contact`]); the contact's nodal forces on bore A are the buckling case's
/// load (the prestress of K_G), everything else as [`rod_buckling`]. The pressure arc depends on
/// the load's magnitude, so it is solved at `compression_n` itself; λ₁ · `compression_n` is the
/// linear buckling load with that pressure held in shape.
pub fn rod_buckling_contact(
    mesh: &TetMesh,
    material: &Material,
    bores: &BoreSpec,
    compression_n: f64,
    quadrature: QuadratureChoice,
    options: &BucklingOptions,
    system: Option<&FactorisedSystem>,
) -> Result<BucklingSolution> {
    let case = rod_fx_case(mesh, bores, compression_n)?;
    let [c_a, _] = clearances_m(bores, &case.loaded, &case.fixed);
    let force = case.direction.map(|v| v * compression_n);
    let contact = solve_contact(&ContactProblem {
        mesh,
        material: *material,
        quadrature,
        prescribed: case.fixed_dofs.iter().map(|&d| (d, 0.0)).collect(),
        loads: Vec::new(),
        cylinders: vec![pin_in(
            &case.loaded,
            bores.unit_axis()?,
            c_a,
            PinMotion::Force(force),
            bores.pin_elasticity(material)?,
        )?],
        tolerances: ContactTolerances::default(),
    })?;
    let problem = BucklingProblem {
        mesh,
        material: *material,
        fixed_dofs: case.fixed_dofs,
        load: contact.contact_forces[0].clone(),
        quadrature,
    };
    solve_on(&problem, options, system)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::mesh::structured::{TwoEyePlate, two_eye_plate};
    use crate::rod::solve::{RodOptions, solve_rod_fields};

    /// The factorised K of stage 3's static cases is the buckling case's K (the same supports):
    /// reusing it gives the same load factor to the bit; a system with other supports is refused.
    #[test]
    fn reusing_stage_3_s_factor_gives_the_same_load_factor() {
        let mesh = two_eye_plate(&TwoEyePlate::default()).unwrap();
        let (material, bores) = (Material::STEEL, BoreSpec::default());
        let kept = solve_rod_fields(
            &mesh,
            &material,
            &bores,
            1000.0,
            &RodOptions {
                keep_system: true,
                ..RodOptions::default()
            },
        )
        .unwrap();
        let system = kept.system.expect("kept");
        let options = BucklingOptions::default();
        let q = QuadratureChoice::Auto;
        let fresh = rod_buckling(&mesh, &material, &bores, 5000.0, q, &options, None).unwrap();
        let reused =
            rod_buckling(&mesh, &material, &bores, 5000.0, q, &options, Some(&system)).unwrap();
        assert_eq!(fresh.load_factor, reused.load_factor);
        assert_eq!(fresh.mode, reused.mode);
        assert!(fresh.load_factor > 0.0);
        // without keep_system nothing is kept
        let plain =
            solve_rod_fields(&mesh, &material, &bores, 1000.0, &RodOptions::default()).unwrap();
        assert!(plain.system.is_none());
        // other supports: the problem's DofMap differs from the system's
        let case = rod_fx_case(&mesh, &bores, 5000.0).unwrap();
        let problem = BucklingProblem {
            mesh: &mesh,
            material,
            fixed_dofs: case.fixed_dofs[..case.fixed_dofs.len() - 3].to_vec(),
            load: case.load,
            quadrature: q,
        };
        let err = solve_buckling_with(&problem, &system, &options).unwrap_err();
        assert!(err.to_string().contains("other supports"), "{err}");
    }

    /// A rigid pin without clearance presses its bore nearly as the cosine pressure does (its arc
    /// 80° either side, its peak 4.5 % below: docs/contact.md); a thin plate's buckling factor,
    /// which depends on how the eye is pressed (the uniform traction also pulls on the far half
    /// of the eye: 24 % lower here), is then the cosine's within a few per cent.
    #[test]
    fn a_zero_clearance_pin_buckles_a_thin_plate_as_the_cosine_pressure_does() {
        let p = TwoEyePlate {
            thickness: 0.004,
            n_z: 2,
            curved: true,
            ..TwoEyePlate::default()
        };
        let mesh = two_eye_plate(&p).unwrap();
        let material = Material::STEEL;
        let spec = |bore_load| BoreSpec {
            fixed_centre_m: [p.length, 0.0, 0.0],
            bore_load,
            clearance_a_m: Some(0.0),
            clearance_b_m: Some(0.0),
            ..BoreSpec::default()
        };
        let (q, options) = (QuadratureChoice::Auto, BucklingOptions::default());
        let f = 1e3;
        let contact = rod_buckling_contact(
            &mesh,
            &material,
            &spec(crate::rod::pin_load::BoreLoad::Contact),
            f,
            q,
            &options,
            None,
        )
        .unwrap()
        .load_factor;
        let factor = |b| {
            rod_buckling(&mesh, &material, &spec(b), f, q, &options, None)
                .unwrap()
                .load_factor
        };
        let cosine = factor(crate::rod::pin_load::BoreLoad::Cosine);
        let uniform = factor(crate::rod::pin_load::BoreLoad::Uniform);
        eprintln!("λ₁: contact {contact:.4}, cosine {cosine:.4}, uniform {uniform:.4}");
        assert!((contact / cosine - 1.0).abs() < 0.03, "{contact} {cosine}");
        assert!(uniform < 0.9 * cosine, "{uniform} {cosine}");
    }
}
