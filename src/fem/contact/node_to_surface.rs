//! Frictionless small-sliding contact between two deformable surfaces of 6-node faces (or a
//! deformable surface and one whose nodes are held): the contact rows, their compliance and the
//! complementarity problem.
//!
//! **Gap.** Every integration point x_q of the slave faces is projected once, in the undeformed
//! geometry, on the master surface: the closest point x_p = Σ_i N_i(s, t) x_i of the nearest
//! master face, with the face's outward unit normal n there. Its gap, linear in the
//! displacements (small sliding: the pairing and n frozen), is
//!
//! g = n·(x_q − x_p) + n·(Σ_a N_a(q) u_a − Σ_i N_i u_i),
//!
//! positive when open. **Pressure.** As for the pins ([`super::weights`]): a pressure λ_b per
//! slave node, interpolated piecewise linearly on the four sub-triangles of each slave face
//! (ψ_b, Puso & Laursen's pressure space for quadratic faces), the weighted gap
//! G_b = ∫ ψ_b g dA integrated on the slave faces, and the nodal forces f = Bᵀ λ, the virtual work ∫ p n·(δu_s − δu_m) dA
//! of the pressure p = Σ λ_b ψ_b, B the rows of G: a uniform pressure gives the consistent nodal
//! forces on both sides (to the integration of the master's shape functions across its face
//! edges). A point whose projection falls outside the master surface carries no gap.
//!
//! **Laws** (the CalculiX manual, ccx 2.20, "*SURFACE BEHAVIOR"): *hard* contact λ_b ≥ 0,
//! G_b ≥ 0, λ_b G_b = 0; the *linear* penalty p = K · overclosure (no tension) weighted the same
//! way, λ_b = K max(0, −G_b / W_b) with W_b = ∫ ψ_b dA, which is the complementarity problem of
//! G_b + (W_b / K) λ_b ≥ 0, λ_b ≥ 0, λ_b (G_b + (W_b / K) λ_b) = 0: the hard problem with the
//! compliance W_b / K added on the diagonal.
//!
//! **Solution.** With u₀ the solution without contact and the columns u_j = K⁻¹ B_jᵀ (one solve
//! each with the factor of K, supplied by the caller), G = h + S λ with h = B u₀ + G⁰ and
//! S = B K⁻¹ Bᵀ (+ the penalty's diagonal): the linear complementarity problem of [`super::lcp`]
//! without free unknowns, solved by the primal–dual active-set method; then u = u₀ + Σ_j λ_j u_j.

use std::collections::HashMap;

use super::lcp::{MixedLcp, solve as solve_lcp};
use crate::fem::boundary::{face_point, norm};
use crate::fem::error::{FemError, Result};
use crate::fem::quadrature::TRI6;

/// One contact row: the weighted gap G_b = g0 + Σ terms · u of a slave node.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactRow {
    /// The slave node b (its index in the caller's numbering).
    pub node: usize,
    /// W_b = ∫ ψ_b dA (area).
    pub weight: f64,
    /// The weighted initial gap Σ_a D_ba n·(x_a − x_p) (area × length).
    pub g0: f64,
    /// (DOF, coefficient), 3 DOFs per node.
    pub terms: Vec<(usize, f64)>,
}

/// The contact law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Law {
    /// λ ≥ 0, G ≥ 0, λ G = 0.
    Hard,
    /// p = K · overclosure (K: pressure per length).
    Linear(f64),
}

/// The closest point of a 6-node face `x` to `p`: (s, t), the point, its distance and the
/// outward unit normal there (Newton on the squared distance, kept in the triangle).
fn project(x: &[[f64; 3]; 6], p: [f64; 3]) -> ([f64; 2], [f64; 3], f64, [f64; 3]) {
    let mut st = [1.0 / 3.0, 1.0 / 3.0];
    for _ in 0..30 {
        let (xp, _, _) = face_point(x, st);
        // tangents by central differences of the quadratic map (exact for a quadratic)
        let h = 1e-6;
        let ts: [f64; 3] = {
            let (a, _, _) = face_point(x, [st[0] + h, st[1]]);
            let (b, _, _) = face_point(x, [st[0] - h, st[1]]);
            std::array::from_fn(|j| (a[j] - b[j]) / (2.0 * h))
        };
        let tt: [f64; 3] = {
            let (a, _, _) = face_point(x, [st[0], st[1] + h]);
            let (b, _, _) = face_point(x, [st[0], st[1] - h]);
            std::array::from_fn(|j| (a[j] - b[j]) / (2.0 * h))
        };
        let d: [f64; 3] = std::array::from_fn(|j| p[j] - xp[j]);
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        // Gauss–Newton: [ts·ts ts·tt; tt·ts tt·tt] Δ = [ts·d; tt·d]
        let (a11, a12, a22) = (dot(ts, ts), dot(ts, tt), dot(tt, tt));
        let (b1, b2) = (dot(ts, d), dot(tt, d));
        let det = a11 * a22 - a12 * a12;
        if det <= 0.0 {
            break;
        }
        let ds = (a22 * b1 - a12 * b2) / det;
        let dt = (a11 * b2 - a12 * b1) / det;
        let mut next = [st[0] + ds, st[1] + dt];
        // back into the triangle
        next[0] = next[0].max(0.0);
        next[1] = next[1].max(0.0);
        let sum = next[0] + next[1];
        if sum > 1.0 {
            next = [next[0] / sum, next[1] / sum];
        }
        let step = (next[0] - st[0]).abs() + (next[1] - st[1]).abs();
        st = next;
        if step < 1e-13 {
            break;
        }
    }
    let (xp, c, _) = face_point(x, st);
    let l = norm(c);
    let n = [c[0] / l, c[1] / l, c[2] / l];
    let d = norm(std::array::from_fn(|j| p[j] - xp[j]));
    (st, xp, d, n)
}

/// The sub-triangles of a 6-node face (local nodes: corners 0–2, midside 3 = 01, 4 = 12,
/// 5 = 20) and the area coordinates of the face's nodes: the support of the hat functions ψ_b.
const SUB_TRIANGLES: [[usize; 3]; 4] = [[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]];
const NODE_ST: [[f64; 2]; 6] = [
    [0.0, 0.0],
    [1.0, 0.0],
    [0.0, 1.0],
    [0.5, 0.0],
    [0.5, 0.5],
    [0.0, 0.5],
];

/// Times each sub-triangle is split in four for the integration of the weighted gaps: the
/// master's shape functions have kinks at its face edges inside a slave face, which a rule on
/// the whole sub-triangle integrates only to its size; on 4² pieces a uniform pressure through
/// a non-matching flat pair (3 × 3 on 5 × 5 faces) gives the closed form's total force to 2e-7
/// and every nodal pressure to 1.5e-3 (`tests/deck_contact.rs`, 2026-11-29).
const SPLIT: u32 = 2;

/// The pieces of a triangle split `SPLIT` times in four: per piece its three vertices in the
/// triangle's barycentric coordinates.
static PIECES: std::sync::LazyLock<Vec<[[f64; 3]; 3]>> = std::sync::LazyLock::new(|| {
    let mut pieces = vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]];
    for _ in 0..SPLIT {
        let mut next = Vec::with_capacity(4 * pieces.len());
        for [a, b, c] in pieces {
            let mid = |u: [f64; 3], v: [f64; 3]| -> [f64; 3] {
                std::array::from_fn(|k| 0.5 * (u[k] + v[k]))
            };
            let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        pieces = next;
    }
    pieces
});

/// A point paired with the master surface: its gap, the master face's nodes, their shape values
/// at the closest point, the normal there.
type Paired = (f64, [usize; 6], [f64; 6], [f64; 3]);

/// The master surface point nearest to `p`: (gap g0 = n·(p − x_p), the master face's nodes and
/// shape values at x_p, n), or `None` when it is farther than `reach` or beside the surface's
/// rim (the offset not along the normal).
fn pair(
    x: &[[f64; 3]],
    master: &[[usize; 6]],
    boxes: &[([f64; 3], [f64; 3])],
    p: [f64; 3],
    reach: f64,
) -> Option<Paired> {
    // (distance, face, (s, t), closest point, normal)
    type Nearest = (f64, usize, [f64; 2], [f64; 3], [f64; 3]);
    let mut best: Option<Nearest> = None;
    for (k, m) in master.iter().enumerate() {
        let (lo, hi) = boxes[k];
        let out: f64 = (0..3)
            .map(|j| (lo[j] - p[j]).max(p[j] - hi[j]).max(0.0).powi(2))
            .sum::<f64>()
            .sqrt();
        if best.as_ref().is_some_and(|b| out > b.0) {
            continue;
        }
        let xm: [[f64; 3]; 6] = std::array::from_fn(|i| x[m[i]]);
        let (st, xp, d, n) = project(&xm, p);
        if best.as_ref().is_none_or(|b| d < b.0) {
            best = Some((d, k, st, xp, n));
        }
    }
    let (d, k, st, xp, n) = best?;
    let off: [f64; 3] = std::array::from_fn(|j| p[j] - xp[j]);
    let along = off[0] * n[0] + off[1] * n[1] + off[2] * n[2];
    if d > reach || (d - along.abs()) > 1e-6 * d.max(1e-6 * reach) {
        return None;
    }
    let (_, _, shape) = face_point(&std::array::from_fn(|i| x[master[k][i]]), st);
    Some((along, master[k], shape, n))
}

/// The contact rows of slave faces `slave` on master faces `master` (6 node indices each, in
/// the order of [`crate::fem::shape::TET10_FACES`], normals outward), coordinates `x`: the
/// weighted gaps G_b = ∫ ψ_b g dA integrated on the slave faces (the degree-4 rule on each of
/// the four sub-triangles), g at each integration point from its projection on the nearest
/// master face. `reach` bounds the pairing: a point farther than it from the master surface, or
/// beside the surface's rim, carries no gap.
pub fn contact_rows(
    x: &[[f64; 3]],
    slave: &[[usize; 6]],
    master: &[[usize; 6]],
    reach: f64,
) -> Vec<ContactRow> {
    let boxes: Vec<([f64; 3], [f64; 3])> = master
        .iter()
        .map(|m| {
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for &i in m {
                for j in 0..3 {
                    lo[j] = lo[j].min(x[i][j]);
                    hi[j] = hi[j].max(x[i][j]);
                }
            }
            (lo, hi)
        })
        .collect();
    let mut rows: Vec<ContactRow> = Vec::new();
    let mut row_of: HashMap<usize, usize> = HashMap::new();
    let mut terms: Vec<HashMap<usize, f64>> = Vec::new();
    for face in slave {
        let xs: [[f64; 3]; 6] = std::array::from_fn(|i| x[face[i]]);
        let r: [usize; 6] = std::array::from_fn(|bi| {
            *row_of.entry(face[bi]).or_insert_with(|| {
                rows.push(ContactRow {
                    node: face[bi],
                    weight: 0.0,
                    g0: 0.0,
                    terms: Vec::new(),
                });
                terms.push(HashMap::new());
                rows.len() - 1
            })
        });
        for sub in SUB_TRIANGLES {
            let [p0, p1, p2] = sub.map(|k| NODE_ST[k]);
            // the sub-triangle is a quarter of the face in (s, t): Jacobian 1/4, each of its
            // pieces 1/4^SPLIT of that
            let jac = ((p1[0] - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (p1[1] - p0[1])).abs()
                / PIECES.len() as f64;
            for (piece, (q, w)) in PIECES
                .iter()
                .flat_map(|t| TRI6.points.iter().zip(TRI6.weights).map(move |qw| (t, qw)))
            {
                // the point's barycentric coordinates in the sub-triangle
                let lp = [1.0 - q[0] - q[1], q[0], q[1]];
                let l: [f64; 3] =
                    std::array::from_fn(|k| (0..3).map(|v| lp[v] * piece[v][k]).sum::<f64>());
                let st = [
                    l[0] * p0[0] + l[1] * p1[0] + l[2] * p2[0],
                    l[0] * p0[1] + l[1] * p1[1] + l[2] * p2[1],
                ];
                let (xq, c, ns) = face_point(&xs, st);
                let da = w * jac * norm(c);
                let paired = pair(x, master, &boxes, xq, reach);
                for (k, &b) in sub.iter().enumerate() {
                    let wb = l[k] * da;
                    let row = r[b];
                    rows[row].weight += wb;
                    let Some((g0, mnodes, nm, n)) = paired else {
                        continue;
                    };
                    rows[row].g0 += wb * g0;
                    for a in 0..6 {
                        for (j, nj) in n.iter().enumerate() {
                            *terms[row].entry(3 * face[a] + j).or_default() += wb * ns[a] * nj;
                            *terms[row].entry(3 * mnodes[a] + j).or_default() -= wb * nm[a] * nj;
                        }
                    }
                }
            }
        }
    }
    for (row, t) in rows.iter_mut().zip(terms) {
        let mut t: Vec<(usize, f64)> = t.into_iter().filter(|t| t.1 != 0.0).collect();
        t.sort_by_key(|t| t.0);
        row.terms = t;
    }
    rows.retain(|r| !r.terms.is_empty());
    rows
}

/// The solution of a contact problem.
#[derive(Clone, Debug)]
pub struct NodeToSurfaceSolution {
    /// λ_b per row (pressure).
    pub pressure: Vec<f64>,
    /// The weighted gaps G_b at the solution (with the penalty's share for a linear law).
    pub gap: Vec<f64>,
    /// The contact's nodal forces Bᵀ λ (3 per node).
    pub forces: Vec<f64>,
    /// Active-set iterations.
    pub iterations: usize,
}

/// Solves the contact of `rows`, row j under `laws[j]`: `u0` the displacements without contact (3 per
/// node), `solve(F)` the displacements K⁻¹ F of several force vectors at once (the supports
/// held at zero).
pub fn solve_node_to_surface(
    rows: &[ContactRow],
    laws: &[Law],
    u0: &[f64],
    solve: &mut dyn FnMut(Vec<Vec<f64>>) -> Result<Vec<Vec<f64>>>,
) -> Result<NodeToSurfaceSolution> {
    let n = u0.len();
    let apply = |row: &ContactRow, u: &[f64]| row.terms.iter().map(|&(d, c)| c * u[d]).sum::<f64>();
    let h: Vec<f64> = rows.iter().map(|r| r.g0 + apply(r, u0)).collect();
    let scale = rows
        .iter()
        .map(|r| r.weight)
        .fold(0.0f64, f64::max)
        .max(f64::MIN_POSITIVE);
    let gap_scale = h.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let p = MixedLcp {
        initial: h.iter().map(|v| *v < 0.0).collect(),
        e: vec![Vec::new(); rows.len()],
        q: Vec::new(),
        gap_tol: 1e-12 * gap_scale.max(scale * f64::EPSILON),
        max_iterations: 200,
        h,
    };
    let mut columns = |js: &[usize]| -> Result<Vec<Vec<f64>>> {
        let forces: Vec<Vec<f64>> = js
            .iter()
            .map(|&j| {
                let mut f = vec![0.0; n];
                for &(d, c) in &rows[j].terms {
                    f[d] += c;
                }
                f
            })
            .collect();
        let us = solve(forces)?;
        Ok(js
            .iter()
            .zip(&us)
            .map(|(&j, u)| {
                let mut col: Vec<f64> = rows.iter().map(|r| apply(r, u)).collect();
                if let Law::Linear(k) = laws[j] {
                    col[j] += rows[j].weight / k;
                }
                col
            })
            .collect())
    };
    let sol = solve_lcp(&p, &mut columns).map_err(|e| {
        FemError::Solver(format!(
            "{e}: the contact pair's surfaces cannot carry the load (a body held by contact \
             alone needs supports of its own)"
        ))
    })?;
    let mut forces = vec![0.0; n];
    for (r, lam) in rows.iter().zip(&sol.lambda) {
        for &(d, c) in &r.terms {
            forces[d] += c * lam;
        }
    }
    Ok(NodeToSurfaceSolution {
        pressure: sol.lambda,
        gap: sol.g,
        forces,
        iterations: sol.iterations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat master face under a slave face 0.1 above it: every node's gap is 0.1, the weights
    /// sum to the area, the weighted gap is 0.1 × W_b.
    #[test]
    fn a_flat_pair_has_the_distance_as_its_gap() {
        let tri = |z: f64, flip: bool| -> Vec<[f64; 3]> {
            let c = if flip {
                [[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]]
            } else {
                [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
            };
            let mid = |a: [f64; 2], b: [f64; 2]| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
            [
                c[0],
                c[1],
                c[2],
                mid(c[0], c[1]),
                mid(c[1], c[2]),
                mid(c[2], c[0]),
            ]
            .iter()
            .map(|p| [p[0], p[1], z])
            .collect()
        };
        // master normal +z (counter-clockwise seen from above), slave normal −z
        let mut x = tri(0.0, false);
        x.extend(tri(0.1, true));
        let master = [[0, 1, 2, 3, 4, 5]];
        let slave = [[6, 7, 8, 9, 10, 11]];
        let rows = contact_rows(&x, &slave, &master, 1.0);
        assert_eq!(rows.len(), 6);
        let area: f64 = rows.iter().map(|r| r.weight).sum();
        assert!((area - 0.5).abs() < 1e-14);
        for r in &rows {
            assert!((r.g0 - 0.1 * r.weight).abs() < 1e-12, "{r:?}");
        }
        // a rigid lift of the slave by 0.05 in z opens every weighted gap by 0.05 W_b
        let mut u = vec![0.0; 3 * x.len()];
        for a in 6..12 {
            u[3 * a + 2] = 0.05;
        }
        for r in &rows {
            let g: f64 = r.terms.iter().map(|&(d, c)| c * u[d]).sum();
            assert!((g - 0.05 * r.weight).abs() < 1e-12);
        }
    }
}
