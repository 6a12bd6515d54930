//! The holes of an open surface, measured: how many boundary loops, and how wide the widest is.
//!
//! The boundary edges (used by one triangle only) of a surface with holes form closed loops,
//! walked here along the direction their triangle gives them. A loop's width is
//! w = 2 |A| / P, with A = ½ Σ (pᵢ − c) × (pᵢ₊₁ − c) its vector area and P its perimeter: the
//! radius of a round hole, the width of a long slit. A slit far narrower than the part (two
//! rows of vertices that should have been one, the export's rounding) is an export artefact; a
//! hole as wide as a facet or wider is a missing face.

pub use super::error::Gaps;
use super::weld::IndexedMesh;
use nalgebra::Vector3;
use std::collections::HashMap;

/// A gap narrower than this share of the bounding-box diagonal is taken for an export
/// artefact (vertices meant to coincide, written apart), wider for a missing face.
pub const ARTEFACT_WIDTH_REL: f64 = 1e-4;

/// Measures the boundary loops of `mesh`; `None` when it has no boundary edge.
pub fn measure_gaps(mesh: &IndexedMesh) -> Option<Gaps> {
    let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
    for &[a, b, c] in &mesh.triangles {
        for (i, j) in [(a, b), (b, c), (c, a)] {
            *uses.entry((i.min(j), i.max(j))).or_default() += 1;
        }
    }
    // directed boundary edges: an edge used once, in the direction its triangle goes
    let mut out: HashMap<u32, Vec<u32>> = HashMap::new();
    let mut open = 0usize;
    for &[a, b, c] in &mesh.triangles {
        for (i, j) in [(a, b), (b, c), (c, a)] {
            if uses[&(i.min(j), i.max(j))] == 1 {
                out.entry(i).or_default().push(j);
                open += 1;
            }
        }
    }
    if open == 0 {
        return None;
    }
    let (lo, hi) = mesh.bounding_box();
    let diagonal = (hi - lo).norm();
    let mut starts: Vec<u32> = out.keys().copied().collect();
    starts.sort_unstable();
    let (mut loops, mut widest, mut at) = (0, 0.0f64, Vector3::zeros());
    for start in starts {
        while let Some(first) = out.get_mut(&start).and_then(Vec::pop) {
            let mut points = vec![mesh.vertices[start as usize]];
            let mut v = first;
            while v != start {
                points.push(mesh.vertices[v as usize]);
                match out.get_mut(&v).and_then(Vec::pop) {
                    Some(w) => v = w,
                    None => break,
                }
            }
            loops += 1;
            let c = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
            let (mut area, mut perimeter) = (Vector3::zeros(), 0.0);
            for (k, p) in points.iter().enumerate() {
                let q = points[(k + 1) % points.len()];
                area += (p - c).cross(&(q - c)) * 0.5;
                perimeter += (q - p).norm();
            }
            let width = if perimeter > 0.0 {
                2.0 * area.norm() / perimeter
            } else {
                0.0
            };
            if width >= widest {
                widest = width;
                at = c;
            }
        }
    }
    Some(Gaps {
        loops,
        widest,
        at,
        artefact: widest <= ARTEFACT_WIDTH_REL * diagonal,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitives::cuboid;

    #[test]
    fn a_missing_face_and_a_slit_are_told_apart() {
        let closed = cuboid(Vector3::new(10.0, 20.0, 30.0), Vector3::zeros());
        assert_eq!(measure_gaps(&closed), None);
        // one triangle of a 10 × 20 face removed: a right triangle of legs 10 and 20, whose
        // width 2 A / P = 2 · 100 / (30 + √500) is 3.82
        let mut hole = closed.clone();
        let removed = hole.triangles.remove(0);
        let g = measure_gaps(&hole).unwrap();
        assert_eq!(g.loops, 1);
        let [a, b, c] = removed.map(|v| closed.vertices[v as usize]);
        let (ab, bc, ca) = ((b - a).norm(), (c - b).norm(), (a - c).norm());
        let expected = 2.0 * 0.5 * (b - a).cross(&(c - a)).norm() / (ab + bc + ca);
        assert!(
            (g.widest - expected).abs() < 1e-12,
            "{} {expected}",
            g.widest
        );
        assert!(!g.artefact);
        // the same box with one corner vertex written twice, 1e-6 apart, in the triangles of
        // one face: a slit of width ~0 along the edges at that corner
        let mut slit = closed.clone();
        let v = slit.triangles[0][0];
        slit.vertices
            .push(slit.vertices[v as usize] + Vector3::new(0.0, 1e-6, 0.0));
        let twin = slit.vertices.len() as u32 - 1;
        for t in slit.triangles.iter_mut().filter(|t| t.contains(&v)).take(1) {
            for c in t.iter_mut().filter(|c| **c == v) {
                *c = twin;
            }
        }
        let g = measure_gaps(&slit).unwrap();
        assert!(g.artefact, "{g:?}");
        assert!(g.widest < 1e-5, "{g:?}");
    }
}
