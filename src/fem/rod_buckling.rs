//! Linear buckling of the rod (issue 20): the F_x case of stage 3 ([`super::rod::rod_fx_case`]:
//! bore B fixed, the pin force on bore A towards B, a compression) handed to the general
//! eigen-solver of [`super::buckling`].

use super::bores::BoreSpec;
use super::buckling::{BucklingOptions, BucklingProblem, BucklingSolution, solve_buckling};
use super::element::QuadratureChoice;
use super::error::Result;
use super::material::Material;
use super::mesh::TetMesh;
use super::rod::rod_fx_case;

/// Linear buckling of a rod under the compressive F_x case of stage 3 ([`rod_fx_case`]): bore B
/// fixed, bore A loaded by a uniform traction of resultant `compression_n` along A→B (towards the
/// fixed bore: compression). λ₁ · `compression_n` is the linear buckling load.
pub fn rod_buckling(
    mesh: &TetMesh,
    material: &Material,
    bores: &BoreSpec,
    compression_n: f64,
    quadrature: QuadratureChoice,
    options: &BucklingOptions,
) -> Result<BucklingSolution> {
    let case = rod_fx_case(mesh, bores, compression_n)?;
    solve_buckling(
        &BucklingProblem {
            mesh,
            material: *material,
            fixed_dofs: case.fixed_dofs,
            load: case.load,
            quadrature,
        },
        options,
    )
}
