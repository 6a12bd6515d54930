//! The two views of a picture: orthographic frames (plan, oblique), the projection onto them and
//! the placement of a view's image (model mm → image pixels).

use anyhow::{Result, bail};
use nalgebra::Vector3;

/// Tilt of the oblique view from +z towards −y (degrees).
const OBLIQUE_TILT_DEG: f64 = 38.0;
/// Turn of the oblique view towards +x (degrees).
const OBLIQUE_YAW_DEG: f64 = 15.0;
/// Blank pixels around the model in each view image.
const PAD_PX: f64 = 8.0;

/// An orthographic view: screen right, screen up and the direction towards the viewer (unit,
/// right-handed: right × up = toward).
#[derive(Clone, Debug)]
pub(super) struct Frame {
    pub(super) right: Vector3<f64>,
    pub(super) up: Vector3<f64>,
    pub(super) toward: Vector3<f64>,
    pub(super) caption: String,
}

impl Frame {
    pub(super) fn plan() -> Frame {
        Frame {
            right: Vector3::x(),
            up: Vector3::y(),
            toward: Vector3::z(),
            caption: "Plan view from +z (looking along −z)".into(),
        }
    }

    pub(super) fn oblique() -> Frame {
        let (tilt, yaw) = (OBLIQUE_TILT_DEG.to_radians(), OBLIQUE_YAW_DEG.to_radians());
        let toward = Vector3::new(yaw.sin() * tilt.cos(), -tilt.sin(), yaw.cos() * tilt.cos());
        let y = Vector3::y();
        let up = y - toward * y.dot(&toward);
        // Times the reciprocal of the norm, not `normalize()` (which divides by the norm): the two
        // can differ in the last bit, and the pictures are pinned byte for byte.
        let up = up * (1.0 / up.norm());
        let right = up.cross(&toward);
        Frame {
            right,
            up,
            toward,
            caption: format!(
                "Oblique view from +z, tilted {OBLIQUE_TILT_DEG}° towards −y and {OBLIQUE_YAW_DEG}° \
                 towards +x (top face and −y flank)"
            ),
        }
    }

    /// (u, v, d): right, up, towards the viewer (mm).
    pub(super) fn project(&self, p: [f64; 3]) -> [f64; 3] {
        let p = Vector3::from(p);
        [p.dot(&self.right), p.dot(&self.up), p.dot(&self.toward)]
    }
}

/// Placement of a view's image: model (u, v) in mm → image pixels.
#[derive(Clone, Copy, Debug)]
pub(super) struct ViewGeom {
    umin: f64,
    vmax: f64,
    /// px per mm.
    scale: f64,
    pub(super) width: u32,
    pub(super) height: u32,
}

impl ViewGeom {
    /// Fits the used vertices into at most `avail_w` × `max_h` px with [`PAD_PX`] around.
    pub(super) fn fit(
        uvd: &[[f64; 3]],
        used: &[bool],
        avail_w: f64,
        max_h: f64,
    ) -> Result<ViewGeom> {
        let (mut umin, mut umax, mut vmin, mut vmax) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for (p, _) in uvd.iter().zip(used).filter(|(_, u)| **u) {
            umin = umin.min(p[0]);
            umax = umax.max(p[0]);
            vmin = vmin.min(p[1]);
            vmax = vmax.max(p[1]);
        }
        let (su, sv) = (umax - umin, vmax - vmin);
        let tiny = 1e-9 * su.max(sv);
        let mut s = f64::INFINITY;
        if su > tiny {
            s = s.min((avail_w - 2.0 * PAD_PX) / su);
        }
        if sv > tiny {
            s = s.min((max_h - 2.0 * PAD_PX) / sv);
        }
        if !(s.is_finite() && s > 0.0) {
            bail!("the surface has zero extent in a view");
        }
        Ok(ViewGeom {
            umin,
            vmax,
            scale: s,
            width: (su * s + 2.0 * PAD_PX).ceil() as u32,
            height: (sv * s + 2.0 * PAD_PX).ceil() as u32,
        })
    }

    /// Image pixel coordinates (x right, y down) of a projected point.
    pub(super) fn pixel(&self, p: [f64; 3]) -> [f64; 2] {
        [
            PAD_PX + (p[0] - self.umin) * self.scale,
            PAD_PX + (self.vmax - p[1]) * self.scale,
        ]
    }
}
