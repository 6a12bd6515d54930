//! Consistent nodal forces of a surface traction on 6-node faces: f_a = ∫ N_a t dA, integrated with
//! the degree-4 triangle rule on the (possibly curved) face (Zienkiewicz & Taylor, 7th ed., §6.6;
//! for a straight face and a uniform traction this gives 0 at the corners and 1/3 of the face load at
//! each midside node).

use super::boundary::{face_coords, face_point, norm};
use super::error::{FemError, Result};
use super::mesh::TetMesh;
use super::quadrature::TRI6;

/// A uniform traction over a set of faces and its consistent nodal forces.
#[derive(Clone, Debug)]
pub struct SurfaceLoad {
    /// Nodal forces, 3 per node (N), global DOF order.
    pub forces: Vec<f64>,
    /// Loaded area (same quadrature as the forces), m².
    pub area_m2: f64,
    /// The traction, Pa.
    pub traction_pa: [f64; 3],
    /// Sum of the nodal forces, N.
    pub resultant_n: [f64; 3],
    /// |resultant − requested| / |requested|.
    pub resultant_error_rel: f64,
}

/// Consistent nodal forces (3 per node) of the constant traction `traction` (Pa) on `faces`.
pub fn traction_forces(mesh: &TetMesh, faces: &[[usize; 6]], traction: [f64; 3]) -> Vec<f64> {
    let mut f = vec![0.0; mesh.n_dofs()];
    for face in faces {
        let x = face_coords(mesh, face);
        for (p, w) in TRI6.points.iter().zip(TRI6.weights) {
            let (_, c, n) = face_point(&x, *p);
            let da = w * norm(c);
            for a in 0..6 {
                for j in 0..3 {
                    f[3 * face[a] + j] += n[a] * da * traction[j];
                }
            }
        }
    }
    f
}

/// Area of `faces` with the load quadrature.
pub fn faces_area(mesh: &TetMesh, faces: &[[usize; 6]]) -> f64 {
    faces
        .iter()
        .map(|f| super::boundary::face_area(&face_coords(mesh, f), &TRI6))
        .sum()
}

/// The uniform traction over `faces` whose resultant is `resultant` (N), as consistent nodal forces.
/// The resultant of the nodal forces is checked against `resultant` to round-off (1e-10 relative).
pub fn uniform_traction_with_resultant(
    mesh: &TetMesh,
    faces: &[[usize; 6]],
    resultant: [f64; 3],
) -> Result<SurfaceLoad> {
    let area_m2 = faces_area(mesh, faces);
    if area_m2.is_nan() || area_m2 <= 0.0 {
        return Err(FemError::InvalidInput(
            "the loaded surface has no area".into(),
        ));
    }
    let traction_pa = resultant.map(|v| v / area_m2);
    let forces = traction_forces(mesh, faces, traction_pa);
    let mut sum = [0.0; 3];
    for (i, v) in forces.iter().enumerate() {
        sum[i % 3] += v;
    }
    let fmag = norm(resultant);
    let err = norm([
        sum[0] - resultant[0],
        sum[1] - resultant[1],
        sum[2] - resultant[2],
    ]);
    let rel = if fmag > 0.0 { err / fmag } else { err };
    if rel > 1e-10 {
        return Err(FemError::Check(format!(
            "nodal forces sum to {sum:?} N, requested {resultant:?} N (relative error {rel:.2e})"
        )));
    }
    Ok(SurfaceLoad {
        forces,
        area_m2,
        traction_pa,
        resultant_n: sum,
        resultant_error_rel: rel,
    })
}
