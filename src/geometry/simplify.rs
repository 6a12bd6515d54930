//! Simplification of a closed triangulated surface to a geometric tolerance, so that what a
//! mesher has to read does not grow with the export's triangle count.
//!
//! Quadric error metrics (Garland & Heckbert, "Surface simplification using quadric error
//! metrics", SIGGRAPH 1997) with half-edge collapses onto an existing vertex (subset placement:
//! every kept vertex is a vertex of the export). Each vertex carries the quadric of the planes of
//! its original incident facets, unweighted, so Q(p) = Σ d_i(p)² over those planes and
//! √Q(p) ≥ the largest distance from p to any of them: a collapse is taken only while that stays
//! within the tolerance. A facet subdivided without moving it (a 1 M-triangle export of the same
//! surface) therefore collapses back to the original facets exactly (zero error), and a genuinely
//! finer tessellation of a curved face is coarsened only until it is `tolerance` away from its
//! own planes.
//!
//! A collapse u → v is refused when it would change the topology (the link condition: u and v
//! share exactly the two vertices opposite their edge), flip a facet (its normal turning by more
//! than 60°), or make a facet thinner than both [`MIN_ANGLE_DEG`] and the thinnest facet around
//! u before the collapse (new slivers are what gmsh's surface classification fails on).
//! Quadrics are evaluated relative to the bounding-box centre; their rounding noise is about
//! 1e-8 of the part's size squared, so tolerances below ~1e-4 of the size are not meaningful. The result is
//! still closed, manifold and consistently oriented; the caller validates it again.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use nalgebra::{Matrix4, Vector3, Vector4};

use super::weld::IndexedMesh;

/// A new facet may not have an angle below this (unless it replaces one that is thinner).
pub const MIN_ANGLE_DEG: f64 = 12.0;

/// What a simplification did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimplifyReport {
    pub triangles_before: usize,
    pub triangles_after: usize,
    /// The largest √Q of a kept vertex: a bound of its distance to the original planes it absorbed.
    pub max_error: f64,
}

/// A vertex u to collapse, with the cost of its cheapest collapse when it was queued.
#[derive(PartialEq)]
struct Candidate {
    cost: f64,
    from: u32,
    stamp: u32,
}

impl Eq for Candidate {}
impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        // a min-heap on cost, ties broken by the vertex numbers (deterministic)
        other
            .cost
            .total_cmp(&self.cost)
            .then_with(|| other.from.cmp(&self.from))
    }
}
impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

fn plane_quadric(a: Vector3<f64>, b: Vector3<f64>, c: Vector3<f64>) -> Option<Matrix4<f64>> {
    let n = (b - a).cross(&(c - a));
    let len = n.norm();
    if len.is_nan() || len <= 0.0 {
        return None;
    }
    let n = n / len;
    let p = Vector4::new(n.x, n.y, n.z, -n.dot(&a));
    Some(p * p.transpose())
}

fn quadric_error(q: &Matrix4<f64>, v: Vector3<f64>) -> f64 {
    let h = Vector4::new(v.x, v.y, v.z, 1.0);
    (h.transpose() * q * h)[(0, 0)].max(0.0)
}

/// The cosine of the smallest angle of a triangle (larger = thinner; 1 for a degenerate one).
fn cos_min_angle(a: Vector3<f64>, b: Vector3<f64>, c: Vector3<f64>) -> f64 {
    let cos = |p: Vector3<f64>, q: Vector3<f64>, r: Vector3<f64>| {
        let (u, v) = (q - p, r - p);
        let d = u.norm() * v.norm();
        if d > 0.0 { u.dot(&v) / d } else { 1.0 }
    };
    cos(a, b, c).max(cos(b, c, a)).max(cos(c, a, b))
}

/// Simplifies `mesh` (closed, manifold, consistently oriented) to `tolerance` (its units).
pub fn simplify(mesh: &IndexedMesh, tolerance: f64) -> (IndexedMesh, SimplifyReport) {
    let nv = mesh.vertices.len();
    let (lo, hi) = mesh.bounding_box();
    let centre = 0.5 * (lo + hi);
    let local: Vec<Vector3<f64>> = mesh.vertices.iter().map(|v| v - centre).collect();
    let pos = &local;
    let mut tris: Vec<[u32; 3]> = mesh.triangles.clone();
    let mut alive = vec![true; tris.len()];
    let mut vfaces: Vec<Vec<u32>> = vec![Vec::new(); nv];
    let mut quadric = vec![Matrix4::<f64>::zeros(); nv];
    for (f, t) in tris.iter().enumerate() {
        let [a, b, c] = t.map(|i| pos[i as usize]);
        let q = plane_quadric(a, b, c).unwrap_or_else(Matrix4::zeros);
        for &i in t {
            vfaces[i as usize].push(f as u32);
            quadric[i as usize] += q;
        }
    }
    let mut stamp = vec![0u32; nv];
    let mut removed = vec![false; nv];
    let tol2 = tolerance * tolerance;
    let neighbours = |v: u32, vfaces: &Vec<Vec<u32>>, tris: &Vec<[u32; 3]>| -> Vec<u32> {
        let mut n: Vec<u32> = vfaces[v as usize]
            .iter()
            .flat_map(|&f| tris[f as usize])
            .filter(|&w| w != v)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    };
    let cost_of = |u: u32, v: u32, quadric: &Vec<Matrix4<f64>>| {
        quadric_error(
            &(quadric[u as usize] + quadric[v as usize]),
            pos[v as usize],
        )
    };
    // collapses that cost next to nothing (within 1 % of the tolerance, i.e. rounding: the bulk of
    // a subdivided export) skip the heap
    let free = tol2 * 1e-4;
    let mut heap = BinaryHeap::new();
    let mut zero: Vec<Candidate> = Vec::new();
    let queue = |heap: &mut BinaryHeap<Candidate>,
                 zero: &mut Vec<Candidate>,
                 u: u32,
                 vfaces: &Vec<Vec<u32>>,
                 tris: &Vec<[u32; 3]>,
                 quadric: &Vec<Matrix4<f64>>,
                 stamp: &Vec<u32>| {
        let best = neighbours(u, vfaces, tris)
            .into_iter()
            .map(|v| cost_of(u, v, quadric))
            .fold(f64::INFINITY, f64::min);
        let c = Candidate {
            cost: best,
            from: u,
            stamp: stamp[u as usize],
        };
        if best <= free {
            zero.push(c);
        } else if best <= tol2 {
            heap.push(c);
        }
    };
    for u in (0..nv as u32).rev() {
        queue(&mut heap, &mut zero, u, &vfaces, &tris, &quadric, &stamp);
    }
    let cos_flip = 60f64.to_radians().cos();
    let cos_min_ok = MIN_ANGLE_DEG.to_radians().cos();
    while let Some(c) = zero.pop().or_else(|| heap.pop()) {
        let u = c.from;
        if removed[u as usize] || c.stamp != stamp[u as usize] {
            continue;
        }
        // u's targets, cheapest first; the first valid one is taken
        let nu = neighbours(u, &vfaces, &tris);
        let mut targets: Vec<(f64, u32)> = nu
            .iter()
            .map(|&v| (cost_of(u, v, &quadric), v))
            .filter(|(cost, _)| *cost <= tol2)
            .collect();
        targets.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        // the thinnest facet around u now: new facets may be as thin, or MIN_ANGLE_DEG
        let worst_old = vfaces[u as usize]
            .iter()
            .map(|&f| {
                let c = tris[f as usize].map(|i| pos[i as usize]);
                cos_min_angle(c[0], c[1], c[2])
            })
            .fold(f64::NEG_INFINITY, f64::max);
        let limit = cos_min_ok.max(worst_old);
        let mut chosen = None;
        for &(_, v) in &targets {
            // the two facets on the edge u–v and their opposite vertices
            let shared: Vec<u32> = vfaces[u as usize]
                .iter()
                .copied()
                .filter(|&f| tris[f as usize].contains(&v))
                .collect();
            if shared.len() != 2 {
                continue;
            }
            let opposite: Vec<u32> = shared
                .iter()
                .map(|&f| {
                    *tris[f as usize]
                        .iter()
                        .find(|&&w| w != u && w != v)
                        .expect("a facet has three vertices")
                })
                .collect();
            // link condition
            let nv_ = neighbours(v, &vfaces, &tris);
            let common = nu.iter().filter(|w| nv_.binary_search(w).is_ok()).count();
            if common != 2 || !opposite.iter().all(|o| nv_.binary_search(o).is_ok()) {
                continue;
            }
            // the facets that move with u: no flip, no new sliver
            let moving: Vec<u32> = vfaces[u as usize]
                .iter()
                .copied()
                .filter(|f| !shared.contains(f))
                .collect();
            let ok = moving.iter().all(|&f| {
                let t = tris[f as usize];
                let old = t.map(|i| pos[i as usize]);
                let new = t.map(|i| {
                    if i == u {
                        pos[v as usize]
                    } else {
                        pos[i as usize]
                    }
                });
                let n0 = (old[1] - old[0]).cross(&(old[2] - old[0]));
                let n1 = (new[1] - new[0]).cross(&(new[2] - new[0]));
                let (l0, l1) = (n0.norm(), n1.norm());
                l1 > 0.0
                    && n0.dot(&n1) >= cos_flip * l0 * l1
                    && cos_min_angle(new[0], new[1], new[2]) <= limit
            });
            if ok {
                chosen = Some((v, shared, moving));
                break;
            }
        }
        let Some((v, shared, moving)) = chosen else {
            continue;
        };
        // collapse: u's facets now use v; the two on the edge disappear
        for &f in &shared {
            alive[f as usize] = false;
            for &w in &tris[f as usize] {
                vfaces[w as usize].retain(|&g| g != f);
            }
        }
        for &f in &moving {
            for w in tris[f as usize].iter_mut() {
                if *w == u {
                    *w = v;
                }
            }
            vfaces[v as usize].push(f);
        }
        vfaces[u as usize].clear();
        removed[u as usize] = true;
        let qu = quadric[u as usize];
        quadric[v as usize] += qu;
        // v and its neighbours: new quadric, new neighbourhoods; queued again
        let around = neighbours(v, &vfaces, &tris);
        for &w in around.iter().chain(std::iter::once(&v)) {
            stamp[w as usize] += 1;
            queue(&mut heap, &mut zero, w, &vfaces, &tris, &quadric, &stamp);
        }
    }
    // compact
    let mut index = vec![u32::MAX; nv];
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    let mut max_error2: f64 = 0.0;
    for (f, t) in tris.iter().enumerate() {
        if !alive[f] {
            continue;
        }
        let mut out = [0u32; 3];
        for (k, &i) in t.iter().enumerate() {
            if index[i as usize] == u32::MAX {
                index[i as usize] = vertices.len() as u32;
                vertices.push(mesh.vertices[i as usize]);
                max_error2 = max_error2.max(quadric_error(&quadric[i as usize], pos[i as usize]));
            }
            out[k] = index[i as usize];
        }
        triangles.push(out);
    }
    let report = SimplifyReport {
        triangles_before: mesh.triangles.len(),
        triangles_after: triangles.len(),
        max_error: max_error2.sqrt(),
    };
    (
        IndexedMesh {
            vertices,
            triangles,
        },
        report,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::mass_properties::signed_volume;
    use crate::geometry::primitives::{cuboid, hollow_cylinder};
    use crate::geometry::validate::validate;

    /// Each triangle split into four (midpoints): the same surface with 4× the facets.
    fn subdivide(m: &IndexedMesh) -> IndexedMesh {
        let mut vertices = m.vertices.clone();
        let mut mid = std::collections::HashMap::new();
        let mut get = |a: u32, b: u32, vertices: &mut Vec<Vector3<f64>>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                vertices.push(0.5 * (vertices[a as usize] + vertices[b as usize]));
                (vertices.len() - 1) as u32
            })
        };
        let mut triangles = Vec::new();
        for &[a, b, c] in &m.triangles {
            let (ab, bc, ca) = (
                get(a, b, &mut vertices),
                get(b, c, &mut vertices),
                get(c, a, &mut vertices),
            );
            triangles.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        IndexedMesh {
            vertices,
            triangles,
        }
    }

    #[test]
    fn a_subdivided_box_returns_to_few_facets_with_its_volume() {
        let b = cuboid(Vector3::new(180.0, 50.0, 40.0), Vector3::zeros());
        let fine = subdivide(&subdivide(&subdivide(&b)));
        assert_eq!(fine.triangles.len(), 12 * 64);
        let (s, r) = simplify(&fine, 1e-3);
        let v = validate(s.clone()).expect("still a valid closed solid");
        // flat faces collapse (the angle guard keeps a few more than the 12 of a bare box)
        assert!(r.triangles_after <= 12 * 8, "{r:?}");
        assert!(r.max_error < 1e-4, "{r:?}");
        let vol = signed_volume(&v.mesh);
        assert!((vol - 180.0 * 50.0 * 40.0).abs() < 1e-6, "{vol}");
    }

    #[test]
    fn a_subdivided_tube_keeps_its_facets_to_the_tolerance() {
        let tube = hollow_cylinder(30.0, 12.5, 40.0, 96);
        let fine = subdivide(&subdivide(&tube));
        let (s, r) = simplify(&fine, 1e-3);
        validate(s.clone()).expect("still a valid closed solid");
        // every facet of the tube is its own plane: the subdivision points go, the facets stay
        assert!(r.triangles_after < fine.triangles.len() / 3, "{r:?}");
        assert!(r.triangles_after >= tube.triangles.len(), "{r:?}");
        let (v0, v1) = (signed_volume(&tube), signed_volume(&s));
        assert!((v0 - v1).abs() < 1e-9 * v0, "{v0} {v1}");
        // with a tolerance above a neighbour facet's distance (1.96 mm × sin 3.75° = 0.13 mm) the
        // tube itself is coarsened, within the tolerance
        let (c, rc) = simplify(&tube, 0.2);
        validate(c.clone()).expect("valid");
        assert!(rc.triangles_after < tube.triangles.len(), "{rc:?}");
        assert!(rc.max_error <= 0.2 + 1e-12);
    }
}
