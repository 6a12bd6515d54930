//! Validating that a welded mesh bounds one solid: the precondition of exact mass properties.
//!
//! The divergence theorem turns volume integrals into sums over the boundary triangles only if
//! the triangles form a closed, edge-manifold, consistently and outward oriented surface. The
//! checks, in the order reported: no degenerate triangles; every edge used by exactly two
//! triangles (closed, manifold); each such edge traversed in opposite directions by its two
//! triangles (consistent orientation); positive enclosed volume. A consistently inward-facing
//! surface is flipped, with a warning; anything else is refused.
//!
//! Several bodies in one file (a rod and its cap exported together): the divergence theorem
//! holds shell by shell, so the mass properties of disjoint closed shells simply add. Several
//! closed, consistently oriented shells of the same orientation are accepted as one bonded
//! body, with a warning; shells of opposite orientations (a body inside out, or a cavity whose
//! meaning cannot be checked here) are refused as before. Bodies that touch along a face share
//! its boundary edges, used by four (2k) triangles: such an edge is split into manifold edges
//! by ordering its triangles around it (the radial-edge ordering of non-manifold solid
//! modelling, Weiler 1986): each triangle bounds material on one side, the sequence must
//! alternate between triangles that open and close a material wedge, and at least one of the
//! empty wedges must have zero width (two coincident faces: a face contact). Two solids
//! meeting along an edge only, or edges that do not alternate, stay non-manifold errors.

use super::error::{GapsNote, Location, MeshError};
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
    /// Several bodies of which some do not touch the others: the gap between the nearest two
    /// groups (a lower bound: the distance of their bounding boxes), in the mesh's units.
    pub loose_gap: Option<f64>,
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
    let shells = shells(&mesh, &pairs);
    drop(pairs);
    let mut warnings = Vec::new();
    let (lo, hi) = mesh.bounding_box();
    let box_volume: f64 = (0..3).map(|k| hi[k] - lo[k]).product();
    let mut loose_gap = None;
    if let Some(roots) = shells {
        let (note, gap) = check_shells(&mesh, &roots, box_volume)?;
        warnings.push(note);
        loose_gap = gap;
    }
    if volume.is_nan() || volume.abs() <= 1e-12 * box_volume {
        return Err(MeshError::ZeroVolume { volume });
    }
    if volume < 0.0 {
        mesh.triangles.par_iter_mut().for_each(|t| t.swap(1, 2));
        warnings.push(
            "all triangles faced inward (negative volume); the orientation was flipped".into(),
        );
    }
    Ok(ValidMesh {
        mesh,
        warnings,
        loose_gap,
    })
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
                        ref more => match pair_around_edge(mesh, low as u32, more) {
                            Some(paired) => {
                                for w in paired {
                                    *pairs.next().expect("a slot per use") = w;
                                }
                            }
                            None => found.non_manifold.push((key, more.len())),
                        },
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
        return Err(MeshError::Open {
            count,
            from,
            to,
            gaps: GapsNote(super::gaps::measure_gaps(mesh)),
        });
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

/// Largest width of an empty wedge between two coincident faces [rad] (see the module
/// documentation): the faces of two bodies in contact, equal up to single-precision rounding.
const CONTACT_ANGLE: f64 = 1e-4;

/// The triangles around the edge from vertex `low` to the other vertex of `uses` (each use as
/// filed by [`check_edges`]: other vertex, direction bit, triangle), in pairs bounding one
/// material wedge each, or `None` unless they alternate with a zero-width empty wedge.
fn pair_around_edge(mesh: &IndexedMesh, low: u32, uses: &[u64]) -> Option<Vec<u32>> {
    if uses.len() % 2 == 1 {
        return None;
    }
    let high = (uses[0] >> 32) as u32;
    let p = mesh.vertices[low as usize];
    let d = (mesh.vertices[high as usize] - p).normalize();
    let e1 = d
        .cross(&if d.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        })
        .normalize();
    let e2 = d.cross(&e1);
    // (angle of the third corner about the edge, closes a material wedge, triangle): a triangle
    // traversing low → high has its outward normal towards increasing angle, so material lies
    // just below its angle (it closes a wedge); one traversing high → low opens one.
    let mut around: Vec<(f64, bool, u32)> = uses
        .iter()
        .map(|&w| {
            let t = (w & 0x7fff_ffff) as u32;
            let third = mesh.triangles[t as usize]
                .into_iter()
                .find(|&v| v != low && v != high)
                .expect("a triangle has a third corner");
            let r = mesh.vertices[third as usize] - p;
            (r.dot(&e2).atan2(r.dot(&e1)), (w >> 31) & 1 == 1, t)
        })
        .collect();
    // closers before openers at equal angles: coincident faces leave an empty wedge of width 0
    around.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.cmp(&a.1)).then(a.2.cmp(&b.2)));
    let n = around.len();
    let first = around.iter().position(|x| !x.1)?;
    let mut paired = Vec::with_capacity(n);
    let mut contact = false;
    for k in (0..n).step_by(2) {
        let (open, close) = (around[(first + k) % n], around[(first + k + 1) % n]);
        if open.1 || !close.1 {
            return None;
        }
        let next_open = around[(first + k + 2) % n];
        let empty = (next_open.0 - close.0).rem_euclid(std::f64::consts::TAU);
        contact |= empty <= CONTACT_ANGLE;
        paired.extend([open.2, close.2]);
    }
    contact.then_some(paired)
}

/// Connected components of the triangles across shared edges (union–find with path halving);
/// `pairs` holds two triangle numbers per edge. Each union makes the lower root the root, so
/// every root is the lowest triangle of its shell, whatever the order of the pairs. `None` for
/// one shell, else each triangle's root.
fn shells(mesh: &IndexedMesh, pairs: &[u32]) -> Option<Vec<u32>> {
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
        return None;
    }
    Some(
        (0..parent.len() as u32)
            .map(|i| root(&mut parent, i))
            .collect(),
    )
}

/// Several shells: each must enclose volume, all with the orientation of most of the volume;
/// returns the warning that says they are taken as one body.
fn check_shells(
    mesh: &IndexedMesh,
    roots: &[u32],
    box_volume: f64,
) -> Result<(String, Option<f64>), MeshError> {
    let (lo, hi) = mesh.bounding_box();
    let reference = (lo + hi) / 2.0;
    let mut distinct: Vec<u32> = roots.to_vec();
    distinct.sort_unstable();
    distinct.dedup();
    let mut shell_volume = vec![0.0f64; distinct.len()];
    let mut size = vec![0usize; distinct.len()];
    for (t, r) in roots.iter().enumerate() {
        let k = distinct.binary_search(r).expect("a root");
        let [a, b, c] = mesh.corners(t).map(|p| p - reference);
        shell_volume[k] += a.dot(&b.cross(&c)) / 6.0;
        size[k] += 1;
    }
    // the orientation of most of the volume (outward on a tie) is the body's
    let inward: f64 = shell_volume.iter().filter(|v| **v < 0.0).map(|v| -v).sum();
    let outward: f64 = shell_volume.iter().filter(|v| **v > 0.0).sum();
    let largest: f64 = if inward > outward { -1.0 } else { 1.0 };
    for (k, &v) in shell_volume.iter().enumerate() {
        if v.is_nan() || v.abs() <= 1e-12 * box_volume {
            return Err(MeshError::ZeroVolume { volume: v });
        }
        if v.signum() != largest.signum() {
            let t = distinct[k] as usize;
            return Err(MeshError::MultipleShells {
                count: distinct.len(),
                triangles: size[k],
                at: Location::from(mesh.vertices[mesh.triangles[t][0] as usize]),
            });
        }
    }
    let (groups, gap) = touching_groups(mesh, roots, &distinct);
    if groups == 1 {
        return Ok((
            format!(
                "{} bodies (shells) in one file: treated as one bonded body (their mass properties add)",
                distinct.len()
            ),
            None,
        ));
    }
    Ok((
        format!(
            "{} bodies (shells) in one file, in {groups} groups that do not touch (the nearest \
             two at least {gap:.3} file units apart): their mass properties add, but no load \
             passes between bodies that do not touch, so stage 3 refuses the free body: join \
             them in CAD (rod and cap touch at the joint face) or remove the loose one",
            distinct.len()
        ),
        Some(gap),
    ))
}

/// Groups of shells whose bounding boxes touch or overlap (within 1e-6 of the part's
/// diagonal), joined transitively, and the distance between the bounding boxes of the nearest
/// two groups (0 for one group). Shells of rod and cap meeting at the joint face, or a bolt
/// through its hole, are one group; a body lying apart is another.
fn touching_groups(mesh: &IndexedMesh, roots: &[u32], distinct: &[u32]) -> (usize, f64) {
    let n = distinct.len();
    let mut boxes = vec![
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY)
        );
        n
    ];
    for (t, r) in roots.iter().enumerate() {
        let k = distinct.binary_search(r).expect("a root");
        for p in mesh.corners(t) {
            boxes[k] = (boxes[k].0.inf(&p), boxes[k].1.sup(&p));
        }
    }
    let (lo, hi) = mesh.bounding_box();
    let tolerance = 1e-6 * (hi - lo).norm();
    let gap = |a: &(Vector3<f64>, Vector3<f64>), b: &(Vector3<f64>, Vector3<f64>)| {
        (0..3)
            .map(|k| (a.0[k] - b.1[k]).max(b.0[k] - a.1[k]).max(0.0).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let mut group: Vec<usize> = (0..n).collect();
    loop {
        let mut changed = false;
        for i in 0..n {
            for j in i + 1..n {
                if group[i] != group[j] && gap(&boxes[i], &boxes[j]) <= tolerance {
                    let (keep, drop) = (group[i].min(group[j]), group[i].max(group[j]));
                    group
                        .iter_mut()
                        .filter(|g| **g == drop)
                        .for_each(|g| *g = keep);
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    let mut ids = group.clone();
    ids.sort_unstable();
    ids.dedup();
    let nearest = (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .filter(|&(i, j)| group[i] != group[j])
        .map(|(i, j)| gap(&boxes[i], &boxes[j]))
        .fold(f64::INFINITY, f64::min);
    (ids.len(), if ids.len() > 1 { nearest } else { 0.0 })
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
    fn two_separate_solids_are_one_body_with_a_warning() {
        let a = unit_box();
        let b = transformed(
            &unit_box(),
            &Matrix3::identity(),
            Vector3::new(5.0, 0.0, 0.0),
        );
        let v = validate(union(&a, &b)).unwrap();
        assert_eq!(v.warnings.len(), 1);
        assert!(
            v.warnings[0].starts_with("2 bodies (shells) in one file"),
            "{:?}",
            v.warnings
        );
        assert!((signed_volume(&v.mesh) - 12.0).abs() < 1e-12);
        // both inside out: flipped, both warnings
        let v = validate(flipped(&union(&a, &b))).unwrap();
        assert_eq!(v.warnings.len(), 2);
        assert!(signed_volume(&v.mesh) > 0.0);
        // one of them inside out: refused, the inverted shell located
        let err = validate(union(&a, &flipped(&b))).unwrap_err();
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
    fn bodies_touching_along_a_face_are_one_bonded_body() {
        // a rod and its cap: two boxes sharing the face x = 0.5 (identical corners, so welded
        // into edges of four triangles, and the shared face's two triangles back to back)
        let a = cuboid(Vector3::repeat(1.0), Vector3::zeros());
        let b = cuboid(Vector3::repeat(1.0), Vector3::new(1.0, 0.0, 0.0));
        let m = crate::geometry::weld::weld(&crate::geometry::primitives::to_soup(&union(&a, &b)));
        let v = validate(m).unwrap();
        assert_eq!(v.warnings.len(), 1, "{:?}", v.warnings);
        assert!(v.warnings[0].contains("treated as one bonded body"));
        assert!((signed_volume(&v.mesh) - 2.0).abs() < 1e-12);
        // a smaller second box on the face: the contact face is only part of a face
        let c = cuboid(Vector3::new(1.0, 0.5, 0.5), Vector3::new(1.0, 0.0, 0.0));
        let m = crate::geometry::weld::weld(&crate::geometry::primitives::to_soup(&union(&a, &c)));
        let v = validate(m).unwrap();
        assert!((signed_volume(&v.mesh) - 1.25).abs() < 1e-12);
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
