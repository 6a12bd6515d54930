//! Finding the pin bores on the boundary of the mesh (SPEC Stage 3: the small-end bore B is fixed,
//! the big-end bore A is loaded).
//!
//! For a pin axis (a point and a direction, inputs) the bore wall is the set of boundary faces that
//! 1. face the axis: the outward normal at the face centroid points towards the axis within
//!    `normal_tolerance_deg` of the radial direction, and
//! 2. lie on the innermost such cylinder: all three corners at radius r_bore within
//!    `radius_tolerance` (relative), where r_bore is the smallest "largest corner radius" among the
//!    faces of 1. The radius is found, not assumed.
//!
//! Faces are selected by their corners (midside nodes of a straight face on a faceted bore lie on
//! chords, inside the cylinder), and all six nodes of a selected face belong to the set.
//! The set must be plausible: its area close to 2π r × its axial length (`min_coverage`) and no
//! angular gap above 90° around the axis; an empty or implausible set is an error naming the bore.
//! The axial length is the set's whole extent, or, where a filleted or chamfered rim lets some
//! faces of the transition ring pass the radius test (stretching the extent in a few places), the
//! length that holds the middle 80 % of the area, scaled to the whole.

use super::pin_model::PinModel;
use serde::{Deserialize, Serialize};

use crate::fem::boundary::{
    BoundaryFace, dot, face_area, face_coords, face_normal, face_point, norm,
};
use crate::fem::error::{FemError, Result};
use crate::fem::mesh::TetMesh;
use crate::fem::quadrature::TRI6;
use crate::rod::pin_load::BoreLoad;

/// The two pin axes and the tolerances of the bore search. Centres in metres.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BoreSpec {
    /// A point on the crank-pin axis (big end, loaded bore A), m.
    pub loaded_centre_m: [f64; 3],
    /// A point on the piston-pin axis (small end, fixed bore B), m.
    pub fixed_centre_m: [f64; 3],
    /// Pin axis direction (normalised on use).
    pub axis: [f64; 3],
    /// Relative tolerance on the corner radii of bore faces (default 0.01).
    pub radius_tolerance: f64,
    /// Largest angle between a bore face's inward normal and the radial direction, degrees (default 30).
    pub normal_tolerance_deg: f64,
    /// Smallest accepted area / (2π r × axial length) of a bore set (default 0.85), for a full
    /// bore; a partial bore's is scaled by its arc.
    pub min_coverage: f64,
    /// The arc the loaded and the fixed bore span, degrees: 360 for a full bore, less for a
    /// partial one (a big end modelled without its cap); the load acts on the surface that exists.
    #[serde(default = "full_arc")]
    pub loaded_arc_deg: f64,
    #[serde(default = "full_arc")]
    pub fixed_arc_deg: f64,
    /// How a pin's force is spread over its bore: uniform (default) or a cosine bearing
    /// pressure on the pressed half ([`crate::rod::pin_load::BoreLoad`], `[fem] bore_load`).
    #[serde(default)]
    pub bore_load: BoreLoad,
    /// With contact ([`BoreLoad::Contact`]): the radial clearance of pin A in bore A and of pin B
    /// in bore B, m (negative: an interference); `None`: [`default_clearance_m`] of the bore
    /// found.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearance_a_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearance_b_m: Option<f64>,
    /// With contact: rigid pins (default) or elastic ones ([`PinModel`], `[fem] pins`).
    #[serde(default, skip_serializing_if = "PinModel::is_rigid")]
    pub pins: PinModel,
    /// With elastic pins: their inner radius over the bore's; `None`:
    /// [`super::pin_model::DEFAULT_PIN_INNER_RATIO`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pin_inner_ratio: Option<f64>,
}

/// Radial clearance of a pin in its bore where none is given, as a fraction of the bore's
/// diameter: c = 0.35 ‰ · d (a diametral clearance of 0.7 ‰ · d). Engine makers' figures for
/// rods of this size: big-end oil clearance 0.025–0.050 mm on a 56 mm crank pin (Toyota/Lexus
/// 2UR-FSE, 0.45–0.9 ‰), 0.020–0.058 mm on 42 mm (Yanmar 3YM30, 0.5–1.4 ‰), piston pin in the
/// small-end bush about 0.028 mm on 38.1 mm (Caterpillar 3208, 0.7 ‰); docs/contact.md.
pub const DEFAULT_CLEARANCE_PER_DIAMETER: f64 = 0.35e-3;

/// [`DEFAULT_CLEARANCE_PER_DIAMETER`] of a bore of radius `radius_m` (m).
pub fn default_clearance_m(radius_m: f64) -> f64 {
    DEFAULT_CLEARANCE_PER_DIAMETER * 2.0 * radius_m
}

fn full_arc() -> f64 {
    360.0
}

impl Default for BoreSpec {
    /// The rodstudy mechanism interface: A = (0, 0, 0), B = (180, 0, 0) mm, pin axis z.
    fn default() -> Self {
        BoreSpec::from_mm([0.0, 0.0, 0.0], [180.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    }
}

impl BoreSpec {
    /// Pin centres in millimetres (as in the sidecar), default tolerances.
    pub fn from_mm(loaded_centre_mm: [f64; 3], fixed_centre_mm: [f64; 3], axis: [f64; 3]) -> Self {
        BoreSpec {
            loaded_centre_m: loaded_centre_mm.map(|v| v * 1e-3),
            fixed_centre_m: fixed_centre_mm.map(|v| v * 1e-3),
            axis,
            radius_tolerance: 0.01,
            normal_tolerance_deg: 30.0,
            min_coverage: 0.85,
            loaded_arc_deg: 360.0,
            fixed_arc_deg: 360.0,
            bore_load: BoreLoad::Uniform,
            clearance_a_m: None,
            clearance_b_m: None,
            pins: PinModel::Rigid,
            pin_inner_ratio: None,
        }
    }

    /// The pins' elasticity under contact, of `material` ([`PinModel::elasticity`]); `None`:
    /// rigid pins.
    pub fn pin_elasticity(
        &self,
        material: &crate::fem::material::Material,
    ) -> Result<Option<crate::fem::contact::PinElasticity>> {
        self.pins.elasticity(material, self.pin_inner_ratio)
    }

    /// Unit axis; error if zero or not finite.
    pub fn unit_axis(&self) -> Result<[f64; 3]> {
        let l = norm(self.axis);
        if !(l.is_finite() && l > 0.0) {
            return Err(FemError::InvalidInput(format!(
                "pin axis {:?} has no direction",
                self.axis
            )));
        }
        Ok(self.axis.map(|v| v / l))
    }
}

/// Which bore.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum BoreRole {
    /// Big-end bore A (crank pin), carries the load.
    Loaded,
    /// Small-end bore B (piston pin), fixed.
    Fixed,
}

impl std::fmt::Display for BoreRole {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            BoreRole::Loaded => "loaded big-end bore A",
            BoreRole::Fixed => "fixed small-end bore B",
        })
    }
}

/// A bore wall found on the mesh boundary.
#[derive(Clone, Debug)]
pub struct BoreSurface {
    /// Which bore.
    pub role: BoreRole,
    /// The pin centre it was searched around, m.
    pub centre_m: [f64; 3],
    /// The radius found (largest corner radius of the innermost face), m.
    pub radius_m: f64,
    /// The faces (6 global node indices each, outward order).
    pub faces: Vec<[usize; 6]>,
    /// All nodes of those faces, sorted.
    pub nodes: Vec<usize>,
    /// Area of the faces, m².
    pub area_m2: f64,
    /// Axial extent of the set (min, max of the axial coordinate from the centre), m.
    pub axial_range_m: [f64; 2],
    /// area / (2π r × axial length).
    pub coverage: f64,
    /// Largest angular gap between corners of the set around the axis, degrees.
    pub max_angular_gap_deg: f64,
}

/// The share of a bore set's area left out at each end for [`quantile_length`].
const LENGTH_QUANTILE: f64 = 0.1;

/// Area of a triangle up to the axial coordinate `z`: its corners' axial coordinates `zs`
/// (sorted), its area `a`. The area density along the axis rises linearly from zs[0] to zs[1]
/// and falls linearly to zs[2].
fn area_below(a: f64, zs: [f64; 3], z: f64) -> f64 {
    let [z1, z2, z3] = zs;
    if z <= z1 {
        0.0
    } else if z >= z3 || z3 - z1 <= 0.0 {
        a
    } else if z <= z2 {
        a * (z - z1).powi(2) / ((z3 - z1) * (z2 - z1))
    } else {
        a * (1.0 - (z3 - z).powi(2) / ((z3 - z1) * (z3 - z2)))
    }
}

/// The wall's axial length from the distribution of its area along the axis: the distance
/// between the axial coordinates below which [`LENGTH_QUANTILE`] and 1 − [`LENGTH_QUANTILE`] of
/// the area lie, divided by 1 − 2·[`LENGTH_QUANTILE`] (exact for a wall of uniform width). A
/// sparse fringe of faces at the ends (the first faces of a rim fillet or chamfer that pass the
/// radius test) moves it little, while it stretches the set's whole extent.
fn quantile_length(spans: &[(f64, [f64; 3])], zmin: f64, zmax: f64) -> f64 {
    let total: f64 = spans.iter().map(|s| s.0).sum();
    let at = |share: f64| -> f64 {
        let (mut lo, mut hi) = (zmin, zmax);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            let below: f64 = spans.iter().map(|&(a, zs)| area_below(a, zs, mid)).sum();
            if below < share * total {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    };
    (at(1.0 - LENGTH_QUANTILE) - at(LENGTH_QUANTILE)) / (1.0 - 2.0 * LENGTH_QUANTILE)
}

/// Finds one bore wall, see the module documentation.
pub fn find_bore(
    mesh: &TetMesh,
    boundary: &[BoundaryFace],
    role: BoreRole,
    centre: [f64; 3],
    spec: &BoreSpec,
) -> Result<BoreSurface> {
    let axis = spec.unit_axis()?;
    let centre_mm = centre.map(|v| v * 1e3);
    let not_found = |reason: String| {
        bore_error(
            role,
            "no bore found around the pin axis through",
            centre_mm,
            &reason,
        )
    };
    let implausible =
        |reason: String| bore_error(role, "implausible bore surface around", centre_mm, &reason);
    let radial = |p: [f64; 3]| -> ([f64; 3], f64) {
        let v = [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
        let along = dot(v, axis);
        let r = [
            v[0] - along * axis[0],
            v[1] - along * axis[1],
            v[2] - along * axis[2],
        ];
        (r, along)
    };
    let cos_tol = spec.normal_tolerance_deg.to_radians().cos();
    // 1. faces whose outward normal points at the axis
    let mut cands: Vec<(usize, f64, [f64; 3])> = Vec::new(); // (face, max corner radius, corner radii)
    for (i, f) in boundary.iter().enumerate() {
        let x = face_coords(mesh, &f.nodes);
        let (pc, _, _) = face_point(&x, [1.0 / 3.0, 1.0 / 3.0]);
        let (rv, _) = radial(pc);
        let rc = norm(rv);
        if rc == 0.0 {
            continue;
        }
        let n = face_normal(&x);
        if dot(n, rv) / rc <= -cos_tol {
            let radii = [0, 1, 2].map(|a| norm(radial(x[a]).0));
            cands.push((i, radii[0].max(radii[1]).max(radii[2]), radii));
        }
    }
    let Some(r_bore) = cands.iter().map(|c| c.1).min_by(|a, b| a.total_cmp(b)) else {
        return Err(not_found("no boundary face faces the pin axis".into()));
    };
    if r_bore <= 0.0 {
        return Err(not_found("a boundary face touches the pin axis".into()));
    }
    // 2. the innermost cylinder
    let (lo, hi) = (
        r_bore * (1.0 - spec.radius_tolerance),
        r_bore * (1.0 + spec.radius_tolerance),
    );
    let sel: Vec<usize> = cands
        .iter()
        .filter(|c| c.2.iter().all(|r| *r >= lo && *r <= hi))
        .map(|c| c.0)
        .collect();
    if sel.len() < 3 {
        return Err(implausible(format!(
            "only {} boundary face(s) at radius {:.3} mm",
            sel.len(),
            r_bore * 1e3
        )));
    }
    let faces: Vec<[usize; 6]> = sel.iter().map(|&i| boundary[i].nodes).collect();
    let mut nodes: Vec<usize> = faces.iter().flatten().copied().collect();
    nodes.sort_unstable();
    nodes.dedup();
    // axial range and angular coverage from the corners
    let e1 = {
        let t = if axis[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let d = dot(t, axis);
        let v = [t[0] - d * axis[0], t[1] - d * axis[1], t[2] - d * axis[2]];
        v.map(|c| c / norm(v))
    };
    let e2 = crate::fem::boundary::cross(axis, e1);
    let (mut zmin, mut zmax) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut angles = Vec::with_capacity(3 * faces.len());
    // each face's area along the axis (its three corners' axial coordinates), for the length
    // of the wall between the area's quantiles
    let mut spans: Vec<(f64, [f64; 3])> = Vec::with_capacity(faces.len());
    for f in &faces {
        let mut z = [0.0; 3];
        for (k, &n) in f[..3].iter().enumerate() {
            let (rv, along) = radial(mesh.nodes()[n]);
            zmin = zmin.min(along);
            zmax = zmax.max(along);
            z[k] = along;
            angles.push(dot(rv, e2).atan2(dot(rv, e1)).to_degrees());
        }
        z.sort_by(|a, b| a.total_cmp(b));
        spans.push((face_area(&face_coords(mesh, f), &TRI6), z));
    }
    let area_m2: f64 = spans.iter().map(|s| s.0).sum();
    let core_length = quantile_length(&spans, zmin, zmax);
    angles.sort_by(|a, b| a.total_cmp(b));
    let mut gap = 360.0 + angles[0] - angles[angles.len() - 1];
    for w in angles.windows(2) {
        gap = f64::max(gap, w[1] - w[0]);
    }
    let length = zmax - zmin;
    let coverage = area_m2 / (2.0 * std::f64::consts::PI * r_bore * length);
    // a partial bore (stage 1 measured its arc) covers that fraction of a full wall
    let arc = match role {
        BoreRole::Loaded => spec.loaded_arc_deg,
        BoreRole::Fixed => spec.fixed_arc_deg,
    }
    .clamp(1.0, 360.0);
    let share = arc / 360.0;
    let core_coverage = area_m2 / (2.0 * std::f64::consts::PI * r_bore * core_length);
    let within = |c: f64| c >= spec.min_coverage * share && c <= 1.05 * share;
    // a filleted or chamfered rim: some faces of the transition ring pass the radius test and
    // stretch the axial range; the length between the area's quantiles is then the wall's
    let plausible = length > 0.0 && (within(coverage) || within(core_coverage));
    if !plausible {
        let what = if arc < 360.0 {
            format!("an arc of {arc:.0}° of a cylinder wall (the partial bore stage 1 measured)")
        } else {
            "a full cylinder wall".to_string()
        };
        return Err(implausible(format!(
            "{} faces at radius {:.3} mm cover {:.1} mm² over an axial length of {:.3} mm: {:.1} % of a \
             full cylinder wall ({:.1} % over the length {:.3} mm that holds the middle 80 % of the area; expected \
             {:.0}–{:.0} % for {what})",
            faces.len(),
            r_bore * 1e3,
            area_m2 * 1e6,
            length * 1e3,
            100.0 * coverage,
            100.0 * core_coverage,
            core_length * 1e3,
            100.0 * spec.min_coverage * share,
            105.0 * share
        )));
    }
    if gap > 90.0 + (360.0 - arc) {
        return Err(implausible(format!(
            "the faces at radius {:.3} mm leave a gap of {gap:.0}° around the axis",
            r_bore * 1e3
        )));
    }
    Ok(BoreSurface {
        role,
        centre_m: centre,
        radius_m: r_bore,
        faces,
        nodes,
        area_m2,
        axial_range_m: [zmin, zmax],
        coverage,
        max_angular_gap_deg: gap,
    })
}

/// Finds both bores; they must not share nodes. Returns (loaded A, fixed B).
pub fn find_bores(
    mesh: &TetMesh,
    boundary: &[BoundaryFace],
    spec: &BoreSpec,
) -> Result<(BoreSurface, BoreSurface)> {
    let loaded = find_bore(mesh, boundary, BoreRole::Loaded, spec.loaded_centre_m, spec)?;
    let fixed = find_bore(mesh, boundary, BoreRole::Fixed, spec.fixed_centre_m, spec)?;
    let shared = loaded
        .nodes
        .iter()
        .filter(|n| fixed.nodes.binary_search(n).is_ok())
        .count();
    if shared > 0 {
        return Err(bore_error(
            BoreRole::Fixed,
            "implausible bore surface around",
            spec.fixed_centre_m.map(|v| v * 1e3),
            &format!("it shares {shared} nodes with the loaded bore"),
        ));
    }
    Ok((loaded, fixed))
}

/// What a bore that is not found, or not a cylinder wall, most often means.
const BORE_HINT: &str = "check the pins (sidecar `crank_pin`/`piston_pin` in the design file's \
     units, or found from the geometry) and the units (sidecar `units`; a given mesh is in the \
     design's units and axes)";

/// The refusal of a bore: which, what is wrong (`what` ends in "around …"), where (mm), why, and
/// what it most often means.
fn bore_error(role: BoreRole, what: &str, centre_mm: [f64; 3], reason: &str) -> FemError {
    let [x, y, z] = centre_mm;
    FemError::Problem(format!(
        "{role}: {what} ({x:.3}, {y:.3}, {z:.3}) mm: {reason} ({BORE_HINT})"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A triangle with one corner at z = 1 above an edge at z = 0: the part above z = ½ is a
    /// similar triangle of half the size, a quarter of the area.
    #[test]
    fn area_below_a_plane_of_a_triangle() {
        assert_eq!(area_below(2.0, [0.0, 0.0, 1.0], 0.5), 1.5);
        // the mirror: an edge at z = 1, a corner at z = 0
        assert_eq!(area_below(2.0, [0.0, 1.0, 1.0], 0.5), 0.5);
        // a corner in between: the two pieces meet at zs[1] and add up to the whole
        let (a, zs) = (3.0, [0.0, 0.25, 1.0]);
        assert!((area_below(a, zs, 0.25) - a * 0.25).abs() < 1e-15);
        assert_eq!(area_below(a, zs, -1.0), 0.0);
        assert_eq!(area_below(a, zs, 2.0), a);
    }

    /// A wall of uniform width (a strip of triangle pairs) has the length between its area
    /// quantiles equal to its extent; a sparse fringe of faces beyond one end (the first faces
    /// of a rim fillet that pass the radius test) stretches the extent by 3 mm but the quantile
    /// length by under 2 %.
    #[test]
    fn quantile_length_of_a_wall_and_of_a_wall_with_a_fringe() {
        let (length, rows) = (0.028, 14);
        let dz = length / rows as f64;
        let mut spans: Vec<(f64, [f64; 3])> = Vec::new();
        for k in 0..rows {
            let (z0, z1) = (k as f64 * dz, (k + 1) as f64 * dz);
            for _ in 0..40 {
                spans.push((1e-6, [z0, z0, z1]));
                spans.push((1e-6, [z0, z1, z1]));
            }
        }
        let l = quantile_length(&spans, 0.0, length);
        assert!((l / length - 1.0).abs() < 1e-12, "{l}");
        // a fringe: 6 faces of the 80 in a ring reaching 3 mm beyond the end
        for _ in 0..6 {
            spans.push((1e-6, [length, length, length + 0.003]));
        }
        let l = quantile_length(&spans, 0.0, length + 0.003);
        assert!((l / length - 1.0).abs() < 0.02, "{l}");
    }
}
