//! A bore as the finder measures it, the pair of pin bores, and the thresholds of the search.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Largest dihedral angle between neighbouring facets within one smooth patch [deg].
pub const SMOOTH_ANGLE_DEG: f64 = 30.0;
/// Largest smallest-eigenvalue share of Σ A n nᵀ for a patch around one axis.
pub const MAX_OFF_AXIS_SHARE: f64 = 0.05;
/// Smallest middle-eigenvalue share of Σ A n nᵀ for a curved patch (an arc of about 20°).
pub const MIN_CURVED_SHARE: f64 = 0.01;
/// Largest RMS distance of a patch's vertices from the fitted cylinder, relative to its radius.
pub const MAX_RESIDUAL_REL: f64 = 2e-3;
/// Smallest arc of a bore that may be a pin bore [deg].
pub const MIN_PIN_ARC_DEG: f64 = 120.0;
/// A third bore whose wall area is at least this share of the second pin's is a competitor.
pub const COMPARABLE_AREA: f64 = 0.3;
/// Radii closer than this (relative) cannot tell the crank end from the piston end.
pub const EQUAL_RADII_REL: f64 = 0.01;
/// Axes within this angle are parallel [deg].
pub const PARALLEL_DEG: f64 = 1.0;
/// An arc with a gap below this is a full bore [deg].
pub const FULL_GAP_DEG: f64 = 0.5;

/// A cylindrical hole (or part of one) in the rod's surface, in the mesh's units (metres).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bore {
    /// Point of the axis at the middle of the bore's axial extent.
    pub centre: [f64; 3],
    pub radius: f64,
    /// Unit axis, its largest component positive.
    pub axis: [f64; 3],
    /// Arc of the cylinder the wall covers [deg]: 360 for a full bore.
    pub arc_deg: f64,
    /// Extent of the wall along the axis.
    pub length: f64,
    /// The wall closes around the axis.
    pub full: bool,
    /// Unit direction from the axis to the middle of the opening (partial bores only).
    pub opening: Option<[f64; 3]>,
    /// RMS distance of the wall's vertices from the fitted cylinder.
    pub residual_rms: f64,
    /// Area of the wall.
    pub area: f64,
    pub triangles: usize,
}

impl Bore {
    pub fn centre_v(&self) -> Vector3<f64> {
        Vector3::from(self.centre)
    }
    pub fn axis_v(&self) -> Vector3<f64> {
        Vector3::from(self.axis)
    }
    /// Distance of `p` from the bore's axis line.
    pub fn distance_from_axis(&self, p: Vector3<f64>) -> f64 {
        let d = p - self.centre_v();
        (d - self.axis_v() * self.axis_v().dot(&d)).norm()
    }
}

/// The two pin bores the rod is built around.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FoundPins {
    /// The larger bore: crank end A.
    pub crank: Bore,
    /// The smaller bore: piston end B.
    pub piston: Bore,
    /// The common pin axis (mean of the two, unit, largest component positive).
    pub axis: [f64; 3],
    /// Distance between the two axes in the plane normal to the pin axis.
    pub centre_distance: f64,
}
