//! The bore check of each pin of a loaded design: the pin sits in a bore, full (every in-plane
//! ray meets its wall) or partial (a big end without its cap: the axis ray is clear and a partial
//! bore the geometry shows holds it), and a sidecar's pin agrees with the bore that sits there
//! (inside the part, on the bore's axis, along the bore's axis).

use super::bore_check::{RodSurface, first_in_plane_hits};
use super::bore_finder::FoundPins;
use super::bore_finder::{Bore, find_bores, smooth_patches_through};
use super::sidecar::Units;
use super::weld::IndexedMesh;
use anyhow::{Result, bail};
use nalgebra::Vector3;
use rayon::prelude::*;

/// What the bore check of a design's pins needs of the design.
pub(super) struct PinsView<'a> {
    /// The validated surface, metres.
    pub(super) mesh: &'a IndexedMesh,
    /// The file's units (for messages).
    pub(super) units: Units,
    /// The pin axis (the mechanism frame's z).
    pub(super) axis: Vector3<f64>,
    pub(super) crank: Vector3<f64>,
    pub(super) piston: Vector3<f64>,
    /// The pins are the sidecar's.
    pub(super) from_sidecar: bool,
    /// The sidecar gives `pin_axis`.
    pub(super) axis_given: bool,
    /// The bores the pin search found, when it was asked.
    pub(super) found: Option<&'a FoundPins>,
}

/// What the bore check measured of one pin.
pub(super) struct PinBore {
    pub(super) radius: f64,
    pub(super) arc_deg: f64,
}

pub(super) fn axis_name(a: Vector3<f64>) -> String {
    match [a.x, a.y, a.z] {
        [1.0, 0.0, 0.0] => "x".into(),
        [0.0, 1.0, 0.0] => "y".into(),
        [0.0, 0.0, 1.0] => "z".into(),
        _ => format!("({:.4}, {:.4}, {:.4})", a.x, a.y, a.z),
    }
}

#[derive(Clone, Copy, PartialEq)]
pub(super) enum Pin {
    Crank,
    Piston,
}

/// The bore check of one pin: a full bore by the in-plane rays; a partial bore (found, or met by
/// sidecar pins whose in-plane rays leave the part) by the axis ray and the arc's fit.
pub(super) fn pin_bore(
    d: &PinsView<'_>,
    surface: &RodSurface,
    pin: Pin,
    bores: &std::sync::OnceLock<Vec<Bore>>,
    warnings: &mut Vec<String>,
) -> Result<PinBore> {
    let bores = || bores.get_or_init(|| find_bores(d.mesh));
    let scale = d.units.to_metres();
    let units = d.units.symbol();
    let axis = d.axis;
    let (name, centre, end, letter) = match pin {
        Pin::Crank => ("crank pin (A)", d.crank, "big end", "A"),
        Pin::Piston => ("piston pin (B)", d.piston, "small end", "B"),
    };
    if d.from_sidecar {
        sidecar_pin_in_the_part(d, name, centre)?;
    }
    let found = d.found.map(|f| match pin {
        Pin::Crank => &f.crank,
        Pin::Piston => &f.piston,
    });
    let partial = |bore: &Bore, warnings: &mut Vec<String>| -> Result<PinBore> {
        surface.partial_bore(name, centre, axis, scale, units)?;
        warnings.push(format!(
            "{end} without cap: loads on the existing arc ({:.0}°)",
            bore.arc_deg
        ));
        Ok(PinBore {
            radius: bore.radius,
            arc_deg: bore.arc_deg,
        })
    };
    if let Some(bore) = found
        && !bore.full
    {
        return partial(bore, warnings);
    }
    match surface.bore_radius_probed(name, centre, axis, scale, units) {
        Ok((radius, probe)) => {
            // the bores are fitted only where the rays do not show the pin on a round bore's
            // axis well within the check's tolerances
            if d.from_sidecar && !probe.on_the_axis() {
                let near = bores_around_the_pin(d.mesh, centre, axis, radius);
                pin_on_the_bores_axis(d, &near, name, centre, axis, warnings)?;
            }
            Ok(PinBore {
                radius,
                arc_deg: 360.0,
            })
        }
        Err(e) if d.from_sidecar && surface.probe(centre, axis).open_share() > 0.0 => {
            // sidecar pins in an open arc? measure the partial bores whose circle holds the pin
            let partials: Vec<&Bore> = bores()
                .iter()
                .filter(|b| !b.full && b.axis_v().dot(&axis).abs() > 1f64.to_radians().cos())
                .collect();
            let near = partials
                .iter()
                .filter(|b| b.distance_from_axis(centre) < b.radius)
                .min_by(|a, b| {
                    a.distance_from_axis(centre)
                        .total_cmp(&b.distance_from_axis(centre))
                });
            let Some(bore) = near else {
                if partials.is_empty() {
                    return Err(e);
                }
                let seen = partials
                    .iter()
                    .map(|b| super::bore_finder::describe(b, d.units))
                    .collect::<Vec<_>>()
                    .join("; ");
                return Err(e.context(format!(
                    "the rays across the {name} leave the part, and no partial bore the geometry \
                     shows holds it (partial bores seen: {seen}): correct the pin centre in the \
                     sidecar"
                )));
            };
            let off = bore.distance_from_axis(centre);
            let c = bore.centre_v() / scale;
            let what = format!(
                "{end} without cap: bore {letter} is an arc of {:.0}° (open on one side), radius {:.3} {units}, axis through ({:.3}, {:.3}, {:.3}) {units}",
                bore.arc_deg,
                bore.radius / scale,
                c.x,
                c.y,
                c.z
            );
            if off <= 0.01 * bore.radius {
                partial(bore, warnings)
            } else {
                bail!(
                    "{what}; the sidecar's {name} is {:.3} {units} away from that axis: correct the pin centre in the sidecar",
                    off / scale
                )
            }
        }
        Err(e) => Err(e),
    }
}

/// The bores of the wall around a sidecar's pin whose in-plane rays met a wall `radius` away:
/// the smooth patches of the surface within 2·`radius` of the pin's axis that hold the
/// triangles those rays meet first, given to the bore finder on their own. The rest of the
/// part (the eye's faces, its outline, the shank) is not searched: on design 1 subdivided to
/// 1.6 M triangles the crank's wall is 13 % of them.
fn bores_around_the_pin(
    mesh: &IndexedMesh,
    centre: Vector3<f64>,
    axis: Vector3<f64>,
    radius: f64,
) -> Vec<Bore> {
    let reach = 2.0 * radius;
    let near: Vec<bool> = mesh
        .vertices
        .par_iter()
        .map(|v| {
            let d = v - centre;
            (d - axis * axis.dot(&d)).norm() <= reach
        })
        .collect();
    let around: Vec<u32> = (0..mesh.triangles.len() as u32)
        .into_par_iter()
        .filter(|&t| mesh.triangles[t as usize].iter().any(|&v| near[v as usize]))
        .collect();
    let around = restricted(mesh, &around);
    let seeds = first_in_plane_hits(&around, centre, axis);
    let wall = smooth_patches_through(&around, &seeds);
    find_bores(&restricted(&around, &wall))
}

/// The triangles `triangles` (increasing) of `mesh` on their own, their vertices in the same
/// order without the gaps: the bore finder sees the same edge order and fits the same points as
/// it would on the whole vertex list.
fn restricted(mesh: &IndexedMesh, triangles: &[u32]) -> IndexedMesh {
    let triangles: Vec<[u32; 3]> = triangles
        .iter()
        .map(|&t| mesh.triangles[t as usize])
        .collect();
    let mut used = vec![false; mesh.vertices.len()];
    for &v in triangles.iter().flatten() {
        used[v as usize] = true;
    }
    let mut number = vec![u32::MAX; mesh.vertices.len()];
    let mut vertices = Vec::new();
    for (v, _) in used.iter().enumerate().filter(|(_, u)| **u) {
        number[v] = vertices.len() as u32;
        vertices.push(mesh.vertices[v]);
    }
    IndexedMesh {
        vertices,
        triangles: triangles
            .into_iter()
            .map(|t| t.map(|v| number[v as usize]))
            .collect(),
    }
}

/// A sidecar's pin must lie within the part's bounding box (grown by 1 % of its diagonal): a pin
/// outside it sits in no bore, whatever the rays from it meet.
fn sidecar_pin_in_the_part(d: &PinsView<'_>, name: &str, centre: Vector3<f64>) -> Result<()> {
    let (lo, hi) = d.mesh.bounding_box();
    let margin = 0.01 * (hi - lo).norm();
    let outside = (0..3)
        .map(|k| {
            (lo[k] - margin - centre[k])
                .max(centre[k] - hi[k] - margin)
                .max(0.0)
        })
        .fold(0.0f64, f64::max);
    if outside == 0.0 {
        return Ok(());
    }
    let s = 1.0 / d.units.to_metres();
    let u = d.units.symbol();
    let (c, lo, hi) = (centre * s, lo * s, hi * s);
    bail!(
        "the sidecar's {name} at ({:.3}, {:.3}, {:.3}) {u} lies outside the part (its bounding box \
         spans ({:.3}, {:.3}, {:.3}) – ({:.3}, {:.3}, {:.3}) {u}, {:.3} {u} beyond it): correct \
         the pin centre in the sidecar (in the file's units, {u}), or leave the pins out to have \
         them found from the geometry",
        c.x,
        c.y,
        c.z,
        lo.x,
        lo.y,
        lo.z,
        hi.x,
        hi.y,
        hi.z,
        outside * s
    )
}

/// A sidecar's pin must sit on the axis of the bore around it: the bore the geometry shows
/// there (found as the pin search finds bores, on the wall around the pin:
/// [`bores_around_the_pin`]; within the bore's radius of the pin, its axis parallel) may lie 1 % of its radius from the pin unremarked, up to 5 % with a warning (a pin
/// rounded to 0.1 mm in a small bore), beyond that the design is refused. A pin off the centre
/// still sees a wall all round, so the bore check alone would pass it and measure the wrong
/// radius and centre distance.
fn pin_on_the_bores_axis(
    d: &PinsView<'_>,
    bores: &[Bore],
    name: &str,
    centre: Vector3<f64>,
    axis: Vector3<f64>,
    warnings: &mut Vec<String>,
) -> Result<()> {
    let scale = d.units.to_metres();
    let units = d.units.symbol();
    // the bore around the pin runs along another axis than the sidecar's `pin_axis`
    let around = bores
        .iter()
        .filter(|b| b.full && b.distance_from_axis(centre) < 0.05 * b.radius)
        .filter(|b| (centre - b.centre_v()).dot(&b.axis_v()).abs() <= 0.5 * b.length)
        .min_by(|a, b| {
            a.distance_from_axis(centre)
                .total_cmp(&b.distance_from_axis(centre))
        });
    if let Some(b) = around
        && d.axis_given
    {
        let tilt = b.axis_v().dot(&axis).abs().min(1.0).acos().to_degrees();
        if tilt > 1.0 {
            let a = b.axis;
            bail!(
                "the sidecar's `pin_axis` ({:.4}, {:.4}, {:.4}) is {tilt:.1}° off the axis of the \
                 bore around the {name} ({:.4}, {:.4}, {:.4}): the inertia about the pin axis and \
                 the loads' plane would be those of a tilted pin; correct `pin_axis` (or leave it \
                 out to have it found from the bores)",
                axis.x,
                axis.y,
                axis.z,
                a[0],
                a[1],
                a[2]
            );
        }
    }
    let near = bores
        .iter()
        .filter(|b| b.full && b.axis_v().dot(&axis).abs() > 1f64.to_radians().cos())
        .filter(|b| b.distance_from_axis(centre) < b.radius)
        .min_by(|a, b| {
            a.distance_from_axis(centre)
                .total_cmp(&b.distance_from_axis(centre))
        });
    let Some(bore) = near else { return Ok(()) };
    let off = bore.distance_from_axis(centre);
    if off <= 0.01 * bore.radius {
        return Ok(());
    }
    let c = bore.centre_v() / scale;
    if off <= 0.05 * bore.radius {
        warnings.push(format!(
            "the sidecar's {name} is {:.3} {units} off the axis of the bore around it (radius \
             {:.3} {units}, axis through ({:.3}, {:.3}, {:.3}) {units}): l and the bore radius \
             are measured from the pin as given",
            off / scale,
            bore.radius / scale,
            c.x,
            c.y,
            c.z
        ));
        return Ok(());
    }
    bail!(
        "the sidecar's {name} is {:.3} {units} off the axis of the bore around it (radius {:.3} \
         {units}, axis through ({:.3}, {:.3}, {:.3}) {units}): correct the pin centre in the \
         sidecar, or leave the pins out to have them found from the geometry",
        off / scale,
        bore.radius / scale,
        c.x,
        c.y,
        c.z
    )
}
