//! The rod's mass properties in the crank–slider frame (SPEC "The mechanism", "Stage 1").
//!
//! Origin at the crank pin A; x̂ along A→B (the rod's long axis, projected normal to the pin
//! axis); ẑ along the pin axis; ŷ = ẑ × x̂ completes the plane of motion. Planar dynamics needs
//! the mass, l1 = (G − A)·x̂, the transverse offset (G − A)·ŷ and I_zz = ẑᵀ I_G ẑ about the pin
//! axis through the centroid G. I_xx = x̂ᵀ I_G x̂ about the long axis is reported too: it is
//! what the thesis' Table 5.1 calls the "moment of inertia about the centroid" (≈ 0.002 kg·m²),
//! an order of magnitude below I_zz, and it plays no part in the planar dynamics.

use super::mass_properties::MassProperties;
use anyhow::{Result, bail};
use nalgebra::Vector3;
use serde::Serialize;

/// Orthonormal frame of the mechanism plane, anchored at the crank pin A.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MechanismFrame {
    pub origin: Vector3<f64>,
    pub x: Vector3<f64>,
    pub y: Vector3<f64>,
    pub z: Vector3<f64>,
    /// Distance A→B in the plane of motion [m].
    pub centre_distance: f64,
}

impl MechanismFrame {
    /// Frame from the two pin centres and the pin axis (need not be exactly normal to A→B).
    pub fn new(
        crank_pin: Vector3<f64>,
        piston_pin: Vector3<f64>,
        axis: Vector3<f64>,
    ) -> Result<Self> {
        let z = axis.normalize();
        let ab = piston_pin - crank_pin;
        let in_plane = ab - z * z.dot(&ab);
        let centre_distance = in_plane.norm();
        if centre_distance.is_nan() || centre_distance <= 1e-9 * ab.norm() || centre_distance == 0.0
        {
            bail!(
                "the crank and piston pins coincide in the plane of motion (A→B = {ab:?} m is parallel to the pin axis)"
            );
        }
        let x = in_plane / centre_distance;
        Ok(MechanismFrame {
            origin: crank_pin,
            x,
            y: z.cross(&x),
            z,
            centre_distance,
        })
    }
}

/// What the planar mechanism needs of the rod, plus the moments a user compares with CAD.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RodInFrame {
    /// Centroid distance from the crank pin A along A→B [m].
    pub l1_m: f64,
    /// Centroid offset in the plane of motion, normal to A→B (positive towards ŷ = ẑ × x̂) [m].
    pub offset_m: f64,
    /// Centroid offset along the pin axis (out of the plane of motion) [m].
    pub offset_z_m: f64,
    /// Moment of inertia about the pin-axis direction through the centroid [kg·m²]: used by the dynamics.
    pub i_zz_kgm2: f64,
    /// Moment of inertia about the rod's long axis through the centroid [kg·m²]: Table 5.1's column.
    pub i_xx_kgm2: f64,
    /// Moment of inertia about ŷ through the centroid [kg·m²].
    pub i_yy_kgm2: f64,
    /// Centre distance A→B in the plane of motion [m].
    pub centre_distance_m: f64,
}

impl RodInFrame {
    pub fn new(frame: &MechanismFrame, mass: &MassProperties) -> Self {
        let g = mass.centroid - frame.origin;
        RodInFrame {
            l1_m: g.dot(&frame.x),
            offset_m: g.dot(&frame.y),
            offset_z_m: g.dot(&frame.z),
            i_zz_kgm2: mass.moment_about(&frame.z),
            i_xx_kgm2: mass.moment_about(&frame.x),
            i_yy_kgm2: mass.moment_about(&frame.y),
            centre_distance_m: frame.centre_distance,
        }
    }
}
