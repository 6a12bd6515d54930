//! The weighted gaps of a wall: where the contact pressure lives and how it is weighed.
//!
//! On a 6-node face the consistent nodal weights ∫ N_a dA of a uniform pressure are 0 at the
//! corners and A/3 at the midside nodes of a straight face (and the corner weights turn negative
//! on distorted ones), so a node-to-surface contact with those weights leaves the corners
//! unrestrained and a nodal pressure undefined there. The remedy used here is a mortar-type
//! (face-integrated) discretisation with a pressure interpolated piecewise linearly on the four
//! sub-triangles of each face (corner–midside–midside and the middle one), the pressure space
//! of Puso & Laursen's segment-to-segment contact for quadratic faces (M. A. Puso, T. A. Laursen,
//! *A mortar segment-to-segment contact method for large deformation solid mechanics*, CMAME 193
//! (2004), §5; B. I. Wohlmuth, *Discretization Methods and Iterative Solvers Based on Domain
//! Decomposition*, 2001, for the weighted gap). Every wall node b carries a pressure value λ_b
//! (Pa) with the hat function ψ_b of the sub-triangles, positive everywhere, ∫ψ_b dA = A/12 at a
//! corner and A/4 at a midside node of a straight face, and Σ_b ψ_b = 1.
//!
//! With the displacement's face shape functions N_a the mortar weights are
//!
//! D_ba = ∫_Γ ψ_b N_a dA,
//!
//! the weighted gap of node b is G_b = Σ_a D_ba g_a (g_a the nodal gap of
//! [`super::cylinder`]), and the contact's nodal forces on the body are
//! f_a = Σ_b λ_b D_ba e_a — the virtual work ∫ p e_r · δu dA of the pressure p = Σ λ_b ψ_b with
//! e_r frozen at the nodes. A uniform pressure p therefore gives the consistent forces
//! p ∫ N_a dA e_a exactly (Σ_b ψ_b = 1), and the contact conditions are posed node by node on the
//! weighted gap: λ_b ≥ 0, G_b ≥ 0, λ_b G_b = 0. The integrals use the degree-4 rule on each
//! sub-triangle (ψ_b N_a is cubic on a straight face).

use std::collections::HashMap;

use super::cylinder::{Cylinder, plane_basis, radial};
use crate::fem::boundary::{face_coords, face_point, norm};
use crate::fem::error::{FemError, Result};
use crate::fem::mesh::TetMesh;
use crate::fem::quadrature::TRI6;

/// The four sub-triangles of a 6-node triangle (local nodes: corners 0–2, midside 3 = 01,
/// 4 = 12, 5 = 20).
const SUB_TRIANGLES: [[usize; 3]; 4] = [[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]];

/// Area coordinates (s, t) of the six face nodes.
const NODE_ST: [[f64; 2]; 6] = [
    [0.0, 0.0],
    [1.0, 0.0],
    [0.0, 1.0],
    [0.5, 0.0],
    [0.5, 0.5],
    [0.0, 0.5],
];

/// The contact rows of one cylinder: its wall nodes, their radial directions, initial gaps and
/// mortar weights.
#[derive(Clone, Debug)]
pub struct Wall {
    /// Index of the cylinder.
    pub cylinder: usize,
    /// Unit axis â.
    pub axis: [f64; 3],
    /// Point on the axis, m.
    pub centre: [f64; 3],
    /// (t₁, t₂): the plane of the pin's translation; angles are measured from t₁ towards t₂.
    pub basis: ([f64; 3], [f64; 3]),
    /// Wall nodes (global, sorted): the pressure nodes.
    pub nodes: Vec<usize>,
    /// Unit radial direction e_r at each node.
    pub e: Vec<[f64; 3]>,
    /// Angle of each node about the axis, radians in (−π, π].
    pub angle: Vec<f64>,
    /// Initial nodal gap g₀ (m).
    pub g0: Vec<f64>,
    /// Row b of D: (index into `nodes` of a, D_ba in m²).
    pub weights: Vec<Vec<(usize, f64)>>,
    /// ∫ψ_b dA, m² (the area each pressure node stands for).
    pub area: Vec<f64>,
    /// First global contact row of this wall.
    pub offset: usize,
    /// Per face: its nodes (indices into `nodes`), ∫ψ_b dA of each, and its area (m²).
    pub faces: Vec<([usize; 6], [f64; 6], f64)>,
}

impl Wall {
    /// Builds the wall of `cyl` (cylinder number `index`, its rows from `offset`).
    pub fn new(mesh: &TetMesh, cyl: &Cylinder, index: usize, offset: usize) -> Result<Wall> {
        let axis = cyl.unit_axis(index)?;
        let mut nodes: Vec<usize> = cyl.faces.iter().flatten().copied().collect();
        nodes.sort_unstable();
        nodes.dedup();
        if let Some(&n) = nodes.iter().find(|&&n| n >= mesh.n_nodes()) {
            return Err(FemError::InvalidInput(format!(
                "contact cylinder {index}: face node {n} out of range"
            )));
        }
        let local: HashMap<usize, usize> = nodes.iter().enumerate().map(|(i, &n)| (n, i)).collect();
        let basis = plane_basis(axis);
        let mut e = Vec::with_capacity(nodes.len());
        let mut angle = Vec::with_capacity(nodes.len());
        let mut g0 = Vec::with_capacity(nodes.len());
        for &n in &nodes {
            let (r0, er) = radial(mesh.nodes()[n], cyl.axis_point_m, axis);
            if r0.partial_cmp(&(1e-9 * cyl.radius_m)) != Some(std::cmp::Ordering::Greater) {
                return Err(FemError::InvalidInput(format!(
                    "contact cylinder {index}: wall node {n} lies on the axis"
                )));
            }
            e.push(er);
            angle.push(
                crate::fem::boundary::dot(er, basis.1)
                    .atan2(crate::fem::boundary::dot(er, basis.0)),
            );
            g0.push(cyl.nominal_bore_radius_m.unwrap_or(r0) - cyl.radius_m);
        }
        let mut rows: Vec<HashMap<usize, f64>> = vec![HashMap::new(); nodes.len()];
        let mut faces = Vec::with_capacity(cyl.faces.len());
        for face in &cyl.faces {
            let x = face_coords(mesh, face);
            let d = face_weights(&x);
            let psi: [f64; 6] = std::array::from_fn(|b| d[b].iter().sum());
            faces.push((face.map(|n| local[&n]), psi, psi.iter().sum()));
            for (b, row) in d.iter().enumerate() {
                let entry = &mut rows[local[&face[b]]];
                for (a, v) in row.iter().enumerate() {
                    *entry.entry(local[&face[a]]).or_insert(0.0) += v;
                }
            }
        }
        let weights: Vec<Vec<(usize, f64)>> = rows
            .into_iter()
            .map(|r| {
                let mut v: Vec<(usize, f64)> = r.into_iter().collect();
                v.sort_unstable_by_key(|p| p.0);
                v
            })
            .collect();
        let area = weights
            .iter()
            .map(|r| r.iter().map(|p| p.1).sum())
            .collect();
        Ok(Wall {
            cylinder: index,
            axis,
            centre: cyl.axis_point_m,
            basis,
            nodes,
            e,
            angle,
            g0,
            weights,
            area,
            offset,
            faces,
        })
    }

    /// Number of pressure nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the wall has no node.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// c_b = Σ_a D_ba e_a: the force on the body of a unit λ_b (N/Pa).
    pub fn force_per_pressure(&self, b: usize) -> [f64; 3] {
        let mut c = [0.0; 3];
        for &(a, d) in &self.weights[b] {
            for (cj, ej) in c.iter_mut().zip(self.e[a]) {
                *cj += d * ej;
            }
        }
        c
    }

    /// The pressure `lambda` smoothed over the faces: at each node the area-weighted mean of
    /// the face means Σ_b λ_b ∫ψ_b / A of the faces around it.
    pub fn smoothed(&self, lambda: &[f64]) -> Vec<f64> {
        let mut sum = vec![0.0; self.len()];
        let mut area = vec![0.0; self.len()];
        for (nodes, psi, a) in &self.faces {
            let mean: f64 = nodes
                .iter()
                .zip(psi)
                .map(|(&b, p)| lambda[b] * p)
                .sum::<f64>()
                / a;
            for &b in nodes {
                sum[b] += mean * a;
                area[b] += a;
            }
        }
        sum.iter().zip(&area).map(|(s, a)| s / a).collect()
    }

    /// Weighted gaps G_b = Σ_a D_ba g_a of the nodal gaps `g`.
    pub fn weighted(&self, g: &[f64]) -> Vec<f64> {
        self.weights
            .iter()
            .map(|r| r.iter().map(|&(a, d)| d * g[a]).sum())
            .collect()
    }

    /// Nodal gaps g_a = g₀ + e_a · (u_a − w) of the displacements `u` (3 per global node) and
    /// the pin translation `w`.
    pub fn gaps(&self, u: &[f64], w: [f64; 3]) -> Vec<f64> {
        self.nodes
            .iter()
            .enumerate()
            .map(|(a, &n)| {
                let e = self.e[a];
                self.g0[a] + (0..3).map(|j| e[j] * (u[3 * n + j] - w[j])).sum::<f64>()
            })
            .collect()
    }

    /// Adds the contact forces Σ_b λ_b D_ba e_a of the pressures `lambda` (Pa) to `f`
    /// (3 per global node).
    pub fn add_forces(&self, lambda: &[f64], f: &mut [f64]) {
        for (b, row) in self.weights.iter().enumerate() {
            if lambda[b] == 0.0 {
                continue;
            }
            for &(a, d) in row {
                let n = self.nodes[a];
                for j in 0..3 {
                    f[3 * n + j] += lambda[b] * d * self.e[a][j];
                }
            }
        }
    }
}

/// D_ba = ∫ ψ_b N_a dA of one 6-node face with node coordinates `x` (row b: pressure node,
/// column a: displacement node).
pub fn face_weights(x: &[[f64; 3]; 6]) -> [[f64; 6]; 6] {
    let mut d = [[0.0; 6]; 6];
    for sub in SUB_TRIANGLES {
        let [p0, p1, p2] = sub.map(|k| NODE_ST[k]);
        // the affine map of the reference triangle onto the sub-triangle: its Jacobian is twice
        // the sub-triangle's area in (s, t), 1/4
        let jac = ((p1[0] - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (p1[1] - p0[1])).abs();
        for (q, w) in TRI6.points.iter().zip(TRI6.weights) {
            let l = [1.0 - q[0] - q[1], q[0], q[1]];
            let st = [
                l[0] * p0[0] + l[1] * p1[0] + l[2] * p2[0],
                l[0] * p0[1] + l[1] * p1[1] + l[2] * p2[1],
            ];
            let (_, c, n) = face_point(x, st);
            let da = w * jac * norm(c);
            for (k, &b) in sub.iter().enumerate() {
                for a in 0..6 {
                    d[b][a] += l[k] * n[a] * da;
                }
            }
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pressure_weights_are_positive_and_a_uniform_pressure_gives_the_consistent_forces() {
        // a straight face of area 1/2 in the plane z = 0
        let x = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.5, 0.0, 0.0],
            [0.5, 0.5, 0.0],
            [0.0, 0.5, 0.0],
        ];
        let d = face_weights(&x);
        let area = 0.5;
        for (b, drow) in d.iter().enumerate() {
            let row: f64 = drow.iter().sum();
            // ∫ψ_b = A/12 at a corner, A/4 at a midside node (hat functions on A/4 triangles)
            let expect = if b < 3 { area / 12.0 } else { area / 4.0 };
            assert!((row - expect).abs() < 1e-15, "{b}: {row}");
        }
        for a in 0..6 {
            let col: f64 = d.iter().map(|r| r[a]).sum();
            // Σ_b ψ_b = 1: ∫ N_a = 0 at a corner, A/3 at a midside node (Zienkiewicz & Taylor)
            let expect = if a < 3 { 0.0 } else { area / 3.0 };
            assert!((col - expect).abs() < 1e-15, "{a}: {col}");
        }
        // D is invertible: a face whose six weighted gaps vanish has all six nodal gaps zero
        let m = nalgebra::SMatrix::<f64, 6, 6>::from_fn(|i, j| d[i][j]);
        let sv = m.singular_values();
        assert!(sv.min() > 1e-3 * sv.max(), "{sv}");
    }
}
