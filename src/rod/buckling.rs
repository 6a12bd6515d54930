//! Linear buckling of the rod: the F_x case of stage 3 ([`super::solve::rod_fx_case`]:
//! bore B fixed, the pin force on bore A towards B, a compression) handed to the general
//! eigen-solver of [`crate::fem::buckling`].

use super::bores::BoreSpec;
use super::solve::rod_fx_case;
use crate::fem::buckling::{
    BucklingOptions, BucklingProblem, BucklingSolution, solve_buckling, solve_buckling_with,
};
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
    match system {
        Some(system) => solve_buckling_with(&problem, system, options),
        None => solve_buckling(&problem, options),
    }
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
}
