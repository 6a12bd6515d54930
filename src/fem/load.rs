//! Consistent nodal forces of a surface traction on 6-node faces: f_a = ∫ N_a t dA, integrated with
//! the degree-4 triangle rule on the (possibly curved) face (Zienkiewicz & Taylor, 7th ed., §6.6;
//! for a straight face and a uniform traction this gives 0 at the corners and 1/3 of the face load at
//! each midside node).
//!
//! A cylinder wall can also carry a bearing pressure normal to it, p(θ) = p₀ cos θ over the half
//! a pin presses on ([`cosine_pressure_with_resultant`]): on a full cylinder of radius r and length
//! L its resultant is p₀ r L π/2 (∫ cos²θ dθ over the half). On a mesh the amplitude is solved
//! for so that the resultant of the consistent nodal forces equals F to round-off (below).

use super::boundary::{cross, dot, face_coords, face_point, norm};
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

/// The cosine bearing pressure over `faces` (a bore wall around the axis through `centre` with
/// unit direction `axis`) whose resultant is `resultant` (N, perpendicular to the axis).
///
/// At a point x of the wall let e_r be the unit radial direction from the axis, d̂ = F/|F| and
/// ê = â × d̂; c = e_r · d̂ = cos θ, s = e_r · ê = sin θ. The traction on the body is the pressure
/// pushing the wall outward, t = p e_r, with
///
/// p = α c + β c s for c > 0, p = 0 elsewhere,
///
/// the cosine (α) and a small skew term (β) that the two in-plane components of the resultant of
/// the consistent nodal forces fix exactly: the 2 × 2 system
/// [R₁·d̂ R₂·d̂; R₁·ê R₂·ê] (α, β)ᵀ = (|F|, 0)ᵀ, with R₁, R₂ the resultants of the two shapes.
/// On a symmetric wall β = 0; a mesh's asymmetry makes it small. The axial component vanishes
/// because e_r ⊥ axis. Refused: a force along the axis, no wall on the pressed half (a partial
/// bore whose missing side the pin would press on), or |β| ≥ α (the pressure would turn tensile
/// somewhere on the half). The resultant is checked to 1e-12 relative.
pub fn cosine_pressure_with_resultant(
    mesh: &TetMesh,
    faces: &[[usize; 6]],
    centre: [f64; 3],
    axis: [f64; 3],
    resultant: [f64; 3],
) -> Result<SurfaceLoad> {
    let fmag = norm(resultant);
    let along = dot(resultant, axis);
    if !(fmag.is_finite() && fmag > 0.0) || along.abs() > 1e-9 * fmag {
        return Err(FemError::InvalidInput(format!(
            "a cosine bore load needs a force perpendicular to the pin axis, got {resultant:?} N"
        )));
    }
    let d = resultant.map(|v| v / fmag);
    let e = cross(axis, d);
    // the two shapes' nodal forces in one pass
    let (mut f1, mut f2) = (vec![0.0; mesh.n_dofs()], vec![0.0; mesh.n_dofs()]);
    let mut pressed_area = 0.0;
    for face in faces {
        let x = face_coords(mesh, face);
        for (p, w) in TRI6.points.iter().zip(TRI6.weights) {
            let (xp, jac, n) = face_point(&x, *p);
            let v = std::array::from_fn::<f64, 3, _>(|j| xp[j] - centre[j]);
            let a = dot(v, axis);
            let r = std::array::from_fn::<f64, 3, _>(|j| v[j] - a * axis[j]);
            let rl = norm(r);
            if rl == 0.0 {
                continue;
            }
            let er = r.map(|c| c / rl);
            let (c, s) = (dot(er, d), dot(er, e));
            if c <= 0.0 {
                continue;
            }
            let da = w * norm(jac);
            pressed_area += da;
            for k in 0..6 {
                for j in 0..3 {
                    let base = n[k] * da * c * er[j];
                    f1[3 * face[k] + j] += base;
                    f2[3 * face[k] + j] += base * s;
                }
            }
        }
    }
    let sum = |f: &[f64]| {
        let mut r = [0.0; 3];
        for (i, v) in f.iter().enumerate() {
            r[i % 3] += v;
        }
        r
    };
    let (r1, r2) = (sum(&f1), sum(&f2));
    let (a11, a12, a21, a22) = (dot(r1, d), dot(r2, d), dot(r1, e), dot(r2, e));
    let det = a11 * a22 - a12 * a21;
    let pressed = pressed_area > 0.0;
    let solvable = det.abs() > 1e-12 * a11.abs() * a22.abs().max(f64::MIN_POSITIVE);
    if !pressed || !solvable {
        return Err(FemError::InvalidInput(format!(
            "no bore wall on the half the pin presses on (force direction {d:?}): a partial bore \
             open on that side cannot carry a cosine bearing pressure; use bore_load = \"uniform\""
        )));
    }
    let alpha = fmag * a22 / det;
    let beta = -fmag * a21 / det;
    if !(alpha > 0.0 && beta.abs() < alpha) {
        return Err(FemError::InvalidInput(format!(
            "the cosine bearing pressure for the pin force along {d:.3?} would turn tensile (α \
             {alpha:.3e}, β {beta:.3e}): the bore wall is too far from a half cylinder on the \
             pressed side (a partial bore, e.g. a big end without its cap, open there); use \
             bore_load = \"uniform\""
        )));
    }
    let forces: Vec<f64> = f1
        .iter()
        .zip(&f2)
        .map(|(a, b)| alpha * a + beta * b)
        .collect();
    let got = sum(&forces);
    let err = norm([
        got[0] - resultant[0],
        got[1] - resultant[1],
        got[2] - resultant[2],
    ]);
    let rel = err / fmag;
    if rel > 1e-12 {
        return Err(FemError::Check(format!(
            "cosine bearing pressure: nodal forces sum to {got:?} N, requested {resultant:?} N \
             (relative error {rel:.2e})"
        )));
    }
    Ok(SurfaceLoad {
        forces,
        area_m2: pressed_area,
        // the peak pressure (at θ = 0) along d̂
        traction_pa: d.map(|v| v * alpha),
        resultant_n: got,
        resultant_error_rel: rel,
    })
}
