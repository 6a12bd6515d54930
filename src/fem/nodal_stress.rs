//! Nodal stresses formed as CalculiX forms them for the 10-node tetrahedron (C3D10): the stress at
//! the four integration points of the 4-point rule, extrapolated linearly to the four corner nodes
//! of each element, the midside nodes given the mean of their two corners, and every node's value
//! the unweighted mean over the elements that share it.
//!
//! Source: the CalculiX CrunchiX source, `extrapolate.f` (ccx 2.x): for a C3D10 the integration
//! points are those of `gauss3d5` (the 4-point rule of [`TET4`], point k nearest corner k), the
//! corner values are `a4 · y_ip` with the 4 × 4 matrix `a4` (1.92705 on the diagonal, −0.30902 off
//! it), the midside nodes the mean of the corners of their edge (`nonei10`), and the nodal result
//! the sum over the elements divided by their number (`inum`). The CalculiX manual ("Output
//! variables", *NODE FILE/*EL FILE S) describes the same: "the values at the integration points are
//! extrapolated to the nodes and averaged".
//!
//! The exact extrapolation matrix is the inverse of the integration points' volume coordinates,
//! (I − b 𝟙𝟙ᵀ)/(a − b) with a = (5 + 3√5)/20, b = (5 − √5)/20: √5 (1 − b) = 1.927051, −√5 b =
//! −0.309017. CalculiX prints it to five decimals, so its rows sum to 0.99999, not 1: a uniform
//! stress comes out 1e-5 low at the nodes. [`Extrapolation::Exact`] uses the exact matrix (a
//! uniform field is reproduced to round-off), [`Extrapolation::CalculiX`] CalculiX's rounded one
//! (to reproduce ccx's numbers to round-off).
//!
//! Components here as in [`crate::fem::material`]: `[xx, yy, zz, xy, yz, zx]`.

use rayon::prelude::*;

use super::element::{shape_gradients, strain};
use super::error::Result;
use super::material::Material;
use super::mesh::TetMesh;
use super::quadrature::TET4;
use super::shape::TET10_EDGES;

/// Which corner-extrapolation matrix to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Extrapolation {
    /// The exact inverse of the 4-point rule's volume coordinates (rows sum to 1).
    #[default]
    Exact,
    /// CalculiX's `a4` as printed in `extrapolate.f` (1.92705, −0.30902; rows sum to 0.99999).
    CalculiX,
}

impl Extrapolation {
    /// (diagonal, off-diagonal) of the 4 × 4 corner-extrapolation matrix.
    pub fn coefficients(self) -> (f64, f64) {
        match self {
            Extrapolation::Exact => {
                let s5 = 5.0_f64.sqrt();
                let b = (5.0 - s5) / 20.0;
                (s5 * (1.0 - b), -s5 * b)
            }
            Extrapolation::CalculiX => (1.927_05, -0.309_02),
        }
    }
}

/// Stresses of one solution at the integration points and at the nodes.
#[derive(Clone, Debug)]
pub struct NodalStress {
    /// σ at the four integration points of each element ([`TET4`] order).
    pub integration_points: Vec<[[f64; 6]; 4]>,
    /// σ per node: extrapolated per element and averaged without weights (nodes used by no
    /// element: zero).
    pub nodal: Vec<[f64; 6]>,
}

/// σ at the 4-point rule's integration points, extrapolated and averaged as CalculiX does (see the
/// module documentation), for the displacements `u` (3 per node).
pub fn calculix_nodal_stress(
    mesh: &TetMesh,
    material: &Material,
    u: &[f64],
    extrapolation: Extrapolation,
) -> Result<NodalStress> {
    let integration_points: Vec<[[f64; 6]; 4]> = (0..mesh.n_elements())
        .into_par_iter()
        .map(|e| {
            let x = mesh.element_coords(e);
            let ue = mesh.element_displacements(e, u);
            let mut out = [[0.0; 6]; 4];
            for (k, xi) in TET4.points.iter().enumerate() {
                let (g, _) = shape_gradients(&x, *xi, e, "integration point")?;
                out[k] = material.stress(&strain(&g, &ue));
            }
            Ok(out)
        })
        .collect::<Result<_>>()?;
    let (diag, off) = extrapolation.coefficients();
    let mut sum = vec![[0.0; 6]; mesh.n_nodes()];
    let mut count = vec![0u32; mesh.n_nodes()];
    for (el, ip) in mesh.elements().iter().zip(&integration_points) {
        let mut node = [[0.0; 6]; 10];
        for (j, nj) in node.iter_mut().take(4).enumerate() {
            *nj = std::array::from_fn(|c| {
                (0..4)
                    .map(|l| if l == j { diag } else { off } * ip[l][c])
                    .sum()
            });
        }
        for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
            node[4 + k] = std::array::from_fn(|c| 0.5 * (node[*a][c] + node[*b][c]));
        }
        for a in 0..10 {
            for c in 0..6 {
                sum[el[a]][c] += node[a][c];
            }
            count[el[a]] += 1;
        }
    }
    let nodal = nodal_mean(&sum, &count);
    Ok(NodalStress {
        integration_points,
        nodal,
    })
}

/// Per node the mean of the values its elements gave it (`sum` over `count` elements; zero on
/// a node of no element).
pub fn nodal_mean(sum: &[[f64; 6]], count: &[u32]) -> Vec<[f64; 6]> {
    sum.iter()
        .zip(count)
        .map(|(s, &n)| {
            if n == 0 {
                [0.0; 6]
            } else {
                s.map(|v| v / f64::from(n))
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_rows_sum_to_one_and_calculix_rounds_them() {
        let (d, o) = Extrapolation::Exact.coefficients();
        assert!((d + 3.0 * o - 1.0).abs() < 1e-15);
        assert!((d - 1.927_05).abs() < 1e-5 && (o + 0.309_02).abs() < 1e-5);
        let (d, o) = Extrapolation::CalculiX.coefficients();
        assert!((d + 3.0 * o - 0.999_99).abs() < 1e-12);
    }
}
