//! The scale of the STL's facets on curved surfaces: the floor of the adaptive mesh size.
//!
//! A CAD export approximates a fillet by flat facets meeting at small kink angles. gmsh remeshes
//! that faceted surface, not the smooth one, so an element smaller than the facet spacing resolves
//! the kinks, and each kink is a (small) re-entrant corner: an artificial stress raiser that grows
//! under refinement (measured in issue 10: 0.6 mm elements on a fillet faceted at 15° read 6 %
//! above the smooth geometry). The adaptive loop therefore never asks for elements smaller than
//! the local facet spacing: the distance between neighbouring kinks, i.e. for a facet with a
//! "curved" edge (dihedral angle between [`FLAT_DEG`] and the classification angle, above which
//! an edge is a real feature of the part) its height over that edge, 2·area / edge length.

use std::collections::HashMap;

use nalgebra::Vector3;

use super::stress::point_triangle_distance;

/// Dihedral angle below which two facets count as coplanar (a subdivided flat face), degrees.
pub const FLAT_DEG: f64 = 0.5;

/// The facets on each edge (vertex pair, smaller index first).
fn edge_faces(triangles: &[[u32; 3]]) -> HashMap<(u32, u32), Vec<u32>> {
    let mut out: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            out.entry((a.min(b), a.max(b))).or_default().push(f as u32);
        }
    }
    out
}

/// Facet spacing on the curved parts of a triangulated surface, looked up by position.
#[derive(Clone, Debug)]
pub struct FacetScale {
    cell: f64,
    grid: HashMap<[i64; 3], Vec<u32>>,
    triangles: Vec<[[f64; 3]; 3]>,
    spacing: Vec<f64>,
}

/// A vertex as a nalgebra vector.
fn v3(p: [f64; 3]) -> Vector3<f64> {
    Vector3::from(p)
}

impl FacetScale {
    /// From a closed, consistently oriented triangulation; `feature_deg` is the dihedral angle at
    /// and above which an edge is a feature (gmsh's classification angle). Units are those of
    /// `vertices`; `cell` is the lookup grid spacing in the same units.
    pub fn new(vertices: &[[f64; 3]], triangles: &[[u32; 3]], feature_deg: f64, cell: f64) -> Self {
        let corners = |t: &[u32; 3]| t.map(|i| v3(vertices[i as usize]));
        let normal = |t: &[u32; 3]| {
            let [a, b, c] = corners(t);
            let n = (b - a).cross(&(c - a));
            let l = n.norm();
            (n / l, 0.5 * l)
        };
        let edge_faces = edge_faces(triangles);
        let (lo, hi) = (FLAT_DEG.to_radians().cos(), feature_deg.to_radians().cos());
        let mut spacing = vec![f64::INFINITY; triangles.len()];
        for ((a, b), faces) in &edge_faces {
            if faces.len() != 2 {
                continue;
            }
            let (n0, _) = normal(&triangles[faces[0] as usize]);
            let (n1, _) = normal(&triangles[faces[1] as usize]);
            let c = n0.dot(&n1);
            if !(c < lo && c > hi) {
                continue;
            }
            let len = (v3(vertices[*a as usize]) - v3(vertices[*b as usize])).norm();
            for &f in faces {
                let (_, area) = normal(&triangles[f as usize]);
                let h = 2.0 * area / len;
                spacing[f as usize] = spacing[f as usize].min(h);
            }
        }
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        let mut tris = Vec::new();
        let mut sp = Vec::new();
        let key = |p: [f64; 3]| p.map(|v| (v / cell).floor() as i64);
        for (f, t) in triangles.iter().enumerate() {
            if !spacing[f].is_finite() {
                continue;
            }
            let c = t.map(|i| vertices[i as usize]);
            let id = tris.len() as u32;
            tris.push(c);
            sp.push(spacing[f]);
            let (mut l, mut h) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for p in &c {
                for j in 0..3 {
                    l[j] = l[j].min(p[j]);
                    h[j] = h[j].max(p[j]);
                }
            }
            let (kl, kh) = (key(l), key(h));
            for x in kl[0]..=kh[0] {
                for y in kl[1]..=kh[1] {
                    for z in kl[2]..=kh[2] {
                        grid.entry([x, y, z]).or_default().push(id);
                    }
                }
            }
        }
        FacetScale {
            cell,
            grid,
            triangles: tris,
            spacing: sp,
        }
    }

    /// Number of facets on curved surfaces.
    pub fn curved_facets(&self) -> usize {
        self.triangles.len()
    }

    /// The spacing of the nearest curved facet within one grid cell of `p`, or 0 when there is
    /// none (flat faces and sharp features have no floor).
    pub fn at(&self, p: [f64; 3]) -> f64 {
        let k = p.map(|v| (v / self.cell).floor() as i64);
        let mut best = (f64::INFINITY, 0.0);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = self.grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                        for &i in list {
                            let d = point_triangle_distance(p, self.triangles[i as usize]);
                            if d < best.0 {
                                best = (d, self.spacing[i as usize]);
                            }
                        }
                    }
                }
            }
        }
        if best.0 <= self.cell { best.1 } else { 0.0 }
    }

    /// Median spacing over the curved facets (0 when there are none), for reports.
    pub fn median_spacing(&self) -> f64 {
        if self.spacing.is_empty() {
            return 0.0;
        }
        let mut s = self.spacing.clone();
        s.sort_by(|a, b| a.total_cmp(b));
        s[s.len() / 2]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A prism over a regular n-gon (radius 1, height 2): the side facets meet at 360/n degrees,
    /// their kink spacing is the polygon's side 2 sin(π/n); the caps are flat and meet the sides at
    /// 90° (a feature), so they have no floor.
    #[test]
    fn polygon_prism_spacing_is_the_side_length() {
        let n = 24;
        let mut v = Vec::new();
        for i in 0..n {
            let a = 2.0 * std::f64::consts::PI * i as f64 / n as f64;
            v.push([a.cos(), a.sin(), 0.0]);
            v.push([a.cos(), a.sin(), 2.0]);
        }
        v.push([0.0, 0.0, 0.0]);
        v.push([0.0, 0.0, 2.0]);
        let (cb, ct) = (2 * n as u32, 2 * n as u32 + 1);
        let mut t = Vec::new();
        for i in 0..n as u32 {
            let j = (i + 1) % n as u32;
            t.push([2 * i, 2 * j, 2 * j + 1]);
            t.push([2 * i, 2 * j + 1, 2 * i + 1]);
            t.push([cb, 2 * j, 2 * i]);
            t.push([ct, 2 * i + 1, 2 * j + 1]);
        }
        let fs = FacetScale::new(&v, &t, 40.0, 0.5);
        let side = 2.0 * (std::f64::consts::PI / n as f64).sin();
        // on the side wall, half-way up
        let got = fs.at([1.0, 0.05, 1.0]);
        assert!((got - side).abs() < 1e-12, "{got} vs {side}");
        // the middle of a cap is far from any curved facet
        assert_eq!(fs.at([0.0, 0.0, 2.0]), 0.0);
        assert_eq!(fs.curved_facets(), 2 * n);
    }
}

/// The sharp re-entrant (concave) edges of a closed, outward-oriented triangulation: edges whose
/// two facets meet at a dihedral angle of at least `feature_deg` with the material on the reflex
/// side. Such an edge is a stress singularity of linear elasticity (at a 90° re-entrant edge the
/// stress grows like r^−0.46 towards it, Williams 1952): its peak grows without bound under
/// refinement, so it is left out of the judged peak like the fixed bore's edge, and reported.
/// Returns the edges as segments (units of `vertices`).
pub fn reentrant_edges(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    feature_deg: f64,
) -> Vec<[[f64; 3]; 2]> {
    let edge_faces = edge_faces(triangles);
    let cos_feature = feature_deg.to_radians().cos();
    let mut out = Vec::new();
    for ((a, b), faces) in &edge_faces {
        if faces.len() != 2 {
            continue;
        }
        let t0 = triangles[faces[0] as usize].map(|i| v3(vertices[i as usize]));
        let t1 = triangles[faces[1] as usize];
        let n0 = (t0[1] - t0[0]).cross(&(t0[2] - t0[0])).normalize();
        let c1 = t1.map(|i| v3(vertices[i as usize]));
        let n1 = (c1[1] - c1[0]).cross(&(c1[2] - c1[0])).normalize();
        let cos = n0.dot(&n1);
        if cos > cos_feature {
            continue;
        }
        // concave: the far corner of facet 1 lies outside facet 0's plane
        let far = t1
            .iter()
            .find(|&&i| i != *a && i != *b)
            .map(|&i| vertices[i as usize])
            .expect("a triangle has a corner off each of its edges");
        if (v3(far) - t0[0]).dot(&n0) > 0.0 {
            out.push([vertices[*a as usize], vertices[*b as usize]]);
        }
    }
    out.sort_by(|p, q| p[0].partial_cmp(&q[0]).unwrap_or(std::cmp::Ordering::Equal));
    out
}

#[cfg(test)]
mod reentrant_tests {
    use super::*;

    /// An L-shaped prism (a 2×2×1 block with a 1×1 quadrant removed) has exactly one re-entrant
    /// edge: the inner corner's vertical edge, from (1, 1, 0) to (1, 1, 1).
    #[test]
    fn the_inner_corner_of_an_l_block_is_the_one_reentrant_edge() {
        // L outline, counter-clockwise seen from +z
        let outline = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ];
        let mut v: Vec<[f64; 3]> = Vec::new();
        for z in [0.0, 1.0] {
            for p in outline {
                v.push([p[0], p[1], z]);
            }
        }
        let n = outline.len() as u32;
        let mut t = Vec::new();
        for i in 0..n {
            let j = (i + 1) % n;
            t.push([i, j, n + j]);
            t.push([i, n + j, n + i]);
        }
        // caps: fan from vertex 0 works for this L (star-shaped from (0,0))
        for i in 1..n - 1 {
            t.push([0, i + 1, i]); // bottom, normal −z
            t.push([n, n + i, n + i + 1]); // top, normal +z
        }
        let e = reentrant_edges(&v, &t, 40.0);
        assert_eq!(e.len(), 1, "{e:?}");
        let mut s = e[0];
        s.sort_by(|a, b| a[2].total_cmp(&b[2]));
        assert_eq!(s, [[1.0, 1.0, 0.0], [1.0, 1.0, 1.0]]);
    }
}
