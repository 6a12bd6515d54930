//! Boundary faces derived from the tetrahedra (a face used by exactly one tet), as 6-node triangles
//! oriented with outward normals. The surface triangles of the input file are not used.

use std::collections::HashMap;

use super::error::{FemError, Result};
use super::mesh::TetMesh;
use super::quadrature::TriRule;
use super::shape::{TET10_FACES, tri6_grad, tri6_shape};

/// A boundary face: corners c0 c1 c2 then midside nodes of c0c1, c1c2, c2c0 (global node indices),
/// ordered so that (c1 − c0) × (c2 − c0) points out of the body.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoundaryFace {
    /// Element the face belongs to.
    pub element: usize,
    /// Local face number (see [`TET10_FACES`]).
    pub local_face: usize,
    /// Global node indices.
    pub nodes: [usize; 6],
}

/// All boundary faces, in element order. A face shared by more than two tets is an error.
pub fn boundary_faces(mesh: &TetMesh) -> Result<Vec<BoundaryFace>> {
    let mut count: HashMap<[usize; 3], u32> = HashMap::with_capacity(2 * mesh.n_elements());
    let key = |el: &[usize; 10], f: &[usize; 6]| {
        let mut k = [el[f[0]], el[f[1]], el[f[2]]];
        k.sort_unstable();
        k
    };
    for el in mesh.elements() {
        for f in &TET10_FACES {
            *count.entry(key(el, f)).or_insert(0) += 1;
        }
    }
    if let Some((k, c)) = count
        .iter()
        .filter(|(_, c)| **c > 2)
        .min_by_key(|(k, _)| **k)
    {
        return Err(FemError::NonManifold {
            corners: *k,
            count: *c as usize,
        });
    }
    let mut out = Vec::new();
    for (e, el) in mesh.elements().iter().enumerate() {
        for (lf, f) in TET10_FACES.iter().enumerate() {
            if count[&key(el, f)] == 1 {
                out.push(BoundaryFace {
                    element: e,
                    local_face: lf,
                    nodes: std::array::from_fn(|a| el[f[a]]),
                });
            }
        }
    }
    Ok(out)
}

/// Coordinates of a face's six nodes.
pub fn face_coords(mesh: &TetMesh, face: &[usize; 6]) -> [[f64; 3]; 6] {
    std::array::from_fn(|a| mesh.nodes()[face[a]])
}

/// Position, tangents' cross product (∂x/∂s × ∂x/∂t: outward normal times the area density, twice
/// the area for a straight face) and shape functions of a 6-node face at (s, t).
pub fn face_point(x: &[[f64; 3]; 6], st: [f64; 2]) -> ([f64; 3], [f64; 3], [f64; 6]) {
    let n = tri6_shape(st);
    let g = tri6_grad(st);
    let mut p = [0.0; 3];
    let mut ts = [0.0; 3];
    let mut tt = [0.0; 3];
    for a in 0..6 {
        for j in 0..3 {
            p[j] += n[a] * x[a][j];
            ts[j] += g[a][0] * x[a][j];
            tt[j] += g[a][1] * x[a][j];
        }
    }
    (p, cross(ts, tt), n)
}

/// Unit outward normal at the face centroid (s = t = 1/3).
pub fn face_normal(x: &[[f64; 3]; 6]) -> [f64; 3] {
    let (_, c, _) = face_point(x, [1.0 / 3.0, 1.0 / 3.0]);
    let l = norm(c);
    [c[0] / l, c[1] / l, c[2] / l]
}

/// Face area with `rule`.
pub fn face_area(x: &[[f64; 3]; 6], rule: &TriRule) -> f64 {
    rule.points
        .iter()
        .zip(rule.weights)
        .map(|(p, w)| w * norm(face_point(x, *p).1))
        .sum()
}

pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
