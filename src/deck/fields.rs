//! Stresses and strains of a deck's solution at the integration points and at the nodes, formed
//! as CalculiX forms them (`extrapolate.f`, ccx 2.x; see [`crate::fem::nodal_stress`] for the
//! C3D10 matrix): per element the integration-point values extrapolated to the corners (C3D10:
//! the 4 × 4 matrix of [`Extrapolation`]; C3D4: its one point's value at every corner), C3D10
//! midside nodes the mean of their edge's corners, every node the unweighted mean over the
//! elements that share it. Components `[xx, yy, zz, xy, yz, zx]` here (tensor shear strains,
//! ccx's E).

use super::system::DeckSystem;
use crate::fem::nodal_stress::{Extrapolation, nodal_mean};
use crate::fem::shape::TET10_EDGES;
use crate::fem::solid_element::strain;

/// Integration-point and nodal values of one field.
pub struct Field {
    /// Per element, per integration point.
    pub points: Vec<Vec<[f64; 6]>>,
    /// Per deck node (zero where no element).
    pub nodal: Vec<[f64; 6]>,
}

/// Strain (`stress = false`) or stress at the integration points and nodes for the
/// displacements `u` (3 per deck node).
pub fn field(sys: &DeckSystem, u: &[f64], stress: bool, extrapolation: Extrapolation) -> Field {
    let points: Vec<Vec<[f64; 6]>> = sys
        .points
        .iter()
        .zip(&sys.connectivity)
        .zip(&sys.material)
        .map(|((pts, nodes), (mat, _))| {
            let ue: Vec<f64> = nodes
                .iter()
                .flat_map(|&n| (0..3).map(move |j| u[3 * n + j]))
                .collect();
            pts.iter()
                .map(|p| {
                    let eps = strain(p, &ue);
                    if stress { mat.stress(&eps) } else { eps }
                })
                .collect()
        })
        .collect();
    let (diag, off) = extrapolation.coefficients();
    let mut sum = vec![[0.0; 6]; sys.used.len()];
    let mut count = vec![0u32; sys.used.len()];
    for (nodes, ip) in sys.connectivity.iter().zip(&points) {
        let mut node = vec![[0.0; 6]; nodes.len()];
        if ip.len() == 1 {
            node.fill(ip[0]);
        } else {
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
        }
        for (a, &n) in nodes.iter().enumerate() {
            for c in 0..6 {
                sum[n][c] += node[a][c];
            }
            count[n] += 1;
        }
    }
    let nodal = nodal_mean(&sum, &count);
    Field { points, nodal }
}
