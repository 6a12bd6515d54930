//! Element matrices of the solid tetrahedra a CalculiX/Abaqus deck names, integrated with the rules
//! CalculiX integrates them with, so that both codes solve the same discrete problem:
//!
//! * **C3D10** (quadratic, 10 nodes, [`super::shape`]): the 4-point degree-2 rule ([`TET4`];
//!   CalculiX `e_c3d.f`, `mint3d = 4` for `C3D10`) for stiffness, mass and geometric stiffness;
//! * **C3D4** (linear, 4 nodes): N_a = L_a (volume coordinates), constant gradients, one point at
//!   the centroid (`e_c3d.f`, `mint3d = 1` for `C3D4` with the default scheme), weight 1/6.
//!
//! For an isotropic material with Lamé constants λ, μ (Zienkiewicz & Taylor, 7th ed., ch. 6; Hughes,
//! "The Finite Element Method", §2.8), at each integration point with weight w and det J:
//!
//! * stiffness K_ab,ij = Σ w det J (λ g_a,i g_b,j + μ g_a,j g_b,i + μ δ_ij g_a·g_b);
//! * mass M_ab,ij = Σ w det J ρ N_a N_b δ_ij (consistent, CalculiX's `sm` in `e_c3d.f`, on the
//!   same points as the stiffness: for C3D4 at the centroid, M_ab = ρV/16 for every a, b);
//! * geometric stiffness K_σ,ab,ij = δ_ij Σ w det J g_aᵀ σ⁰ g_b (Bathe, "Finite Element
//!   Procedures", 2nd ed., §6.3.2, eq. 6.61), σ⁰ the linear stress at the same point;
//! * strain ε = sym(Σ_a u_a ⊗ g_a), components `[xx, yy, zz, xy, yz, zx]` (tensor shears).
//!
//! det J ≤ 0 at an integration point is refused ([`FemError::NegativeJacobian`]); a C3D10 whose
//! det J is negative only at a corner (a badly curved midside node) is integrable, as CalculiX
//! integrates it, and is reported by [`inverted_corners`] for a warning.

use nalgebra::DMatrix;

use super::element::shape_gradients;
use super::error::{FemError, Result};
use super::material::Material;
use super::quadrature::TET4;
use super::shape::{TET10_NODE_XI, tet10_shape};

/// The element family.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SolidKind {
    /// 4-node linear tetrahedron (C3D4).
    Tet4,
    /// 10-node quadratic tetrahedron (C3D10), VTK node order.
    Tet10,
}

impl SolidKind {
    /// Number of nodes.
    pub fn nodes(self) -> usize {
        match self {
            SolidKind::Tet4 => 4,
            SolidKind::Tet10 => 10,
        }
    }

    /// Number of integration points (CalculiX's `mint3d`).
    pub fn points(self) -> usize {
        match self {
            SolidKind::Tet4 => 1,
            SolidKind::Tet10 => 4,
        }
    }
}

/// One integration point: shape values N_a, gradients g_a = ∂N_a/∂x, and w det J.
#[derive(Clone, Debug)]
pub struct IntegrationPoint {
    /// N_a.
    pub n: Vec<f64>,
    /// ∂N_a/∂x.
    pub g: Vec<[f64; 3]>,
    /// Weight times det J (the point's volume).
    pub dv: f64,
}

/// The integration points of an element with coordinates `x` (`kind.nodes()` of them);
/// `element` labels an error.
pub fn integration_points(
    kind: SolidKind,
    x: &[[f64; 3]],
    element: usize,
) -> Result<Vec<IntegrationPoint>> {
    match kind {
        SolidKind::Tet10 => {
            let xe: [[f64; 3]; 10] = std::array::from_fn(|a| x[a]);
            TET4.points
                .iter()
                .zip(TET4.weights)
                .map(|(xi, w)| {
                    let (g, det) = shape_gradients(&xe, *xi, element, "integration point")?;
                    Ok(IntegrationPoint {
                        n: tet10_shape(*xi).to_vec(),
                        g: g.to_vec(),
                        dv: w * det,
                    })
                })
                .collect()
        }
        SolidKind::Tet4 => {
            let d = |i: usize| [x[i][0] - x[0][0], x[i][1] - x[0][1], x[i][2] - x[0][2]];
            let (a, b, c) = (d(1), d(2), d(3));
            // J = [a b c] (columns ∂x/∂ξ, ∂x/∂η, ∂x/∂ζ); rows of J⁻¹ = cofactors / det
            let cross = |p: [f64; 3], q: [f64; 3]| {
                [
                    p[1] * q[2] - p[2] * q[1],
                    p[2] * q[0] - p[0] * q[2],
                    p[0] * q[1] - p[1] * q[0],
                ]
            };
            let (bc, ca, ab) = (cross(b, c), cross(c, a), cross(a, b));
            let det = a[0] * bc[0] + a[1] * bc[1] + a[2] * bc[2];
            if !(det > 0.0 && det.is_finite()) {
                return Err(FemError::NegativeJacobian {
                    element,
                    det_j: det,
                    xi: [0.25; 3],
                    where_: "integration point",
                });
            }
            let g1 = bc.map(|v| v / det);
            let g2 = ca.map(|v| v / det);
            let g3 = ab.map(|v| v / det);
            let g0 = std::array::from_fn(|j| -(g1[j] + g2[j] + g3[j]));
            Ok(vec![IntegrationPoint {
                n: vec![0.25; 4],
                g: vec![g0, g1, g2, g3],
                dv: det / 6.0,
            }])
        }
    }
}

/// The corners (0-based local numbers) of a C3D10 at which det J ≤ 0 (none for a C3D4, whose
/// Jacobian is constant).
pub fn inverted_corners(kind: SolidKind, x: &[[f64; 3]]) -> Vec<usize> {
    if kind == SolidKind::Tet4 {
        return Vec::new();
    }
    let xe: [[f64; 3]; 10] = std::array::from_fn(|a| x[a]);
    (0..4)
        .filter(|&c| shape_gradients(&xe, TET10_NODE_XI[c], 0, "node").is_err())
        .collect()
}

/// The stiffness matrix (3n × 3n, DOFs node by node).
pub fn stiffness(points: &[IntegrationPoint], material: &Material) -> DMatrix<f64> {
    let n = points[0].g.len();
    let (lambda, mu) = material.lame();
    let mut k = DMatrix::zeros(3 * n, 3 * n);
    for p in points {
        let g = &p.g;
        for a in 0..n {
            for b in 0..n {
                let dot = g[a][0] * g[b][0] + g[a][1] * g[b][1] + g[a][2] * g[b][2];
                for i in 0..3 {
                    for j in 0..3 {
                        let mut v = lambda * g[a][i] * g[b][j] + mu * g[a][j] * g[b][i];
                        if i == j {
                            v += mu * dot;
                        }
                        k[(3 * a + i, 3 * b + j)] += p.dv * v;
                    }
                }
            }
        }
    }
    k
}

/// The consistent mass matrix of density `rho` (3n × 3n).
pub fn mass(points: &[IntegrationPoint], rho: f64) -> DMatrix<f64> {
    let n = points[0].n.len();
    let mut m = DMatrix::zeros(3 * n, 3 * n);
    for p in points {
        for a in 0..n {
            for b in 0..n {
                let v = p.dv * rho * p.n[a] * p.n[b];
                for i in 0..3 {
                    m[(3 * a + i, 3 * b + i)] += v;
                }
            }
        }
    }
    m
}

/// The geometric stiffness of the pre-stress `sigma[k]` at point k (`[xx, yy, zz, xy, yz, zx]`).
pub fn geometric_stiffness(points: &[IntegrationPoint], sigma: &[[f64; 6]]) -> DMatrix<f64> {
    let n = points[0].g.len();
    let mut k = DMatrix::zeros(3 * n, 3 * n);
    for (p, s) in points.iter().zip(sigma) {
        let m = [[s[0], s[3], s[5]], [s[3], s[1], s[4]], [s[5], s[4], s[2]]];
        for a in 0..n {
            for b in 0..n {
                let h: f64 = m
                    .iter()
                    .zip(&p.g[a])
                    .map(|(row, ga)| {
                        ga * (row[0] * p.g[b][0] + row[1] * p.g[b][1] + row[2] * p.g[b][2])
                    })
                    .sum();
                for i in 0..3 {
                    k[(3 * a + i, 3 * b + i)] += p.dv * h;
                }
            }
        }
    }
    k
}

/// The strain at a point from the element's nodal displacements `u` (3 per node).
pub fn strain(p: &IntegrationPoint, u: &[f64]) -> [f64; 6] {
    let mut h = [[0.0; 3]; 3];
    for (a, g) in p.g.iter().enumerate() {
        for i in 0..3 {
            for j in 0..3 {
                h[i][j] += u[3 * a + i] * g[j];
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A C3D4 and the straight C3D10 on the same corners have the same volume; the C3D4's
    /// stiffness annihilates rigid translations; its mass sums to ρ V per direction.
    #[test]
    fn tet4_volume_rigid_motion_and_mass() {
        let x4 = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.3, 1.5, 0.0],
            [0.2, 0.4, 1.1],
        ];
        let p4 = integration_points(SolidKind::Tet4, &x4, 0).unwrap();
        let mut x10 = x4.to_vec();
        for [a, b] in crate::fem::shape::TET10_EDGES {
            x10.push(std::array::from_fn(|j| 0.5 * (x4[a][j] + x4[b][j])));
        }
        let p10 = integration_points(SolidKind::Tet10, &x10, 0).unwrap();
        let v4: f64 = p4.iter().map(|p| p.dv).sum();
        let v10: f64 = p10.iter().map(|p| p.dv).sum();
        // closed form: det[a b c]/6 = 2 · 1.5 · 1.1 / 6
        assert!((v4 - 0.55).abs() < 1e-14 && (v10 - 0.55).abs() < 1e-14);
        let k = stiffness(&p4, &Material::STEEL);
        let t = DMatrix::from_fn(12, 1, |r, _| if r % 3 == 1 { 1.0 } else { 0.0 });
        assert!((k * t).amax() < 1e-3);
        let m = mass(&p4, 7800.0);
        let total: f64 = (0..12)
            .step_by(3)
            .flat_map(|r| (0..12).step_by(3).map(move |c| (r, c)))
            .map(|(r, c)| m[(r, c)])
            .sum();
        assert!((total - 7800.0 * 0.55).abs() < 1e-9);
    }
}
