//! The boundary surface of a tet10 mesh as linear triangles (positions in mm), the surface the
//! pictures are drawn on.

use crate::fem::boundary::boundary_faces;
use crate::fem::mesh::TetMesh;

/// Vertices (mm) and triangles of a surface, as [`tet10_surface`] returns them.
pub type SurfaceMesh = (Vec<[f64; 3]>, Vec<[usize; 3]>);

/// Boundary surface of a tet10 mesh as linear triangles, positions in mm.
///
/// Returns all mesh nodes converted from metres to mm (same indices as the mesh, so a nodal field
/// such as the averaged von Mises stress can be passed as [`SurfaceField::values`](super::SurfaceField::values) unchanged;
/// interior nodes are simply not referenced) and the triangles: each 6-node boundary face (corners
/// c0 c1 c2, midside m01 m12 m20) is split into (c0, m01, m20), (m01, c1, m12), (m20, m12, c2) and
/// (m01, m12, m20), all oriented like the face (outward normal).
pub fn tet10_surface(mesh: &TetMesh) -> crate::fem::Result<SurfaceMesh> {
    let faces = boundary_faces(mesh)?;
    let vertices = mesh
        .nodes()
        .iter()
        .map(|p| [p[0] * 1e3, p[1] * 1e3, p[2] * 1e3])
        .collect();
    let mut triangles = Vec::with_capacity(4 * faces.len());
    for f in &faces {
        let [c0, c1, c2, m01, m12, m20] = f.nodes;
        triangles.extend_from_slice(&[
            [c0, m01, m20],
            [m01, c1, m12],
            [m20, m12, c2],
            [m01, m12, m20],
        ]);
    }
    Ok((vertices, triangles))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::picture::test_util::single_tet10;
    use nalgebra::Vector3;

    #[test]
    fn tet10_surface_of_one_tet() {
        let mesh = single_tet10();
        let (v, t) = tet10_surface(&mesh).unwrap();
        assert_eq!(v.len(), 10);
        assert_eq!(t.len(), 16);
        for (p, q) in v.iter().zip(mesh.nodes()) {
            for j in 0..3 {
                assert!((p[j] - 1e3 * q[j]).abs() < 1e-9);
            }
        }
        assert_eq!(v[1], [1000.0, 0.0, 0.0]);
        // every node is used; the triangles tile the surface: total area, equal quarters, outward
        let mut used = [false; 10];
        let centroid = Vector3::repeat(250.0);
        let mut total = 0.0;
        for tri in &t {
            for &i in tri {
                used[i] = true;
            }
            let [a, b, c] = tri.map(|i| Vector3::from(v[i]));
            let n = (b - a).cross(&(c - a));
            let area = 0.5 * n.norm();
            let on_slanted = tri
                .iter()
                .all(|&i| (v[i].iter().sum::<f64>() - 1000.0).abs() < 1e-9);
            let expected = if on_slanted {
                3f64.sqrt() / 2.0 * 1e6
            } else {
                0.5e6
            } / 4.0;
            assert!((area - expected).abs() < 1e-6 * expected, "{tri:?}: {area}");
            assert!(n.dot(&(a - centroid)) > 0.0, "{tri:?} points inwards");
            total += area;
        }
        assert!(used.iter().all(|u| *u));
        assert!((total - (1.5e6 + 3f64.sqrt() / 2.0 * 1e6)).abs() < 1e-3);
    }
}
