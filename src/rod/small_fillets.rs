//! Small concave fillets, which the adaptive loop's uniform first mesh cannot see.
//!
//! A recovery-based indicator measures what a mesh resolves. A concave fillet far smaller than
//! the first mesh's 5 mm elements (an R1 fillet at a shank's step) is meshed as a plain corner of
//! the facets: the stress concentration it makes is not in the solution, so neither the
//! recovered stress nor the indicator there says that anything is missing, and the loop refines
//! elsewhere. Whether such a fillet then got fine elements depended on where gmsh's
//! classification happened to cut the surface into patches (the stepped foreign rod's big-end step fillet had 1.0–1.2 mm elements on one route and 5 mm on the other,
//! and its F_x peak read 35 % apart, each route with a bar of 5–16 %).
//!
//! So the geometry sets a ceiling on the element size near every concave fillet whose radius is
//! below [`SMALL_FILLET_RADIUS_MM`]: from the second mesh on, at most R + g·d at distance d from
//! a kink of it (one element across the radius at the fillet, growing by [`GRADING`] per unit of
//! distance). The radius across a kink edge is its facet spacing over its kink angle, s / θ
//! (the chord of a circle of radius R subtends s / R), or the radius that the chain of a coarsely
//! faceted fillet describes ([`super::facets::EdgeKind::Fillet`]). The five committed designs
//! have no concave fillet below 4 mm, so the ceiling does not touch them.

use super::facets::{EdgeKind, SurfaceEdges};
use super::segment_grid::SegmentGrid;

/// Concave fillets below this radius are refined from the second mesh on whatever the first
/// mesh's indicator says, mm: well below the first mesh's 5 mm elements.
pub const SMALL_FILLET_RADIUS_MM: f64 = 2.0;

/// Growth of the ceiling with the distance from the fillet (size per unit distance).
pub const GRADING: f64 = 0.5;

/// How far from a small fillet the ceiling reaches, mm: there it is R + 5 mm, above the first
/// mesh's size.
pub const SMALL_FILLET_REACH_MM: f64 = 10.0;

/// The kinks of the small concave fillets of a triangulated surface, looked up by position.
#[derive(Clone, Debug, Default)]
pub struct SmallFillets {
    kinks: SegmentGrid,
    radius: Vec<f64>,
}

impl SmallFillets {
    /// The concave kinks of `edges` whose radius is below `max_radius` (units of `vertices`);
    /// `cell` is the lookup distance: no ceiling is given farther than `cell` from a kink.
    pub fn from_edges(
        edges: &SurfaceEdges,
        vertices: &[[f64; 3]],
        max_radius: f64,
        cell: f64,
    ) -> Self {
        let mut out = SmallFillets {
            kinks: SegmentGrid::new(cell),
            radius: Vec::new(),
        };
        for e in &edges.edges {
            if !e.concave {
                continue;
            }
            let r = match e.kind {
                EdgeKind::Fillet => e.radius,
                EdgeKind::Kink => match edges.kink_spacing(e, vertices) {
                    Some(s) => s / e.angle_deg.to_radians(),
                    None => continue,
                },
                EdgeKind::Flat | EdgeKind::Sharp => continue,
            };
            if r > 0.0 && r < max_radius {
                out.kinks.push(e.vertices.map(|v| vertices[v as usize]));
                out.radius.push(r);
            }
        }
        out
    }

    /// Number of kink edges of small concave fillets.
    pub fn len(&self) -> usize {
        self.kinks.len()
    }

    /// True when the surface has no small concave fillet.
    pub fn is_empty(&self) -> bool {
        self.kinks.is_empty()
    }

    /// The largest element size at `p`: the least R + [`GRADING`]·d over the kinks within one
    /// cell of `p`, infinite where there is none.
    pub fn ceiling_at(&self, p: [f64; 3]) -> f64 {
        self.kinks
            .nearby(p)
            .map(|(i, d)| self.radius[i] + GRADING * d)
            .fold(f64::INFINITY, f64::min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rod::facets::MAX_FILLET_RADIUS_MM;
    use crate::rod::facets::tests::{l_outline, prism};

    fn fillets(r: f64, facets: usize) -> (SmallFillets, f64) {
        let (v, t) = prism(&l_outline(20.0, 4.0, r, facets), 6.0);
        let edges = SurfaceEdges::new(&v, &t, 40.0, MAX_FILLET_RADIUS_MM);
        let s = SmallFillets::from_edges(&edges, &v, SMALL_FILLET_RADIUS_MM, 10.0);
        // the ceiling on the fillet's arc, half way up
        let a = -0.75 * std::f64::consts::PI;
        let on_arc = [4.0 + r + r * a.cos(), 4.0 + r + r * a.sin(), 3.0];
        let at = s.ceiling_at(on_arc);
        (s, at)
    }

    /// The inner corner of an L-shaped prism filleted with R1 in 12 facets (7.5° kinks, below
    /// the feature angle) or 2 (45° kinks, a coarsely faceted fillet): on the fillet the
    /// ceiling is about the radius; 10 mm away there is none. R4 (as the committed designs'
    /// smallest concave fillets) and the convex outer corners give no ceiling.
    #[test]
    fn the_ceiling_is_the_radius_at_a_small_concave_fillet_and_grows_away() {
        for facets in [12, 2] {
            let (s, at) = fillets(1.0, facets);
            assert!(!s.is_empty(), "{facets} facets");
            assert!(at > 0.8 && at < 1.3, "{facets} facets: ceiling {at}");
            // 3.6 mm from the ends of the arc
            let near = s.ceiling_at([7.0, 7.0, 3.0]);
            assert!(near > at && near < at + GRADING * 4.0, "{near}");
            assert_eq!(s.ceiling_at([18.0, 18.0, 3.0]), f64::INFINITY);
        }
        let (s4, at4) = fillets(4.0, 24);
        assert!(s4.is_empty() && at4 == f64::INFINITY, "R4: {}", s4.len());
        let (sharp, _) = fillets(0.0, 0);
        assert!(
            sharp.is_empty(),
            "a sharp corner is a singularity, not a fillet"
        );
    }
}
