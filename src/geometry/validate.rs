//! Validating that a welded mesh bounds one solid: the precondition of exact mass properties.
//!
//! The divergence theorem turns volume integrals into sums over the boundary triangles only if
//! the triangles form a closed, edge-manifold, consistently and outward oriented surface. The
//! checks, in the order reported: no degenerate triangles; every edge used by exactly two
//! triangles (closed, manifold); each such edge traversed in opposite directions by its two
//! triangles (consistent orientation); one connected shell; positive enclosed volume. A
//! consistently inward-facing surface is flipped, with a warning; anything else is refused.

use super::error::{Location, MeshError};
use super::mass_properties::signed_volume;
use super::weld::IndexedMesh;
use rayon::prelude::*;

/// A mesh that passed [`validate`], with what had to be done to it.
#[derive(Debug, Clone)]
pub struct ValidMesh {
    pub mesh: IndexedMesh,
    /// Human-readable notes, e.g. that the orientation was flipped.
    pub warnings: Vec<String>,
}

/// Sine of the smallest angle below which a triangle counts as degenerate (collinear corners).
const DEGENERATE_SINE: f64 = 1e-12;

/// Checks the mesh bounds one solid and orients it outward; see the module documentation.
pub fn validate(mut mesh: IndexedMesh) -> Result<ValidMesh, MeshError> {
    if mesh.triangles.is_empty() {
        return Err(MeshError::NoTriangles);
    }
    check_degenerate(&mesh)?;
    let pairs = check_edges(&mesh)?;
    check_one_shell(&mesh, &pairs)?;
    let mut warnings = Vec::new();
    let volume = signed_volume(&mesh);
    let (lo, hi) = mesh.bounding_box();
    let box_volume: f64 = (0..3).map(|k| hi[k] - lo[k]).product();
    if volume.is_nan() || volume.abs() <= 1e-12 * box_volume {
        return Err(MeshError::ZeroVolume { volume });
    }
    if volume < 0.0 {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
        warnings.push(
            "all triangles faced inward (negative volume); the orientation was flipped".into(),
        );
    }
    Ok(ValidMesh { mesh, warnings })
}

fn check_degenerate(mesh: &IndexedMesh) -> Result<(), MeshError> {
    let is_degenerate = |t: usize| {
        let [a, b, c] = mesh.triangles[t];
        if a == b || b == c || a == c {
            return true;
        }
        let [p, q, r] = mesh.corners(t);
        let (u, v, w) = (q - p, r - p, r - q);
        let longest = u.norm_squared().max(v.norm_squared()).max(w.norm_squared());
        u.cross(&v).norm() <= DEGENERATE_SINE * longest
    };
    let bad: Vec<usize> = (0..mesh.triangles.len())
        .into_par_iter()
        .filter(|&t| is_degenerate(t))
        .collect();
    match bad.first() {
        Some(&triangle) => Err(MeshError::Degenerate {
            count: bad.len(),
            triangle,
            at: Location::from(mesh.vertices[mesh.triangles[triangle][0] as usize]),
        }),
        None => Ok(()),
    }
}

/// An edge-use: the undirected edge as `(min << 32) | max`, and whether the triangle runs it
/// from min to max.
#[derive(Clone, Copy)]
struct EdgeUse {
    key: u64,
    forward: bool,
    triangle: u32,
}

/// Pairs of triangles across each interior edge, after checking closedness, manifoldness and
/// orientation.
fn check_edges(mesh: &IndexedMesh) -> Result<Vec<(u32, u32)>, MeshError> {
    let mut uses: Vec<EdgeUse> = mesh
        .triangles
        .par_iter()
        .enumerate()
        .flat_map_iter(|(t, &[a, b, c])| {
            [(a, b), (b, c), (c, a)].map(|(i, j)| EdgeUse {
                key: (u64::from(i.min(j)) << 32) | u64::from(i.max(j)),
                forward: i < j,
                triangle: t as u32,
            })
        })
        .collect();
    uses.par_sort_unstable_by_key(|u| u.key);

    let location = |key: u64| {
        (
            Location::from(mesh.vertices[(key >> 32) as usize]),
            Location::from(mesh.vertices[(key & 0xffff_ffff) as usize]),
        )
    };
    let (mut open, mut non_manifold, mut inconsistent) = (Vec::new(), Vec::new(), Vec::new());
    let mut pairs = Vec::with_capacity(uses.len() / 2);
    for group in uses.chunk_by(|a, b| a.key == b.key) {
        match group {
            [single] => open.push(single.key),
            [first, second] if first.forward == second.forward => inconsistent.push(first.key),
            [first, second] => pairs.push((first.triangle, second.triangle)),
            more => non_manifold.push((more[0].key, more.len())),
        }
    }
    if let Some(&key) = open.first() {
        let (from, to) = location(key);
        return Err(MeshError::Open {
            count: open.len(),
            from,
            to,
        });
    }
    if let Some(&(key, faces)) = non_manifold.first() {
        let (from, to) = location(key);
        return Err(MeshError::NonManifold {
            count: non_manifold.len(),
            faces,
            from,
            to,
        });
    }
    if let Some(&key) = inconsistent.first() {
        let (from, to) = location(key);
        return Err(MeshError::Inconsistent {
            count: inconsistent.len(),
            from,
            to,
        });
    }
    Ok(pairs)
}

/// Connected components of the triangles across shared edges (union–find with path halving).
fn check_one_shell(mesh: &IndexedMesh, pairs: &[(u32, u32)]) -> Result<(), MeshError> {
    let mut parent: Vec<u32> = (0..mesh.triangles.len() as u32).collect();
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    for &(a, b) in pairs {
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        if ra != rb {
            parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
    let roots: Vec<u32> = (0..parent.len() as u32)
        .map(|i| root(&mut parent, i))
        .collect();
    let first_root = roots[0];
    let other: Vec<usize> = (0..roots.len())
        .filter(|&t| roots[t] != first_root)
        .collect();
    let Some(&example) = other.first() else {
        return Ok(());
    };
    let mut distinct = roots.clone();
    distinct.sort_unstable();
    distinct.dedup();
    let example_root = roots[example];
    Err(MeshError::MultipleShells {
        count: distinct.len(),
        triangles: roots.iter().filter(|&&r| r == example_root).count(),
        at: Location::from(mesh.vertices[mesh.triangles[example][0] as usize]),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitives::{cuboid, flipped, torus, transformed, voxel_rod};
    use nalgebra::{Matrix3, Vector3};

    fn unit_box() -> IndexedMesh {
        cuboid(Vector3::new(1.0, 2.0, 3.0), Vector3::zeros())
    }

    /// Two meshes side by side as one (indices of the second shifted).
    fn union(a: &IndexedMesh, b: &IndexedMesh) -> IndexedMesh {
        let offset = a.vertices.len() as u32;
        let mut m = a.clone();
        m.vertices.extend(&b.vertices);
        m.triangles
            .extend(b.triangles.iter().map(|t| t.map(|i| i + offset)));
        m
    }

    #[test]
    fn valid_solids_pass_untouched() {
        for mesh in [unit_box(), torus(1.0, 0.3, 24, 12), voxel_rod().0] {
            let v = validate(mesh.clone()).unwrap();
            assert!(v.warnings.is_empty());
            assert_eq!(v.mesh, mesh);
        }
    }

    #[test]
    fn inverted_mesh_is_flipped_with_a_warning() {
        let v = validate(flipped(&voxel_rod().0)).unwrap();
        assert_eq!(v.warnings.len(), 1);
        assert!(v.warnings[0].contains("flipped"));
        assert!(signed_volume(&v.mesh) > 0.0);
    }

    #[test]
    fn open_mesh_is_refused_with_count_and_location() {
        let mut m = unit_box();
        m.triangles.pop();
        let err = validate(m).unwrap_err();
        assert!(matches!(err, MeshError::Open { count: 3, .. }), "{err}");
        assert!(
            err.to_string().contains("open mesh: 3 boundary edge(s)"),
            "{err}"
        );
    }

    #[test]
    fn one_flipped_triangle_is_inconsistent_orientation() {
        let mut m = torus(1.0, 0.3, 24, 12);
        m.triangles[7].swap(0, 1);
        let err = validate(m).unwrap_err();
        assert!(
            matches!(err, MeshError::Inconsistent { count: 3, .. }),
            "{err}"
        );
    }

    #[test]
    fn boxes_sharing_an_edge_are_non_manifold() {
        // Two cubes touching along one edge: that edge is used by four triangles.
        let a = cuboid(Vector3::repeat(1.0), Vector3::zeros());
        let b = cuboid(Vector3::repeat(1.0), Vector3::new(1.0, 1.0, 0.0));
        let mut m = union(&a, &b);
        // Weld the shared corners so the edge is one edge of the mesh.
        m = crate::geometry::weld::weld(&crate::geometry::primitives::to_soup(&m));
        let err = validate(m).unwrap_err();
        assert!(
            matches!(err, MeshError::NonManifold { faces: 4, .. }),
            "{err}"
        );
    }

    #[test]
    fn two_separate_solids_are_two_shells() {
        let a = unit_box();
        let b = transformed(
            &unit_box(),
            &Matrix3::identity(),
            Vector3::new(5.0, 0.0, 0.0),
        );
        let err = validate(union(&a, &b)).unwrap_err();
        assert!(
            matches!(
                err,
                MeshError::MultipleShells {
                    count: 2,
                    triangles: 12,
                    ..
                }
            ),
            "{err}"
        );
        assert!(
            err.to_string().contains("(5.5"),
            "location of the second shell: {err}"
        );
    }

    #[test]
    fn degenerate_triangles_are_refused() {
        let mut m = unit_box();
        m.triangles[0][1] = m.triangles[0][0];
        assert!(matches!(
            validate(m).unwrap_err(),
            MeshError::Degenerate {
                count: 1,
                triangle: 0,
                ..
            }
        ));
        // Collinear corners: a zero-area sliver added into an otherwise closed box.
        let mut m = unit_box();
        let mid = (m.vertices[0] + m.vertices[1]) / 2.0;
        m.vertices.push(mid);
        let k = (m.vertices.len() - 1) as u32;
        m.triangles.push([0, 1, k]);
        assert!(matches!(
            validate(m).unwrap_err(),
            MeshError::Degenerate { .. }
        ));
    }

    #[test]
    fn flat_closed_surface_has_no_volume() {
        // A "solid" folded flat: two triangles back to back.
        let m = IndexedMesh {
            vertices: vec![Vector3::zeros(), Vector3::x(), Vector3::y()],
            triangles: vec![[0, 1, 2], [0, 2, 1]],
        };
        assert!(matches!(
            validate(m).unwrap_err(),
            MeshError::ZeroVolume { .. }
        ));
    }
}
