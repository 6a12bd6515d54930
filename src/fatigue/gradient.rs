//! The related stress gradient χ* at the surface nodes of a tet10 mesh, from a nodal stress field.
//!
//! FKM defines it for the local approach as the slope of the stress under the surface, related to
//! the surface value (FKM guideline, 6th ed. 2012, §4.3.1.3, eq. 4.3.9):
//!
//!   χ* = −(1/σ(0)) · dσ/dd |_{d=0},
//!
//! d the depth along the inward normal, σ the stress component assessed (for a direction e in the
//! surface, σ = e · σ · e; for shear the corresponding component). A notch root has χ* > 0.
//!
//! **How, on tet10.** The nodal stress field (best the recovered σ* of
//! [`crate::fem::recovery`]; the nodal average also works) is interpolated inside each element
//! with its quadratic shape functions. From a surface node x_n with outward unit normal n the
//! field is sampled at the K points x_n − d_k n, d_k = k D / K (k = 1..K, K = 6 by default), each
//! located in the mesh (searched in the node's elements and up to three rings of neighbours; the
//! natural coordinates by Newton on the isoparametric map, exact in one step on straight elements).
//! Each of the six components is fitted by a least-squares cubic in d over the samples, and the
//! fit's value and slope at d = 0 are the surface stress and its normal derivative. The surface
//! node's own value is left out of the fit: it is the one-sided extrapolation of the recovery, the
//! least accurate value of the field, and with it in the fit its error over the short lever D
//! dominates the slope (measured on the Kirsch hole: +3.7 % with a quadratic through the surface
//! value at D = 1.5 element lengths, growing as the mesh is refined). The cubic keeps the
//! truncation error small at that depth (−0.2 % for Kirsch's profile at D = a/12, −1.2 % at a/6).
//! The default depth D is two mean edge lengths of the node's elements
//! ([`SampleDepth::ElementLengths`]); a fixed depth in metres can be set instead (OptiStruct and
//! HyperLife take a 1 mm finite difference, whose error at a sharp notch is larger).
//!
//! The derivative of the whole tensor is returned ([`DepthGradient`]), per field: the fields of
//! the unit load cases of a linear model can be combined over the cycle like the stresses, and χ*
//! taken for any direction afterwards ([`DepthGradient::chi_star`]). Where the inward normal leaves
//! the body before the samples can be fitted (a thin wall, a sharp convex edge), the point gets
//! `None`: no support credited (n = 1) is the conservative reading.
//!
//! **Surface normals** ([`surface_points`]): the area-weighted mean of the outward normals of the
//! boundary faces around a node. At a sharp edge that mean points between the faces; such nodes
//! are rarely notch roots, and a caller that knows a better normal can pass its own.

use nalgebra::{DMatrix, Matrix3, Vector3};
use rayon::prelude::*;

use super::tensor::{axpy, dot, norm, quadratic_form, unit};
use crate::fem::boundary::{boundary_faces, face_coords, face_point};
use crate::fem::error::Result;
use crate::fem::mesh::TetMesh;
use crate::fem::recovery::node_elements;
use crate::fem::shape::{TET10_EDGES, tet10_grad, tet10_shape};

/// A surface node and its outward unit normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// Node index.
    pub node: usize,
    /// Outward unit normal.
    pub outward_normal: [f64; 3],
}

/// Every node on the boundary of `mesh` (corners and midside nodes), with the area-weighted mean
/// outward normal of the faces around it, in node order.
pub fn surface_points(mesh: &TetMesh) -> Result<Vec<SurfacePoint>> {
    let mut acc = vec![[0.0; 3]; mesh.n_nodes()];
    let mut on = vec![false; mesh.n_nodes()];
    for f in boundary_faces(mesh)? {
        let x = face_coords(mesh, &f.nodes);
        // ∂x/∂s × ∂x/∂t at the centroid: the outward normal times twice the area (straight face)
        let (_, c, _) = face_point(&x, [1.0 / 3.0, 1.0 / 3.0]);
        for &n in &f.nodes {
            on[n] = true;
            for j in 0..3 {
                acc[n][j] += c[j];
            }
        }
    }
    Ok((0..mesh.n_nodes())
        .filter(|&n| on[n])
        .map(|n| SurfacePoint {
            node: n,
            outward_normal: unit(acc[n]),
        })
        .collect())
}

/// How deep under the surface the field is sampled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SampleDepth {
    /// This many mean edge lengths of the node's elements.
    ElementLengths(f64),
    /// A fixed depth, m.
    Metres(f64),
}

/// Options of [`depth_gradients`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GradientOptions {
    /// The deepest sample.
    pub depth: SampleDepth,
    /// Samples K under the surface (at least 3; a cubic fit needs 4, with 3 a quadratic is used).
    pub intervals: usize,
}

impl Default for GradientOptions {
    /// Two element lengths deep, 6 samples.
    fn default() -> Self {
        GradientOptions {
            depth: SampleDepth::ElementLengths(2.0),
            intervals: 6,
        }
    }
}

/// The stress of one field at a surface node and its derivative with depth, Pa and Pa/m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthGradient {
    /// σ at the surface: the fit's value at d = 0 (close to the nodal value).
    pub stress: [f64; 6],
    /// dσ/dd at the surface, d the depth along the inward normal.
    pub d_stress_d_depth: [f64; 6],
}

impl DepthGradient {
    /// χ* of the normal stress in unit direction `e`: −(e·dσ/dd·e)/(e·σ·e), 1/m (0 where that
    /// stress is zero).
    pub fn chi_star(&self, e: [f64; 3]) -> f64 {
        let s = quadratic_form(&self.stress, e, e);
        if s == 0.0 {
            return 0.0;
        }
        -quadratic_form(&self.d_stress_d_depth, e, e) / s
    }

    /// The gradient of the combination Σ f_k · (field k): linear in the fields.
    pub fn combine(parts: &[(f64, &DepthGradient)]) -> DepthGradient {
        let mut out = DepthGradient {
            stress: [0.0; 6],
            d_stress_d_depth: [0.0; 6],
        };
        for (f, g) in parts {
            out.stress = axpy(&out.stress, *f, &g.stress);
            out.d_stress_d_depth = axpy(&out.d_stress_d_depth, *f, &g.d_stress_d_depth);
        }
        out
    }
}

/// The gradients of every field at one surface point.
#[derive(Clone, Debug, PartialEq)]
pub struct PointGradients {
    /// Depth of the deepest sample used, m.
    pub depth_m: f64,
    /// Samples fitted.
    pub samples: usize,
    /// One per field, in the order given.
    pub fields: Vec<DepthGradient>,
}

/// The depth gradients of the nodal stress `fields` (each one `[f64; 6]` per node, Pa) at
/// `points` (see the module documentation); `None` where fewer than three samples lie in the
/// body.
pub fn depth_gradients(
    mesh: &TetMesh,
    fields: &[&[[f64; 6]]],
    points: &[SurfacePoint],
    options: &GradientOptions,
) -> Vec<Option<PointGradients>> {
    let elems_of = node_elements(mesh);
    let neighbours = face_neighbours(mesh);
    let k = options.intervals.max(3);
    points
        .par_iter()
        .map(|p| {
            let ring0: Vec<usize> = elems_of[p.node].iter().map(|&e| e as usize).collect();
            let depth = match options.depth {
                SampleDepth::Metres(d) => d,
                SampleDepth::ElementLengths(f) => f * mean_edge(mesh, &ring0),
            };
            let x0 = mesh.nodes()[p.node];
            let n = p.outward_normal;
            let mut rings = vec![ring0];
            let mut ds = Vec::with_capacity(k);
            let mut values: Vec<Vec<[f64; 6]>> = vec![Vec::with_capacity(k); fields.len()];
            let mut last: Option<usize> = None;
            for i in 1..=k {
                let d = depth * i as f64 / k as f64;
                let x = std::array::from_fn(|j| x0[j] - d * n[j]);
                // from the previous sample a walk that leaves the mesh has crossed the wall
                // between the two: the point is outside, no ring search
                let start = last.unwrap_or(rings[0][0]);
                let found = match walk(mesh, &neighbours, start, x) {
                    Walk::Found(e, xi) => Some((e, xi)),
                    Walk::Left if last.is_some() => None,
                    _ => locate(mesh, &elems_of, &mut rings, last, x),
                };
                let Some((e, xi)) = found else {
                    break;
                };
                last = Some(e);
                let sh = tet10_shape(xi);
                let el = &mesh.elements()[e];
                for (f, v) in fields.iter().zip(values.iter_mut()) {
                    let mut s = [0.0; 6];
                    for a in 0..10 {
                        s = axpy(&s, sh[a], &f[el[a]]);
                    }
                    v.push(s);
                }
                ds.push(d);
            }
            if ds.len() < 3 {
                return None;
            }
            let dmax = *ds.last().expect("samples");
            let degree = if ds.len() >= 4 { 3 } else { 2 };
            let (w0, w1) = fit_weights(&ds, dmax, degree);
            let apply = |v: &[[f64; 6]], w: &[f64]| -> [f64; 6] {
                std::array::from_fn(|c| v.iter().zip(w).map(|(s, w)| w * s[c]).sum())
            };
            Some(PointGradients {
                depth_m: dmax,
                samples: ds.len(),
                fields: values
                    .iter()
                    .map(|v| DepthGradient {
                        stress: apply(v, &w0),
                        d_stress_d_depth: apply(v, &w1),
                    })
                    .collect(),
            })
        })
        .collect()
}

/// Weights (w0, w1) with Σ w0_k v_k and Σ w1_k v_k the value and the slope at d = 0 of the
/// least-squares polynomial of `degree` through (d_k, v_k); computed on d/`scale` for conditioning.
fn fit_weights(ds: &[f64], scale: f64, degree: usize) -> (Vec<f64>, Vec<f64>) {
    let m = degree + 1;
    let v = DMatrix::from_fn(ds.len(), m, |i, j| (ds[i] / scale).powi(j as i32));
    let normal = v.transpose() * &v;
    let inv = normal.try_inverse().expect("distinct depths");
    // coefficients c = (VᵀV)⁻¹ Vᵀ y: the rows 0 and 1 of (VᵀV)⁻¹ Vᵀ are the weights
    let p = inv * v.transpose();
    let w0 = (0..ds.len()).map(|k| p[(0, k)]).collect();
    let w1 = (0..ds.len()).map(|k| p[(1, k)] / scale).collect();
    (w0, w1)
}

/// Mean corner-edge length of `elems`.
fn mean_edge(mesh: &TetMesh, elems: &[usize]) -> f64 {
    let mut sum = 0.0;
    let mut count = 0usize;
    for &e in elems {
        let el = &mesh.elements()[e];
        for [a, b] in TET10_EDGES {
            let (p, q) = (mesh.nodes()[el[a]], mesh.nodes()[el[b]]);
            sum += norm(std::array::from_fn(|j| p[j] - q[j]));
            count += 1;
        }
    }
    sum / count as f64
}

/// Per element, the element across the face opposite each corner (`NO_NEIGHBOUR` on the boundary).
fn face_neighbours(mesh: &TetMesh) -> Vec<[u32; 4]> {
    let mut out = vec![[NO_NEIGHBOUR; 4]; mesh.n_elements()];
    let mut open: std::collections::HashMap<[usize; 3], (u32, usize)> =
        std::collections::HashMap::with_capacity(2 * mesh.n_elements());
    for (e, el) in mesh.elements().iter().enumerate() {
        for i in 0..4 {
            let mut f = [el[(i + 1) % 4], el[(i + 2) % 4], el[(i + 3) % 4]];
            f.sort_unstable();
            match open.remove(&f) {
                Some((o, j)) => {
                    out[e][i] = o;
                    out[o as usize][j] = e as u32;
                }
                None => {
                    open.insert(f, (e as u32, i));
                }
            }
        }
    }
    out
}

const NO_NEIGHBOUR: u32 = u32::MAX;

/// The element containing `x` by a walk through face neighbours from `start` (towards the face of
/// the most negative volume coordinate of the corner tetrahedron), and its natural coordinates.
/// The walk may leave the mesh ([`Walk::Left`]) or not settle; from an element next to `x` (the
/// previous sample's, a fraction of an element length away) leaving means `x` is outside, from
/// farther away the ring search of [`locate`] decides (a walk can leave a non-convex body on its
/// way to a point inside).
fn walk(mesh: &TetMesh, neighbours: &[[u32; 4]], start: usize, x: [f64; 3]) -> Walk {
    let mut e = start;
    for _ in 0..64 {
        let c = mesh.element_coords(e);
        let jac = Matrix3::from_fn(|i, k| c[k + 1][i] - c[0][i]);
        let r = Vector3::new(x[0] - c[0][0], x[1] - c[0][1], x[2] - c[0][2]);
        let Some(inv) = jac.try_inverse() else {
            return Walk::Unsettled;
        };
        let xi = inv * r;
        let l = [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]];
        let (i, lmin) =
            l.iter().enumerate().fold(
                (0, f64::INFINITY),
                |b, (i, &v)| if v < b.1 { (i, v) } else { b },
            );
        if lmin >= -1e-9 {
            return match natural_coords(mesh, e, x) {
                Some(xi) => Walk::Found(e, xi),
                None => Walk::Unsettled,
            };
        }
        let next = neighbours[e][i];
        if next == NO_NEIGHBOUR {
            return Walk::Left;
        }
        e = next as usize;
    }
    Walk::Unsettled
}

/// Where a [`walk`] ended.
enum Walk {
    /// In this element, at these natural coordinates.
    Found(usize, [f64; 3]),
    /// Through a boundary face.
    Left,
    /// Nowhere decided (a curved element, a degenerate one, too many steps).
    Unsettled,
}

/// The element of the search rings (grown on demand, up to four) containing `x`, and its natural
/// coordinates; `hint` first.
fn locate(
    mesh: &TetMesh,
    elems_of: &[Vec<u32>],
    rings: &mut Vec<Vec<usize>>,
    hint: Option<usize>,
    x: [f64; 3],
) -> Option<(usize, [f64; 3])> {
    if let Some(e) = hint
        && let Some(xi) = natural_coords(mesh, e, x)
    {
        return Some((e, xi));
    }
    let mut level = 0;
    loop {
        if level == rings.len() {
            if rings.len() == 4 {
                return None;
            }
            let mut seen: Vec<usize> = rings.iter().flatten().copied().collect();
            seen.sort_unstable();
            let mut next: Vec<usize> = rings[level - 1]
                .iter()
                .flat_map(|&e| mesh.elements()[e][..4].iter())
                .flat_map(|&m| elems_of[m].iter().map(|&e| e as usize))
                .filter(|e| seen.binary_search(e).is_err())
                .collect();
            next.sort_unstable();
            next.dedup();
            if next.is_empty() {
                return None;
            }
            rings.push(next);
        }
        for &e in &rings[level] {
            if let Some(xi) = natural_coords(mesh, e, x) {
                return Some((e, xi));
            }
        }
        level += 1;
    }
}

/// Natural coordinates of `x` in element `e` when it lies inside (volume coordinates ≥ −1e-9).
fn natural_coords(mesh: &TetMesh, e: usize, x: [f64; 3]) -> Option<[f64; 3]> {
    let c = mesh.element_coords(e);
    // quick reject on the corner tetrahedron's bounding box, widened by a tenth for curved sides
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &c {
        for j in 0..3 {
            lo[j] = lo[j].min(p[j]);
            hi[j] = hi[j].max(p[j]);
        }
    }
    let pad = 0.1 * (0..3).map(|j| hi[j] - lo[j]).fold(0.0, f64::max);
    if (0..3).any(|j| x[j] < lo[j] - pad || x[j] > hi[j] + pad) {
        return None;
    }
    // a straight element (midside nodes at the edge midpoints): the isoparametric map is the
    // corner tetrahedron's affine map, inverted directly
    let scale = pad * 10.0;
    let straight = TET10_EDGES.iter().enumerate().all(|(m, [a, b])| {
        (0..3).all(|j| (c[4 + m][j] - 0.5 * (c[*a][j] + c[*b][j])).abs() <= 1e-12 * scale)
    });
    if straight {
        let jac = Matrix3::from_fn(|i, k| c[k + 1][i] - c[0][i]);
        let r = Vector3::new(x[0] - c[0][0], x[1] - c[0][1], x[2] - c[0][2]);
        let xi = jac.try_inverse()? * r;
        let l = [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]];
        return l
            .iter()
            .all(|&v| v >= -1e-9)
            .then_some([xi[0], xi[1], xi[2]]);
    }
    let mut xi = [0.25; 3];
    for _ in 0..25 {
        let n = tet10_shape(xi);
        let g = tet10_grad(xi);
        let mut r = [0.0; 3];
        let mut jac = Matrix3::zeros();
        for a in 0..10 {
            for i in 0..3 {
                r[i] += n[a] * c[a][i];
                for k in 0..3 {
                    jac[(i, k)] += c[a][i] * g[a][k];
                }
            }
        }
        let res = Vector3::new(x[0] - r[0], x[1] - r[1], x[2] - r[2]);
        let step = jac.try_inverse()? * res;
        for k in 0..3 {
            xi[k] += step[k];
        }
        if step.norm() < 1e-13 {
            break;
        }
    }
    let l = [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]];
    l.iter().all(|&v| v >= -1e-9).then_some(xi)
}

/// The unit vector in the surface (orthogonal to `n`) closest to `e`.
pub fn in_surface(e: [f64; 3], n: [f64; 3]) -> [f64; 3] {
    let f = dot(e, n);
    unit(std::array::from_fn(|j| e[j] - f * n[j]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::mesh::structured::box_tet10;

    #[test]
    fn cubic_fit_is_exact_on_cubics() {
        let ds = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0].map(|d| d * 1e-3);
        let (w0, w1) = fit_weights(&ds, 6e-3, 3);
        let v: Vec<f64> = ds
            .iter()
            .map(|d| 3.0 - 5.0 * d + 7.0 * d * d - 400.0 * d * d * d)
            .collect();
        let a: f64 = w0.iter().zip(&v).map(|(w, v)| w * v).sum();
        let b: f64 = w1.iter().zip(&v).map(|(w, v)| w * v).sum();
        // b carries the round-off of 3 over a lever of 6 mm: 1e-6 relative
        assert!((a - 3.0).abs() < 1e-12 && (b + 5.0).abs() < 5e-6, "{a} {b}");
    }

    #[test]
    fn linear_field_in_a_box_has_its_exact_gradient() {
        // σ_xx = s0 (1 − χ z') with z' the depth under the top face z = lz: χ* = χ exactly
        let (lx, lz) = (0.02, 0.01);
        let mesh = box_tet10(lx, lx, lz, 4, 4, 3).unwrap();
        let (s0, chi) = (100e6, 150.0);
        let field: Vec<[f64; 6]> = mesh
            .nodes()
            .iter()
            .map(|p| [s0 * (1.0 - chi * (lz - p[2])), 0.0, 0.0, 0.0, 0.0, 0.0])
            .collect();
        let pts = surface_points(&mesh).unwrap();
        let top: Vec<SurfacePoint> = pts
            .into_iter()
            .filter(|p| {
                let x = mesh.nodes()[p.node];
                (x[2] - lz).abs() < 1e-12
                    && x[0] > 1e-9
                    && x[0] < lx - 1e-9
                    && x[1] > 1e-9
                    && x[1] < lx - 1e-9
            })
            .collect();
        assert!(!top.is_empty());
        let g = depth_gradients(&mesh, &[&field], &top, &GradientOptions::default());
        for (p, g) in top.iter().zip(&g) {
            assert!((p.outward_normal[2] - 1.0).abs() < 1e-12);
            let g = g.as_ref().expect("inside");
            let c = g.fields[0].chi_star([1.0, 0.0, 0.0]);
            assert!((c - chi).abs() < 1e-6 * chi, "{c}");
        }
    }
}
