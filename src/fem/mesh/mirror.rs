//! A half model's mesh mirrored into the whole: the mesh of the part at z ≥ c, whose face on the
//! plane z = c is the symmetry plane, and its mirror image, joined at the plane's nodes.
//!
//! The image of node (x, y, z) is (x, y, 2c − z); a node on the plane is its own image and is
//! shared. A mirror image reverses orientation, so each image element lists its corners 0, 2, 1,
//! 3 (VTK tetra10), and its midside nodes follow their edges: 4 (0–1) ↔ 6 (2–0), 5 (1–2) stays,
//! 7 (0–3) stays, 8 (1–3) ↔ 9 (2–3). A vector field of the half (a displacement) maps to the image
//! as (u_x, u_y, −u_z); under the symmetry condition u_z = 0 on the plane the two agree there.

use super::TetMesh;
use crate::fem::boundary::boundary_faces;
use crate::fem::error::{FemError, Result};

/// The node order of an element's mirror image (VTK tetra10).
const IMAGE_ORDER: [usize; 10] = [0, 2, 1, 3, 6, 5, 4, 7, 9, 8];

/// A half mesh mirrored into the whole ([`mirror`]).
#[derive(Clone, Debug)]
pub struct MirroredMesh {
    /// The whole mesh: the half's nodes first (in their order), then the images of the nodes off
    /// the plane; the half's elements first, then their images.
    pub whole: TetMesh,
    /// The plane's nodes (indices of the half, which the whole shares).
    pub plane_nodes: Vec<usize>,
    /// For each node of the whole: the node of the half it is, or is the image of.
    pub source: Vec<usize>,
    /// Nodes of the half.
    pub half_nodes: usize,
}

impl MirroredMesh {
    /// A vector field of the half (3 per node) on the whole: the images' z components reversed.
    pub fn mirror_vector(&self, half: &[f64]) -> Vec<f64> {
        let mut whole = Vec::with_capacity(3 * self.source.len());
        for (n, &s) in self.source.iter().enumerate() {
            let sign = if n < self.half_nodes { 1.0 } else { -1.0 };
            whole.extend([half[3 * s], half[3 * s + 1], sign * half[3 * s + 2]]);
        }
        whole
    }

    /// A nodal force field of the half (forces, reactions; 3 per node) on the whole: a node off
    /// the plane carries its own force, its image the mirror image; a plane node carries the
    /// forces of both halves, twice the in-plane components of the half's, and no z component
    /// (the two halves' cancel).
    pub fn mirror_forces(&self, half: &[f64]) -> Vec<f64> {
        let mut whole = self.mirror_vector(half);
        for &n in &self.plane_nodes {
            whole[3 * n] *= 2.0;
            whole[3 * n + 1] *= 2.0;
            whole[3 * n + 2] = 0.0;
        }
        whole
    }
}

/// The mesh `half` (of the part at z ≥ `c`, m) and its mirror image in the plane z = `c`. The
/// plane's nodes are those of the boundary faces lying in the plane (within `tolerance`, m); they
/// are put on it exactly. Refused: a half with no face on the plane, or with nodes below it.
pub fn mirror(half: &TetMesh, c: f64, tolerance: f64) -> Result<MirroredMesh> {
    let nodes = half.nodes();
    if let Some((i, p)) = nodes.iter().enumerate().find(|(_, p)| p[2] < c - tolerance) {
        return Err(FemError::InvalidMesh(format!(
            "the half model's node {i} at z = {:.6} mm lies below its symmetry plane z = {:.6} mm",
            p[2] * 1e3,
            c * 1e3
        )));
    }
    let on_plane = |n: usize| (nodes[n][2] - c).abs() <= tolerance;
    let mut plane = vec![false; nodes.len()];
    for f in boundary_faces(half)? {
        if f.nodes.iter().all(|&n| on_plane(n)) {
            for &n in &f.nodes {
                plane[n] = true;
            }
        }
    }
    let plane_nodes: Vec<usize> = (0..nodes.len()).filter(|&n| plane[n]).collect();
    if plane_nodes.is_empty() {
        return Err(FemError::InvalidMesh(format!(
            "the half model has no face on its symmetry plane z = {:.6} mm",
            c * 1e3
        )));
    }
    let mut whole_nodes: Vec<[f64; 3]> = nodes
        .iter()
        .enumerate()
        .map(|(n, p)| if plane[n] { [p[0], p[1], c] } else { *p })
        .collect();
    let mut source: Vec<usize> = (0..nodes.len()).collect();
    let mut image = vec![usize::MAX; nodes.len()];
    for (n, p) in nodes.iter().enumerate() {
        image[n] = if plane[n] {
            n
        } else {
            whole_nodes.push([p[0], p[1], 2.0 * c - p[2]]);
            source.push(n);
            whole_nodes.len() - 1
        };
    }
    let mut elements = half.elements().to_vec();
    elements.extend(
        half.elements()
            .iter()
            .map(|el| IMAGE_ORDER.map(|a| image[el[a]])),
    );
    Ok(MirroredMesh {
        whole: TetMesh::new(whole_nodes, elements)?,
        plane_nodes,
        source,
        half_nodes: nodes.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::QuadratureChoice;
    use crate::fem::mesh::structured::{box_tet10, signed_volume};

    /// A box on z ∈ [0, 2] mirrored in z = 0: the whole spans [−2, 2] with twice the volume,
    /// every element positive, the plane's nodes shared (the whole has 2n − n_plane nodes).
    #[test]
    fn a_box_mirrored_is_twice_the_box() {
        let half = box_tet10(1.0, 1.5, 2.0, 2, 3, 4).unwrap();
        let m = mirror(&half, 0.0, 1e-12).unwrap();
        let (lo, hi) = m.whole.bounding_box();
        assert_eq!((lo[2], hi[2]), (-2.0, 2.0));
        let vol = |mesh: &TetMesh| {
            mesh.elements()
                .iter()
                .map(|el| signed_volume(mesh.nodes(), &[el[0], el[1], el[2], el[3]]) / 6.0)
                .sum::<f64>()
        };
        assert!((vol(&m.whole) - 2.0 * vol(&half)).abs() < 1e-12);
        assert!(
            m.whole
                .check_jacobians(QuadratureChoice::default())
                .unwrap()
                > 0.0
        );
        // (2·2+1)·(2·3+1) nodes of the quadratic grid in the plane
        assert_eq!(m.plane_nodes.len(), 5 * 7);
        assert_eq!(m.whole.n_nodes(), 2 * half.n_nodes() - m.plane_nodes.len());
        // a field (x, y, z) maps to its image with z reversed
        let u: Vec<f64> = half.nodes().iter().flat_map(|p| *p).collect();
        let w = m.mirror_vector(&u);
        for (n, p) in m.whole.nodes().iter().enumerate() {
            let s = half.nodes()[m.source[n]];
            assert_eq!([w[3 * n], w[3 * n + 1]], [s[0], s[1]]);
            assert_eq!(w[3 * n + 2].abs(), p[2].abs());
        }
    }

    #[test]
    fn a_half_below_its_plane_or_off_it_is_refused() {
        let half = box_tet10(1.0, 1.0, 1.0, 1, 1, 2).unwrap();
        let e = mirror(&half, 0.5, 1e-9).unwrap_err().to_string();
        assert!(e.contains("below its symmetry plane"), "{e}");
        let e = mirror(&half, -0.5, 1e-9).unwrap_err().to_string();
        assert!(e.contains("no face on its symmetry plane"), "{e}");
    }
}
