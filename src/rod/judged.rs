//! The judged region of a rod: the nodes whose stress the criterion judges. Two kinds of place are
//! left out, each by a band of fixed physical width (not a number of elements, so that refinement
//! does not move the band towards the singularity):
//! - the fixed bore B: the edge of a fully fixed surface is a singularity whose peak grows under
//!   refinement (band `[fem] fixed_band_mm`, [`DEFAULT_FIXED_BAND_M`]);
//! - sharp re-entrant edges of the geometry ([`super::facets::reentrant_edges`]; band
//!   `[fem] singular_band_mm`, [`DEFAULT_SINGULAR_BAND_M`]).
//!
//! Used by the static cases ([`super::solve`]), the adaptive loop (the floor of the sizes near a
//! singularity) and the cycle ([`super::cycle`]).

use crate::fem::mesh::TetMesh;
use crate::fem::stress::{Peak, nodes_away_from, nodes_away_from_segments, point_segment_distance};

/// The default band around the fixed bore excluded from the judged stress measure: 6 mm.
pub const DEFAULT_FIXED_BAND_M: f64 = 6e-3;

/// The default band around sharp re-entrant edges left out of the judged peak: 3 mm.
pub const DEFAULT_SINGULAR_BAND_M: f64 = 3e-3;

/// The bands left out of the judged peak.
#[derive(Clone, Copy, Debug)]
pub struct Bands<'a> {
    /// The fixed bore's faces.
    pub fixed_faces: &'a [[usize; 6]],
    /// Width of the band around them, m.
    pub fixed_band_m: f64,
    /// Sharp re-entrant edges (segments, m).
    pub singular_edges_m: &'a [[[f64; 3]; 2]],
    /// Width of the band around them, m.
    pub singular_band_m: f64,
}

/// Per node: judged (outside both bands), and left out for a sharp edge alone.
#[derive(Clone, Debug)]
pub struct JudgedNodes {
    /// Outside the bands around the fixed bore and the sharp edges.
    pub judged: Vec<bool>,
    /// Inside a band around a sharp edge but outside the fixed bore's.
    pub in_edge_band: Vec<bool>,
}

/// The judged nodes of `mesh` ([`JudgedNodes`]).
pub fn judged_nodes(mesh: &TetMesh, bands: &Bands<'_>) -> JudgedNodes {
    let away_fixed = nodes_away_from(mesh, bands.fixed_faces, bands.fixed_band_m);
    let away_edges = nodes_away_from_segments(mesh, bands.singular_edges_m, bands.singular_band_m);
    let judged = away_fixed
        .iter()
        .zip(&away_edges)
        .map(|(a, b)| *a && *b)
        .collect();
    let in_edge_band = away_fixed
        .iter()
        .zip(&away_edges)
        .map(|(f, e)| *f && !*e)
        .collect();
    JudgedNodes {
        judged,
        in_edge_band,
    }
}

/// Per node, the smallest element size adaptive refinement may ask for near a singularity, m:
/// within twice a band of it, a third of the fixed bore's band or a sixth of a sharp edge's (so
/// that six elements lie between the edge and the judged stress at the band's border); else 0.
pub fn singularity_floor(mesh: &TetMesh, bands: &Bands<'_>) -> Vec<f64> {
    let (band, singular_band) = (bands.fixed_band_m, bands.singular_band_m);
    let near_fixed = nodes_away_from(mesh, bands.fixed_faces, 2.0 * band);
    let near_edges = nodes_away_from_segments(mesh, bands.singular_edges_m, 2.0 * singular_band);
    near_fixed
        .iter()
        .zip(&near_edges)
        .map(|(f, e)| match (f, e) {
            (true, true) => 0.0,
            (false, true) => band / 3.0,
            (true, false) => singular_band / 6.0,
            (false, false) => (band / 3.0).max(singular_band / 6.0),
        })
        .collect()
}

/// The warning of a band around sharp edges that holds the highest stress of its neighbourhood,
/// above the judged peak `judged_pa` of the case labelled `label`: where, how far from the nearest
/// edge, by how much, and what it means on an STL or on an exact geometry.
pub fn edge_band_warning(
    label: &str,
    hidden: &Peak,
    judged_pa: f64,
    edges: &[[[f64; 3]; 2]],
    band: f64,
    exact_geometry: bool,
) -> String {
    let d = edges
        .iter()
        .map(|s| point_segment_distance(hidden.location_m, *s))
        .fold(f64::INFINITY, f64::min);
    let p = hidden.location_m.map(|v| v * 1e3);
    let advice = if exact_geometry {
        "the edge is sharp in the B-rep, where the stress has no finite peak; if the real part \
         rounds it, model the fillet in CAD and the peak is there"
    } else {
        "if that edge is rounded in the real part (a fillet the export cut into few facets), the \
         peak is there (a STEP export settles it)"
    };
    format!(
        "{label}: the {:.1} mm band around the sharp re-entrant edges holds the highest stress of its neighbourhood, {:.1} MPa at ({:.1}, {:.1}, {:.1}) mm, {:.2} mm from the nearest edge, {:.0} % above the judged peak {:.1} MPa: left out as a singularity; {advice}",
        band * 1e3,
        hidden.value * 1e-6,
        p[0],
        p[1],
        p[2],
        d * 1e3,
        100.0 * (hidden.value / judged_pa - 1.0),
        judged_pa * 1e-6
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The edge band's warning fits the geometry: on an STL a sharp edge may be a fillet cut into
    /// few facets (a STEP settles it); on a STEP the edge is sharp in the B-rep.
    #[test]
    fn the_edge_band_warning_fits_stl_and_step() {
        let hidden = Peak {
            value: 120e6,
            node: 0,
            element: None,
            location_m: [0.01, 0.0, 0.0],
        };
        let edges = [[[0.0, 0.0, 0.0], [0.0, 0.0, 0.01]]];
        let stl = edge_band_warning("F_x", &hidden, 100e6, &edges, 3e-3, false);
        assert!(stl.contains("(a STEP export settles it)"), "{stl}");
        assert!(stl.contains("10.00 mm from the nearest edge") && stl.contains("20 % above"));
        let step = edge_band_warning("F_x", &hidden, 100e6, &edges, 3e-3, true);
        assert!(step.contains("sharp in the B-rep"), "{step}");
        assert!(
            !step.contains("STEP export") && !step.contains("facets"),
            "{step}"
        );
    }
}
