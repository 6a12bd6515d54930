//! Proof that each pin centre sits in a bore, by ray casts against the rod's surface.
//!
//! A pin centre is in a bore when it is not inside material, a ray along the pin axis (both
//! ways) hits nothing, and rays in the plane of motion hit the bore wall in every direction.
//! The shortest in-plane hit is reported as the bore radius. A failure almost always means the
//! STL's units or the pin positions in the sidecar are wrong, and the message says so.
//!
//! About thirty rays per design need no acceleration structure: each query first keeps the
//! triangles that can meet its rays (those whose projection across the axis covers the centre,
//! for the axis line; those that straddle the plane through the centre normal to the axis, for
//! the in-plane rays), one pass over the triangles, then intersects those few exactly
//! (Möller & Trumbore, "Fast, minimum storage ray/triangle intersection", JGT 2 (1997)).
//! Containment is the parity of the crossings of a ray along +axis, tilted by about 1e-3 so that
//! it does not run through an edge, the majority of three such rays. (Building a BVH over a
//! million triangles for thirty rays cost more than the rest of stage 1 together.)

use super::weld::IndexedMesh;
use anyhow::{Result, bail};
use nalgebra::Vector3;

/// Number of in-plane ray directions (every 30°).
pub const IN_PLANE_RAYS: usize = 12;

/// [`BoreProbe::on_the_axis`]: the largest angle, degrees, between an in-plane ray and the normal
/// of the facet it meets (in the plane across the axis).
pub const FACING_DEG: f64 = 3.0;

/// [`BoreProbe::on_the_axis`]: the largest spread of the in-plane hit distances, relative.
pub const RANGE_REL: f64 = 0.01;

/// The rod's surface for the bore queries.
pub struct RodSurface<'a> {
    mesh: &'a IndexedMesh,
    /// Bounding-box diagonal.
    extent: f64,
}

/// Tilts of the three containment rays off the axis (in u, v): small, irrational-looking
/// directions so that a ray does not run exactly through an edge or vertex of the triangulation
/// (pin centres sit on symmetry lines, where CAD meshes have edges); the majority counts.
const TILTS: [[f64; 2]; 3] = [
    [0.618_033_988_7e-3, 0.381_966_011_3e-3],
    [-0.414_213_562_4e-3, 0.732_050_807_6e-3],
    [0.236_067_977_5e-3, -0.645_751_311_1e-3],
];

/// Distance t > 0 along `dir` from `origin` to the triangle (a, b, c), if the ray meets it.
fn ray_triangle(
    origin: Vector3<f64>,
    dir: Vector3<f64>,
    [a, b, c]: [Vector3<f64>; 3],
) -> Option<f64> {
    let (e1, e2) = (b - a, c - a);
    let p = dir.cross(&e2);
    let det = e1.dot(&p);
    let scale = e1.norm() * e2.norm();
    if det.abs() <= 1e-14 * scale {
        return None; // parallel to the triangle's plane
    }
    let inv = 1.0 / det;
    let s = origin - a;
    let u = s.dot(&p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(&e1);
    let v = dir.dot(&q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(&q) * inv;
    (t > 0.0).then_some(t)
}

impl<'a> RodSurface<'a> {
    /// The query surface of a validated, outward-oriented mesh (in metres).
    pub fn new(mesh: &'a IndexedMesh) -> Result<Self> {
        if mesh.triangles.is_empty() {
            bail!("the surface has no triangles");
        }
        let (lo, hi) = mesh.bounding_box();
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
        self.bore_radius_probed(pin, centre, axis, scale, units)
            .map(|(r, _)| r)
    }

    /// [`RodSurface::bore_radius`] with the rays' record ([`BoreProbe`]).
    pub fn bore_radius_probed(
        &self,
        pin: &str,
        centre: Vector3<f64>,
        axis: Vector3<f64>,
        scale: f64,
        units: &str,
    ) -> Result<(f64, BoreProbe)> {
        let hint = "check the STL units (sidecar `units`, default mm) and the pin centres (sidecar `crank_pin`, `piston_pin`)";
        let at = shown(centre, scale, units);
        let probe = self.probe(centre, axis);
        probe.axis_clear(pin, &at, scale, units, hint)?;
        let mut radius = f64::INFINITY;
        for hit in &probe.in_plane {
            match hit {
                Some(t) => radius = radius.min(*t),
                None => bail!(
                    "the {pin} centre {at} is not inside a bore: a ray across the pin axis leaves the part without touching it (the centre lies outside the rod): {hint}"
                ),
            }
        }
        Ok((radius, probe))
    }

    /// Checks that `centre` lies on the axis of a partial bore (an arc open on one side, e.g. a
    /// big end without its cap, found by [`super::bore_finder`]): not inside material and no
    /// material along the pin axis through it. The in-plane rays that leave through the opening
    /// are expected; the bore radius is the one fitted to the arc. Returns the number of
    /// in-plane directions (of [`IN_PLANE_RAYS`]) that meet the wall.
    pub fn partial_bore(
        &self,
        pin: &str,
        centre: Vector3<f64>,
        axis: Vector3<f64>,
        scale: f64,
        units: &str,
    ) -> Result<usize> {
        let hint = "check the STL units (sidecar `units`, default mm) and the pin centres (sidecar `crank_pin`, `piston_pin`)";
        let at = shown(centre, scale, units);
        let probe = self.probe(centre, axis);
        probe.axis_clear(pin, &at, scale, units, hint)?;
        let hits = probe.in_plane.iter().filter(|h| h.is_some()).count();
        if hits == 0 {
            bail!(
                "the {pin} centre {at} is not inside a bore: no ray across the pin axis touches the part: {hint}"
            );
        }
        Ok(hits)
    }

    /// The ray casts from `centre`: containment, the axis line both ways, the in-plane rays.
    pub fn probe(&self, centre: Vector3<f64>, axis: Vector3<f64>) -> BoreProbe {
        let (axis, u, v) = plane_basis(axis);
        // one pass: the triangles the axis line (and the slightly tilted containment rays) can
        // meet, and those across the plane
        let margin = 1e-3 * self.extent;
        let mut on_axis = Vec::new();
        let mut across_plane = Vec::new();
        // each vertex's coordinates in the frame (u, v, axis) at the centre once: a vertex is a
        // corner of about six triangles
        let frame: Vec<[f64; 3]> = self
            .mesh
            .vertices
            .iter()
            .map(|p| {
                let d = p - centre;
                [d.dot(&u), d.dot(&v), d.dot(&axis)]
            })
            .collect();
        for (t, ids) in self.mesh.triangles.iter().enumerate() {
            let (mut ulo, mut uhi, mut vlo, mut vhi, mut wlo, mut whi) = (
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            );
            for &i in ids {
                let [pu, pv, pw] = frame[i as usize];
                ulo = ulo.min(pu);
                uhi = uhi.max(pu);
                vlo = vlo.min(pv);
                vhi = vhi.max(pv);
                wlo = wlo.min(pw);
                whi = whi.max(pw);
            }
            if ulo <= margin && uhi >= -margin && vlo <= margin && vhi >= -margin {
                on_axis.push(self.mesh.corners(t));
            }
            if wlo <= 0.0 && whi >= 0.0 {
                across_plane.push(self.mesh.corners(t));
            }
        }
        let hits = |dir: Vector3<f64>, tris: &[[Vector3<f64>; 3]]| -> Vec<f64> {
            tris.iter()
                .filter_map(|&t| ray_triangle(centre, dir, t))
                .collect()
        };
        let odd = TILTS
            .iter()
            .filter(|[a, b]| hits((axis + u * *a + v * *b).normalize(), &on_axis).len() % 2 == 1)
            .count();
        let along_axis = [axis, -axis].map(|dir| hits(dir, &on_axis).into_iter().reduce(f64::min));
        let (in_plane, in_plane_normals) = (0..IN_PLANE_RAYS)
            .map(|k| {
                let angle = std::f64::consts::TAU * k as f64 / IN_PLANE_RAYS as f64;
                let dir = u * angle.cos() + v * angle.sin();
                let first = across_plane
                    .iter()
                    .filter_map(|&t| ray_triangle(centre, dir, t).map(|d| (d, t)))
                    .min_by(|a, b| a.0.total_cmp(&b.0));
                match first {
                    Some((d, [a, b, c])) => (Some(d), (b - a).cross(&(c - a)).try_normalize(0.0)),
                    None => (None, None),
                }
            })
            .unzip();
        BoreProbe {
            inside: odd >= 2,
            along_axis,
            in_plane,
            in_plane_normals,
            axis,
            directions: (0..IN_PLANE_RAYS)
                .map(|k| {
                    let angle = std::f64::consts::TAU * k as f64 / IN_PLANE_RAYS as f64;
                    u * angle.cos() + v * angle.sin()
                })
                .collect(),
        }
    }
}

/// The triangles of `mesh` the [`IN_PLANE_RAYS`] rays from `centre` across `axis` meet first
/// (the directions of [`RodSurface::probe`]), each once: the wall around a pin.
pub fn first_in_plane_hits(
    mesh: &IndexedMesh,
    centre: Vector3<f64>,
    axis: Vector3<f64>,
) -> Vec<u32> {
    let (axis, u, v) = plane_basis(axis);
    let across_plane: Vec<u32> = (0..mesh.triangles.len() as u32)
        .filter(|&t| {
            let ws = mesh.corners(t as usize).map(|p| (p - centre).dot(&axis));
            ws.iter().any(|&w| w <= 0.0) && ws.iter().any(|&w| w >= 0.0)
        })
        .collect();
    let mut first: Vec<u32> = (0..IN_PLANE_RAYS)
        .filter_map(|k| {
            let angle = std::f64::consts::TAU * k as f64 / IN_PLANE_RAYS as f64;
            let dir = u * angle.cos() + v * angle.sin();
            across_plane
                .iter()
                .filter_map(|&t| {
                    ray_triangle(centre, dir, mesh.corners(t as usize)).map(|d| (d, t))
                })
                .min_by(|x, y| x.0.total_cmp(&y.0))
                .map(|(_, t)| t)
        })
        .collect();
    first.sort_unstable();
    first.dedup();
    first
}

/// A point in the file's units, as messages show it.
fn shown(centre: Vector3<f64>, scale: f64, units: &str) -> String {
    let p = centre / scale;
    format!("({:.3}, {:.3}, {:.3}) {units}", p.x, p.y, p.z)
}

/// What the rays from a pin centre met (distances in the mesh's units).
#[derive(Debug, Clone, PartialEq)]
pub struct BoreProbe {
    /// The centre is inside material (the majority of the three containment rays).
    pub inside: bool,
    /// The nearest hit along +axis and along −axis.
    pub along_axis: [Option<f64>; 2],
    /// The nearest hit in each of the [`IN_PLANE_RAYS`] directions across the axis.
    pub in_plane: Vec<Option<f64>>,
    /// The unit normal of the triangle each in-plane ray meets first.
    pub in_plane_normals: Vec<Option<Vector3<f64>>>,
    /// The pin axis (unit) and the in-plane rays' directions.
    pub axis: Vector3<f64>,
    pub directions: Vec<Vector3<f64>>,
}

impl BoreProbe {
    /// Whether the rays show the centre on the axis of a round bore parallel to the pin axis,
    /// to within half the sidecar check's tolerances (1 % of the radius off the axis, 1° of tilt),
    /// without fitting the bore: every ray meets a facet within [`FACING_DEG`] of facing it
    /// square (so the faceting changes a hit distance by at most 1 − cos 3° = 0.14 % of the
    /// radius), the hit distances t_k agree within [`RANGE_REL`] (an offset e makes them
    /// t_k ≈ r − e cos(θ_k − φ): a range of at least 2e cos 15° for 12 rays, so
    /// e ≤ (1 % + 0.14 %) r / 1.93 = 0.59 % r), and no hit facet's normal has a component along
    /// the pin axis above sin 0.5° (a wall tilted by τ has one of sin τ cos(θ_k − φ), at least
    /// sin τ cos 15°: τ < 0.52°). `false` decides nothing: the bores are then fitted.
    pub fn on_the_axis(&self) -> bool {
        // per ray: (hit distance, facet normal, ray direction)
        type Hit = (f64, Vector3<f64>, Vector3<f64>);
        let hits: Option<Vec<Hit>> = self
            .in_plane
            .iter()
            .zip(&self.in_plane_normals)
            .zip(&self.directions)
            .map(|((t, n), d)| Some(((*t)?, (*n)?, *d)))
            .collect();
        let Some(hits) = hits.filter(|h| !h.is_empty()) else {
            return false;
        };
        let (lo, hi) = hits.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), h| {
            (lo.min(h.0), hi.max(h.0))
        });
        let square = FACING_DEG.to_radians().cos();
        let tilt = 0.5f64.to_radians().sin();
        hi - lo <= RANGE_REL * lo
            && hits.iter().all(|(_, n, d)| {
                let along = n.dot(&self.axis);
                let in_plane = (n - self.axis * along).norm();
                along.abs() <= tilt && in_plane > 0.0 && n.dot(d).abs() / in_plane >= square
            })
    }

    /// Refuses a centre in material or with material along its axis (the messages of
    /// [`RodSurface::bore_radius`]).
    fn axis_clear(&self, pin: &str, at: &str, scale: f64, units: &str, hint: &str) -> Result<()> {
        if self.inside {
            bail!("the {pin} centre {at} lies inside material, not in a bore: {hint}");
        }
        if let Some(t) = self.along_axis.iter().flatten().next() {
            bail!(
                "a ray along the pin axis from the {pin} centre {at} hits material after {:.3} {units}: there is no through-bore at the pin: {hint}",
                t / scale
            );
        }
        Ok(())
    }

    /// Share of the in-plane rays that leave the part without meeting it.
    pub fn open_share(&self) -> f64 {
        self.in_plane.iter().filter(|h| h.is_none()).count() as f64 / self.in_plane.len() as f64
    }
}

/// The unit `axis` and two unit vectors u, v across it (a right-handed frame u, v, axis: u ⟂ the
/// axis and the coordinate axis least aligned with it).
fn plane_basis(axis: Vector3<f64>) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let axis = axis.normalize();
    let u = axis
        .cross(&if axis.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        })
        .normalize();
    let v = axis.cross(&u);
    (axis, u, v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitives::{cuboid, hollow_cylinder};

    /// A tube (outer 30, bore 12.5 mm, 96 facets): its axis is in the bore, the bore radius is the
    /// inscribed radius of the 96-gon (12.5 cos(π/96), the shortest of the 12 rays can be a chord
    /// midpoint or a vertex), a point in the wall is inside material, a point outside is refused.
    #[test]
    fn tube_bore_wall_and_outside() {
        let tube = hollow_cylinder(30.0, 12.5, 40.0, 96);
        let s = RodSurface::new(&tube).unwrap();
        let z = Vector3::z();
        let r = s
            .bore_radius("pin", Vector3::zeros(), z, 1.0, "mm")
            .unwrap();
        let inscribed = 12.5 * (std::f64::consts::PI / 96.0).cos();
        assert!(r >= inscribed - 1e-9 && r <= 12.5 + 1e-9, "{r}");
        // y = 0 runs along edges of the annulus caps' triangulation
        let wall = s.bore_radius("pin", Vector3::new(20.0, 0.0, 0.0), z, 1.0, "mm");
        assert!(wall.unwrap_err().to_string().contains("inside material"));
        let outside = s.bore_radius("pin", Vector3::new(50.0, 0.0, 0.0), z, 1.0, "mm");
        assert!(
            outside
                .unwrap_err()
                .to_string()
                .contains("leaves the part without touching it")
        );
        // a box: its centre is inside material; a point beside it along an axis is blocked
        let b = cuboid(Vector3::new(10.0, 10.0, 10.0), Vector3::zeros());
        let s = RodSurface::new(&b).unwrap();
        let inside = s.bore_radius("pin", Vector3::zeros(), z, 1.0, "mm");
        assert!(inside.unwrap_err().to_string().contains("inside material"));
        let blocked = s.bore_radius("pin", Vector3::new(0.0, 0.0, 20.0), z, 1.0, "mm");
        assert!(
            blocked
                .unwrap_err()
                .to_string()
                .contains("hits material after 15.000 mm")
        );
    }

    /// The rays decide "on the axis" only well inside the sidecar check's tolerances (1 % of the
    /// radius, 1°): on a 96-facet tube (facets 1.9° either side of square) a centred pin, 0.3 %
    /// off and a pin axis 0.3° off pass; 0.6 % off (a spread of 1.2 %), a pin axis 0.6° off and
    /// a 24-facet bore (facets 7.5° either side) are left to the fitted bores.
    #[test]
    fn the_rays_show_a_pin_on_the_axis_only_well_within_the_tolerances() {
        let tube = hollow_cylinder(30.0, 12.5, 40.0, 96);
        let s = RodSurface::new(&tube).unwrap();
        let z = Vector3::z();
        let at = |x: f64, axis: Vector3<f64>| {
            s.bore_radius_probed("pin", Vector3::new(x, 0.0, 0.0), axis, 1.0, "mm")
                .unwrap()
                .1
                .on_the_axis()
        };
        assert!(at(0.0, z));
        assert!(at(0.003 * 12.5, z));
        assert!(!at(0.006 * 12.5, z));
        let tilted = |deg: f64| Vector3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos());
        assert!(at(0.0, tilted(0.3)));
        assert!(!at(0.0, tilted(0.6)));
        let coarse = hollow_cylinder(30.0, 12.5, 40.0, 24);
        let s = RodSurface::new(&coarse).unwrap();
        let probe = s
            .bore_radius_probed("pin", Vector3::zeros(), z, 1.0, "mm")
            .unwrap()
            .1;
        assert!(!probe.on_the_axis());
    }
}
