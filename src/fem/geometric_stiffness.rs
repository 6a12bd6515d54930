//! Geometric (initial-stress) stiffness of the 10-node tetrahedron.
//!
//! The second variation of the Green–Lagrange strain energy under a pre-stress σ⁰ gives
//! K_σ = ∫ Gᵀ S G dV (K.-J. Bathe, *Finite Element Procedures*, 2nd ed., §6.3.2, eq. 6.61 and
//! table 6.4 — the "K_NL" matrix of the total/updated Lagrangian formulation evaluated at the
//! reference state; R. D. Cook, D. S. Malkus, M. E. Plesha, R. J. Witt, *Concepts and
//! Applications of Finite Element Analysis*, 4th ed., §18.2 and §18.6). Here G maps the element's
//! nodal displacements to the nine displacement gradients ∂u_i/∂x_k and S is the 9 × 9 block
//! diagonal with the 3 × 3 Cauchy stress σ⁰ in each of its three blocks. For nodes a, b with
//! shape-function gradients g_a = ∂N_a/∂x this is, block by block,
//!
//! K_σ,ab,ij = δ_ij ∫ g_aᵀ σ⁰ g_b dV,
//!
//! the same scalar 10 × 10 matrix H_ab = ∫ g_aᵀ σ⁰ g_b dV on each of the three displacement
//! components. A tensile σ⁰ makes K_σ positive semi-definite (stiffening), a compressive one
//! negative. The pre-stress is the linear-elastic stress σ⁰ = D ε(u⁰) of the reference load case,
//! evaluated at the quadrature points of the element.

use nalgebra::SMatrix;

use super::element::{ElementCoords, ElementStiffness, shape_gradients, strain};
use super::error::Result;
use super::material::Material;
use super::quadrature::TetRule;

/// The scalar 10 × 10 kernel H_ab = ∫ g_aᵀ σ⁰ g_b dV of an element's geometric stiffness.
pub type GeometricKernel = SMatrix<f64, 10, 10>;

/// H_ab = ∫ g_aᵀ σ g_b dV with the stress `stress(p)` (components `[xx, yy, zz, xy, yz, zx]`, Pa)
/// at each point p of `rule` (by index). Checks det J > 0 at the rule's points.
pub fn geometric_kernel_with(
    x: &ElementCoords,
    rule: &TetRule,
    element: usize,
    stress: impl Fn(usize, &[[f64; 3]; 10]) -> [f64; 6],
) -> Result<GeometricKernel> {
    let mut h = GeometricKernel::zeros();
    for (q, (p, w)) in rule.points.iter().zip(rule.weights).enumerate() {
        let (g, det) = shape_gradients(x, *p, element, "quadrature point")?;
        let s = stress(q, &g);
        let sig = [[s[0], s[3], s[5]], [s[3], s[1], s[4]], [s[5], s[4], s[2]]];
        let f = w * det;
        // σ g_b for every b, then g_a · (σ g_b)
        let sg: [[f64; 3]; 10] = std::array::from_fn(|b| {
            std::array::from_fn(|i| sig[i][0] * g[b][0] + sig[i][1] * g[b][1] + sig[i][2] * g[b][2])
        });
        for a in 0..10 {
            for b in a..10 {
                h[(a, b)] += f * (g[a][0] * sg[b][0] + g[a][1] * sg[b][1] + g[a][2] * sg[b][2]);
            }
        }
    }
    for a in 0..10 {
        for b in 0..a {
            h[(a, b)] = h[(b, a)];
        }
    }
    Ok(h)
}

/// The kernel H of an element whose pre-stress is the linear-elastic stress σ⁰ = D ε(u⁰) of the
/// element displacements `u` (m), evaluated at each point of `rule`.
pub fn geometric_kernel(
    x: &ElementCoords,
    u: &[[f64; 3]; 10],
    material: &Material,
    rule: &TetRule,
    element: usize,
) -> Result<GeometricKernel> {
    geometric_kernel_with(x, rule, element, |_, g| material.stress(&strain(g, u)))
}

/// The full 30 × 30 K_σ (DOF order node 0: x y z, node 1: …) of a kernel: K_σ,ab,ij = δ_ij H_ab.
pub fn expand_kernel(h: &GeometricKernel) -> ElementStiffness {
    let mut k = ElementStiffness::zeros();
    for a in 0..10 {
        for b in 0..10 {
            for i in 0..3 {
                k[(3 * a + i, 3 * b + i)] = h[(a, b)];
            }
        }
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::quadrature::{TET4, TET14};

    /// A straight-sided tet10 from four corners (midside nodes at the edge midpoints).
    fn tet10(c: [[f64; 3]; 4]) -> ElementCoords {
        let mid = |a: usize, b: usize| std::array::from_fn(|j| 0.5 * (c[a][j] + c[b][j]));
        // VTK edge order: 01, 12, 20, 03, 13, 23
        [
            c[0],
            c[1],
            c[2],
            c[3],
            mid(0, 1),
            mid(1, 2),
            mid(2, 0),
            mid(0, 3),
            mid(1, 3),
            mid(2, 3),
        ]
    }

    fn skewed() -> ElementCoords {
        tet10([
            [0.0, 0.0, 0.0],
            [0.011, 0.001, -0.002],
            [0.002, 0.009, 0.001],
            [0.001, 0.002, 0.012],
        ])
    }

    #[test]
    fn symmetric_for_a_general_stress() {
        // reference: K_σ = ∫ Gᵀ S G dV is symmetric because S is (Bathe §6.3.2)
        let x = skewed();
        let s = [3.0e6, -7.0e6, 1.5e6, 2.0e6, -0.5e6, 4.0e6];
        let h = geometric_kernel_with(&x, &TET14, 0, |q, _| s.map(|v| v * (1.0 + 0.1 * q as f64)))
            .unwrap();
        let k = expand_kernel(&h);
        let asym = (k - k.transpose()).abs().max();
        assert!(asym <= 1e-12 * k.abs().max(), "asymmetry {asym}");
        // a rigid translation has no gradient: K_σ t = 0
        let t = nalgebra::SVector::<f64, 30>::from_fn(|i, _| [0.3, -0.2, 0.7][i % 3]);
        let kt = (k * t).abs().max();
        assert!(kt <= 1e-9 * k.abs().max(), "K_σ t = {kt}");
    }

    #[test]
    fn uniaxial_stress_against_the_bar_value() {
        // reference: for a uniaxial stress σ along x and the transverse field u_y = θ x
        // (a small rotation-like shear of the fibres), uᵀ K_σ u = ∫ σ (∂u_y/∂x)² dV = σ θ² V —
        // the work of the axial force on the fibres' inclination, the string/bar term of
        // Cook et al. §18.2 (P L θ² for a bar of force P and length L).
        let x = skewed();
        let sigma = -42.0e6;
        let theta = 1e-3;
        let h =
            geometric_kernel_with(&x, &TET4, 0, |_, _| [sigma, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
        let k = expand_kernel(&h);
        let u = nalgebra::SVector::<f64, 30>::from_fn(|i, _| {
            if i % 3 == 1 { theta * x[i / 3][0] } else { 0.0 }
        });
        let volume = crate::fem::element::corner_volume(&x);
        let expected = sigma * theta * theta * volume;
        let got = (u.transpose() * k * u)[(0, 0)];
        assert!(
            (got - expected).abs() <= 1e-12 * expected.abs(),
            "{got} against {expected}"
        );
        // an axial stretch u_x = ε x has no transverse gradient along y, z: uᵀ K_σ u = σ ε² V too
        let eps = 2e-4;
        let v =
            nalgebra::SVector::<f64, 30>::from_fn(
                |i, _| {
                    if i % 3 == 0 { eps * x[i / 3][0] } else { 0.0 }
                },
            );
        let got = (v.transpose() * k * v)[(0, 0)];
        let expected = sigma * eps * eps * volume;
        assert!((got - expected).abs() <= 1e-12 * expected.abs());
        // a field varying only across the stress (u_y = θ z) carries no work of σ_xx
        let w = nalgebra::SVector::<f64, 30>::from_fn(|i, _| {
            if i % 3 == 1 { theta * x[i / 3][2] } else { 0.0 }
        });
        let got = (w.transpose() * k * w)[(0, 0)];
        assert!(got.abs() <= 1e-12 * (sigma * theta * theta * volume).abs());
    }

    #[test]
    fn from_displacements_matches_the_given_stress() {
        // a uniform strain field gives the uniform stress D ε: both routes agree
        let x = skewed();
        let m = Material::STEEL;
        let e = [1e-4, -3e-5, 2e-5, 4e-5, 0.0, -1e-5];
        let u: [[f64; 3]; 10] = std::array::from_fn(|a| {
            let p = x[a];
            [
                e[0] * p[0] + e[3] * p[1] + e[5] * p[2],
                e[3] * p[0] + e[1] * p[1] + e[4] * p[2],
                e[5] * p[0] + e[4] * p[1] + e[2] * p[2],
            ]
        });
        let s = m.stress(&e);
        let h1 = geometric_kernel(&x, &u, &m, &TET4, 0).unwrap();
        let h2 = geometric_kernel_with(&x, &TET4, 0, |_, _| s).unwrap();
        assert!((h1 - h2).abs().max() <= 1e-9 * h2.abs().max());
    }
}
