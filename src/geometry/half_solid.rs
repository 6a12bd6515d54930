//! The half of a closed surface on one side of a plane z = c, closed again by a cap in the plane:
//! the solid a mirror-symmetric part's half model is meshed from ([`super::mirror_symmetry`]).
//!
//! Each triangle is clipped against the half-space z ≥ c (Sutherland–Hodgman, one plane); the
//! points where an edge crosses the plane are shared by the two triangles of that edge, so the
//! clipped surface stays watertight apart from its cut. The cut's edges, all in the plane, bound
//! the cap: the section of the solid at z = c, outline and holes. It is triangulated as a
//! constrained Delaunay triangulation of the cut's points and edges (`spade`), keeping the
//! triangles whose centroid the cut winds around once (the side triangles run the cut
//! counter-clockwise around the section, seen from +z), and oriented with the outward normal −z.
//! Vertices within [`SNAP_REL`] of the extent from the plane are put on it first, so that no
//! sliver of a triangle is left between a vertex and the plane.

use std::collections::HashMap;

use nalgebra::Vector3;
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};

use super::weld::IndexedMesh;

/// Vertices this close to the plane (relative to the surface's largest extent) are moved onto it.
pub const SNAP_REL: f64 = 1e-9;

/// A vertex closer to the plane than this fraction of the z-extent of an edge of it that crosses
/// the plane is moved onto the plane (within the caller's largest move).
pub const SNAP_FRACTION: f64 = 0.25;

/// The half of `mesh` (closed, outward oriented) at z ≥ `c`, capped in the plane z = c; a vertex
/// at most `max_snap` from the plane may be moved onto it ([`SNAP_FRACTION`]). Errors name what
/// keeps the section from being capped (no section, crossing cut edges).
pub fn half_above(mesh: &IndexedMesh, c: f64, max_snap: f64) -> Result<IndexedMesh, String> {
    let (lo, hi) = mesh.bounding_box();
    let extent = (hi - lo).max();
    if !(lo.z < c && c < hi.z) {
        return Err(format!(
            "the plane z = {c} does not cut the surface (z from {} to {})",
            lo.z, hi.z
        ));
    }
    // a vertex near the plane, whose edges across it would be cut within their first quarter (in
    // z), is put on the plane: the cut then leaves no needle between it and the crossing point
    let snap_floor = SNAP_REL * extent;
    let mut near = vec![f64::INFINITY; mesh.vertices.len()];
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let (za, zb) = (mesh.vertices[a].z - c, mesh.vertices[b].z - c);
            if za * zb < 0.0 {
                let dz = (za - zb).abs();
                near[a] = near[a].min(SNAP_FRACTION * dz);
                near[b] = near[b].min(SNAP_FRACTION * dz);
            }
        }
    }
    let mut vertices: Vec<Vector3<f64>> = mesh
        .vertices
        .iter()
        .zip(&near)
        .map(|(v, &n)| {
            let d = (v.z - c).abs();
            if d <= snap_floor || (d < n.min(max_snap)) {
                Vector3::new(v.x, v.y, c)
            } else {
                *v
            }
        })
        .collect();
    let side: Vec<i8> = vertices
        .iter()
        .map(|v| {
            if v.z > c {
                1
            } else if v.z < c {
                -1
            } else {
                0
            }
        })
        .collect();
    // the point where edge (a, b) crosses the plane, one vertex per edge
    let mut crossing: HashMap<(u32, u32), u32> = HashMap::new();
    let mut cross = |a: u32, b: u32, vertices: &mut Vec<Vector3<f64>>| -> u32 {
        let key = (a.min(b), a.max(b));
        *crossing.entry(key).or_insert_with(|| {
            // interpolate from the lower index, so that both triangles get the same bits
            let (p, q) = (vertices[key.0 as usize], vertices[key.1 as usize]);
            let t = (c - p.z) / (q.z - p.z);
            let x = p + (q - p) * t;
            vertices.push(Vector3::new(x.x, x.y, c));
            (vertices.len() - 1) as u32
        })
    };
    let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(mesh.triangles.len() / 2 + 1024);
    for t in &mesh.triangles {
        let s = t.map(|i| side[i as usize]);
        if s.iter().all(|&x| x >= 0) {
            if s.iter().any(|&x| x > 0) {
                triangles.push(*t);
            }
            continue;
        }
        if s.iter().all(|&x| x <= 0) {
            continue;
        }
        // Sutherland–Hodgman against z ≥ c: at most four points
        let mut poly: Vec<u32> = Vec::with_capacity(4);
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (sa, sb) = (side[a as usize], side[b as usize]);
            if sa >= 0 {
                poly.push(a);
            }
            if sa * sb < 0 {
                poly.push(cross(a, b, &mut vertices));
            }
        }
        for k in 1..poly.len().saturating_sub(1) {
            triangles.push([poly[0], poly[k], poly[k + 1]]);
        }
    }
    let cap = cap_triangles(&mut vertices, &triangles, c)?;
    triangles.extend(cap);
    // drop the vertices left below the plane, renumbering the rest in order
    let mut new_index = vec![u32::MAX; vertices.len()];
    let mut kept = Vec::new();
    for t in &mut triangles {
        for i in t.iter_mut() {
            if new_index[*i as usize] == u32::MAX {
                new_index[*i as usize] = kept.len() as u32;
                kept.push(vertices[*i as usize]);
            }
            *i = new_index[*i as usize];
        }
    }
    Ok(IndexedMesh {
        vertices: kept,
        triangles,
    })
}

/// The cap of the clipped surface `triangles`: the section bounded by its open edges, which lie
/// in the plane z = c, triangulated and oriented with the outward normal −z.
///
/// Points of the cut that lie on the straight line between their neighbours (a crossing on a
/// quad's diagonal between the crossings of its two sides; the cut of a flat face cut into many
/// triangles) are left out of the triangulation, which would otherwise hold flat triangles
/// wherever round-off puts such a point an ulp outside its chord; the cap triangle on that chord
/// is then split through them (fanned from its opposite corner, or from its centroid, a new
/// point, when more than one of its edges holds such points).
fn cap_triangles(
    vertices: &mut Vec<Vector3<f64>>,
    triangles: &[[u32; 3]],
    c: f64,
) -> Result<Vec<[u32; 3]>, String> {
    // the open edges: directed edges whose reverse no triangle has
    let mut directed: HashMap<(u32, u32), usize> = HashMap::with_capacity(3 * triangles.len());
    for t in triangles {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    let mut open: Vec<(u32, u32)> = directed
        .keys()
        .filter(|(a, b)| !directed.contains_key(&(*b, *a)))
        .copied()
        .collect();
    open.sort_unstable();
    if open.is_empty() {
        return Err(format!("the surface has no section at z = {c}"));
    }
    let at = |v: u32| [vertices[v as usize].x, vertices[v as usize].y];
    if let Some((a, b)) = open
        .iter()
        .find(|(a, b)| vertices[*a as usize].z != c || vertices[*b as usize].z != c)
    {
        let (p, q) = (vertices[*a as usize], vertices[*b as usize]);
        return Err(format!(
            "an open edge from ({:.4}, {:.4}, {:.4}) to ({:.4}, {:.4}, {:.4}) lies off the plane z = {c}: the surface was not closed",
            p.x, p.y, p.z, q.x, q.y, q.z
        ));
    }
    // the cut as loops: one edge out of every point
    let mut next: HashMap<u32, u32> = HashMap::with_capacity(open.len());
    for &(a, b) in &open {
        if next.insert(a, b).is_some() {
            let p = vertices[a as usize];
            return Err(format!(
                "the section at z = {c} touches itself at ({:.4}, {:.4}): two cut edges leave one point",
                p.x, p.y
            ));
        }
    }
    let mut prev: HashMap<u32, u32> = HashMap::with_capacity(open.len());
    for &(a, b) in &open {
        prev.insert(b, a);
    }
    if prev.len() != next.len() {
        return Err(format!(
            "the section at z = {c} is not made of closed loops"
        ));
    }
    // a point on the straight line between its neighbours, running on
    let straight = |v: u32| {
        let (p, q, r) = (at(prev[&v]), at(v), at(next[&v]));
        let (u, w) = ([q[0] - p[0], q[1] - p[1]], [r[0] - q[0], r[1] - q[1]]);
        let cross = u[0] * w[1] - u[1] * w[0];
        let dot = u[0] * w[0] + u[1] * w[1];
        dot > 0.0 && cross.abs() < SLIVER_SINE * (u[0].hypot(u[1]) * w[0].hypot(w[1]))
    };
    // the corners, and the chords between consecutive corners with the points left out on them
    let mut local: HashMap<u32, usize> = HashMap::new();
    let mut points: Vec<u32> = Vec::new();
    let mut chords: Vec<[usize; 2]> = Vec::new();
    // chord (corner a, corner b) in the cut's direction → the points between, a to b
    let mut between: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    let mut seen: std::collections::HashSet<u32> = std::collections::HashSet::new();
    for &(start, _) in &open {
        if seen.contains(&start) || straight(start) {
            continue;
        }
        let mut corner = start;
        let mut on: Vec<u32> = Vec::new();
        let mut v = start;
        loop {
            seen.insert(v);
            let w = next[&v];
            if w != start && straight(w) {
                on.push(w);
            } else {
                for x in [corner, w] {
                    local.entry(x).or_insert_with(|| {
                        points.push(x);
                        points.len() - 1
                    });
                }
                chords.push([local[&corner], local[&w]]);
                if !on.is_empty() {
                    between.insert((corner, w), std::mem::take(&mut on));
                }
                corner = w;
            }
            v = w;
            if v == start {
                break;
            }
        }
    }
    if seen.len() != next.len() {
        return Err(format!(
            "the section at z = {c} has a loop without a corner (a straight line)"
        ));
    }
    let positions: Vec<Point2<f64>> = points
        .iter()
        .map(|&v| Point2::new(at(v)[0], at(v)[1]))
        .collect();
    let mut conflicts = 0usize;
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::try_bulk_load_cdt(
        positions.clone(),
        chords.clone(),
        |_| conflicts += 1,
    )
    .map_err(|e| format!("the section at z = {c} could not be triangulated: {e:?}"))?;
    if cdt.num_vertices() != positions.len() || conflicts > 0 {
        return Err(format!(
            "the section at z = {c} has coincident points or crossing edges ({} of {} points distinct, {conflicts} crossing edges)",
            cdt.num_vertices(),
            positions.len()
        ));
    }
    // points inside the section (Ruppert's refinement, the cut's edges kept whole): without them
    // the cap is a fan of needles across the rod, which gmsh's reparametrisation of the patch
    // folds
    let mean_chord = chords
        .iter()
        .map(|&[a, b]| (positions[a].x - positions[b].x).hypot(positions[a].y - positions[b].y))
        .sum::<f64>()
        / chords.len() as f64;
    cdt.refine(
        RefinementParameters::<f64>::new()
            .exclude_outer_faces(true)
            .keep_constraint_edges()
            .with_angle_limit(AngleLimit::from_deg(25.0))
            .with_max_allowed_area(CAP_AREA_PER_CHORD2 * mean_chord * mean_chord)
            .with_min_required_area(1e-2 * mean_chord * mean_chord)
            .with_max_additional_vertices(MAX_CAP_POINTS),
    );
    for v in cdt.vertices().skip(points.len()) {
        let p = v.position();
        vertices.push(Vector3::new(p.x, p.y, c));
        points.push((vertices.len() - 1) as u32);
    }
    // a triangle of the section is one the cut winds around once (the side triangles run it
    // counter-clockwise around the section seen from +z, clockwise around a hole)
    let winding = |p: Point2<f64>| -> i32 {
        let mut w = 0;
        for &[a, b] in &chords {
            let (pa, pb) = (positions[a], positions[b]);
            let cross = (pb.x - pa.x) * (p.y - pa.y) - (p.x - pa.x) * (pb.y - pa.y);
            if pa.y <= p.y {
                if pb.y > p.y && cross > 0.0 {
                    w += 1;
                }
            } else if pb.y <= p.y && cross < 0.0 {
                w -= 1;
            }
        }
        w
    };
    let mut cap = Vec::new();
    for face in cdt.inner_faces() {
        let [p, q, r] = face.positions();
        let centroid = Point2::new((p.x + q.x + r.x) / 3.0, (p.y + q.y + r.y) / 3.0);
        match winding(centroid) {
            0 => continue,
            1 => {}
            w => {
                return Err(format!(
                    "the section at z = {c} winds {w} times around ({:.4}, {:.4}): overlapping shells",
                    centroid.x, centroid.y
                ));
            }
        }
        // counter-clockwise seen from +z; the cap faces −z
        let [a, b, cc] = face.vertices().map(|v| points[v.fix().index()]);
        let tri = [a, cc, b];
        // its boundary with the points left out on its chords (a chord runs the other way in the
        // cut)
        let mut ring: Vec<u32> = Vec::with_capacity(3);
        let mut split_edges = 0;
        let mut split_at = 0;
        for k in 0..3 {
            let (u, v) = (tri[k], tri[(k + 1) % 3]);
            ring.push(u);
            if let Some(on) = between.get(&(v, u)) {
                split_edges += 1;
                split_at = (k + 2) % 3;
                ring.extend(on.iter().rev());
            }
        }
        match split_edges {
            0 => cap.push(tri),
            1 => {
                // fan from the corner opposite the split edge
                let apex = tri[split_at];
                let i0 = ring.iter().position(|&v| v == apex).expect("a corner");
                let n = ring.len();
                for k in 1..n - 1 {
                    cap.push([apex, ring[(i0 + k) % n], ring[(i0 + k + 1) % n]]);
                }
            }
            _ => {
                let g = tri.map(|v| vertices[v as usize]);
                let g = (g[0] + g[1] + g[2]) / 3.0;
                vertices.push(Vector3::new(g.x, g.y, c));
                let gi = (vertices.len() - 1) as u32;
                for k in 0..ring.len() {
                    cap.push([ring[k], ring[(k + 1) % ring.len()], gi]);
                }
            }
        }
    }
    Ok(cap)
}

/// The largest triangle of the cap, in squared mean lengths of the cut's edges.
const CAP_AREA_PER_CHORD2: f64 = 16.0;

/// At most this many points are added inside a cap.
const MAX_CAP_POINTS: usize = 200_000;

/// Points of the cut closer than this (as the sine of the angle they make) to the line between
/// their neighbours count as on it.
const SLIVER_SINE: f64 = 1e-10;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::mass_properties::signed_volume;
    use crate::geometry::primitives::{cuboid, hollow_cylinder};
    use crate::geometry::validate::validate;

    fn volume(m: &IndexedMesh) -> f64 {
        signed_volume(m)
    }

    /// A box cut through its middle: half the volume, closed and outward (validate passes
    /// without a warning), the cap two or more triangles in the plane.
    #[test]
    fn half_a_box_is_half_its_volume_and_closed() {
        let b = cuboid(Vector3::new(4.0, 2.0, 6.0), Vector3::new(1.0, -1.0, 0.5));
        let h = half_above(&b, 0.5, 0.0).unwrap();
        let v = validate(h.clone()).unwrap();
        assert!(v.warnings.is_empty(), "{:?}", v.warnings);
        assert!((volume(&h) - 24.0).abs() < 1e-12, "{}", volume(&h));
        let (lo, hi) = h.bounding_box();
        assert_eq!(lo.z, 0.5);
        assert!((hi.z - 3.5).abs() < 1e-15);
    }

    /// A tube along z cut across: the section is an annulus (a hole in the cap), the half's
    /// volume half the tube's; off the middle, the volume of the part above the plane.
    #[test]
    fn half_a_tube_caps_an_annulus() {
        let t = hollow_cylinder(2.0, 1.0, 4.0, 48);
        let (lo, hi) = t.bounding_box();
        let full = volume(&t);
        let mid = 0.5 * (lo.z + hi.z);
        let h = half_above(&t, mid, 0.0).unwrap();
        assert!(validate(h.clone()).unwrap().warnings.is_empty());
        assert!(
            (volume(&h) / full - 0.5).abs() < 1e-12,
            "{}",
            volume(&h) / full
        );
        let q = lo.z + 0.25 * (hi.z - lo.z);
        let h = half_above(&t, q, 0.0).unwrap();
        assert!(validate(h.clone()).unwrap().warnings.is_empty());
        assert!((volume(&h) / full - 0.75).abs() < 1e-12);
    }

    /// A tube lying along x, cut along its axis: the cut passes through vertices (snapped) and
    /// crosses edges, and the section is two strips.
    #[test]
    fn half_a_tube_cut_along_its_axis() {
        let t = hollow_cylinder(2.0, 1.0, 4.0, 48);
        let rot =
            nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), 0.5 * std::f64::consts::PI);
        let t = IndexedMesh {
            vertices: t.vertices.iter().map(|v| rot * v).collect(),
            triangles: t.triangles,
        };
        let full = volume(&t);
        let h = half_above(&t, 0.0, 0.0).unwrap();
        assert!(validate(h.clone()).unwrap().warnings.is_empty());
        // the 48-gon is symmetric about its own axis plane: exactly half
        assert!(
            (volume(&h) / full - 0.5).abs() < 1e-12,
            "{}",
            volume(&h) / full
        );
    }

    #[test]
    fn a_plane_beside_the_surface_is_refused() {
        let b = cuboid(Vector3::new(1.0, 1.0, 1.0), Vector3::zeros());
        let e = half_above(&b, 2.0, 0.0).unwrap_err();
        assert!(e.contains("does not cut"), "{e}");
    }
}
