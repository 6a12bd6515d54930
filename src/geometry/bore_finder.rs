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
use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// Largest dihedral angle between neighbouring facets within one smooth patch [deg].
pub const SMOOTH_ANGLE_DEG: f64 = 30.0;
/// Largest smallest-eigenvalue share of Σ A n nᵀ for a patch around one axis.
const MAX_OFF_AXIS_SHARE: f64 = 0.05;
/// Smallest middle-eigenvalue share of Σ A n nᵀ for a curved patch (an arc of about 20°).
const MIN_CURVED_SHARE: f64 = 0.01;
/// Largest RMS distance of a patch's vertices from the fitted cylinder, relative to its radius.
pub const MAX_RESIDUAL_REL: f64 = 2e-3;
/// Smallest arc of a bore that may be a pin bore [deg].
pub const MIN_PIN_ARC_DEG: f64 = 120.0;
/// A third bore whose wall area is at least this share of the second pin's is a competitor.
pub const COMPARABLE_AREA: f64 = 0.3;
/// Radii closer than this (relative) cannot tell the crank end from the piston end.
pub const EQUAL_RADII_REL: f64 = 0.01;
/// Axes within this angle are parallel [deg].
const PARALLEL_DEG: f64 = 1.0;
/// An arc with a gap below this is a full bore [deg].
const FULL_GAP_DEG: f64 = 0.5;

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
    let pair_area = |f: &Vec<&Bore>| f[0].area + f[1].area;
    let mut pairs: Vec<&Vec<&Bore>> = families.iter().filter(|f| f.len() >= 2).collect();
    if pairs.is_empty() {
        return Err(PinSearchError::NotParallel(list(
            &cands.iter().collect::<Vec<_>>(),
        )));
    }
    pairs.sort_by(|a, b| pair_area(b).total_cmp(&pair_area(a)));
    if pairs.len() > 1 && pair_area(pairs[1]) >= COMPARABLE_AREA * pair_area(pairs[0]) {
        return Err(PinSearchError::NotParallel(list(
            &[&pairs[0][..2], &pairs[1][..2]].concat(),
        )));
    }
    let family = pairs[0];
    let competitors: Vec<&Bore> = family[2..]
        .iter()
        .copied()
        .filter(|b| b.area >= COMPARABLE_AREA * family[1].area)
        .collect();
    if !competitors.is_empty() {
        let all: Vec<&Bore> = family[..2].iter().chain(&competitors).copied().collect();
        return Err(PinSearchError::Ambiguous {
            count: all.len(),
            list: list(&all),
        });
    }
    let (p, q) = (family[0], family[1]);
    if (p.radius - q.radius).abs() <= EQUAL_RADII_REL * p.radius.max(q.radius) {
        return Err(PinSearchError::EqualRadii(list(&[p, q])));
    }
    let (crank, piston) = if p.radius > q.radius { (p, q) } else { (q, p) };
    let (a, b) = (crank.axis_v(), piston.axis_v());
    let axis = canonical((a + b * a.dot(&b).signum()).normalize());
    let ab = piston.centre_v() - crank.centre_v();
    let centre_distance = (ab - axis * axis.dot(&ab)).norm();
    if centre_distance <= crank.radius + piston.radius {
        return Err(PinSearchError::Ambiguous {
            count: 2,
            list: format!("{} (the two bores overlap)", list(&[crank, piston])),
        });
    }
    Ok(FoundPins {
        crank: crank.clone(),
        piston: piston.clone(),
        axis: axis.into(),
        centre_distance,
    })
}

/// The direction with its largest component positive.
fn canonical(a: Vector3<f64>) -> Vector3<f64> {
    let k = a.iamax();
    if a[k] < 0.0 { -a } else { a }
}

/// One fitted cylinder: a point of the axis, the unit axis, the radius, the RMS residual.
#[derive(Debug, Clone, Copy)]
struct Cylinder {
    origin: Vector3<f64>,
    axis: Vector3<f64>,
    radius: f64,
    rms: f64,
}

/// Two unit vectors completing `a` to a right-handed orthonormal frame.
fn frame_of(a: Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if a.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let u = a.cross(&helper).normalize();
    (u, a.cross(&u))
}

/// Kåsa's algebraic circle fit to plane points: (centre, radius), or None when degenerate.
fn kasa(points: &[(f64, f64)]) -> Option<((f64, f64), f64)> {
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), &(x, y)| (a + x / n, b + y / n));
    let mut m = Matrix3::zeros();
    let mut rhs = Vector3::zeros();
    for &(x, y) in points {
        let (x, y) = (x - mx, y - my);
        let row = Vector3::new(x, y, 1.0);
        m += row * row.transpose();
        rhs -= row * (x * x + y * y);
    }
    let s = m.lu().solve(&rhs)?;
    let (cx, cy) = (-s.x / 2.0, -s.y / 2.0);
    let r2 = cx * cx + cy * cy - s.z;
    (r2 > 0.0).then(|| ((cx + mx, cy + my), r2.sqrt()))
}

/// Geometric cylinder fit to `points` starting from axis `axis`: Kåsa on the projection, then
/// Gauss–Newton over (centre offset ×2, axis tilt ×2, radius), the frame re-centred after each step.
fn fit_cylinder(points: &[Vector3<f64>], axis: Vector3<f64>) -> Option<Cylinder> {
    if points.len() < 5 {
        return None;
    }
    let mean = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
    let mut a = axis.normalize();
    let (u, v) = frame_of(a);
    let plane: Vec<(f64, f64)> = points
        .iter()
        .map(|p| ((p - mean).dot(&u), (p - mean).dot(&v)))
        .collect();
    let ((cx, cy), mut r) = kasa(&plane)?;
    let mut o = mean + u * cx + v * cy;
    let mut rms = f64::INFINITY;
    for _ in 0..12 {
        let (u, v) = frame_of(a);
        // centre the origin on the points' axial mean
        let wm = points.iter().map(|p| (p - o).dot(&a)).sum::<f64>() / points.len() as f64;
        o += a * wm;
        let mut jtj = nalgebra::Matrix5::<f64>::zeros();
        let mut jtr = nalgebra::Vector5::<f64>::zeros();
        let mut ss = 0.0;
        for p in points {
            let d = p - o;
            let (x, y, w) = (d.dot(&u), d.dot(&v), d.dot(&a));
            let rho = (x * x + y * y).sqrt();
            if rho == 0.0 {
                continue;
            }
            let res = rho - r;
            ss += res * res;
            let j = nalgebra::Vector5::new(-x / rho, -y / rho, -w * x / rho, -w * y / rho, -1.0);
            jtj += j * j.transpose();
            jtr += j * res;
        }
        rms = (ss / points.len() as f64).sqrt();
        let Some(step) = jtj.cholesky().map(|c| c.solve(&(-jtr))) else {
            break;
        };
        o += u * step[0] + v * step[1];
        a = (a + u * step[2] + v * step[3]).normalize();
        r += step[4];
        if step.norm() <= 1e-13 * r.max(1e-300) {
            break;
        }
    }
    // the residual at the final parameters
    let mut ss = 0.0;
    for p in points {
        let d = p - o;
        let rho = (d - a * a.dot(&d)).norm();
        ss += (rho - r) * (rho - r);
    }
    rms = rms.min((ss / points.len() as f64).sqrt());
    (r.is_finite() && r > 0.0).then_some(Cylinder {
        origin: o,
        axis: a,
        radius: r,
        rms,
    })
}

/// Smooth patches: triangle groups joined across manifold edges with small dihedral angles;
/// and each triangle's neighbours across its manifold edges (`u32::MAX`: none).
fn smooth_patches(mesh: &IndexedMesh, normals: &[Vector3<f64>]) -> (Vec<Vec<u32>>, Vec<[u32; 3]>) {
    let n = mesh.triangles.len();
    let mut uses: Vec<(u64, u32)> = Vec::with_capacity(3 * n);
    for (t, &[a, b, c]) in mesh.triangles.iter().enumerate() {
        for (i, j) in [(a, b), (b, c), (c, a)] {
            uses.push(((u64::from(i.min(j)) << 32) | u64::from(i.max(j)), t as u32));
        }
    }
    uses.sort_unstable();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    let cos_max = SMOOTH_ANGLE_DEG.to_radians().cos();
    let mut neighbours = vec![[u32::MAX; 3]; n];
    let mut link = |a: u32, b: u32| {
        if let Some(slot) = neighbours[a as usize].iter_mut().find(|x| **x == u32::MAX) {
            *slot = b;
        }
    };
    for group in uses.chunk_by(|x, y| x.0 == y.0) {
        if let [(_, s), (_, t)] = *group {
            link(s, t);
            link(t, s);
        }
        if let [(_, s), (_, t)] = *group
            && normals[s as usize].dot(&normals[t as usize]) >= cos_max
        {
            let (ra, rb) = (root(&mut parent, s), root(&mut parent, t));
            if ra != rb {
                parent[ra.max(rb) as usize] = ra.min(rb);
            }
        }
    }
    let mut index = vec![u32::MAX; n];
    let mut patches: Vec<Vec<u32>> = Vec::new();
    for t in 0..n as u32 {
        let r = root(&mut parent, t) as usize;
        if index[r] == u32::MAX {
            index[r] = patches.len() as u32;
            patches.push(Vec::new());
        }
        patches[index[r] as usize].push(t);
    }
    (patches, neighbours)
}

/// A fitted concave cylindrical patch before merging.
struct Wall {
    cyl: Cylinder,
    triangles: Vec<u32>,
    area: f64,
}

/// Every bore of the surface (any arc), merged, largest wall area first.
pub fn find_bores(mesh: &IndexedMesh) -> Vec<Bore> {
    let normals_areas: Vec<(Vector3<f64>, f64)> = (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            let n = (b - a).cross(&(c - a));
            let twice = n.norm();
            (
                if twice > 0.0 {
                    n / twice
                } else {
                    Vector3::zeros()
                },
                twice / 2.0,
            )
        })
        .collect();
    let normals: Vec<Vector3<f64>> = normals_areas.iter().map(|x| x.0).collect();
    let mut walls: Vec<Wall> = Vec::new();
    // whether a cylinder came out of splitting a smooth patch
    let mut split = false;
    let (patches, neighbours) = smooth_patches(mesh, &normals);
    let mut patch_of = vec![0u32; mesh.triangles.len()];
    for (k, p) in patches.iter().enumerate() {
        for &t in p {
            patch_of[t as usize] = k as u32;
        }
    }
    for (k, patch) in patches.into_iter().enumerate() {
        if patch.len() < 4 {
            continue;
        }
        match wall_of(mesh, &normals_areas, patch) {
            Ok(w) => walls.push(w),
            Err((patch, true)) => {
                // a smooth patch of several surfaces (a bore whose rims are rounded into the
                // faces): the cylinders in it, one by one
                let inside = |t: u32| patch_of[t as usize] == k as u32;
                for part in cylinders_in(mesh, &normals_areas, &neighbours, &patch, inside) {
                    if let Ok(w) = wall_of(mesh, &normals_areas, part) {
                        walls.push(w);
                        split = true;
                    }
                }
            }
            Err(_) => {}
        }
    }
    // merge coaxial walls of equal radius
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, w) in walls.iter().enumerate() {
        let same = |g: &Vec<usize>| {
            let c = &walls[g[0]].cyl;
            let d = w.cyl.origin - c.origin;
            let off = (d - c.axis * c.axis.dot(&d)).norm();
            c.axis.dot(&w.cyl.axis).abs() >= PARALLEL_DEG.to_radians().cos()
                && off <= EQUAL_RADII_REL * c.radius
                && (c.radius - w.cyl.radius).abs() <= EQUAL_RADII_REL * c.radius
        };
        match groups.iter_mut().find(|g| same(g)) {
            Some(g) => g.push(i),
            None => groups.push(vec![i]),
        }
    }
    let mut bores: Vec<Bore> = groups
        .iter()
        .filter_map(|g| {
            let triangles: Vec<u32> = g
                .iter()
                .flat_map(|&i| walls[i].triangles.iter().copied())
                .collect();
            let area: f64 = g.iter().map(|&i| walls[i].area).sum();
            let cyl = if g.len() == 1 {
                walls[g[0]].cyl
            } else {
                fit_cylinder(&patch_vertices(mesh, &triangles), walls[g[0]].cyl.axis)?
            };
            if !split {
                return Some(describe_wall(mesh, &cyl, &triangles, area));
            }
            // pieces of a wall the growth left out (small strips between regions, which are not
            // curved enough to stand alone): every facet on the cylinder, facing its axis
            let mut all = triangles;
            all.extend(on_cylinder(mesh, &normals_areas, &cyl));
            all.sort_unstable();
            all.dedup();
            let area = all.iter().map(|&t| normals_areas[t as usize].1).sum();
            // the rounds the wall runs into are tangent to it: trim the vertices that leave the
            // cylinder by more than rounding, refit, and take the axial extent from those left
            let mut points = patch_vertices(mesh, &all);
            let mut cyl = fit_cylinder(&points, cyl.axis)?;
            let noise =
                points.iter().map(|p| p.amax()).fold(0.0, f64::max) * 4.0 * f32::EPSILON as f64;
            for rel in [1e-4, 1e-5] {
                points.retain(|p| {
                    let d = p - cyl.origin;
                    ((d - cyl.axis * cyl.axis.dot(&d)).norm() - cyl.radius).abs()
                        <= rel * cyl.radius + noise
                });
                cyl = fit_cylinder(&points, cyl.axis)?;
            }
            let mut bore = describe_wall(mesh, &cyl, &all, area);
            let a = Vector3::from(bore.axis);
            let (lo, hi) = points
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                    let w = (p - cyl.origin).dot(&a);
                    (lo.min(w), hi.max(w))
                });
            bore.centre = (cyl.origin + a * ((lo + hi) / 2.0)).into();
            bore.length = hi - lo;
            Some(bore)
        })
        .collect();
    bores.sort_by(|a, b| b.area.total_cmp(&a.area));
    bores
}

/// The concave cylinder a patch is, or the patch back with whether it is curved but not one
/// cylinder (worth splitting).
fn wall_of(
    mesh: &IndexedMesh,
    normals_areas: &[(Vector3<f64>, f64)],
    patch: Vec<u32>,
) -> Result<Wall, (Vec<u32>, bool)> {
    let Some((l0, l1, axis, area)) = scatter_axis(normals_areas, &patch) else {
        return Err((patch, false));
    };
    if l1 < MIN_CURVED_SHARE {
        return Err((patch, false));
    }
    if l0 > MAX_OFF_AXIS_SHARE {
        return Err((patch, true));
    }
    let points = patch_vertices(mesh, &patch);
    let Some(cyl) = fit_cylinder(&points, axis) else {
        return Err((patch, true));
    };
    if cyl.rms > MAX_RESIDUAL_REL * cyl.radius {
        return Err((patch, true));
    }
    // normals towards the axis: a bore's wall, not a boss
    let mut facing = 0.0;
    for &t in &patch {
        let [a, b, c] = mesh.corners(t as usize);
        let d = (a + b + c) / 3.0 - cyl.origin;
        let radial = d - cyl.axis * cyl.axis.dot(&d);
        if let Some(r) = radial.try_normalize(0.0) {
            let (n, ar) = normals_areas[t as usize];
            facing += n.dot(&r) * ar;
        }
    }
    if facing / area > -0.5 {
        return Err((patch, false));
    }
    Ok(Wall {
        cyl,
        triangles: patch,
        area,
    })
}

/// (smallest, middle eigenvalue, smallest eigenvector, area) of the area-weighted normal
/// scatter Σ A n nᵀ / Σ A of some triangles.
fn scatter_axis(
    normals_areas: &[(Vector3<f64>, f64)],
    triangles: &[u32],
) -> Option<(f64, f64, Vector3<f64>, f64)> {
    let mut scatter = Matrix3::zeros();
    let mut area = 0.0;
    for &t in triangles {
        let (n, a) = normals_areas[t as usize];
        scatter += n * n.transpose() * a;
        area += a;
    }
    if area <= 0.0 {
        return None;
    }
    let eig = SymmetricEigen::new(scatter / area);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let axis: Vector3<f64> = eig.eigenvectors.column(order[0]).into_owned();
    Some((
        eig.eigenvalues[order[0]],
        eig.eigenvalues[order[1]],
        axis,
        area,
    ))
}

/// Largest tilt of a facet normal out of the plane ⟂ to a cylinder's axis, when growing [deg].
const GROW_TILT_DEG: f64 = 6.0;
/// Largest distance of a facet's corners from a cylinder when growing, relative to its radius.
const GROW_DISTANCE_REL: f64 = 1e-3;

/// The cylindrical regions of a smooth patch that is not one cylinder (e.g. a bore whose rims
/// are rounded into the faces): from each seed triangle not yet taken, a cylinder is fitted to
/// its two rings of neighbours and grown across neighbours whose corners lie on it (within
/// [`GROW_DISTANCE_REL`]) and whose normals are ⟂ to its axis (within [`GROW_TILT_DEG`]),
/// refitted once to the grown region and grown again.
fn cylinders_in(
    mesh: &IndexedMesh,
    normals_areas: &[(Vector3<f64>, f64)],
    neighbours: &[[u32; 3]],
    patch: &[u32],
    inside: impl Fn(u32) -> bool,
) -> Vec<Vec<u32>> {
    use std::collections::HashSet;
    let mut taken: HashSet<u32> = HashSet::new();
    let mut parts = Vec::new();
    let next_to = |t: u32| {
        neighbours[t as usize]
            .into_iter()
            .filter(|&s| s != u32::MAX && inside(s))
    };
    let max_tilt = GROW_TILT_DEG.to_radians().sin();
    for &seed in patch {
        if taken.contains(&seed) {
            continue;
        }
        // two rings around the seed
        let mut ring = vec![seed];
        for depth in 0..2 {
            let _ = depth;
            let now = ring.clone();
            for t in now {
                for s in next_to(t) {
                    if !ring.contains(&s) && !taken.contains(&s) {
                        ring.push(s);
                    }
                }
            }
        }
        if ring.len() < 6 {
            continue;
        }
        let Some((l0, l1, axis, _)) = scatter_axis(normals_areas, &ring) else {
            continue;
        };
        if l1 < 1e-4 || l0 > 0.1 * l1 {
            continue;
        }
        let Some(mut cyl) = fit_cylinder(&patch_vertices(mesh, &ring), axis) else {
            continue;
        };
        let mut region: Vec<u32> = Vec::new();
        for round in 0..2 {
            let fits = |t: u32, cyl: &Cylinder| {
                let n = normals_areas[t as usize].0;
                n.dot(&cyl.axis).abs() <= max_tilt
                    && mesh.corners(t as usize).iter().all(|p| {
                        let d = p - cyl.origin;
                        ((d - cyl.axis * cyl.axis.dot(&d)).norm() - cyl.radius).abs()
                            <= GROW_DISTANCE_REL * cyl.radius
                    })
            };
            if !fits(seed, &cyl) {
                break;
            }
            let mut member: HashSet<u32> = HashSet::from([seed]);
            let mut queue = vec![seed];
            while let Some(t) = queue.pop() {
                for s in next_to(t) {
                    if !taken.contains(&s) && !member.contains(&s) && fits(s, &cyl) {
                        member.insert(s);
                        queue.push(s);
                    }
                }
            }
            region = member.into_iter().collect();
            region.sort_unstable();
            if round == 0 {
                match fit_cylinder(&patch_vertices(mesh, &region), cyl.axis) {
                    Some(c) if c.rms <= MAX_RESIDUAL_REL * c.radius => cyl = c,
                    _ => break,
                }
            }
        }
        if region.len() >= 6 {
            taken.extend(region.iter().copied());
            parts.push(region);
        }
    }
    parts
}

/// Every facet whose corners lie on `cyl` (within [`GROW_DISTANCE_REL`]) and whose normal
/// points at its axis (within [`GROW_TILT_DEG`]).
fn on_cylinder(
    mesh: &IndexedMesh,
    normals_areas: &[(Vector3<f64>, f64)],
    cyl: &Cylinder,
) -> Vec<u32> {
    let cos_tilt = GROW_TILT_DEG.to_radians().cos();
    (0..mesh.triangles.len() as u32)
        .filter(|&t| {
            let c = mesh.corners(t as usize);
            let radial = |p: &Vector3<f64>| {
                let d = p - cyl.origin;
                d - cyl.axis * cyl.axis.dot(&d)
            };
            if !c
                .iter()
                .all(|p| (radial(p).norm() - cyl.radius).abs() <= GROW_DISTANCE_REL * cyl.radius)
            {
                return false;
            }
            let mid = radial(&((c[0] + c[1] + c[2]) / 3.0));
            mid.try_normalize(0.0)
                .is_some_and(|r| normals_areas[t as usize].0.dot(&r) <= -cos_tilt)
        })
        .collect()
}

/// The distinct vertices of some triangles.
fn patch_vertices(mesh: &IndexedMesh, triangles: &[u32]) -> Vec<Vector3<f64>> {
    let mut ids: Vec<u32> = triangles
        .iter()
        .flat_map(|&t| mesh.triangles[t as usize])
        .collect();
    ids.sort_unstable();
    ids.dedup();
    ids.iter().map(|&i| mesh.vertices[i as usize]).collect()
}

/// Arc, extent, centre and opening of a fitted wall.
fn describe_wall(mesh: &IndexedMesh, cyl: &Cylinder, triangles: &[u32], area: f64) -> Bore {
    let a = canonical(cyl.axis);
    let (u, v) = frame_of(a);
    let angle = |p: Vector3<f64>| {
        let d = p - cyl.origin;
        d.dot(&v).atan2(d.dot(&u)).rem_euclid(TAU)
    };
    let mut intervals: Vec<(f64, f64)> = Vec::with_capacity(triangles.len() + 8);
    let (mut wlo, mut whi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &t in triangles {
        let c = mesh.corners(t as usize);
        let t0 = angle(c[0]);
        let (mut lo, mut hi) = (0.0f64, 0.0f64);
        for p in &c[1..] {
            let mut d = angle(*p) - t0;
            if d > PI {
                d -= TAU;
            } else if d < -PI {
                d += TAU;
            }
            lo = lo.min(d);
            hi = hi.max(d);
        }
        for p in c {
            let w = (p - cyl.origin).dot(&a);
            wlo = wlo.min(w);
            whi = whi.max(w);
        }
        let start = (t0 + lo).rem_euclid(TAU);
        let end = start + (hi - lo);
        if end > TAU {
            intervals.push((start, TAU));
            intervals.push((0.0, end - TAU));
        } else {
            intervals.push((start, end));
        }
    }
    intervals.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)));
    // union of the intervals and the largest gap (cyclically)
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for (s, e) in intervals {
        match merged.last_mut() {
            Some(last) if s <= last.1 => last.1 = last.1.max(e),
            _ => merged.push((s, e)),
        }
    }
    let covered: f64 = merged.iter().map(|(s, e)| e - s).sum();
    let mut gap = (0.0, 0.0); // (size, middle angle)
    for (k, &(_, e)) in merged.iter().enumerate() {
        let next = if k + 1 < merged.len() {
            merged[k + 1].0
        } else {
            merged[0].0 + TAU
        };
        if next - e > gap.0 {
            gap = (next - e, (e + next) / 2.0);
        }
    }
    let full = gap.0 < FULL_GAP_DEG.to_radians();
    let arc_deg = if full { 360.0 } else { covered.to_degrees() };
    let centre = cyl.origin + a * ((wlo + whi) / 2.0);
    Bore {
        centre: centre.into(),
        radius: cyl.radius,
        axis: a.into(),
        arc_deg,
        length: whi - wlo,
        full,
        opening: (!full).then(|| (u * gap.1.cos() + v * gap.1.sin()).into()),
        residual_rms: cyl.rms,
        area,
        triangles: triangles.len(),
    }
}

#[cfg(test)]
pub mod tests {
    use super::*;
    use crate::geometry::primitives::{to_soup, transformed};
    use crate::geometry::validate::validate;
    use crate::geometry::weld::weld;
    use nalgebra::{Rotation3, Vector2};
    use std::collections::HashMap;

    /// A hole of a test plate: centre x (mm), radius, and whether it is cut in half at its
    /// centre plane (a big end without its cap, open towards −x).
    pub struct Hole {
        pub x: f64,
        pub r: f64,
        pub half: bool,
    }

    /// Plane triangulation of a bar of half-width `s` (mm) along x with the given holes (left to
    /// right, each in a square tile of half-size `s`, tiles joined by rectangles), extruded over
    /// z ∈ [−h/2, h/2], `n` segments per full turn (a multiple of 8); welded as the STL stores
    /// it, validated, in metres.
    pub fn plate(holes: &[Hole], s: f64, h: f64, n: usize) -> IndexedMesh {
        assert!(n.is_multiple_of(8));
        let mut tris: Vec<[Vector2<f64>; 3]> = Vec::new();
        // right and left edge chains of each tile (bottom to top)
        type Chain = Vec<Vector2<f64>>;
        let mut chains: Vec<(Chain, Chain)> = Vec::new();
        for hole in holes {
            let c = Vector2::new(hole.x, 0.0);
            let ks: Vec<i64> = if hole.half {
                (-(n as i64) / 4..=n as i64 / 4).collect()
            } else {
                (0..=n as i64).collect()
            };
            let at = |k: i64| {
                let th = TAU * k.rem_euclid(n as i64) as f64 / n as f64;
                let d = Vector2::new(th.cos(), th.sin());
                let t = s / d.x.abs().max(d.y.abs());
                // exact square coordinates at the corners and the edge middles
                let k8 = k.rem_euclid(n as i64);
                let sq = if (8 * k8) % n as i64 == 0 {
                    let (x, y) = [
                        (s, 0.0),
                        (s, s),
                        (0.0, s),
                        (-s, s),
                        (-s, 0.0),
                        (-s, -s),
                        (0.0, -s),
                        (s, -s),
                    ][(8 * k8 / n as i64) as usize];
                    Vector2::new(x, y)
                } else {
                    Vector2::new((d.x * t).clamp(-s, s), (d.y * t).clamp(-s, s))
                };
                (c + d * hole.r, c + sq)
            };
            let pts: Vec<_> = ks.iter().map(|&k| at(k)).collect();
            for w in pts.windows(2) {
                let ((c0, s0), (c1, s1)) = (w[0], w[1]);
                tris.push([c0, c1, s1]);
                tris.push([c0, s1, s0]);
            }
            let mut right: Vec<_> = pts
                .iter()
                .map(|p| p.1)
                .filter(|p| (p.x - (c.x + s)).abs() < 1e-12)
                .collect();
            let mut left: Vec<_> = pts
                .iter()
                .map(|p| p.1)
                .filter(|p| (p.x - (c.x - s)).abs() < 1e-12)
                .collect();
            right.sort_by(|a, b| a.y.total_cmp(&b.y));
            right.dedup();
            left.sort_by(|a, b| a.y.total_cmp(&b.y));
            left.dedup();
            chains.push((left, right));
        }
        // rectangles between consecutive tiles: zip the right chain of one and the left of the next
        for k in 0..holes.len().saturating_sub(1) {
            let (l, r) = (&chains[k].1, &chains[k + 1].0);
            let (mut i, mut j) = (0, 0);
            while i + 1 < l.len() || j + 1 < r.len() {
                if j + 1 >= r.len() || (i + 1 < l.len() && l[i + 1].y <= r[j + 1].y) {
                    tris.push([l[i], r[j], l[i + 1]]);
                    i += 1;
                } else {
                    tris.push([l[i], r[j], r[j + 1]]);
                    j += 1;
                }
            }
        }
        // index the plane points, orient counter-clockwise, find the boundary edges
        let mut ids: HashMap<(u64, u64), u32> = HashMap::new();
        let mut pts: Vec<Vector2<f64>> = Vec::new();
        let mut id = |p: Vector2<f64>| {
            *ids.entry((p.x.to_bits(), p.y.to_bits()))
                .or_insert_with(|| {
                    pts.push(p);
                    (pts.len() - 1) as u32
                })
        };
        let mut plane: Vec<[u32; 3]> = Vec::new();
        for [a, b, c] in tris {
            let cross = (b - a).perp(&(c - a));
            if cross.abs() < 1e-12 {
                continue;
            }
            let t = [id(a), id(b), id(c)];
            plane.push(if cross > 0.0 { t } else { [t[0], t[2], t[1]] });
        }
        let mut edge_count: HashMap<(u32, u32), i32> = HashMap::new();
        for t in &plane {
            for (i, j) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                *edge_count.entry((i.min(j), i.max(j))).or_default() += 1;
            }
        }
        let np = pts.len() as u32;
        let mut mesh = IndexedMesh {
            vertices: pts
                .iter()
                .map(|p| Vector3::new(p.x, p.y, -h / 2.0))
                .chain(pts.iter().map(|p| Vector3::new(p.x, p.y, h / 2.0)))
                .collect(),
            triangles: Vec::new(),
        };
        for t in &plane {
            mesh.triangles.push([t[0] + np, t[1] + np, t[2] + np]);
            mesh.triangles.push([t[0], t[2], t[1]]);
            for (i, j) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                if edge_count[&(i.min(j), i.max(j))] == 1 {
                    // interior on the left of i→j: the wall faces right
                    mesh.triangles.push([i, j, j + np]);
                    mesh.triangles.push([i, j + np, i + np]);
                }
            }
        }
        mesh
    }

    /// The plate as a design file would give it: float32 in mm, welded, validated, metres.
    pub fn as_read(mesh_mm: &IndexedMesh) -> IndexedMesh {
        validate(weld(&to_soup(mesh_mm)))
            .expect("a valid test plate")
            .mesh
            .scaled(1e-3)
    }

    fn rod(holes: &[Hole]) -> IndexedMesh {
        plate(holes, 40.0, 30.0, 96)
    }

    fn close(a: [f64; 3], b: Vector3<f64>, tol: f64) -> bool {
        (Vector3::from(a) - b).norm() <= tol
    }

    #[test]
    fn one_hole_is_one_bore_and_refused_as_pins() {
        let m = as_read(&rod(&[Hole {
            x: 0.0,
            r: 20.0,
            half: false,
        }]));
        let bores = find_bores(&m);
        assert_eq!(bores.len(), 1, "{bores:#?}");
        assert!(bores[0].full && bores[0].arc_deg == 360.0);
        assert!(
            (bores[0].radius - 0.020).abs() < 1e-8,
            "{}",
            bores[0].radius
        );
        assert!((bores[0].length - 0.030).abs() < 1e-8);
        let e = find_pins(&m, None, Units::Mm).unwrap_err();
        assert!(matches!(e, PinSearchError::OnlyOne(_)), "{e}");
        assert!(e.to_string().contains("only one bore"), "{e}");
    }

    #[test]
    fn two_holes_any_pose() {
        let base = rod(&[
            Hole {
                x: 0.0,
                r: 24.0,
                half: false,
            },
            Hole {
                x: 180.0,
                r: 12.0,
                half: false,
            },
        ]);
        // as drawn; then pins along y, shifted by 1 m
        let turn = Rotation3::from_axis_angle(&Vector3::x_axis(), -PI / 2.0).into_inner();
        let poses = [
            (Matrix3::identity(), Vector3::zeros()),
            (turn, Vector3::new(1000.0, -1000.0, 1000.0)),
        ];
        for (rot, shift) in poses {
            let m = as_read(&transformed(&base, &rot, shift));
            let f = find_pins(&m, None, Units::Mm).unwrap();
            let a = (rot * Vector3::zeros() + shift) * 1e-3;
            let b = (rot * Vector3::new(180.0, 0.0, 0.0) + shift) * 1e-3;
            assert!(
                close(f.crank.centre, a, 1e-5),
                "{:?} vs {a}",
                f.crank.centre
            );
            assert!(
                close(f.piston.centre, b, 1e-5),
                "{:?} vs {b}",
                f.piston.centre
            );
            assert!((f.crank.radius - 0.024).abs() < 1e-8);
            assert!((f.piston.radius - 0.012).abs() < 1e-8);
            assert!(close(
                f.axis,
                rot * Vector3::z() * (rot * Vector3::z()).sum().signum(),
                1e-9
            ));
            assert!((f.centre_distance - 0.18).abs() < 1e-8);
            assert!(f.crank.full && f.piston.full);
        }
    }

    #[test]
    fn capless_big_end_is_an_arc_of_180_degrees() {
        let m = as_read(&rod(&[
            Hole {
                x: 0.0,
                r: 24.0,
                half: true,
            },
            Hole {
                x: 180.0,
                r: 12.0,
                half: false,
            },
        ]));
        let f = find_pins(&m, None, Units::Mm).unwrap();
        assert!(!f.crank.full);
        assert!(
            (f.crank.arc_deg - 180.0).abs() < 1e-6,
            "{}",
            f.crank.arc_deg
        );
        assert!(
            close(f.crank.centre, Vector3::zeros(), 1e-5),
            "{:?}",
            f.crank.centre
        );
        assert!((f.crank.radius - 0.024).abs() < 1e-8);
        // opening towards −x
        assert!(close(f.crank.opening.unwrap(), -Vector3::x(), 1e-9));
        assert!(close(f.piston.centre, Vector3::new(0.18, 0.0, 0.0), 1e-5));
    }

    #[test]
    fn equal_radii_and_three_holes_are_refused() {
        let h = |x, r| Hole { x, r, half: false };
        let m = as_read(&rod(&[h(0.0, 20.0), h(180.0, 20.1)]));
        let e = find_pins(&m, None, Units::Mm).unwrap_err();
        assert!(
            e.to_string()
                .contains("cannot tell the crank end from the piston end"),
            "{e}"
        );
        let m = as_read(&rod(&[h(0.0, 24.0), h(120.0, 16.0), h(240.0, 12.0)]));
        let e = find_pins(&m, None, Units::Mm).unwrap_err();
        assert!(
            matches!(e, PinSearchError::Ambiguous { count: 3, .. }),
            "{e}"
        );
        // a small oil hole does not compete
        let m = as_read(&rod(&[h(0.0, 24.0), h(120.0, 2.0), h(240.0, 12.0)]));
        let f = find_pins(&m, None, Units::Mm).unwrap();
        assert!((f.centre_distance - 0.24).abs() < 1e-8);
        // restricted to another axis: nothing
        let e = find_pins(&m, Some(Vector3::y()), Units::Mm).unwrap_err();
        assert!(matches!(e, PinSearchError::NoBore(_)), "{e}");
    }
}
