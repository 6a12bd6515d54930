//! Proof that each pin centre sits in a bore, by ray casts against the rod's surface (parry3d).
//!
//! A pin centre is in a bore when it is not inside material, a ray along the pin axis (both
//! ways) hits nothing, and rays in the plane of motion hit the bore wall in every direction.
//! The shortest in-plane hit is reported as the bore radius. A failure almost always means the
//! STL's units or the pin positions in the sidecar are wrong, and the message says so.

use super::weld::IndexedMesh;
use anyhow::{Result, bail};
use nalgebra::Vector3;
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::query::{PointQuery, Ray, RayCast};
use parry3d_f64::shape::{TriMesh, TriMeshFlags};

/// Number of in-plane ray directions (every 30°).
const IN_PLANE_RAYS: usize = 12;

/// The rod's surface prepared for ray casts and containment queries.
pub struct RodSurface {
    mesh: TriMesh,
    extent: f64,
}

fn pvec(v: Vector3<f64>) -> PVec {
    PVec::new(v.x, v.y, v.z)
}

impl RodSurface {
    /// Builds the query structure from a validated, outward-oriented mesh (in metres).
    pub fn new(mesh: &IndexedMesh) -> Result<Self> {
        let (lo, hi) = mesh.bounding_box();
        let vertices = mesh.vertices.iter().map(|v| pvec(*v)).collect();
        let mesh = TriMesh::with_flags(vertices, mesh.triangles.clone(), TriMeshFlags::ORIENTED)
            .map_err(|e| anyhow::anyhow!("cannot build the ray-cast structure: {e:?}"))?;
        Ok(RodSurface {
            mesh,
            extent: (hi - lo).norm(),
        })
    }

    /// Checks that `centre` lies in a through-bore along `axis` and returns the bore radius [m].
    /// `pin` names the pin in messages (e.g. "crank pin (A)"); `units` is the file's unit symbol.
    pub fn bore_radius(
        &self,
        pin: &str,
        centre: Vector3<f64>,
        axis: Vector3<f64>,
        scale: f64,
        units: &str,
    ) -> Result<f64> {
        let hint = "check the STL units (sidecar `units`, default mm) and the pin centres (sidecar `crank_pin`, `piston_pin`)";
        let shown = centre / scale;
        let at = format!("({:.3}, {:.3}, {:.3}) {units}", shown.x, shown.y, shown.z);
        if self.mesh.contains_local_point(pvec(centre)) {
            bail!("the {pin} centre {at} lies inside material, not in a bore: {hint}");
        }
        for dir in [axis, -axis] {
            if let Some(t) = self.mesh.cast_local_ray(
                &Ray::new(pvec(centre), pvec(dir)),
                self.extent * 2.0,
                true,
            ) {
                bail!(
                    "a ray along the pin axis from the {pin} centre {at} hits material after {:.3} {units}: there is no through-bore at the pin: {hint}",
                    t / scale
                );
            }
        }
        let u = axis
            .cross(&if axis.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            })
            .normalize();
        let v = axis.cross(&u);
        let mut radius = f64::INFINITY;
        for k in 0..IN_PLANE_RAYS {
            let angle = std::f64::consts::TAU * k as f64 / IN_PLANE_RAYS as f64;
            let dir = u * angle.cos() + v * angle.sin();
            match self.mesh.cast_local_ray(
                &Ray::new(pvec(centre), pvec(dir)),
                self.extent * 2.0,
                true,
            ) {
                Some(t) => radius = radius.min(t),
                None => bail!(
                    "the {pin} centre {at} is not inside a bore: a ray across the pin axis leaves the part without touching it (the centre lies outside the rod): {hint}"
                ),
            }
        }
        Ok(radius)
    }
}
