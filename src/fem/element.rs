//! The isoparametric 10-node tetrahedron: Jacobian, shape-function gradients, stiffness, volume.
//!
//! Stiffness K = ∫ Bᵀ D B dV (Zienkiewicz & Taylor, 7th ed., ch. 6; Hughes, "The Finite Element
//! Method", §2.8 and §3.7), written for an isotropic material in Lamé form, block by block: for nodes
//! a, b with gradients g_a = ∂N_a/∂x,
//! K_ab,ij = ∫ λ g_a,i g_b,j + μ g_a,j g_b,i + μ δ_ij (g_a · g_b) dV.
//!
//! Quadrature: [`QuadratureChoice::Auto`] uses the 4-point rule (exact) for straight-sided elements
//! and the 14-point degree-5 rule for curved ones (a midside node off its edge midpoint).
//! The Jacobian determinant is checked at every quadrature point used and at the ten nodes (where
//! stresses are evaluated); zero or negative is a [`FemError::NegativeJacobian`] naming the element.

use nalgebra::SMatrix;
use serde::{Deserialize, Serialize};

use super::error::{FemError, Result};
use super::material::Material;
use super::quadrature::{TET4, TET14, TetRule};
use super::shape::{TET10_EDGES, TET10_NODE_XI, tet10_grad};

/// Node coordinates of one element, in element node order.
pub type ElementCoords = [[f64; 3]; 10];

/// 30×30 element stiffness matrix, DOF order (node 0: x y z, node 1: x y z, ...).
pub type ElementStiffness = SMatrix<f64, 30, 30>;

/// Which tetrahedron rule to integrate element matrices with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum QuadratureChoice {
    /// 4-point rule for straight-sided elements (exact), 14-point rule for curved ones.
    #[default]
    Auto,
    /// Always the 4-point degree-2 rule.
    Degree2,
    /// Always the 14-point degree-5 rule.
    Degree5,
}

/// Relative offset (to the edge length) above which a midside node makes an element "curved".
pub const CURVED_TOLERANCE: f64 = 1e-9;

/// True when every midside node sits at its edge midpoint (to [`CURVED_TOLERANCE`] of the edge).
pub fn is_straight(x: &ElementCoords) -> bool {
    TET10_EDGES.iter().enumerate().all(|(k, [a, b])| {
        let (pa, pb, pm) = (x[*a], x[*b], x[4 + k]);
        let off: f64 = (0..3)
            .map(|j| (pm[j] - 0.5 * (pa[j] + pb[j])).powi(2))
            .sum();
        let len: f64 = (0..3).map(|j| (pb[j] - pa[j]).powi(2)).sum();
        off <= CURVED_TOLERANCE * CURVED_TOLERANCE * len
    })
}

impl QuadratureChoice {
    /// The rule this choice uses for an element with coordinates `x`.
    pub fn rule_for(self, x: &ElementCoords) -> &'static TetRule {
        match self {
            QuadratureChoice::Degree2 => &TET4,
            QuadratureChoice::Degree5 => &TET14,
            QuadratureChoice::Auto => {
                if is_straight(x) {
                    &TET4
                } else {
                    &TET14
                }
            }
        }
    }
}

/// Gradients ∂N_a/∂x (10 × 3) and det J at natural coordinates `xi`, with J_ij = ∂x_i/∂ξ_j.
/// Errors if det J ≤ 0 (or not finite); `element` and `where_` only label the error.
pub fn shape_gradients(
    x: &ElementCoords,
    xi: [f64; 3],
    element: usize,
    where_: &'static str,
) -> Result<([[f64; 3]; 10], f64)> {
    let dn = tet10_grad(xi);
    let mut j = [[0.0; 3]; 3];
    for a in 0..10 {
        for r in 0..3 {
            for c in 0..3 {
                j[r][c] += x[a][r] * dn[a][c];
            }
        }
    }
    // cofactor matrix and determinant
    let cof = [
        [
            j[1][1] * j[2][2] - j[1][2] * j[2][1],
            j[1][2] * j[2][0] - j[1][0] * j[2][2],
            j[1][0] * j[2][1] - j[1][1] * j[2][0],
        ],
        [
            j[0][2] * j[2][1] - j[0][1] * j[2][2],
            j[0][0] * j[2][2] - j[0][2] * j[2][0],
            j[0][1] * j[2][0] - j[0][0] * j[2][1],
        ],
        [
            j[0][1] * j[1][2] - j[0][2] * j[1][1],
            j[0][2] * j[1][0] - j[0][0] * j[1][2],
            j[0][0] * j[1][1] - j[0][1] * j[1][0],
        ],
    ];
    let det = j[0][0] * cof[0][0] + j[0][1] * cof[0][1] + j[0][2] * cof[0][2];
    if !(det > 0.0 && det.is_finite()) {
        return Err(FemError::NegativeJacobian {
            element,
            det_j: det,
            xi,
            where_,
        });
    }
    // J^{-1} = cof^T / det; ∂N/∂x_r = Σ_c ∂N/∂ξ_c (J^{-1})_{c r} = Σ_c dn_c cof[r][c] / det
    let mut g = [[0.0; 3]; 10];
    for a in 0..10 {
        for r in 0..3 {
            g[a][r] = (dn[a][0] * cof[r][0] + dn[a][1] * cof[r][1] + dn[a][2] * cof[r][2]) / det;
        }
    }
    Ok((g, det))
}

/// Checks det J > 0 at the points of `rule` and at the ten nodes; returns the smallest det J.
pub fn check_jacobian(x: &ElementCoords, rule: &TetRule, element: usize) -> Result<f64> {
    let mut min = f64::INFINITY;
    for p in rule.points {
        min = min.min(shape_gradients(x, *p, element, "quadrature point")?.1);
    }
    for p in TET10_NODE_XI {
        min = min.min(shape_gradients(x, p, element, "node")?.1);
    }
    Ok(min)
}

/// Element volume ∫ det J dξ with `rule` (checks the Jacobian at the rule's points).
pub fn element_volume(x: &ElementCoords, rule: &TetRule, element: usize) -> Result<f64> {
    let mut v = 0.0;
    for (p, w) in rule.points.iter().zip(rule.weights) {
        v += w * shape_gradients(x, *p, element, "quadrature point")?.1;
    }
    Ok(v)
}

/// Signed volume of the corner tetrahedron (positive for right-handed corner order).
pub fn corner_volume(x: &ElementCoords) -> f64 {
    let d = |i: usize| [x[i][0] - x[0][0], x[i][1] - x[0][1], x[i][2] - x[0][2]];
    let (a, b, c) = (d(1), d(2), d(3));
    (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0]))
        / 6.0
}

/// Element stiffness matrix with `rule`. Checks det J > 0 at the rule's points and at the nodes.
pub fn element_stiffness(
    x: &ElementCoords,
    material: &Material,
    rule: &TetRule,
    element: usize,
) -> Result<ElementStiffness> {
    for p in TET10_NODE_XI {
        shape_gradients(x, p, element, "node")?;
    }
    let (lambda, mu) = material.lame();
    let mut k = ElementStiffness::zeros();
    for (p, w) in rule.points.iter().zip(rule.weights) {
        let (g, det) = shape_gradients(x, *p, element, "quadrature point")?;
        let f = w * det;
        for a in 0..10 {
            for b in a..10 {
                let dot = g[a][0] * g[b][0] + g[a][1] * g[b][1] + g[a][2] * g[b][2];
                for i in 0..3 {
                    for jj in 0..3 {
                        let mut v = lambda * g[a][i] * g[b][jj] + mu * g[a][jj] * g[b][i];
                        if i == jj {
                            v += mu * dot;
                        }
                        k[(3 * a + i, 3 * b + jj)] += f * v;
                    }
                }
            }
        }
    }
    // fill the lower block triangle by symmetry
    for a in 0..10 {
        for b in 0..a {
            for i in 0..3 {
                for jj in 0..3 {
                    k[(3 * a + i, 3 * b + jj)] = k[(3 * b + jj, 3 * a + i)];
                }
            }
        }
    }
    Ok(k)
}

/// Strain tensor `[xx, yy, zz, xy, yz, zx]` from gradients and element displacements.
pub fn strain(g: &[[f64; 3]; 10], u: &[[f64; 3]; 10]) -> [f64; 6] {
    // H_ij = ∂u_i/∂x_j
    let mut h = [[0.0; 3]; 3];
    for a in 0..10 {
        for i in 0..3 {
            for j in 0..3 {
                h[i][j] += u[a][i] * g[a][j];
            }
        }
    }
    [
        h[0][0],
        h[1][1],
        h[2][2],
        0.5 * (h[0][1] + h[1][0]),
        0.5 * (h[1][2] + h[2][1]),
        0.5 * (h[2][0] + h[0][2]),
    ]
}
