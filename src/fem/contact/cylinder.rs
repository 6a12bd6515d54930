//! A rigid cylinder (a pin) and the linearised gap between it and the body's wall.
//!
//! The cylinder has an axis through `axis_point_m` with unit direction â and radius ρ. At a wall
//! point x of the body let r(x) = x − c − ((x − c)·â) â be its offset from the axis, r₀ = |r| and
//! e_r = r / r₀ the unit radial direction. With the body displacement u and the pin's rigid
//! translation w (perpendicular to â), the gap between wall and pin, linearised in u and w (small
//! displacements, e_r frozen at the reference position; Wriggers, *Computational Contact
//! Mechanics*, 2nd ed., §4.1, the normal gap to a rigid obstacle), is
//!
//! g = r₀ − ρ + e_r · (u − w),
//!
//! positive when open. A bore of radius R around a pin of radius ρ = R − c starts with the gap
//! g₀ = r₀ − ρ = c (the clearance); c < 0 is an interference (a pressed pin). The contact
//! pressure p ≥ 0 pushes the wall away from the axis: the traction on the body is p e_r, and the
//! body pushes the pin with −p e_r.

use crate::fem::boundary::{dot, norm};
use crate::fem::error::{FemError, Result};
use crate::fem::material::Material;

/// How a pin moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PinMotion {
    /// The pin's axis is held where it is (w = 0): the pin holds the body.
    Fixed,
    /// The pin carries this force on the body (N, perpendicular to its axis); its translation
    /// perpendicular to the axis is unknown and follows from the contact.
    Force([f64; 3]),
}

/// Where an elastic pin is held.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PinHold {
    /// At its core (the nodes at the inner radius): a solid pin's compliance under the pressure.
    Core,
    /// At its two end faces (the bore's faces): the pin also bends and shears between them.
    Ends,
}

/// An elastic pin's material, hold and bore.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PinElasticity {
    /// The pin's material.
    pub material: Material,
    /// Where it is held.
    pub hold: PinHold,
    /// Its inner radius (its bore, or its rigid core) over the wall's radius, in (0, 1).
    pub inner_ratio: f64,
}

/// A cylinder pressing on a set of the body's boundary faces: rigid, or elastic
/// ([`super::elastic_pin`]).
#[derive(Clone, Debug)]
pub struct Cylinder {
    /// A point on the axis, m.
    pub axis_point_m: [f64; 3],
    /// Axis direction (normalised by the solver).
    pub axis: [f64; 3],
    /// Pin radius ρ, m (bore radius − clearance; larger than the bore for an interference).
    pub radius_m: f64,
    /// The boundary faces it may touch (6 global node indices each, as from
    /// [`crate::fem::boundary::boundary_faces`]): the bore wall.
    pub faces: Vec<[usize; 6]>,
    /// When given, the initial gap of every wall node is this radius − ρ (the nominal
    /// clearance), instead of the node's own distance from the axis − ρ: straight-sided faces
    /// on a bore have their midside nodes inside the circle by the sagitta h²/(8R), which
    /// otherwise reads as an interference of that size.
    pub nominal_bore_radius_m: Option<f64>,
    /// Fixed or force-driven.
    pub motion: PinMotion,
    /// `None`: the pin is rigid; else its elasticity.
    pub elastic: Option<PinElasticity>,
}

impl Cylinder {
    /// The unit axis; refuses a zero axis, a non-positive radius and a force along the axis
    /// (frictionless contact cannot carry it).
    pub(crate) fn unit_axis(&self, index: usize) -> Result<[f64; 3]> {
        let l = norm(self.axis);
        if !(l.is_finite() && l > 0.0) {
            return Err(FemError::InvalidInput(format!(
                "contact cylinder {index}: zero or non-finite axis {:?}",
                self.axis
            )));
        }
        if !(self.radius_m.is_finite() && self.radius_m > 0.0) {
            return Err(FemError::InvalidInput(format!(
                "contact cylinder {index}: radius must be > 0 m, got {}",
                self.radius_m
            )));
        }
        if self.faces.is_empty() {
            return Err(FemError::InvalidInput(format!(
                "contact cylinder {index}: no wall faces"
            )));
        }
        let a = self.axis.map(|v| v / l);
        if let PinMotion::Force(f) = self.motion {
            let fm = norm(f);
            if !f.iter().all(|v| v.is_finite()) || dot(f, a).abs() > 1e-9 * fm.max(1e-300) {
                return Err(FemError::InvalidInput(format!(
                    "contact cylinder {index}: a frictionless pin carries only a force \
                     perpendicular to its axis, got {f:?} N along the axis {a:?}"
                )));
            }
        }
        Ok(a)
    }
}

/// Radial offset of `x` from the axis through `c` with unit direction `a`: (r₀, e_r).
pub(crate) fn radial(x: [f64; 3], c: [f64; 3], a: [f64; 3]) -> (f64, [f64; 3]) {
    let v = std::array::from_fn::<f64, 3, _>(|j| x[j] - c[j]);
    let along = dot(v, a);
    let r = std::array::from_fn::<f64, 3, _>(|j| v[j] - along * a[j]);
    let r0 = norm(r);
    (r0, r.map(|v| v / r0))
}

/// Two unit vectors completing `a` to a right-handed orthonormal frame (t₁, t₂, â).
pub(crate) fn plane_basis(a: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let seed = if a[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let s = dot(seed, a);
    let t1 = std::array::from_fn::<f64, 3, _>(|j| seed[j] - s * a[j]);
    let l = norm(t1);
    let t1 = t1.map(|v| v / l);
    (t1, crate::fem::boundary::cross(a, t1))
}
