//! Finding the pin bores of a rod from its surface: cylinder fits to the facets of the holes.
//!
//! Method (SPEC "Sidecar": pins not given are found from the geometry):
//! 1. **Smooth patches.** The triangles of the validated, outward surface are joined across
//!    every manifold edge whose dihedral angle is below [`SMOOTH_ANGLE_DEG`]; the connected
//!    groups are the smooth patches (a bore's wall meets the faces of the eye, a chamfer or the
//!    joint face of a capless big end at a sharp edge, so its wall is one patch or several).
//! 2. **A common axis.** A patch is a cylinder candidate when all its facet normals are ⟂ to one
//!    direction: the eigenvector of the smallest eigenvalue of the area-weighted scatter
//!    Σ A n nᵀ (near zero for a cylinder), while the middle eigenvalue is not (a curved patch,
//!    not a flat face).
//! 3. **Circle, then cylinder fit.** The patch's vertices, projected on the plane ⟂ to that axis,
//!    get an algebraic circle fit (Kåsa, "A circle fitting procedure and its error analysis",
//!    IEEE Trans. Instrum. Meas. 25 (1976) 8–14), then a few Gauss–Newton steps of the geometric
//!    (orthogonal-distance) cylinder fit over the centre, the axis tilt and the radius, in the
//!    parametrisation of Lukács, Martin & Marshall, "Faithful least-squares fitting of spheres,
//!    cylinders, cones and tori for reliable segmentation", ECCV 1998, linearised about the
//!    current axis. STL vertices lie on the true surface, so a cylinder fits to rounding; a
//!    fillet torus or a cone leaves a residual and is dropped ([`MAX_RESIDUAL_REL`]).
//! 4. **Bore, not boss.** Kept when the facet normals point towards the fitted axis (a hole's
//!    wall faces inward), area-weighted.
//! 5. **Merge.** Coaxial patches of equal radius (a bore split by a groove, by CAD face splits,
//!    or the two halves of a big end drawn as rod and cap) become one bore.
//! 6. **Arc and length.** Each triangle covers the angular interval of its corners about the
//!    axis; the union of the intervals is the bore's arc (360° for a full bore, 180° for a big end
//!    without its cap). The axial extent of the vertices gives the length; the bore's centre is the
//!    point of the axis at the middle of that extent.
//! 7. **The pins.** Candidate pins are bores with an arc of at least [`MIN_PIN_ARC_DEG`] (concave
//!    fillets are arcs of at most about 90°). Among the families of parallel candidates, the two
//!    largest by wall area are the pair the rod is built around; the larger radius is the crank
//!    end A, the smaller the piston end B. Refused, with what to write in the sidecar: no bore or
//!    only one; axes not parallel; a third candidate of comparable size ([`COMPARABLE_AREA`]);
//!    equal radii (within [`EQUAL_RADII_REL`]).

use super::sidecar::Units;
use super::weld::IndexedMesh;
use nalgebra::Vector3;

mod bore;
mod fit;
mod patches;
#[cfg(test)]
mod tests;
mod walls;

pub use bore::*;
pub use patches::smooth_patches_through;
pub use walls::find_bores;

use fit::canonical;

/// Why the pins could not be found; the text says what to write in the sidecar.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PinSearchError {
    #[error("no cylindrical bore found{0}: give crank_pin, piston_pin and pin_axis in the sidecar")]
    NoBore(String),
    #[error(
        "only one bore found ({0}): a rod needs two pin bores; give crank_pin, piston_pin and pin_axis in the sidecar"
    )]
    OnlyOne(String),
    #[error(
        "the bores' axes are not parallel ({0}): give crank_pin, piston_pin and pin_axis in the sidecar"
    )]
    NotParallel(String),
    #[error(
        "{count} bores of comparable size could be the pins ({list}): give crank_pin and piston_pin in the sidecar"
    )]
    Ambiguous { count: usize, list: String },
    #[error(
        "equal bore radii ({0}): cannot tell the crank end from the piston end: give crank_pin and piston_pin in the sidecar"
    )]
    EqualRadii(String),
}

/// A bore described for a message, in the file's units.
pub fn describe(b: &Bore, units: Units) -> String {
    let s = 1.0 / units.to_metres();
    let u = units.symbol();
    let c = b.centre_v() * s;
    let a = b.axis;
    format!(
        "radius {:.3} {u} at ({:.3}, {:.3}, {:.3}) {u}, axis ({:.3}, {:.3}, {:.3}), arc {:.0}°",
        b.radius * s,
        c.x,
        c.y,
        c.z,
        a[0],
        a[1],
        a[2],
        b.arc_deg
    )
}

/// Finds the pin bores of `mesh` (validated, outward, metres). `axis`, when given, keeps only
/// bores along it. `units` is used in messages only.
pub fn find_pins(
    mesh: &IndexedMesh,
    axis: Option<Vector3<f64>>,
    units: Units,
) -> Result<FoundPins, PinSearchError> {
    let all = find_bores(mesh);
    let parallel =
        |a: &Bore, b: Vector3<f64>| a.axis_v().dot(&b).abs() >= PARALLEL_DEG.to_radians().cos();
    let restricted = match axis {
        Some(ax) => format!(" along the sidecar's pin_axis {:?}", [ax.x, ax.y, ax.z]),
        None => String::new(),
    };
    let mut cands: Vec<Bore> = all
        .into_iter()
        .filter(|b| b.arc_deg >= MIN_PIN_ARC_DEG)
        .filter(|b| axis.is_none_or(|ax| parallel(b, ax.normalize())))
        .collect();
    cands.sort_by(|a, b| b.area.total_cmp(&a.area));
    let list = |bs: &[&Bore]| {
        bs.iter()
            .map(|b| describe(b, units))
            .collect::<Vec<_>>()
            .join("; ")
    };
    match cands.len() {
        0 => return Err(PinSearchError::NoBore(restricted)),
        1 => return Err(PinSearchError::OnlyOne(list(&[&cands[0]]))),
        _ => {}
    }
    // families of parallel candidates, in order of their largest member
    let mut families: Vec<Vec<&Bore>> = Vec::new();
    for b in &cands {
        match families.iter_mut().find(|f| parallel(f[0], b.axis_v())) {
            Some(f) => f.push(b),
            None => families.push(vec![b]),
        }
    }
    let seen = list(&cands.iter().collect::<Vec<_>>());
    if families.iter().all(|f| f.len() < 2) {
        return Err(PinSearchError::NotParallel(seen));
    }
    let (p, q) = match pair_at_the_ends(mesh, &families) {
        Some(Ok(pair)) => pair,
        Some(Err(rivals)) => {
            return Err(PinSearchError::Ambiguous {
                count: rivals,
                list: seen,
            });
        }
        None => pair_by_wall_area(&families, &seen)?,
    };
    if (p.radius - q.radius).abs() <= EQUAL_RADII_REL * p.radius.max(q.radius) {
        return Err(PinSearchError::EqualRadii(format!(
            "{}; all bores seen: {seen}",
            list(&[p, q])
        )));
    }
    let (crank, piston) = if p.radius > q.radius { (p, q) } else { (q, p) };
    let (a, b) = (crank.axis_v(), piston.axis_v());
    let axis = canonical((a + b * a.dot(&b).signum()).normalize());
    let ab = piston.centre_v() - crank.centre_v();
    let centre_distance = (ab - axis * axis.dot(&ab)).norm();
    if centre_distance <= crank.radius + piston.radius {
        return Err(PinSearchError::Ambiguous {
            count: 2,
            list: format!(
                "{} (the two bores overlap); all bores seen: {seen}",
                list(&[crank, piston])
            ),
        });
    }
    Ok(FoundPins {
        crank: crank.clone(),
        piston: piston.clone(),
        axis: axis.into(),
        centre_distance,
    })
}

/// The pin pair a rod is built around: two parallel bores at the two ends of the part's long
/// extent. The long direction ℓ is the principal direction of the largest second moment of the
/// surface (area-weighted triangle centroids). A family of parallel bores may hold the pins only
/// if its axis is across ℓ (|a·ℓ| ≤ cos 60°: cap-bolt holes run along the rod, oil holes across
/// the pin axis are another family); within it, a pair qualifies when the line between the two
/// axes runs along ℓ (within 30°) and the two bores span at least half the part's extent along
/// that line (d + r₁ + r₂ ≥ ½ extent). The qualifying pair farthest apart wins; another pair
/// within 2 % of its distance (and not sharing both bores) makes the choice ambiguous:
/// `Some(Err(count))`. `None` when no pair qualifies (a part that is no elongated rod): the
/// caller falls back on wall area.
fn pair_at_the_ends<'a>(
    mesh: &IndexedMesh,
    families: &[Vec<&'a Bore>],
) -> Option<Result<(&'a Bore, &'a Bore), usize>> {
    let long = long_direction(mesh)?;
    let extent = |u: Vector3<f64>| {
        let (lo, hi) = mesh
            .vertices
            .iter()
            .map(|v| v.dot(&u))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            });
        hi - lo
    };
    let mut pairs: Vec<(f64, &Bore, &Bore)> = Vec::new();
    for family in families.iter().filter(|f| f.len() >= 2) {
        let a = family[0].axis_v();
        if a.dot(&long).abs() > 60f64.to_radians().cos() {
            continue;
        }
        let along = (long - a * a.dot(&long)).normalize();
        for (i, p) in family.iter().enumerate() {
            for q in &family[i + 1..] {
                let d = q.centre_v() - p.centre_v();
                let d = d - a * a.dot(&d);
                let distance = d.norm();
                if distance <= p.radius + q.radius {
                    continue;
                }
                let u = d / distance;
                if u.dot(&along).abs() < 30f64.to_radians().cos() {
                    continue;
                }
                if distance + p.radius + q.radius >= 0.5 * extent(u) {
                    pairs.push((distance, p, q));
                }
            }
        }
    }
    pairs.sort_by(|x, y| y.0.total_cmp(&x.0));
    let &(best, p, q) = pairs.first()?;
    let rivals = pairs[1..]
        .iter()
        .filter(|(d, r, s)| *d >= 0.98 * best && !(std::ptr::eq(*r, p) && std::ptr::eq(*s, q)))
        .count();
    Some(if rivals == 0 {
        Ok((p, q))
    } else {
        Err(rivals + 2)
    })
}

/// The unit direction of the largest second moment of the surface about its centroid
/// (area-weighted triangle centroids); `None` for an empty surface.
fn long_direction(mesh: &IndexedMesh) -> Option<Vector3<f64>> {
    let mut area = 0.0;
    let mut first = Vector3::zeros();
    let mut second = nalgebra::Matrix3::zeros();
    for t in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.corners(t);
        let w = 0.5 * (b - a).cross(&(c - a)).norm();
        let m = (a + b + c) / 3.0;
        area += w;
        first += m * w;
        second += m * m.transpose() * w;
    }
    if area <= 0.0 {
        return None;
    }
    let mean = first / area;
    let cov = second / area - mean * mean.transpose();
    let eig = nalgebra::SymmetricEigen::new(cov);
    let k = eig.eigenvalues.imax();
    Some(eig.eigenvectors.column(k).into_owned())
}

/// The pin pair as the two largest bores by wall area of the largest family, for a part whose
/// long extent tells nothing ([`pair_at_the_ends`] found no pair): refused when another family's
/// pair or a third bore of the family is of comparable size.
fn pair_by_wall_area<'a>(
    families: &[Vec<&'a Bore>],
    seen: &str,
) -> Result<(&'a Bore, &'a Bore), PinSearchError> {
    let pair_area = |f: &Vec<&Bore>| f[0].area + f[1].area;
    let mut pairs: Vec<&Vec<&Bore>> = families.iter().filter(|f| f.len() >= 2).collect();
    pairs.sort_by(|a, b| pair_area(b).total_cmp(&pair_area(a)));
    if pairs.len() > 1 && pair_area(pairs[1]) >= COMPARABLE_AREA * pair_area(pairs[0]) {
        return Err(PinSearchError::NotParallel(seen.to_string()));
    }
    let family = pairs[0];
    let competitors = family[2..]
        .iter()
        .filter(|b| b.area >= COMPARABLE_AREA * family[1].area)
        .count();
    if competitors > 0 {
        return Err(PinSearchError::Ambiguous {
            count: competitors + 2,
            list: seen.to_string(),
        });
    }
    Ok((family[0], family[1]))
}
