//! Facets that cross or overlap each other: a surface that intersects itself bounds no solid, and
//! gmsh refuses to mesh it ("Invalid boundary mesh (overlapping facets)").
//!
//! Candidate pairs come from a uniform grid of cells twice the mean edge length: each triangle is
//! filed in the cells its bounding box touches, and a pair is tested once, in the first cell the two
//! boxes share. Triangles that share a vertex are neighbours and skipped. The test of a pair is
//! Möller's interval test ("A fast triangle-triangle intersection test", J. Graphics Tools 2(2),
//! 1997): the signed distances of each triangle's corners from the other's plane must change sign,
//! beyond the welding tolerance on both sides (an STL's single-precision rounding), and the two
//! triangles' intervals on the line where the planes meet must overlap by more than it. Coplanar pairs (every distance within the tolerance) overlap
//! when a corner of one lies strictly inside the other or two edges cross, in the plane of the
//! larger projection, and face the same way (coplanar facets facing each other are two bodies
//! touching at a face, as rod and cap at the joint face).

use super::weld::{IndexedMesh, near_weld_tolerance};
use nalgebra::{Vector2, Vector3};
use rayon::prelude::*;
use std::collections::HashMap;

/// Facets that cross: how many pairs, and the first (triangle numbers and a point of the crossing).
#[derive(Debug, Clone, PartialEq)]
pub struct Crossing {
    pub pairs: usize,
    pub triangles: (usize, usize),
    pub at: Vector3<f64>,
}

/// The crossing facets of `mesh`, `None` when no two facets cross.
pub fn crossing_facets(mesh: &IndexedMesh) -> Option<Crossing> {
    let n = mesh.triangles.len();
    if n < 2 {
        return None;
    }
    let (lo, _) = mesh.bounding_box();
    let eps = near_weld_tolerance(mesh);
    let mean_edge = (0..n)
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            (b - a).norm() + (c - b).norm() + (a - c).norm()
        })
        .sum::<f64>()
        / (3 * n) as f64;
    let cell = 2.0 * mean_edge.max(eps);
    let key = |p: Vector3<f64>| -> [i64; 3] {
        std::array::from_fn(|k| ((p[k] - lo[k]) / cell).floor() as i64)
    };
    let boxes: Vec<([i64; 3], [i64; 3])> = (0..n)
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            let (l, h) = (a.inf(&b).inf(&c), a.sup(&b).sup(&c));
            (key(l), key(h))
        })
        .collect();
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    for (t, (l, h)) in boxes.iter().enumerate() {
        for x in l[0]..=h[0] {
            for y in l[1]..=h[1] {
                for z in l[2]..=h[2] {
                    grid.entry([x, y, z]).or_default().push(t as u32);
                }
            }
        }
    }
    let cells: Vec<(&[i64; 3], &Vec<u32>)> = grid.iter().filter(|(_, v)| v.len() > 1).collect();
    let mut found: Vec<(usize, usize, Vector3<f64>)> = cells
        .par_iter()
        .flat_map_iter(|(c, members)| {
            let mut out = Vec::new();
            for (i, &s) in members.iter().enumerate() {
                for &t in &members[i + 1..] {
                    let (s, t) = (s.min(t) as usize, s.max(t) as usize);
                    // tested in the first cell the two boxes share only
                    let first: [i64; 3] = std::array::from_fn(|k| boxes[s].0[k].max(boxes[t].0[k]));
                    if first != **c {
                        continue;
                    }
                    let (p, q) = (mesh.triangles[s], mesh.triangles[t]);
                    if p.iter().any(|v| q.contains(v)) {
                        continue;
                    }
                    if let Some(at) = cross(mesh.corners(s), mesh.corners(t), eps) {
                        out.push((s, t, at));
                    }
                }
            }
            out
        })
        .collect();
    found.sort_by_key(|a| (a.0, a.1));
    let &(s, t, at) = found.first()?;
    Some(Crossing {
        pairs: found.len(),
        triangles: (s, t),
        at,
    })
}

/// A point where triangles `a` and `b` cross or overlap, if they do (beyond `eps`).
fn cross(a: [Vector3<f64>; 3], b: [Vector3<f64>; 3], eps: f64) -> Option<Vector3<f64>> {
    let plane = |t: &[Vector3<f64>; 3]| {
        let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
        let len = n.norm();
        (len > 0.0).then(|| n / len)
    };
    let (na, nb) = (plane(&a)?, plane(&b)?);
    let da = a.map(|p| nb.dot(&(p - b[0])));
    let db = b.map(|p| na.dot(&(p - a[0])));
    if da.iter().all(|x| x.abs() <= eps) && db.iter().all(|x| x.abs() <= eps) {
        // facing each other: two bodies touching at a face (rod and cap), not an overlap
        if na.dot(&nb) < 0.0 {
            return None;
        }
        return coplanar_overlap(a, b, na, eps);
    }
    // each must reach through the other's plane by more than the tolerance on both sides (facets
    // of one flat face, rounded to single precision, are coplanar only to that)
    let straddles = |d: &[f64; 3]| d.iter().any(|&x| x > eps) && d.iter().any(|&x| x < -eps);
    if !(straddles(&da) && straddles(&db)) {
        return None;
    }
    // the line where the planes meet, and each triangle's segment on it (the points where its
    // edges pass through the other's plane, ordered along the line)
    let dir = na.cross(&nb);
    if dir.norm() <= eps {
        return None;
    }
    let segment = |t: &[Vector3<f64>; 3], d: &[f64; 3]| -> Option<(Vector3<f64>, Vector3<f64>)> {
        let mut pts = Vec::with_capacity(3);
        for (i, j) in [(0, 1), (1, 2), (2, 0)] {
            let (di, dj) = (d[i], d[j]);
            if (di > eps && dj < -eps) || (di < -eps && dj > eps) {
                pts.push(t[i] + (t[j] - t[i]) * (di / (di - dj)));
            } else if di.abs() <= eps {
                pts.push(t[i]);
            }
        }
        let along = |p: &&Vector3<f64>| dir.dot(p);
        let first = *pts.iter().min_by(|p, q| along(p).total_cmp(&along(q)))?;
        let last = *pts.iter().max_by(|p, q| along(p).total_cmp(&along(q)))?;
        Some((first, last))
    };
    let (a0, a1) = segment(&a, &da)?;
    let (b0, b1) = segment(&b, &db)?;
    let (sa0, sa1) = (dir.dot(&a0), dir.dot(&a1));
    let (lo, hi) = (sa0.max(dir.dot(&b0)), sa1.min(dir.dot(&b1)));
    if hi - lo <= eps * dir.norm() {
        return None;
    }
    // a point of the overlap: on a's segment, at the middle of the common interval
    let mid = (lo + hi) / 2.0;
    Some(if sa1 > sa0 {
        a0 + (a1 - a0) * ((mid - sa0) / (sa1 - sa0))
    } else {
        a0
    })
}

/// Two coplanar triangles overlap (beyond touching): a corner strictly inside the other, or two
/// edges crossing at interior points; in the coordinate plane of the larger projection.
fn coplanar_overlap(
    a: [Vector3<f64>; 3],
    b: [Vector3<f64>; 3],
    normal: Vector3<f64>,
    eps: f64,
) -> Option<Vector3<f64>> {
    let k = normal.iamax();
    let (u, v) = ((k + 1) % 3, (k + 2) % 3);
    let flat = |p: Vector3<f64>| Vector2::new(p[u], p[v]);
    let (pa, pb) = (a.map(flat), b.map(flat));
    let cross2 = |o: Vector2<f64>, p: Vector2<f64>, q: Vector2<f64>| (p - o).perp(&(q - o));
    // strictly inside: beyond eps from each edge line (the cross product is the edge's length
    // times the distance)
    let inside = |p: Vector2<f64>, t: &[Vector2<f64>; 3]| {
        let s = cross2(t[0], t[1], t[2]).signum();
        (0..3).all(|i| s * cross2(t[i], t[(i + 1) % 3], p) > eps * (t[(i + 1) % 3] - t[i]).norm())
    };
    for (i, p) in pa.iter().enumerate() {
        if inside(*p, &pb) {
            return Some(a[i]);
        }
    }
    for (i, p) in pb.iter().enumerate() {
        if inside(*p, &pa) {
            return Some(b[i]);
        }
    }
    for i in 0..3 {
        for j in 0..3 {
            let (p, q) = (pa[i], pa[(i + 1) % 3]);
            let (r, s) = (pb[j], pb[(j + 1) % 3]);
            let (d1, d2) = (cross2(p, q, r), cross2(p, q, s));
            let (d3, d4) = (cross2(r, s, p), cross2(r, s, q));
            let strict = |x: f64, y: f64| (x > eps && y < -eps) || (x < -eps && y > eps);
            if strict(d1, d2) && strict(d3, d4) {
                let t = d3 / (d3 - d4);
                return Some(a[i] + (a[(i + 1) % 3] - a[i]) * t);
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitives::{cuboid, torus};

    /// Two boxes as one surface, apart, touching at a face and interpenetrating: only the last
    /// crosses (its faces cut each other along the overlap's edges); closed solids of their own
    /// (a box, a torus) never cross themselves.
    #[test]
    fn crossings_are_found_where_they_are_and_nowhere_else() {
        let join = |a: &IndexedMesh, b: &IndexedMesh| {
            let mut m = a.clone();
            let k = m.vertices.len() as u32;
            m.vertices.extend(&b.vertices);
            m.triangles
                .extend(b.triangles.iter().map(|t| t.map(|i| i + k)));
            m
        };
        let unit = Vector3::new(10.0, 10.0, 10.0);
        let a = cuboid(unit, Vector3::zeros());
        assert_eq!(crossing_facets(&a), None);
        assert_eq!(crossing_facets(&torus(3.0, 1.0, 48, 24)), None);
        let apart = join(&a, &cuboid(unit, Vector3::new(20.0, 0.0, 0.0)));
        assert_eq!(crossing_facets(&apart), None);
        let through = join(&a, &cuboid(unit, Vector3::new(5.0, 3.0, 2.0)));
        let c = crossing_facets(&through).expect("the boxes cut each other");
        assert!(c.pairs >= 4, "{c:?}");
        // the crossing lies on the surface of both boxes' overlap region [0, 5]×[-2, 5]×[-3, 5]
        assert!(
            (0..3).all(|k| c.at[k] >= -5.0 - 1e-9 && c.at[k] <= 5.0 + 1e-9),
            "{c:?}"
        );
    }

    /// A triangle lying on another in the same plane (a facet written twice, shifted) overlaps.
    #[test]
    fn coplanar_overlap_is_found() {
        let v = |x: f64, y: f64| Vector3::new(x, y, 0.0);
        let a = [v(0.0, 0.0), v(4.0, 0.0), v(0.0, 4.0)];
        let b = [v(1.0, 1.0), v(5.0, 1.0), v(1.0, 5.0)];
        assert!(cross(a, b, 1e-12).is_some());
        let far = [v(10.0, 0.0), v(14.0, 0.0), v(10.0, 4.0)];
        assert!(cross(a, far, 1e-12).is_none());
    }
}
