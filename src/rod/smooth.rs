//! A smooth surface through the STL's vertices, and a tet10 mesh curved onto it: the second
//! geometry of the STL route's geometry error ([`super::solve`]'s `estimated_geometry_error_rel`).
//!
//! An STL is the part's surface cut into flat facets; its vertices lie on the true surface (a CAD
//! export tessellates the B-rep). The straight-sided tet10 mesh of gmsh lies on the facets. What
//! the facets do to the judged peak is measured by solving the same mesh again with its boundary
//! moved onto a smooth surface through the same vertices: the difference of the two peaks is the
//! geometry error, at the discretisation of that mesh, so that the
//! discretisation error largely cancels between the two.
//!
//! **The smooth surface**: curved PN triangles (Vlachos, Peters, Boyd & Mitchell, "Curved PN
//! triangles", I3D 2001): per facet a cubic Bézier triangle from its three corners and a normal at
//! each corner; the edge curve depends only on the edge's two corners and their normals, so
//! neighbouring patches meet without gaps, and a facet whose corner normals are its own normal is
//! the flat facet itself. Corner normals, per smooth sector of the facets around a vertex (sectors
//! are split at sharp edges, [`super::facets::EdgeKind::Sharp`], which stay sharp): the
//! angle-weighted mean of the facet normals, except where one planar region is much wider than
//! the others around the vertex (a flat face that a fillet meets tangentially: 3× the width of
//! every other region, widths 2·area / perimeter), whose normal is then the vertex normal, so that
//! flat faces stay flat and the fillet leaves them tangentially. Along a sharp edge the facets'
//! edges follow a smooth curve through the sharp edge's vertices (its tangent at a vertex that of
//! the circle through the vertex and its two neighbours along the edge), so that the rim of a
//! faceted bore or the outline of a faceted eye becomes round as well. On a circular arc cut into equal
//! facets the edge curve is close to the arc (a cubic Hermite with exact end
//! tangents: at 15° kinks within 1.5 % of the facets' sagitta, at 30° within 5 %, tested).
//!
//! **Curving the mesh**: every node of the boundary faces (corners and midside nodes) is moved to
//! the smooth surface at the nearest point of its facet; midside nodes inside the body move by the
//! mean of their edge's corner moves, so inner elements stay straight. The moves are of the order
//! of the facets' sagitta (ρδ²/8 for a fillet of radius ρ faceted at kinks δ), far below the
//! element size.

use std::collections::HashMap;

use nalgebra::Vector3;

use super::facets::{EdgeKind, SurfaceEdges};
use crate::fem::boundary::boundary_faces;
use crate::fem::error::Result;
use crate::fem::mesh::TetMesh;
use crate::fem::shape::TET10_EDGES;

/// How much wider than every other planar region around a vertex a region must be to set the
/// vertex normal alone (a flat face that a fillet meets tangentially).
pub const DOMINANT_REGION_RATIO: f64 = 3.0;

fn v3(p: [f64; 3]) -> Vector3<f64> {
    Vector3::from(p)
}

/// A smooth surface through the vertices of a triangulation (units of its vertices).
#[derive(Clone, Debug)]
pub struct SmoothSurface {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    /// Per facet, the normal at each of its corners.
    corner_normals: Vec<[[f64; 3]; 3]>,
    /// Per facet, which of its edges (corner k to k + 1) lie on a sharp edge.
    crease: Vec<[bool; 3]>,
    /// Per vertex on a sharp edge that goes on smoothly through it: the edge's tangent there.
    crease_tangent: HashMap<u32, [f64; 3]>,
    cell: f64,
    grid: HashMap<[i64; 3], Vec<u32>>,
}

fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let up = parent[parent[i as usize] as usize];
        parent[i as usize] = up;
        i = up;
    }
    i
}

/// The weight of triangle `t`'s normal in the normal at its corner `k`: the corner's angle. Where a
/// fillet meets a surface of another curvature tangentially, the facets on either side then count
/// alike (Max's weights, sin α / (|e₁| |e₂|), exact on a circle cut into unequal chords, favour the
/// smaller facets and tilt the normal there towards the fillet: measured on the fillet test rod,
/// 3–4× the geometry error of the exact B-rep instead of 1–1.3×).
fn corner_weight(vertices: &[[f64; 3]], t: &[u32; 3], k: usize) -> f64 {
    let p = v3(vertices[t[k] as usize]);
    let a = v3(vertices[t[(k + 1) % 3] as usize]) - p;
    let b = v3(vertices[t[(k + 2) % 3] as usize]) - p;
    let d = a.norm() * b.norm();
    if d > 0.0 {
        (a.dot(&b) / d).clamp(-1.0, 1.0).acos()
    } else {
        0.0
    }
}

impl SmoothSurface {
    /// The smooth surface of `triangles` over `vertices`, with the classified `edges` of the same
    /// triangulation; `cell` is the distance within which points are looked up (units of the
    /// vertices).
    pub fn new(
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
        edges: &SurfaceEdges,
        cell: f64,
    ) -> Self {
        // corner slots 3 f + k, joined across the non-sharp edges at their two vertices
        let slot = |f: u32, v: u32| -> u32 {
            let k = triangles[f as usize]
                .iter()
                .position(|&x| x == v)
                .expect("the facet of an edge has the edge's vertices");
            3 * f + k as u32
        };
        let mut parent: Vec<u32> = (0..3 * triangles.len() as u32).collect();
        for e in &edges.edges {
            if e.kind == EdgeKind::Sharp || e.facets[0] == e.facets[1] {
                continue;
            }
            for v in e.vertices {
                let (a, b) = (
                    find(&mut parent, slot(e.facets[0], v)),
                    find(&mut parent, slot(e.facets[1], v)),
                );
                if a != b {
                    parent[a.max(b) as usize] = a.min(b);
                }
            }
        }
        // per sector: angle-weighted normal sums per planar region
        let mut sectors: HashMap<u32, Vec<(u32, Vector3<f64>)>> = HashMap::new();
        for (f, t) in triangles.iter().enumerate() {
            for k in 0..3 {
                let s = find(&mut parent, 3 * f as u32 + k as u32);
                let w = corner_weight(vertices, t, k);
                let n = v3(edges.normals[f]) * w;
                let r = edges.region[f];
                let list = sectors.entry(s).or_default();
                match list.iter_mut().find(|(q, _)| *q == r) {
                    Some((_, sum)) => *sum += n,
                    None => list.push((r, n)),
                }
            }
        }
        let sector_normal: HashMap<u32, [f64; 3]> = sectors
            .into_iter()
            .map(|(s, regions)| {
                let widest = regions
                    .iter()
                    .max_by(|a, b| {
                        edges.region_width[a.0 as usize]
                            .total_cmp(&edges.region_width[b.0 as usize])
                    })
                    .expect("a sector has a facet");
                let w = edges.region_width[widest.0 as usize];
                let dominant = regions.iter().all(|(r, _)| {
                    *r == widest.0 || w >= DOMINANT_REGION_RATIO * edges.region_width[*r as usize]
                });
                let n = if dominant {
                    widest.1
                } else {
                    regions.iter().map(|(_, n)| n).sum()
                };
                let l = n.norm();
                (s, if l > 0.0 { (n / l).into() } else { [0.0; 3] })
            })
            .collect();
        let corner_normals: Vec<[[f64; 3]; 3]> = (0..triangles.len())
            .map(|f| {
                std::array::from_fn(|k| {
                    let s = find(&mut parent, 3 * f as u32 + k as u32);
                    let n = sector_normal[&s];
                    if n == [0.0; 3] { edges.normals[f] } else { n }
                })
            })
            .collect();
        // sharp edges: their facets' edges along them follow a smooth curve through the sharp
        // edge's vertices, its tangent at a vertex that of the circle through it and its two
        // neighbours along the edge (where the edge goes on within 60° of straight)
        let mut sharp: HashMap<(u32, u32), ()> = HashMap::new();
        let mut along: HashMap<u32, Vec<u32>> = HashMap::new();
        for e in &edges.edges {
            if e.kind == EdgeKind::Sharp && e.facets[0] != e.facets[1] {
                let [a, b] = e.vertices;
                sharp.insert((a, b), ());
                along.entry(a).or_default().push(b);
                along.entry(b).or_default().push(a);
            }
        }
        let crease_tangent: HashMap<u32, [f64; 3]> = along
            .iter()
            .filter(|(_, n)| n.len() == 2)
            .filter_map(|(&v, n)| {
                let p = v3(vertices[v as usize]);
                let d1 = p - v3(vertices[n[0] as usize]);
                let d2 = v3(vertices[n[1] as usize]) - p;
                let (l1, l2) = (d1.norm(), d2.norm());
                if l1 == 0.0 || l2 == 0.0 || d1.dot(&d2) < 0.5 * l1 * l2 {
                    return None;
                }
                let t = d1 / l1 * l2 + d2 / l2 * l1;
                let l = t.norm();
                (l > 0.0).then(|| (v, [t.x / l, t.y / l, t.z / l]))
            })
            .collect();
        let crease: Vec<[bool; 3]> = triangles
            .iter()
            .map(|t| {
                std::array::from_fn(|k| {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    sharp.contains_key(&(a.min(b), a.max(b)))
                })
            })
            .collect();
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        let key = |p: [f64; 3]| p.map(|v| (v / cell).floor() as i64);
        for (f, t) in triangles.iter().enumerate() {
            let c = t.map(|i| vertices[i as usize]);
            let lo: [f64; 3] = std::array::from_fn(|j| c[0][j].min(c[1][j]).min(c[2][j]));
            let hi: [f64; 3] = std::array::from_fn(|j| c[0][j].max(c[1][j]).max(c[2][j]));
            let (kl, kh) = (key(lo), key(hi));
            for x in kl[0]..=kh[0] {
                for y in kl[1]..=kh[1] {
                    for z in kl[2]..=kh[2] {
                        grid.entry([x, y, z]).or_default().push(f as u32);
                    }
                }
            }
        }
        SmoothSurface {
            vertices: vertices.to_vec(),
            triangles: triangles.to_vec(),
            corner_normals,
            crease,
            crease_tangent,
            cell,
            grid,
        }
    }

    /// The facet nearest to `p` within one cell, the barycentric coordinates of the nearest point
    /// on it and the distance; `None` when no facet is that close.
    pub fn closest(&self, p: [f64; 3]) -> Option<(u32, [f64; 3], f64)> {
        let k = p.map(|v| (v / self.cell).floor() as i64);
        let mut best: Option<(u32, [f64; 3], f64)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = self.grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) else {
                        continue;
                    };
                    for &f in list {
                        let t = self.triangles[f as usize].map(|i| self.vertices[i as usize]);
                        let (q, b) = closest_on_triangle(p, t);
                        let d = (v3(q) - v3(p)).norm();
                        if best.is_none_or(|x| d < x.2) {
                            best = Some((f, b, d));
                        }
                    }
                }
            }
        }
        best.filter(|b| b.2 <= self.cell)
    }

    /// The point of facet `f`'s PN patch at barycentric coordinates `b`.
    pub fn patch_point(&self, f: u32, b: [f64; 3]) -> [f64; 3] {
        let t = self.triangles[f as usize];
        let p = t.map(|i| v3(self.vertices[i as usize]));
        let n = self.corner_normals[f as usize].map(v3);
        let crease = self.crease[f as usize];
        // control point next to corner i on the edge towards corner j: in i's tangent plane, or
        // along a sharp edge's tangent (straight on where it has none)
        let c = |i: usize, j: usize| {
            let d = p[j] - p[i];
            let k = if (i + 1) % 3 == j { i } else { j };
            if crease[k] {
                match self.crease_tangent.get(&t[i]) {
                    Some(tt) => {
                        let tt = v3(*tt);
                        let s = if tt.dot(&d) >= 0.0 { 1.0 } else { -1.0 };
                        p[i] + tt * (s * d.norm() / 3.0)
                    }
                    None => p[i] + d / 3.0,
                }
            } else {
                (2.0 * p[i] + p[j] - n[i] * d.dot(&n[i])) / 3.0
            }
        };
        let (b210, b120) = (c(0, 1), c(1, 0));
        let (b021, b012) = (c(1, 2), c(2, 1));
        let (b102, b201) = (c(2, 0), c(0, 2));
        let e = (b210 + b120 + b021 + b012 + b102 + b201) / 6.0;
        let v = (p[0] + p[1] + p[2]) / 3.0;
        let b111 = e + (e - v) / 2.0;
        let [l1, l2, l3] = b;
        let q = p[0] * l1.powi(3)
            + p[1] * l2.powi(3)
            + p[2] * l3.powi(3)
            + b210 * (3.0 * l1 * l1 * l2)
            + b120 * (3.0 * l1 * l2 * l2)
            + b201 * (3.0 * l1 * l1 * l3)
            + b021 * (3.0 * l2 * l2 * l3)
            + b102 * (3.0 * l1 * l3 * l3)
            + b012 * (3.0 * l2 * l3 * l3)
            + b111 * (6.0 * l1 * l2 * l3);
        q.into()
    }

    /// `p` moved onto the smooth surface: the patch point over the nearest point of the nearest
    /// facet (`None` when no facet is within one cell).
    pub fn smooth_point(&self, p: [f64; 3]) -> Option<[f64; 3]> {
        self.closest(p).map(|(f, b, _)| self.patch_point(f, b))
    }
}

/// The nearest point of triangle `t` to `p` and its barycentric coordinates (Ericson, "Real-Time
/// Collision Detection", §5.1.5).
pub fn closest_on_triangle(p: [f64; 3], t: [[f64; 3]; 3]) -> ([f64; 3], [f64; 3]) {
    let [a, b, c] = t.map(v3);
    let p = v3(p);
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    let out =
        |l: [f64; 3]| -> ([f64; 3], [f64; 3]) { ((a * l[0] + b * l[1] + c * l[2]).into(), l) };
    if d1 <= 0.0 && d2 <= 0.0 {
        return out([1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return out([0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return out([1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return out([0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return out([1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return out([0.0, 1.0 - w, w]);
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    out([1.0 - v - w, v, w])
}

/// What curving a mesh did.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct CurveStats {
    /// Boundary nodes moved onto the smooth surface.
    pub moved_nodes: usize,
    /// Boundary nodes with no facet within the lookup distance (left where they were).
    pub unmatched_nodes: usize,
    /// Boundary nodes moved only part of the way: an element would have been distorted (the
    /// smallest det J below [`MIN_JACOBIAN_RATIO`] of its straight value; coarse elements whose
    /// edges cut across a tight corner).
    pub damped_nodes: usize,
    /// The largest move made, in the units of the surface.
    pub max_move: f64,
}

/// The smallest det J of a curved element against its straight self's that the curving accepts.
pub const MIN_JACOBIAN_RATIO: f64 = 0.3;

/// `mesh` (metres) with its boundary moved onto `surface` (`scale` surface units per metre, 1e3
/// for millimetres); midside nodes inside the body follow their edge's corners. Where the move
/// would distort an element (det J anywhere below [`MIN_JACOBIAN_RATIO`] of the straight
/// element's), the moves of its boundary nodes are halved, up to eight times, then dropped.
pub fn curve_onto(
    mesh: &TetMesh,
    surface: &SmoothSurface,
    scale: f64,
) -> Result<(TetMesh, CurveStats)> {
    curve_onto_half(mesh, surface, scale, None)
}

/// [`curve_onto`] for the half model of a symmetric rod when `plane` is `Some((c, tolerance))`
/// (m): the half's faces on its symmetry plane z = c (within `tolerance`) are the inside of the
/// whole and are not curved, and its nodes on the plane move within it (their move's z
/// component dropped), so that the curved half mirrors into a whole without a gap.
pub fn curve_onto_half(
    mesh: &TetMesh,
    surface: &SmoothSurface,
    scale: f64,
    plane: Option<(f64, f64)>,
) -> Result<(TetMesh, CurveStats)> {
    use crate::fem::element::{check_jacobian, corner_volume};
    use crate::fem::quadrature::TET14;
    use rayon::prelude::*;
    let on_plane = |n: usize| plane.is_some_and(|(c, tol)| (mesh.nodes()[n][2] - c).abs() <= tol);
    let faces = boundary_faces(mesh)?;
    let mut on_boundary = vec![false; mesh.n_nodes()];
    for f in &faces {
        if plane.is_some() && f.nodes.iter().all(|&n| on_plane(n)) {
            continue;
        }
        for &n in &f.nodes {
            on_boundary[n] = true;
        }
    }
    let target: Vec<Option<[f64; 3]>> = (0..mesh.n_nodes())
        .into_par_iter()
        .map(|n| {
            if !on_boundary[n] {
                return Some([0.0; 3]);
            }
            let q = mesh.nodes()[n].map(|v| v * scale);
            surface.smooth_point(q).map(|s| {
                let mut d: [f64; 3] = std::array::from_fn(|j| (s[j] - q[j]) / scale);
                if on_plane(n) {
                    d[2] = 0.0;
                }
                d
            })
        })
        .collect();
    let mut stats = CurveStats::default();
    for (t, &b) in target.iter().zip(&on_boundary) {
        if b {
            match t {
                Some(_) => stats.moved_nodes += 1,
                None => stats.unmatched_nodes += 1,
            }
        }
    }
    let full: Vec<[f64; 3]> = target.iter().map(|t| t.unwrap_or([0.0; 3])).collect();
    let touched: Vec<usize> = (0..mesh.n_elements())
        .filter(|&e| mesh.elements()[e].iter().any(|&n| on_boundary[n]))
        .collect();
    let mut damp = vec![1.0f64; mesh.n_nodes()];
    let moves = |damp: &[f64]| -> Vec<[f64; 3]> {
        let mut d: Vec<[f64; 3]> = full
            .iter()
            .zip(damp)
            .map(|(m, f)| m.map(|v| v * f))
            .collect();
        for el in mesh.elements() {
            for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
                let m = el[4 + k];
                if !on_boundary[m] {
                    d[m] = std::array::from_fn(|j| 0.5 * (d[el[*a]][j] + d[el[*b]][j]));
                }
            }
        }
        d
    };
    for round in 0..=8 {
        let d = moves(&damp);
        let bad: Vec<usize> = touched
            .par_iter()
            .copied()
            .filter(|&e| {
                let x0 = mesh.element_coords(e);
                let straight = 6.0 * corner_volume(&x0);
                let el = &mesh.elements()[e];
                let x: [[f64; 3]; 10] =
                    std::array::from_fn(|a| std::array::from_fn(|j| x0[a][j] + d[el[a]][j]));
                check_jacobian(&x, &TET14, e)
                    .map_or(true, |min| min < MIN_JACOBIAN_RATIO * straight)
            })
            .collect();
        if bad.is_empty() {
            break;
        }
        for e in bad {
            for &n in &mesh.elements()[e] {
                if on_boundary[n] {
                    damp[n] = if round < 8 { 0.5 * damp[n] } else { 0.0 };
                }
            }
        }
    }
    let d = moves(&damp);
    stats.damped_nodes = damp
        .iter()
        .zip(&on_boundary)
        .filter(|(f, b)| **b && **f < 1.0)
        .count();
    stats.max_move = d
        .iter()
        .zip(&on_boundary)
        .filter(|(_, b)| **b)
        .map(|(m, _)| v3(*m).norm() * scale)
        .fold(0.0, f64::max);
    let curved = mesh.map_nodes(|i, p| std::array::from_fn(|j| p[j] + d[i][j]))?;
    Ok((curved, stats))
}

/// The judged peaks of a mesh curved onto the smooth surface ([`geometry_check`]).
#[derive(Clone, Debug)]
pub struct GeometryCheck {
    /// Per case ([`super::cases::STATIC_CASES`]): the judged peak of the curved mesh, MPa.
    pub peaks_mpa: Vec<f64>,
    pub stats: CurveStats,
    /// Wall time (curving, solving), s.
    pub seconds: f64,
}

/// Solves `mesh` again with its boundary on `surface` (millimetres, [`curve_onto`]) under the
/// loads and options of the rod analysis (with `rod.reuse_symbolic`, the symbolic analysis of
/// `mesh`'s own solve: the curved mesh has its connectivity), and returns the judged peaks. With
/// a symmetry plane in `rod` (`mirror_plane_z_m`), `mesh` is the half model the analysis solved:
/// the half is curved ([`curve_onto_half`]), solved as the half and mirrored, as the analysis was
/// (on the mirrored whole the check would solve twice the DOFs).
pub fn geometry_check(
    mesh: &TetMesh,
    surface: &SmoothSurface,
    material: &crate::fem::material::Material,
    bores: &super::bores::BoreSpec,
    force_n: f64,
    rod: &super::solve::RodOptions,
) -> Result<GeometryCheck> {
    let start = std::time::Instant::now();
    let plane = rod
        .mirror_plane_z_m
        .map(|c| (c, super::half_model::mirror_plane_tolerance(mesh)));
    let (curved, stats) = curve_onto_half(mesh, surface, 1e3, plane)?;
    let (_, sol) = super::half_model::solve_rod_on(curved, material, bores, force_n, rod)?;
    Ok(GeometryCheck {
        peaks_mpa: sol
            .result
            .cases
            .iter()
            .map(|c| c.max_von_mises_away_from_fixed_mpa)
            .collect(),
        stats,
        seconds: start.elapsed().as_secs_f64(),
    })
}

impl GeometryCheck {
    /// Its record (the surface in millimetres).
    pub fn record(&self) -> super::records::GeometryCheckRecord {
        super::records::GeometryCheckRecord {
            moved_nodes: self.stats.moved_nodes,
            damped_nodes: self.stats.damped_nodes,
            unmatched_nodes: self.stats.unmatched_nodes,
            max_move_mm: self.stats.max_move,
            seconds: self.seconds,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rod::facets::{MAX_FILLET_RADIUS_MM, SurfaceEdges};

    /// A prism over a regular n-gon of radius 1 (height 2), side walls of one quad per side:
    /// points of the side facets and of the caps' rims move onto the circle through the vertices
    /// (within 1.5 % of the facets' sagitta at 15° kinks, 6 % at 30°), and the flat caps stay
    /// flat.
    #[test]
    fn a_faceted_cylinder_becomes_round_and_its_caps_stay_flat() {
        for (n, tolerance) in [(24, 0.015), (12, 0.06)] {
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
            let edges = SurfaceEdges::new(&v, &t, 40.0, MAX_FILLET_RADIUS_MM);
            let s = SmoothSurface::new(&v, &t, &edges, 1.0);
            let half = std::f64::consts::PI / n as f64;
            let sagitta = 1.0 - half.cos();
            // the middle of a side facet, half-way up, and a point near a vertical edge
            for phi in [half, 0.3 * half] {
                // the point on the chord at angle phi
                let (a0, a1) = ((1.0f64, 0.0f64), ((2.0 * half).cos(), (2.0 * half).sin()));
                let u = phi / (2.0 * half);
                let chord = [a0.0 + u * (a1.0 - a0.0), a0.1 + u * (a1.1 - a0.1), 1.0];
                let q = s.smooth_point(chord).unwrap();
                let r = (q[0] * q[0] + q[1] * q[1]).sqrt();
                assert!(
                    (r - 1.0).abs() <= tolerance * sagitta,
                    "{n}-gon, phi {phi}: radius {r}, sagitta {sagitta}"
                );
                assert!((q[2] - 1.0).abs() < 1e-12);
            }
            // a cap point stays on the cap (it moves within it, as the cap's rim, a sharp edge,
            // becomes round)
            let q = s.smooth_point([0.3, 0.2, 2.0]).unwrap();
            assert!((q[2] - 2.0).abs() < 1e-12, "{q:?}");
            // and the rim is the circle: a point on a rim chord goes onto it
            let rim = [
                0.5 * (1.0 + (2.0 * half).cos()),
                0.5 * (2.0 * half).sin(),
                2.0,
            ];
            let q = s.smooth_point(rim).unwrap();
            let r = (q[0] * q[0] + q[1] * q[1]).sqrt();
            assert!(
                (r - 1.0).abs() <= tolerance * sagitta && (q[2] - 2.0).abs() < 1e-12,
                "{n}-gon rim: {q:?}"
            );
        }
    }

    /// The default two-eye plate (polygonal bores), its boundary faces, and the smooth surface
    /// through its boundary's vertices (millimetres), as an STL of the plate would give it.
    fn plate_and_its_smooth_surface() -> (
        crate::fem::mesh::structured::TwoEyePlate,
        TetMesh,
        Vec<crate::fem::boundary::BoundaryFace>,
        SmoothSurface,
    ) {
        use crate::fem::boundary::boundary_faces;
        use crate::fem::mesh::structured::{TwoEyePlate, two_eye_plate};
        let p = TwoEyePlate::default();
        let mesh = two_eye_plate(&p).unwrap();
        let faces = boundary_faces(&mesh).unwrap();
        let v: Vec<[f64; 3]> = mesh.nodes().iter().map(|x| x.map(|c| c * 1e3)).collect();
        let t: Vec<[u32; 3]> = faces
            .iter()
            .map(|f| [f.nodes[0] as u32, f.nodes[1] as u32, f.nodes[2] as u32])
            .collect();
        let edges = SurfaceEdges::new(&v, &t, 40.0, MAX_FILLET_RADIUS_MM);
        let surface = SmoothSurface::new(&v, &t, &edges, 2.0);
        (p, mesh, faces, surface)
    }

    /// A tet10 mesh of a plate with two polygonal bores (16 unequal chords, kinks of 18° to 27°),
    /// its boundary as the STL: curved onto the smooth surface through its vertices, the bore
    /// walls, their rims included, become round (every boundary node on its circle within 15 % of
    /// the largest chord's sagitta, measured 11 %: the angle-weighted normals of unequal chords
    /// lean a little; the straight midside nodes were up to a whole sagitta off), the other faces
    /// do not move, and no element is distorted.
    #[test]
    fn a_polygonal_bore_is_curved_round_and_the_flat_faces_stay() {
        let (p, mesh, faces, surface) = plate_and_its_smooth_surface();
        let (curved, stats) = curve_onto(&mesh, &surface, 1e3).unwrap();
        assert_eq!(stats.unmatched_nodes, 0);
        assert_eq!(stats.damped_nodes, 0);
        curved
            .check_jacobians(crate::fem::QuadratureChoice::Auto)
            .unwrap();
        // the largest chord: from the corner of the square to the middle of its side, 26.6°
        let half = 0.5f64.atan() / 2.0;
        let (mut on_bore, mut before, mut after) = (0, 0.0f64, 0.0f64);
        for f in &faces {
            for &n in &f.nodes {
                let (a, b) = (mesh.nodes()[n], curved.nodes()[n]);
                let mut bore = false;
                for (cx, r) in [(0.0, p.bore_a_radius), (p.length, p.bore_b_radius)] {
                    let ra = (a[0] - cx).hypot(a[1]);
                    let sagitta = r * (1.0 - half.cos());
                    if ra <= r + 1e-9 {
                        bore = true;
                        on_bore += 1;
                        before = before.max((r - ra) / sagitta);
                        after = after.max(((b[0] - cx).hypot(b[1]) - r).abs() / sagitta);
                    }
                }
                if !bore {
                    assert!((v3(a) - v3(b)).norm() < 1e-15, "{a:?} moved to {b:?}");
                }
            }
        }
        assert!(on_bore > 100, "{on_bore}");
        assert!(
            before > 0.9,
            "the straight midside nodes sit on the chords: {before}"
        );
        assert!(after < 0.15, "after: {after} of the sagitta");
    }

    /// The half of the plate above its mid-plane (z ≥ 0), curved with the plane: its faces on the
    /// plane are the whole's inside and stay, its nodes on the plane move within it, and every
    /// node goes where curving the whole plate puts it (the plate and the smooth surface through
    /// its vertices are symmetric), so the curved half mirrors into the curved whole.
    #[test]
    fn a_half_is_curved_as_the_whole_is_and_its_plane_stays_flat() {
        let (_, whole, _, surface) = plate_and_its_smooth_surface();
        let (curved_whole, _) = curve_onto(&whole, &surface, 1e3).unwrap();
        // the half: the elements at z ≥ 0, its nodes numbered as they come
        let mut of = vec![usize::MAX; whole.n_nodes()];
        let mut nodes = Vec::new();
        let elements: Vec<[usize; 10]> = whole
            .elements()
            .iter()
            .filter(|el| el.iter().all(|&n| whole.nodes()[n][2] >= -1e-12))
            .map(|el| {
                el.map(|n| {
                    if of[n] == usize::MAX {
                        of[n] = nodes.len();
                        nodes.push(whole.nodes()[n]);
                    }
                    of[n]
                })
            })
            .collect();
        let half = TetMesh::new(nodes, elements).unwrap();
        let (curved, stats) = curve_onto_half(&half, &surface, 1e3, Some((0.0, 1e-9))).unwrap();
        assert_eq!(stats.unmatched_nodes, 0);
        let (mut plane, mut moved_in_plane) = (0, 0);
        for (w, &h) in of.iter().enumerate() {
            if h == usize::MAX {
                continue;
            }
            let (a, b) = (curved_whole.nodes()[w], curved.nodes()[h]);
            assert!(
                (v3(a) - v3(b)).norm() < 1e-12,
                "node {w}: {a:?} against {b:?}"
            );
            if half.nodes()[h][2] == 0.0 {
                plane += 1;
                assert_eq!(b[2], 0.0, "node {w} left the plane");
                if (v3(b) - v3(half.nodes()[h])).norm() > 1e-9 {
                    moved_in_plane += 1;
                }
            }
        }
        // the bore rims on the plane became round; the rest of the plane stayed
        assert!(plane > 100 && moved_in_plane > 10 && moved_in_plane < plane / 2);
        crate::fem::mesh::mirror::mirror(&curved, 0.0, 1e-9).unwrap();
    }
}
