//! Validating that a welded mesh bounds one solid: the precondition of exact mass properties.
//!
//! The divergence theorem turns volume integrals into sums over the boundary triangles only if
//! the triangles form a closed, edge-manifold, consistently and outward oriented surface. The
//! checks, in the order reported: no degenerate triangles; every edge used by exactly two
//! triangles (closed, manifold); each such edge traversed in opposite directions by its two
//! triangles (consistent orientation); one connected shell; positive enclosed volume. A
//! consistently inward-facing surface is flipped, with a warning; anything else is refused.

use super::error::{Location, MeshError};
use super::mass_properties::signed_volume_and_flagged;
use super::weld::IndexedMesh;
use nalgebra::Vector3;
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
    // The volume is summed in the pass that looks for degenerate triangles; it is needed last.
    let volume = check_degenerate(&mesh)?;
    let ranges = rayon::current_num_threads()
        .min(mesh.vertices.len().div_ceil(4096))
        .max(1);
    let pairs = check_edges(&mesh, ranges)?;
    check_one_shell(&mesh, &pairs)?;
    drop(pairs);
    let mut warnings = Vec::new();
    let (lo, hi) = mesh.bounding_box();
    let box_volume: f64 = (0..3).map(|k| hi[k] - lo[k]).product();
    if volume.is_nan() || volume.abs() <= 1e-12 * box_volume {
        return Err(MeshError::ZeroVolume { volume });
    }
    if volume < 0.0 {
        mesh.triangles.par_iter_mut().for_each(|t| t.swap(1, 2));
        warnings.push(
            "all triangles faced inward (negative volume); the orientation was flipped".into(),
        );
    }
    Ok(ValidMesh { mesh, warnings })
}

/// Refuses degenerate triangles; returns the signed volume (that of
/// [`signed_volume`](super::mass_properties::signed_volume), summed in the same pass).
fn check_degenerate(mesh: &IndexedMesh) -> Result<f64, MeshError> {
    // Plain f64 arithmetic, the operations of nalgebra's `q - p`, `norm_squared`, `cross` and
    // `norm` in their order.
    let is_degenerate = |&[a, b, c]: &[u32; 3], &[p, q, r]: &[Vector3<f64>; 3]| {
        if a == b || b == c || a == c {
            return true;
        }
        let minus = |x: Vector3<f64>, y: Vector3<f64>| [x.x - y.x, x.y - y.y, x.z - y.z];
        let (u, v, w) = (minus(q, p), minus(r, p), minus(r, q));
        let squared = |x: [f64; 3]| x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
        let longest = squared(u).max(squared(v)).max(squared(w));
        let cross = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        squared(cross).sqrt() <= DEGENERATE_SINE * longest
    };
    let (volume, bad) = signed_volume_and_flagged(mesh, is_degenerate);
    match bad.first() {
        Some(&triangle) => Err(MeshError::Degenerate {
            count: bad.len(),
            triangle,
            at: Location::from(mesh.vertices[mesh.triangles[triangle][0] as usize]),
        }),
        None => Ok(volume),
    }
}

/// What grouping the edge-uses by edge found in one range of vertices: the defects (each edge
/// as `(min << 32) | max`, in increasing order).
#[derive(Default)]
struct EdgeDefects {
    open: Vec<u64>,
    non_manifold: Vec<(u64, usize)>,
    inconsistent: Vec<u64>,
}

/// The pairs of triangles across the edges, after checking closedness, manifoldness and
/// orientation: a flat list, two triangle numbers per edge, in increasing edge order.
///
/// Every edge-use (three per triangle) is filed under the lower-numbered vertex of its edge by a
/// counting sort, as `3 × triangle + side`; the few uses filed under one vertex are then sorted
/// by the other vertex, which brings the uses of each edge together (this replaces one sort of
/// all 3T uses), and the two uses of each regular edge are overwritten by its two triangles.
/// The vertices are cut into `ranges` ranges, one per thread; each range files its
/// own uses (every range reads all triangles, but writes only its own vertices' slots), so no
/// thread waits for another, and the defects come out in increasing edge order whatever the
/// scheduling.
fn check_edges(mesh: &IndexedMesh, ranges: usize) -> Result<Vec<u32>, MeshError> {
    let (triangles, n) = (&mesh.triangles, mesh.vertices.len());
    assert!(
        triangles.len() < 1 << 30,
        "too many triangles for the edge table"
    );
    let sides = |[a, b, c]: [u32; 3]| [(a, b), (b, c), (c, a)];
    let bounds: Vec<usize> = (0..=ranges).map(|r| r * n / ranges).collect();
    // The uses filed under each vertex, counted range by range.
    let counts: Vec<Vec<u32>> = (0..ranges)
        .into_par_iter()
        .map(|r| {
            let (first, last) = (bounds[r] as u32, bounds[r + 1] as u32);
            let mut count = vec![0u32; (last - first) as usize];
            for &t in triangles {
                for (i, j) in sides(t) {
                    let low = i.min(j);
                    if (first..last).contains(&low) {
                        count[(low - first) as usize] += 1;
                    }
                }
            }
            count
        })
        .collect();
    let mut filed = vec![0u32; 3 * triangles.len()];
    let mut regions = Vec::with_capacity(ranges);
    let mut rest = filed.as_mut_slice();
    for count in &counts {
        let size = count.iter().map(|&c| c as usize).sum();
        let (region, tail) = std::mem::take(&mut rest).split_at_mut(size);
        regions.push(region);
        rest = tail;
    }
    let defects: Vec<EdgeDefects> = regions
        .into_par_iter()
        .zip(counts)
        .enumerate()
        .map(|(r, (region, count))| {
            let first = bounds[r] as u32;
            // Counting sort: `next[v]` is where the next use filed under v goes; once all are
            // filed, it is where v's uses end.
            let mut next = count;
            let mut at = 0;
            for slot in &mut next {
                let c = *slot;
                *slot = at;
                at += c;
            }
            for (t, &tri) in triangles.iter().enumerate() {
                for (side, (i, j)) in sides(tri).into_iter().enumerate() {
                    let low = i.min(j);
                    if (first..first + next.len() as u32).contains(&low) {
                        let slot = &mut next[(low - first) as usize];
                        region[*slot as usize] = 3 * t as u32 + side as u32;
                        *slot += 1;
                    }
                }
            }
            let mut found = EdgeDefects::default();
            let mut uses: Vec<u64> = Vec::new();
            let mut begin = 0;
            for (v, &end) in next.iter().enumerate() {
                let filed_here = &mut region[begin..end as usize];
                begin = end as usize;
                // (other vertex, forward, triangle) of each use, sorted by the other vertex.
                uses.clear();
                uses.extend(filed_here.iter().map(|&code| {
                    let (t, side) = (code / 3, code % 3);
                    let (i, j) = sides(triangles[t as usize])[side as usize];
                    (u64::from(i.max(j)) << 32) | (u64::from(i < j) << 31) | u64::from(t)
                }));
                uses.sort_unstable();
                let low = u64::from(first) + v as u64;
                let mut pairs = filed_here.iter_mut();
                for group in uses.chunk_by(|a, b| a >> 32 == b >> 32) {
                    let key = (low << 32) | (group[0] >> 32);
                    let forward = |w: u64| (w >> 31) & 1 == 1;
                    match *group {
                        [_] => found.open.push(key),
                        [one, other] if forward(one) == forward(other) => {
                            found.inconsistent.push(key)
                        }
                        [one, other] => {
                            for w in [one, other] {
                                *pairs.next().expect("a slot per use") = w as u32 & 0x7fff_ffff;
                            }
                        }
                        ref more => found.non_manifold.push((key, more.len())),
                    }
                }
            }
            found
        })
        .collect();

    let location = |key: u64| {
        (
            Location::from(mesh.vertices[(key >> 32) as usize]),
            Location::from(mesh.vertices[(key & 0xffff_ffff) as usize]),
        )
    };
    let first_of = |pick: fn(&EdgeDefects) -> usize| {
        let count: usize = defects.iter().map(pick).sum();
        (count, defects.iter().position(|d| pick(d) > 0))
    };
    if let (count, Some(d)) = first_of(|d| d.open.len()) {
        let (from, to) = location(defects[d].open[0]);
        return Err(MeshError::Open { count, from, to });
    }
    if let (count, Some(d)) = first_of(|d| d.non_manifold.len()) {
        let (key, faces) = defects[d].non_manifold[0];
        let (from, to) = location(key);
        return Err(MeshError::NonManifold {
            count,
            faces,
            from,
            to,
        });
    }
    if let (count, Some(d)) = first_of(|d| d.inconsistent.len()) {
        let (from, to) = location(defects[d].inconsistent[0]);
        return Err(MeshError::Inconsistent { count, from, to });
    }
    Ok(filed)
}

/// Connected components of the triangles across shared edges (union–find with path halving);
/// `pairs` holds two triangle numbers per edge. Each union makes the lower root the root, so
/// every root is the lowest triangle of its shell, whatever the order of the pairs.
fn check_one_shell(mesh: &IndexedMesh, pairs: &[u32]) -> Result<(), MeshError> {
    let mut parent: Vec<u32> = (0..mesh.triangles.len() as u32).collect();
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    for pair in pairs.chunks_exact(2) {
        let (ra, rb) = (root(&mut parent, pair[0]), root(&mut parent, pair[1]));
        if ra != rb {
            parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
    if (0..parent.len() as u32).all(|i| root(&mut parent, i) == 0) {
        return Ok(());
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
    use crate::geometry::mass_properties::signed_volume;
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
    fn the_edge_check_does_not_depend_on_the_vertex_ranges() {
        let torus = torus(1.0, 0.3, 24, 12);
        let mut open = torus.clone();
        open.triangles.truncate(open.triangles.len() - 7);
        let mut inconsistent = torus.clone();
        inconsistent.triangles[5].swap(0, 1);
        inconsistent.triangles[200].swap(1, 2);
        let a = cuboid(Vector3::repeat(1.0), Vector3::zeros());
        let b = cuboid(Vector3::repeat(1.0), Vector3::new(1.0, 1.0, 0.0));
        let non_manifold =
            crate::geometry::weld::weld(&crate::geometry::primitives::to_soup(&union(&a, &b)));
        let two_shells = union(
            &torus,
            &transformed(&torus, &Matrix3::identity(), Vector3::new(5.0, 0.0, 0.0)),
        );
        for mesh in [torus, open, inconsistent, non_manifold, two_shells] {
            let one = format!("{:?}", check_edges(&mesh, 1));
            for ranges in 2..=5 {
                assert_eq!(format!("{:?}", check_edges(&mesh, ranges)), one);
            }
        }
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
