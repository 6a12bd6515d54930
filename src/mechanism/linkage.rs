//! The crank–slider linkage on the multibody core, written out once: three
//! moving bodies (crank, rod, piston; thesis eq. 2.14) and the joints O, A, B
//! (revolute, thesis eq. 2.20, 2.23, 2.25) and the slide (translational, eq.
//! 2.28–2.31, ground–piston) for a given geometry and given masses. Nothing is
//! validated here beyond what [`MultibodyBuilder::build`] checks, so l ≤ r,
//! toggle positions and redundant joint sets can be built on purpose.
//!
//! [`CrankSlider`](super::CrankSlider) builds its multibody model from it (with
//! its own names, loads and driver), and so do the test rigs of the multibody
//! core (`test_rig` here, under `#[cfg(test)]`; `tests/common` for the end-to-end
//! tests).
//!
//! Geometry (global frame as in [`crank_slider`](super::crank_slider)): O at
//! the origin; the crank's centroid on the crank line at `crank_centroid_m`
//! from O, the crank pin A at r from O; the rod's centroid at l₁ along A→B and
//! `rod_offset_m` to its left; the piston's centroid on the pin B; the slide
//! along global x through (0, `slide_y_m`).

use nalgebra::Vector2;

use super::body::BodyId;
use super::system::MultibodyBuilder;

/// Geometry and mass properties of a crank–slider on the multibody core.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrankSliderLinkage {
    /// Crank radius r = |OA| (m).
    pub crank_radius_m: f64,
    /// Centre distance l = |AB| (m).
    pub centre_distance_m: f64,
    /// Signed distance e of the crank centroid from O along O→A (m).
    pub crank_centroid_m: f64,
    /// Distance l₁ of the rod centroid from A along A→B (m).
    pub rod_l1_m: f64,
    /// Offset of the rod centroid to the left of A→B (m).
    pub rod_offset_m: f64,
    /// The slide line is y = `slide_y_m` (m).
    pub slide_y_m: f64,
    /// Masses of crank, rod and piston (kg).
    pub masses_kg: [f64; 3],
    /// Centroidal moments of inertia of crank, rod and piston (kg·m²).
    pub inertias_kgm2: [f64; 3],
}

/// One of the four joints of the linkage.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinkageJoint {
    /// Revolute ground–crank at O.
    O,
    /// Revolute crank–rod at A.
    A,
    /// Revolute rod–piston at B.
    B,
    /// Translational ground–piston along x.
    Slide,
}

impl CrankSliderLinkage {
    /// The crank, rod and piston (bodies 0, 1, 2 of a fresh builder).
    pub const CRANK: BodyId = BodyId::Moving(0);
    /// The rod.
    pub const ROD: BodyId = BodyId::Moving(1);
    /// The piston.
    pub const PISTON: BodyId = BodyId::Moving(2);

    /// A builder with the three bodies and the joints O, A, B, slide, in this
    /// order, named `names`; no loads, no gravity, no driver.
    pub fn builder(&self, names: [&str; 4]) -> MultibodyBuilder {
        let mut b = MultibodyBuilder::new();
        self.add_bodies(&mut b);
        for (joint, name) in [
            LinkageJoint::O,
            LinkageJoint::A,
            LinkageJoint::B,
            LinkageJoint::Slide,
        ]
        .into_iter()
        .zip(names)
        {
            self.add_joint(&mut b, joint, name);
        }
        b
    }

    /// Adds crank, rod and piston to an empty builder (they become
    /// [`CRANK`](Self::CRANK), [`ROD`](Self::ROD), [`PISTON`](Self::PISTON)).
    pub fn add_bodies(&self, b: &mut MultibodyBuilder) {
        let (m, i) = (self.masses_kg, self.inertias_kgm2);
        b.add_body("crank", m[0], i[0]);
        b.add_body("rod", m[1], i[1]);
        b.add_body("piston", m[2], i[2]);
    }

    /// Adds one joint of the linkage, named `name`, to a builder whose first
    /// three bodies are those of [`add_bodies`](Self::add_bodies).
    pub fn add_joint<'b>(
        &self,
        b: &'b mut MultibodyBuilder,
        joint: LinkageJoint,
        name: &str,
    ) -> &'b mut MultibodyBuilder {
        let (r, l, e) = (
            self.crank_radius_m,
            self.centre_distance_m,
            self.crank_centroid_m,
        );
        let (l1, off) = (self.rod_l1_m, self.rod_offset_m);
        match joint {
            LinkageJoint::O => b.add_revolute(
                name,
                BodyId::Ground,
                Vector2::zeros(),
                Self::CRANK,
                Vector2::new(-e, 0.0),
            ),
            LinkageJoint::A => b.add_revolute(
                name,
                Self::CRANK,
                Vector2::new(r - e, 0.0),
                Self::ROD,
                Vector2::new(-l1, -off),
            ),
            LinkageJoint::B => b.add_revolute(
                name,
                Self::ROD,
                Vector2::new(l - l1, -off),
                Self::PISTON,
                Vector2::zeros(),
            ),
            LinkageJoint::Slide => b.add_translational(
                name,
                BodyId::Ground,
                Vector2::new(0.0, self.slide_y_m),
                Vector2::new(1.0, 0.0),
                Self::PISTON,
                Vector2::zeros(),
                0.0,
            ),
        }
    }
}

/// The test rig of the multibody core's unit tests: crank 8 kg / 0.015 kg·m²,
/// rod 3 kg / 0.02 kg·m², piston 5 kg, slide on y = 0, with the given r, l,
/// crank centroid e, rod l₁ and offset (the same bodies as the end-to-end
/// tests' rig in `tests/common`).
#[cfg(test)]
pub(crate) fn test_rig(r: f64, l: f64, e: f64, l1: f64, off: f64) -> CrankSliderLinkage {
    CrankSliderLinkage {
        crank_radius_m: r,
        centre_distance_m: l,
        crank_centroid_m: e,
        rod_l1_m: l1,
        rod_offset_m: off,
        slide_y_m: 0.0,
        masses_kg: [8.0, 3.0, 5.0],
        inertias_kgm2: [0.015, 0.02, 0.0],
    }
}
