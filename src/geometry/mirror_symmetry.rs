//! Whether a closed surface is mirror-symmetric about a plane z = c, and how closely.
//!
//! A connecting rod is usually symmetric about its mid-plane across the pin axis (the plane of
//! the crank–slider's motion through the middle of the rod's thickness): under loads in that
//! plane, the displacement field is symmetric too, and half the rod with u_z = 0 on the plane is
//! the whole problem (the half model of every FE code's symmetry conditions). The test: the
//! candidate plane halves the bounding box in z; every vertex mirrored in it must lie on the
//! surface, within `tolerance` (the distance of the mirrored vertex to the nearest triangle,
//! `parry3d`'s point projection on a BVH of the triangles). A feature on one side only (an oil
//! hole, a chamfer, a boss) shows as its vertices' mirror images inside the material or in the
//! air on the other side, at the feature's depth. Two tessellations of the same symmetric
//! surface differ by their chordal error, which the tolerance has to admit.

use nalgebra::Vector3;
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::TriMesh;
use rayon::prelude::*;

use super::weld::IndexedMesh;

/// How well a surface fits its mirror image in the plane z = `z`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MirrorFit {
    /// The plane (the middle of the surface's extent in z), in the surface's units.
    pub z: f64,
    /// The largest distance of a vertex's mirror image from the surface.
    pub max_deviation: f64,
    /// Where the largest deviation is (the vertex or triangle centroid, not its image).
    pub worst_point: [f64; 3],
}

impl MirrorFit {
    /// Whether the surface is symmetric within `tolerance` (its units).
    pub fn is_symmetric(&self, tolerance: f64) -> bool {
        self.max_deviation <= tolerance
    }
}

/// The fit of `mesh` (closed) to its mirror image in the plane halving its extent in z; `None`
/// for a surface without triangles.
pub fn mirror_fit_z(mesh: &IndexedMesh) -> Option<MirrorFit> {
    if mesh.triangles.is_empty() {
        return None;
    }
    let (lo, hi) = mesh.bounding_box();
    let z = 0.5 * (lo.z + hi.z);
    let vertices: Vec<PVec> = mesh
        .vertices
        .iter()
        .map(|v| PVec::new(v.x, v.y, v.z))
        .collect();
    let surface = TriMesh::new(vertices, mesh.triangles.clone()).ok()?;
    // the vertices and the triangles' centroids: a one-sided feature whose vertices all mirror
    // onto faces (a slanted hole with vertices at its rims only) shows at its walls' centroids
    let points: Vec<Vector3<f64>> = mesh
        .vertices
        .iter()
        .copied()
        .chain((0..mesh.triangles.len()).map(|t| {
            let [a, b, c] = mesh.corners(t);
            (a + b + c) / 3.0
        }))
        .collect();
    let (max_deviation, worst) = points
        .par_iter()
        .map(|v| {
            let image = PVec::new(v.x, v.y, 2.0 * z - v.z);
            (surface.distance_to_local_point(image, false), *v)
        })
        .reduce(
            || (0.0, Vector3::zeros()),
            |a, b| if b.0 > a.0 { b } else { a },
        );
    Some(MirrorFit {
        z,
        max_deviation,
        worst_point: [worst.x, worst.y, worst.z],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitives::{cuboid, hollow_cylinder, voxel_solid};

    #[test]
    fn a_box_and_a_tube_are_symmetric_about_their_middle() {
        let b = cuboid(Vector3::new(3.0, 2.0, 5.0), Vector3::new(0.5, 0.0, 7.0));
        let f = mirror_fit_z(&b).unwrap();
        assert_eq!(f.z, 7.0);
        assert!(f.max_deviation < 1e-12, "{f:?}");
        let t = hollow_cylinder(2.0, 1.0, 4.0, 48);
        let f = mirror_fit_z(&t).unwrap();
        assert!(f.max_deviation < 1e-12 && f.is_symmetric(1e-9), "{f:?}");
    }

    /// A block with a hole through it, slanted: its top rim moved along x by the hole's width, so
    /// that every rim vertex mirrors onto a face (or the hole's rim line) and only the walls'
    /// centroids show the slant.
    #[test]
    fn a_slanted_hole_is_seen_at_its_walls() {
        let mut m = voxel_solid(
            [3, 3, 1],
            Vector3::new(1.0, 1.0, 2.0),
            Vector3::zeros(),
            |i, j, _| !(i == 1 && j == 1),
        );
        for v in &mut m.vertices {
            if v.z == 2.0 && (1.0..=2.0).contains(&v.x) && (1.0..=2.0).contains(&v.y) {
                v.x += 0.5;
            }
        }
        let tri = TriMesh::new(
            m.vertices
                .iter()
                .map(|p| PVec::new(p.x, p.y, p.z))
                .collect(),
            m.triangles.clone(),
        )
        .unwrap();
        let vertices_only = m
            .vertices
            .iter()
            .map(|v| tri.distance_to_local_point(PVec::new(v.x, v.y, 2.0 - v.z), false))
            .fold(0.0f64, f64::max);
        assert!(vertices_only < 1e-12, "{vertices_only}");
        let f = mirror_fit_z(&m).unwrap();
        assert!(f.max_deviation > 0.1 && !f.is_symmetric(0.05), "{f:?}");
    }

    /// A block with a pocket in its top face only: the pocket's floor, mirrored, lies inside the
    /// material below, at the pocket's depth from the bottom face.
    #[test]
    fn a_pocket_on_one_side_is_seen_at_its_depth() {
        // 4 × 4 × 4 voxels of 1, the top layer's middle 2 × 2 removed: a pocket 1 deep
        let m = voxel_solid(
            [4, 4, 4],
            Vector3::new(1.0, 1.0, 1.0),
            Vector3::zeros(),
            |i, j, k| !(k == 3 && (1..3).contains(&i) && (1..3).contains(&j)),
        );
        let f = mirror_fit_z(&m).unwrap();
        assert_eq!(f.z, 2.0);
        assert!((f.max_deviation - 1.0).abs() < 1e-12, "{f:?}");
        assert!(!f.is_symmetric(0.1));
        // the worst vertex is one of the pocket's floor (z = 3) or rim
        assert!(f.worst_point[2] >= 3.0, "{f:?}");
    }
}
