//! What the STL's facets say about the part: which edges are kinks of a faceted curved surface,
//! which are faceted small fillets and which are really sharp ([`SurfaceEdges`]), and the local
//! facet spacing that floors the adaptive mesh size ([`FacetScale`]).
//!
//! **Kinks and the floor.** A CAD export approximates a fillet by flat facets meeting at small
//! kink angles. gmsh remeshes that faceted surface, not the smooth one, so an element smaller than
//! the facet spacing resolves the kinks, and each kink is a (small) re-entrant corner: an
//! artificial stress raiser that grows under refinement (measured: 0.6 mm elements on
//! a fillet faceted at 15° read 6 % above the smooth geometry). The adaptive loop therefore never
//! asks for elements smaller than the local facet spacing: at a point, the spacing of the nearest
//! kink edge, the mean height of its two facets over it (2·area / edge length: the distance to the
//! next kinks across it), or the smaller height where one facet is more than twice the other. Only
//! the kinks near the point count, and a flat face covered by a few huge triangles next to a
//! fillet does not set the floor on the fillet (two 119 mm triangles beside an R15 fillet would stop
//! refinement at 5 mm).
//!
//! **Fillet or sharp edge.** An edge whose facets meet at [`FLAT_DEG`] or more but below the
//! feature angle is a kink of a curved surface. At the feature angle or above it is either a real
//! sharp edge (a stress singularity if re-entrant: left out of the judged peak) or one kink of a
//! small fillet that the export cut into very few facets (an R1 fillet at a 0.1 mm chord tolerance
//! has 45° kinks). The surface decides: an edge is a **fillet** kink when its own kink is at most
//! [`MAX_FILLET_KINK_DEG`] (at least one facet per 60° of turn) and the surface keeps turning the
//! same way just beyond one of its two facets: walking away from the edge across the slighter
//! kinks (a strip of coplanar triangles between two kinks of a cylindrical fillet, the small kinks
//! along a fillet that follows a curve), the next kink turns the same way (both re-entrant, or
//! both not) by at least a quarter of the edge's own, near enough that the two describe a radius
//! (their distance over their mean kink) of at most [`MAX_FILLET_RADIUS_MM`]. This also holds in
//! the corner where three faceted fillets meet, whose facets turn about several axes. Otherwise, a
//! single edge where the surface turns by a large angle with flat faces on both sides, it is
//! **sharp**. A fillet is refined like any curved surface (floored at its facet spacing), never
//! excluded.

use std::collections::HashMap;

use nalgebra::Vector3;

use super::segment_grid::SegmentGrid;
use crate::fem::stress::point_segment_distance;

/// Dihedral angle below which two facets count as coplanar (a subdivided flat face), degrees.
pub const FLAT_DEG: f64 = 0.5;

/// The largest kink of a faceted fillet, degrees: at least one facet per 60° of turn (a 90°
/// fillet cut into one chamfer facet has two 45° kinks). A larger kink is a sharp edge.
pub const MAX_FILLET_KINK_DEG: f64 = 60.0;

/// The largest radius a chain of kinks at or above the feature angle may describe to count as a
/// faceted fillet, mm. An export cuts a fillet into facets meeting at ≥ 40° only when its radius is
/// small against the chord tolerance (R ≤ 16.6 × tolerance: 1.7 mm at 0.1 mm, 8.3 mm at 0.5 mm);
/// two re-entrant edges further apart are two sharp edges.
pub const MAX_FILLET_RADIUS_MM: f64 = 10.0;

/// What an edge of the triangulation is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeKind {
    /// Its facets are coplanar (below [`FLAT_DEG`]).
    Flat,
    /// A kink of a faceted curved surface (below the feature angle).
    Kink,
    /// A kink at or above the feature angle that belongs to a faceted small fillet.
    Fillet,
    /// A sharp edge of the part (or an edge not shared by exactly two facets).
    Sharp,
}

/// One edge of the triangulation with its two facets.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceEdge {
    /// Vertex indices, smaller first.
    pub vertices: [u32; 2],
    /// The facets on either side (the second equals the first for an edge with other than two
    /// facets).
    pub facets: [u32; 2],
    /// Dihedral angle between the facet normals, degrees.
    pub angle_deg: f64,
    /// The material is on the reflex side (a re-entrant edge).
    pub concave: bool,
    pub kind: EdgeKind,
    /// For a [`EdgeKind::Fillet`] edge: the radius its chain describes (units of the vertices).
    pub radius: f64,
}

/// The edges of a closed, consistently outward-oriented triangulation, classified (see the module
/// documentation), with the facet normals and the planar regions (maximal sets of facets joined
/// across [`EdgeKind::Flat`] edges) that the classification and the smooth surface of
/// [`super::smooth`] use.
#[derive(Clone, Debug)]
pub struct SurfaceEdges {
    pub edges: Vec<SurfaceEdge>,
    /// Unit outward normal of each facet.
    pub normals: Vec<[f64; 3]>,
    /// Area of each facet.
    pub areas: Vec<f64>,
    /// The planar region of each facet.
    pub region: Vec<u32>,
    /// Per region: 2 · area / perimeter, the width of a strip, about the size of a compact face.
    pub region_width: Vec<f64>,
}

fn v3(p: [f64; 3]) -> Vector3<f64> {
    Vector3::from(p)
}

fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let up = parent[parent[i as usize] as usize];
        parent[i as usize] = up;
        i = up;
    }
    i
}

impl SurfaceEdges {
    /// Classifies the edges of `triangles` over `vertices`; `feature_deg` is the dihedral angle at
    /// and above which an edge is a feature (gmsh's classification angle), `max_fillet_radius`
    /// [`MAX_FILLET_RADIUS_MM`] in the units of `vertices`.
    pub fn new(
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
        feature_deg: f64,
        max_fillet_radius: f64,
    ) -> Self {
        let (normals, areas): (Vec<[f64; 3]>, Vec<f64>) = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| v3(vertices[i as usize]));
                let n = (b - a).cross(&(c - a));
                let l = n.norm();
                let unit = if l > 0.0 { n / l } else { n };
                ([unit.x, unit.y, unit.z], 0.5 * l)
            })
            .unzip();
        let mut by_edge: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
        for (f, t) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                by_edge
                    .entry((a.min(b), a.max(b)))
                    .or_default()
                    .push(f as u32);
            }
        }
        let mut keys: Vec<(u32, u32)> = by_edge.keys().copied().collect();
        keys.sort_unstable();
        let flat_cos = FLAT_DEG.to_radians().cos();
        let mut edges: Vec<SurfaceEdge> = keys
            .iter()
            .map(|&(a, b)| {
                let faces = &by_edge[&(a, b)];
                if faces.len() != 2 {
                    return SurfaceEdge {
                        vertices: [a, b],
                        facets: [faces[0], faces[0]],
                        angle_deg: 180.0,
                        concave: false,
                        kind: EdgeKind::Sharp,
                        radius: 0.0,
                    };
                }
                let (f0, f1) = (faces[0] as usize, faces[1] as usize);
                let (n0, n1) = (v3(normals[f0]), v3(normals[f1]));
                let cos = n0.dot(&n1).clamp(-1.0, 1.0);
                let far = triangles[f1]
                    .iter()
                    .find(|&&i| i != a && i != b)
                    .map(|&i| v3(vertices[i as usize]))
                    .expect("a triangle has a corner off each of its edges");
                let concave = (far - v3(vertices[triangles[f0][0] as usize])).dot(&n0) > 0.0;
                SurfaceEdge {
                    vertices: [a, b],
                    facets: [faces[0], faces[1]],
                    angle_deg: cos.acos().to_degrees(),
                    concave,
                    kind: if cos > flat_cos {
                        EdgeKind::Flat
                    } else {
                        EdgeKind::Kink
                    },
                    radius: 0.0,
                }
            })
            .collect();
        // planar regions: facets joined across flat edges
        let mut parent: Vec<u32> = (0..triangles.len() as u32).collect();
        for e in &edges {
            if e.kind == EdgeKind::Flat {
                let (r0, r1) = (
                    find(&mut parent, e.facets[0]),
                    find(&mut parent, e.facets[1]),
                );
                if r0 != r1 {
                    parent[r0.max(r1) as usize] = r0.min(r1);
                }
            }
        }
        let mut ids: HashMap<u32, u32> = HashMap::new();
        let region: Vec<u32> = (0..triangles.len() as u32)
            .map(|f| {
                let r = find(&mut parent, f);
                let n = ids.len() as u32;
                *ids.entry(r).or_insert(n)
            })
            .collect();
        let n_regions = ids.len();
        let mut area = vec![0.0; n_regions];
        for (f, a) in areas.iter().enumerate() {
            area[region[f] as usize] += a;
        }
        let mut perimeter = vec![0.0; n_regions];
        let mut facet_edges: Vec<[u32; 3]> = vec![[u32::MAX; 3]; triangles.len()];
        for (i, e) in edges.iter().enumerate() {
            for f in e.facets {
                let slot = facet_edges[f as usize]
                    .iter_mut()
                    .find(|x| **x == u32::MAX || **x == i as u32);
                if let Some(x) = slot {
                    *x = i as u32;
                }
            }
            if e.kind == EdgeKind::Flat {
                continue;
            }
            let len = (v3(vertices[e.vertices[0] as usize]) - v3(vertices[e.vertices[1] as usize]))
                .norm();
            perimeter[region[e.facets[0] as usize] as usize] += len;
            if region[e.facets[1] as usize] != region[e.facets[0] as usize] {
                perimeter[region[e.facets[1] as usize] as usize] += len;
            }
        }
        let region_width: Vec<f64> = area
            .iter()
            .zip(&perimeter)
            .map(|(a, p)| if *p > 0.0 { 2.0 * a / p } else { f64::INFINITY })
            .collect();
        // features: fillet kinks or sharp edges
        let feature_cos = feature_deg.to_radians().cos();
        let kinds: Vec<(EdgeKind, f64)> = edges
            .iter()
            .map(|e| {
                if e.kind != EdgeKind::Kink || e.angle_deg.to_radians().cos() > feature_cos {
                    return (e.kind, 0.0);
                }
                if e.angle_deg > MAX_FILLET_KINK_DEG {
                    return (EdgeKind::Sharp, 0.0);
                }
                match fillet_radius(e, &edges, &facet_edges, vertices, max_fillet_radius) {
                    Some(r) => (EdgeKind::Fillet, r),
                    None => (EdgeKind::Sharp, 0.0),
                }
            })
            .collect();
        for (e, (kind, r)) in edges.iter_mut().zip(kinds) {
            e.kind = kind;
            e.radius = r;
        }
        SurfaceEdges {
            edges,
            normals,
            areas,
            region,
            region_width,
        }
    }

    /// The sharp re-entrant edges as segments (units of `vertices`): stress singularities of
    /// linear elasticity (at a 90° re-entrant edge the stress grows like r^−0.46 towards it,
    /// Williams 1952), left out of the judged peak like the fixed bore's edge.
    pub fn sharp_reentrant(&self, vertices: &[[f64; 3]]) -> Vec<[[f64; 3]; 2]> {
        let mut out: Vec<[[f64; 3]; 2]> = self
            .edges
            .iter()
            .filter(|e| e.kind == EdgeKind::Sharp && e.concave && e.facets[0] != e.facets[1])
            .map(|e| e.vertices.map(|v| vertices[v as usize]))
            .collect();
        out.sort_by(|p, q| p[0].partial_cmp(&q[0]).unwrap_or(std::cmp::Ordering::Equal));
        out
    }

    /// The facet spacing at edge `e`: the mean height of its two facets over it (the distance to
    /// the next kinks on either side), or the smaller where one is more than twice the other (a
    /// big flat facet beside a fillet); `None` for an edge of zero length.
    pub fn kink_spacing(&self, e: &SurfaceEdge, vertices: &[[f64; 3]]) -> Option<f64> {
        let s = e.vertices.map(|v| vertices[v as usize]);
        let len = (v3(s[1]) - v3(s[0])).norm();
        if len <= 0.0 {
            return None;
        }
        let [h0, h1] = e.facets.map(|f| 2.0 * self.areas[f as usize] / len);
        let (lo, hi) = (h0.min(h1), h0.max(h1));
        Some(if hi <= 2.0 * lo { 0.5 * (lo + hi) } else { lo })
    }

    /// Edges at or above the feature angle taken for kinks of faceted small fillets.
    pub fn fillet_kinks(&self) -> usize {
        self.edges
            .iter()
            .filter(|e| e.kind == EdgeKind::Fillet)
            .count()
    }
}

/// The radius of the fillet that edge `e` (a kink at or above the feature angle) is a kink of, or
/// `None` when the faces on both its sides are flat (see the module documentation). On each side
/// the surface is walked from `e`'s facet across the edges that turn by less than a quarter of
/// `e`'s kink (coplanar strips, the slight kinks of a fillet along a curve), within reach of a
/// fillet of the largest radius; an edge where the walk stops that turns the same way as `e` (both
/// re-entrant, or both not) by at least a quarter of `e`'s kink continues the chain: the two kinks
/// describe a radius d / (mean kink), d the distance between them.
fn fillet_radius(
    e: &SurfaceEdge,
    edges: &[SurfaceEdge],
    facet_edges: &[[u32; 3]],
    vertices: &[[f64; 3]],
    max_radius: f64,
) -> Option<f64> {
    let seg = e.vertices.map(|v| vertices[v as usize]);
    let theta = e.angle_deg.to_radians();
    let soft = 0.25 * e.angle_deg;
    // a chain of kinks describing at most max_radius spans at most this much across (the kinks at
    // most 60°)
    let reach = max_radius * MAX_FILLET_KINK_DEG.to_radians();
    let mut best: Option<f64> = None;
    for (side, &start) in e.facets.iter().enumerate() {
        let other = e.facets[1 - side];
        let mut seen: std::collections::HashSet<u32> = [start, other].into_iter().collect();
        let mut queue = vec![start];
        while let Some(f) = queue.pop() {
            for &ci in &facet_edges[f as usize] {
                let c = &edges[ci as usize];
                if c.vertices == e.vertices || c.facets[0] == c.facets[1] {
                    continue;
                }
                let beyond = if c.facets[0] == f {
                    c.facets[1]
                } else {
                    c.facets[0]
                };
                if seen.contains(&beyond) {
                    continue;
                }
                let d = c
                    .vertices
                    .iter()
                    .map(|&v| point_segment_distance(vertices[v as usize], seg))
                    .fold(0.0, f64::max);
                if d > reach {
                    continue;
                }
                if c.angle_deg < soft {
                    seen.insert(beyond);
                    queue.push(beyond);
                    continue;
                }
                if c.concave != e.concave {
                    continue;
                }
                let radius = d / (0.5 * (theta + c.angle_deg.to_radians()));
                if radius <= max_radius {
                    best = Some(best.map_or(radius, |b: f64| b.min(radius)));
                }
            }
        }
    }
    best
}

/// The sharp re-entrant (concave) edges of a closed, outward-oriented triangulation (rod frame,
/// mm): edges at or above `feature_deg` with the material on the reflex side that are not kinks of
/// a faceted small fillet ([`SurfaceEdges`]). Returns the edges as segments (units of `vertices`).
pub fn reentrant_edges(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    feature_deg: f64,
) -> Vec<[[f64; 3]; 2]> {
    SurfaceEdges::new(vertices, triangles, feature_deg, MAX_FILLET_RADIUS_MM)
        .sharp_reentrant(vertices)
}

/// Facet spacing at the kinks of a triangulated surface, looked up by position.
#[derive(Clone, Debug)]
pub struct FacetScale {
    kinks: SegmentGrid,
    spacing: Vec<f64>,
}

impl FacetScale {
    /// From a closed, consistently oriented triangulation; `feature_deg` is the dihedral angle at
    /// and above which an edge is a feature (gmsh's classification angle). Units are those of
    /// `vertices` (the fillet radius limit is [`MAX_FILLET_RADIUS_MM`]: millimetres); `cell` is the
    /// lookup distance in the same units.
    pub fn new(vertices: &[[f64; 3]], triangles: &[[u32; 3]], feature_deg: f64, cell: f64) -> Self {
        let edges = SurfaceEdges::new(vertices, triangles, feature_deg, MAX_FILLET_RADIUS_MM);
        Self::from_edges(&edges, vertices, cell)
    }

    /// From classified edges: every [`EdgeKind::Kink`] and [`EdgeKind::Fillet`] edge, its spacing
    /// the mean height of its two facets over it (the distance to the next kinks on either side),
    /// or the smaller where one is more than twice the other (a big flat facet beside a fillet).
    pub fn from_edges(edges: &SurfaceEdges, vertices: &[[f64; 3]], cell: f64) -> Self {
        let mut kinks = SegmentGrid::new(cell);
        let mut spacing = Vec::new();
        for e in &edges.edges {
            if !matches!(e.kind, EdgeKind::Kink | EdgeKind::Fillet) {
                continue;
            }
            let Some(h) = edges.kink_spacing(e, vertices) else {
                continue;
            };
            kinks.push(e.vertices.map(|v| vertices[v as usize]));
            spacing.push(h);
        }
        FacetScale { kinks, spacing }
    }

    /// Number of kink edges.
    pub fn kink_edges(&self) -> usize {
        self.kinks.len()
    }

    /// The spacing of the nearest kink edge within one grid cell of `p`, or 0 when there is none
    /// (flat faces and sharp features have no floor).
    pub fn at(&self, p: [f64; 3]) -> f64 {
        self.kinks
            .nearby(p)
            .fold((f64::INFINITY, 0.0), |best, (i, d)| {
                if d < best.0 {
                    (d, self.spacing[i])
                } else {
                    best
                }
            })
            .1
    }

    /// Median spacing over the kink edges (0 when there are none), for reports.
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
pub(crate) mod tests {
    use super::*;

    /// A prism over the simple counter-clockwise `outline`, from z = 0 to `height`: each side one
    /// quad of two triangles over the whole height (as a CAD export tessellates a ruled face),
    /// the caps triangulated by ear clipping.
    pub(crate) fn prism(outline: &[[f64; 2]], height: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut v: Vec<[f64; 3]> = Vec::new();
        for z in [0.0, height] {
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
        for [a, b, c] in ear_clip(outline) {
            t.push([a, c, b]);
            t.push([n + a, n + b, n + c]);
        }
        (v, t)
    }

    /// Triangles (counter-clockwise) of a simple counter-clockwise polygon, by ear clipping.
    fn ear_clip(poly: &[[f64; 2]]) -> Vec<[u32; 3]> {
        let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
            (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
        };
        let mut idx: Vec<u32> = (0..poly.len() as u32).collect();
        let mut out = Vec::new();
        while idx.len() > 3 {
            let m = idx.len();
            let ear = (0..m)
                .find(|&k| {
                    let (a, b, c) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
                    let (pa, pb, pc) = (poly[a as usize], poly[b as usize], poly[c as usize]);
                    cross(pa, pb, pc) > 1e-12
                        && idx.iter().all(|&q| {
                            q == a || q == b || q == c || {
                                let p = poly[q as usize];
                                !(cross(pa, pb, p) >= 0.0
                                    && cross(pb, pc, p) >= 0.0
                                    && cross(pc, pa, p) >= 0.0)
                            }
                        })
                })
                .expect("a simple polygon has an ear");
            out.push([idx[(ear + m - 1) % m], idx[ear], idx[(ear + 1) % m]]);
            idx.remove(ear);
        }
        out.push([idx[0], idx[1], idx[2]]);
        out
    }

    /// An L outline (legs `leg` long, `thick` wide) whose inner corner at (thick, thick) is a
    /// fillet of radius `r` cut into `facets` equal chords (no fillet: r = 0).
    pub(crate) fn l_outline(leg: f64, thick: f64, r: f64, facets: usize) -> Vec<[f64; 2]> {
        let mut o = vec![[0.0, 0.0], [leg, 0.0], [leg, thick]];
        if r > 0.0 {
            let c = [thick + r, thick + r];
            for k in 0..=facets {
                // from (thick + r, thick) round to (thick, thick + r)
                let a = -std::f64::consts::FRAC_PI_2
                    - std::f64::consts::FRAC_PI_2 * k as f64 / facets as f64;
                o.push([c[0] + r * a.cos(), c[1] + r * a.sin()]);
            }
        } else {
            o.push([thick, thick]);
        }
        o.push([thick, leg]);
        o.push([0.0, leg]);
        o
    }

    fn kinds(e: &SurfaceEdges, kind: EdgeKind) -> Vec<&SurfaceEdge> {
        e.edges.iter().filter(|x| x.kind == kind).collect()
    }

    /// A prism over a regular n-gon (radius 1, height 2): the side facets meet at 360/n degrees,
    /// the kink spacing is the polygon's side 2 sin(π/n); the caps are flat and meet the sides at
    /// 90° (a sharp edge), so they have no floor.
    #[test]
    fn polygon_prism_spacing_is_the_side_length() {
        let n = 24;
        let outline: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let a = 2.0 * std::f64::consts::PI * i as f64 / n as f64;
                [a.cos(), a.sin()]
            })
            .collect();
        let (v, t) = prism(&outline, 2.0);
        let fs = FacetScale::new(&v, &t, 40.0, 0.5);
        let side = 2.0 * (std::f64::consts::PI / n as f64).sin();
        let got = fs.at([1.0, 0.05, 1.0]);
        assert!((got - side).abs() < 1e-12, "{got} vs {side}");
        assert_eq!(fs.at([0.0, 0.0, 2.0]), 0.0);
        assert_eq!(fs.kink_edges(), n);
    }

    /// An L-shaped prism has exactly one sharp re-entrant edge: the inner corner's vertical edge.
    #[test]
    fn the_inner_corner_of_an_l_block_is_the_one_reentrant_edge() {
        let (v, t) = prism(&l_outline(2.0, 1.0, 0.0, 0), 1.0);
        let e = reentrant_edges(&v, &t, 40.0);
        assert_eq!(e.len(), 1, "{e:?}");
        let mut s = e[0];
        s.sort_by(|a, b| a[2].total_cmp(&b[2]));
        assert_eq!(s, [[1.0, 1.0, 0.0], [1.0, 1.0, 1.0]]);
    }

    /// The inner corner filleted with R1 and exported coarsely: two chords (kinks 22.5°, 45°,
    /// 22.5°) or one (a chamfer facet: 45°, 45°). The 45° kinks are at or above the feature angle
    /// but the surface keeps turning beyond them: a fillet of about the true radius, not a sharp
    /// edge, and nothing is left for the singular band.
    #[test]
    fn a_coarsely_faceted_small_fillet_is_a_fillet_not_a_sharp_edge() {
        for facets in [2, 1] {
            let (v, t) = prism(&l_outline(40.0, 10.0, 1.0, facets), 20.0);
            let e = SurfaceEdges::new(&v, &t, 40.0, MAX_FILLET_RADIUS_MM);
            let fillets = kinds(&e, EdgeKind::Fillet);
            let expected = if facets == 2 { 1 } else { 2 };
            assert_eq!(fillets.len(), expected, "{facets} facets");
            for f in &fillets {
                assert!(f.concave);
                assert!((f.angle_deg - 45.0).abs() < 1e-9);
                // the radius the chain describes: chord / mean turn
                assert!(
                    f.radius > 0.8 && f.radius < 2.0,
                    "{facets} facets: radius {}",
                    f.radius
                );
            }
            assert!(
                e.sharp_reentrant(&v).is_empty(),
                "{facets} facets: {:?}",
                e.sharp_reentrant(&v)
            );
            // and the floor at the fillet is its chord (the facet spacing), as on any fillet
            let fs = FacetScale::from_edges(&e, &v, 2.0);
            let chord = 2.0 * (std::f64::consts::FRAC_PI_4 / facets as f64).sin();
            let got = fs.at([10.3, 10.3, 10.0]);
            assert!((got - chord).abs() < 1e-9, "{facets}: {got} vs {chord}");
        }
    }

    /// A pocket (a U channel): floor 8 mm wide between two walls, both edges 90° re-entrant.
    /// The surface turns by 180° over 8 mm, but each edge turns by 90° between flat faces: two
    /// sharp edges, not a fillet. Likewise a 45° bevel 30 mm wide: its two edges describe a radius
    /// of 38 mm, no small fillet.
    #[test]
    fn a_pocket_and_a_wide_bevel_keep_their_sharp_edges() {
        // U outline, counter-clockwise, star-shaped from (10, 0)
        let u = vec![
            [10.0, 0.0],
            [28.0, 0.0],
            [28.0, 20.0],
            [18.0, 20.0],
            [18.0, 5.0],
            [10.0, 5.0],
            [10.0, 20.0],
            [0.0, 20.0],
            [0.0, 0.0],
        ];
        let (v, t) = prism(&u, 10.0);
        let e = SurfaceEdges::new(&v, &t, 40.0, MAX_FILLET_RADIUS_MM);
        assert_eq!(e.sharp_reentrant(&v).len(), 2);
        assert_eq!(e.fillet_kinks(), 0);
        // an L whose inner corner is cut by one 30 mm facet at 45°
        let bevel = vec![
            [0.0, 0.0],
            [100.0, 0.0],
            [100.0, 10.0],
            [10.0 + 21.2132, 10.0],
            [10.0, 10.0 + 21.2132],
            [10.0, 100.0],
            [0.0, 100.0],
        ];
        let (v, t) = prism(&bevel, 10.0);
        let e = SurfaceEdges::new(&v, &t, 40.0, MAX_FILLET_RADIUS_MM);
        assert_eq!(e.sharp_reentrant(&v).len(), 2);
        assert_eq!(e.fillet_kinks(), 0);
    }

    /// An R15 fillet exported at 15° per facet (strips the part's whole height long)
    /// between two flat faces each covered by two huge triangles. The floor on the fillet, also
    /// next to the huge triangles, is the fillet's facet spacing (2 · 15 · sin 7.5° = 3.9 mm), not
    /// the height of a huge triangle over the fillet's edge; far out on the flat face there is
    /// none.
    #[test]
    fn huge_flat_triangles_beside_a_fillet_do_not_set_its_floor() {
        let (v, t) = prism(&l_outline(160.0, 40.0, 15.0, 6), 119.0);
        let fs = FacetScale::new(&v, &t, 40.0, 2.0);
        let chord = 2.0 * 15.0 * (7.5f64.to_radians()).sin();
        // on the flat face 0.5 mm beside the fillet's tangent line (55, 40), and on the fillet
        for p in [[55.5, 40.0, 60.0], [54.9, 40.05, 30.0], [44.4, 44.4, 100.0]] {
            let got = fs.at(p);
            assert!((got - chord).abs() < 1e-6, "{p:?}: {got} vs {chord}");
        }
        assert_eq!(fs.at([100.0, 40.0, 60.0]), 0.0);
    }
}
