//! The bore walls of a surface: smooth patches joined across gentle edges, cylinders fitted to
//! them (or grown from seeds inside a patch whose rims are rounded into the faces), and each wall
//! described as a [`Bore`] (centre, radius, arc, length).

use super::bore::*;
use super::fit::*;
use super::patches::smooth_patches;
use crate::geometry::weld::IndexedMesh;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};

/// A fitted concave cylindrical patch before merging.
pub(super) struct Wall {
    pub(super) cyl: Cylinder,
    pub(super) triangles: Vec<u32>,
    pub(super) area: f64,
}

/// The concave cylinder a patch is, or the patch back with whether it is curved but not one
/// cylinder (worth splitting).
pub(super) fn wall_of(
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
pub(super) fn scatter_axis(
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
pub(super) const GROW_TILT_DEG: f64 = 6.0;
/// Largest distance of a facet's corners from a cylinder when growing, relative to its radius.
pub(super) const GROW_DISTANCE_REL: f64 = 1e-3;

/// The cylindrical regions of a smooth patch that is not one cylinder (e.g. a bore whose rims
/// are rounded into the faces): from each seed triangle not yet taken, a cylinder is fitted to
/// its two rings of neighbours and grown across neighbours whose corners lie on it (within
/// [`GROW_DISTANCE_REL`]) and whose normals are ⟂ to its axis (within [`GROW_TILT_DEG`]),
/// refitted once to the grown region and grown again.
pub(super) fn cylinders_in(
    mesh: &IndexedMesh,
    normals_areas: &[(Vector3<f64>, f64)],
    neighbours: &[[u32; 3]],
    patch: &[u32],
    inside: impl Fn(u32) -> bool + Sync,
) -> Vec<Vec<u32>> {
    // `taken`: in a region already; `member`: in the region being grown, stamped with its seed
    let mut taken = vec![false; mesh.triangles.len()];
    let mut member = vec![u32::MAX; mesh.triangles.len()];
    let mut parts = Vec::new();
    let next_to = |t: u32| {
        neighbours[t as usize]
            .into_iter()
            .filter(|&s| s != u32::MAX && inside(s))
    };
    let max_tilt = GROW_TILT_DEG.to_radians().sin();
    let flat = flat_rings(normals_areas, neighbours, patch, &inside);
    for (&seed, flat) in patch.iter().zip(flat) {
        if taken[seed as usize] || flat {
            continue;
        }
        // two rings around the seed
        let mut ring = vec![seed];
        for depth in 0..2 {
            let _ = depth;
            let now = ring.clone();
            for t in now {
                for s in next_to(t) {
                    if !ring.contains(&s) && !taken[s as usize] {
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
            // the stamp of this growth: the seed and the round
            let stamp = 2 * seed + round;
            member[seed as usize] = stamp;
            region = vec![seed];
            let mut queue = vec![seed];
            while let Some(t) = queue.pop() {
                for s in next_to(t) {
                    if !taken[s as usize] && member[s as usize] != stamp && fits(s, &cyl) {
                        member[s as usize] = stamp;
                        region.push(s);
                        queue.push(s);
                    }
                }
            }
            region.sort_unstable();
            if round == 0 {
                match fit_cylinder(&patch_vertices(mesh, &region), cyl.axis) {
                    Some(c) if c.rms <= MAX_RESIDUAL_REL * c.radius => cyl = c,
                    _ => break,
                }
            }
        }
        if region.len() >= 6 {
            for &t in &region {
                taken[t as usize] = true;
            }
            parts.push(region);
        }
    }
    parts
}

/// For each seed of [`cylinders_in`], whether its two rings of neighbours (taken or not) are
/// flat enough that no ring it could grow has a curved scatter: every normal within δ of the
/// seed's, sin²δ = 1e-5. For any subset of those triangles (the ring left once some are taken)
/// the two smallest eigenvalues of the normalised scatter sum to 1 − λ_max ≤ 1 − n₀ᵀ M n₀ ≤
/// sin²δ, below the 1e-4 a seed needs: the seed is passed over without building its ring.
/// Checked in parallel; on a finely subdivided export most seeds are flat.
fn flat_rings(
    normals_areas: &[(Vector3<f64>, f64)],
    neighbours: &[[u32; 3]],
    patch: &[u32],
    inside: &(impl Fn(u32) -> bool + Sync),
) -> Vec<bool> {
    let cos_delta = (1.0f64 - 1e-5).sqrt();
    patch
        .par_iter()
        .map(|&seed| {
            let n0 = normals_areas[seed as usize].0;
            let near = |t: u32| normals_areas[t as usize].0.dot(&n0) >= cos_delta;
            let next_to = |t: u32| {
                neighbours[t as usize]
                    .into_iter()
                    .filter(|&s| s != u32::MAX && inside(s))
            };
            near(seed) && next_to(seed).all(|s| near(s) && next_to(s).all(near))
        })
        .collect()
}

/// Every facet whose corners lie on `cyl` (within [`GROW_DISTANCE_REL`]) and whose normal
/// points at its axis (within [`GROW_TILT_DEG`]).
pub(super) fn on_cylinder(
    mesh: &IndexedMesh,
    normals_areas: &[(Vector3<f64>, f64)],
    cyl: &Cylinder,
) -> Vec<u32> {
    let cos_tilt = GROW_TILT_DEG.to_radians().cos();
    (0..mesh.triangles.len() as u32)
        .into_par_iter()
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

/// The distinct vertices of some triangles, in the order of their indices. Many triangles (a
/// sixteenth of the vertex count or more: a wall) are marked on a table of the vertices; a few
/// (a ring of a growth) are sorted.
pub(super) fn patch_vertices(mesh: &IndexedMesh, triangles: &[u32]) -> Vec<Vector3<f64>> {
    if 16 * triangles.len() >= mesh.vertices.len() {
        let mut used = vec![false; mesh.vertices.len()];
        for &t in triangles {
            for v in mesh.triangles[t as usize] {
                used[v as usize] = true;
            }
        }
        return used
            .iter()
            .zip(&mesh.vertices)
            .filter_map(|(&u, p)| u.then_some(*p))
            .collect();
    }
    let mut ids: Vec<u32> = triangles
        .iter()
        .flat_map(|&t| mesh.triangles[t as usize])
        .collect();
    ids.sort_unstable();
    ids.dedup();
    ids.iter().map(|&i| mesh.vertices[i as usize]).collect()
}

/// Arc, extent, centre and opening of a fitted wall.
pub(super) fn describe_wall(
    mesh: &IndexedMesh,
    cyl: &Cylinder,
    triangles: &[u32],
    area: f64,
) -> Bore {
    let a = canonical(cyl.axis);
    let (u, v) = frame_of(a);
    let angle = |p: Vector3<f64>| {
        let d = p - cyl.origin;
        d.dot(&v).atan2(d.dot(&u)).rem_euclid(TAU)
    };
    // each vertex's angle once (a vertex is a corner of about six triangles); a few triangles of
    // a large mesh (a wall of the whole part) take theirs as they come
    let mut angles = if 16 * triangles.len() >= mesh.vertices.len() {
        vec![f64::NAN; mesh.vertices.len()]
    } else {
        Vec::new()
    };
    let mut angle_of = |i: u32| match angles.get_mut(i as usize) {
        Some(slot) if slot.is_nan() => {
            *slot = angle(mesh.vertices[i as usize]);
            *slot
        }
        Some(slot) => *slot,
        None => angle(mesh.vertices[i as usize]),
    };
    let mut intervals: Vec<(f64, f64)> = Vec::with_capacity(triangles.len() + 8);
    let (mut wlo, mut whi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &t in triangles {
        let ids = mesh.triangles[t as usize];
        let c = mesh.corners(t as usize);
        let t0 = angle_of(ids[0]);
        let (mut lo, mut hi) = (0.0f64, 0.0f64);
        for &i in &ids[1..] {
            let mut d = angle_of(i) - t0;
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
    // by start alone: the union below is the same whatever the order of equal starts (each
    // extends the interval it starts in to the largest end), and −0 and +0 start alike (the
    // starts are ≥ 0, so their bits order them as numbers)
    let intervals = sorted_by_key(intervals, |x| if x.0 == 0.0 { 0 } else { x.0.to_bits() });
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

/// `items` in the order of `key`, equal keys in their order (a least-significant-digit radix
/// sort, 11 bits a pass, a pass skipped where every key has the same digit): linear in the
/// number of items, where a comparison sort of a wall's 10⁵ arcs took most of its description.
fn sorted_by_key<T: Copy>(items: Vec<T>, key: impl Fn(&T) -> u64) -> Vec<T> {
    const BITS: u32 = 11;
    let mask = (1u64 << BITS) - 1;
    let mut keys: Vec<u64> = items.iter().map(&key).collect();
    let (mut items, mut spare_items) = (items.clone(), items);
    let mut spare_keys = keys.clone();
    for shift in (0..64).step_by(BITS as usize) {
        let digit = |k: u64| ((k >> shift) & mask) as usize;
        let mut start = vec![0usize; 1 << BITS];
        for &k in &keys {
            start[digit(k)] += 1;
        }
        if start.contains(&keys.len()) {
            continue;
        }
        let mut sum = 0;
        for s in start.iter_mut() {
            (*s, sum) = (sum, sum + *s);
        }
        for (&k, &item) in keys.iter().zip(&items) {
            let slot = &mut start[digit(k)];
            spare_keys[*slot] = k;
            spare_items[*slot] = item;
            *slot += 1;
        }
        std::mem::swap(&mut keys, &mut spare_keys);
        std::mem::swap(&mut items, &mut spare_items);
    }
    items
}

/// Every bore of the surface (any arc), merged, largest wall area first.
pub fn find_bores(mesh: &IndexedMesh) -> Vec<Bore> {
    let normals_areas: Vec<(Vector3<f64>, f64)> = (0..mesh.triangles.len())
        .into_par_iter()
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
    let (patches, neighbours) = smooth_patches(mesh, &normals);
    let mut patch_of = vec![0u32; mesh.triangles.len()];
    for (k, p) in patches.iter().enumerate() {
        for &t in p {
            patch_of[t as usize] = k as u32;
        }
    }
    // each patch's walls, and whether they came out of splitting it; patches side by side
    let per_patch: Vec<(Vec<Wall>, bool)> = patches
        .into_par_iter()
        .enumerate()
        .map(|(k, patch)| {
            if patch.len() < 4 {
                return (Vec::new(), false);
            }
            match wall_of(mesh, &normals_areas, patch) {
                Ok(w) => (vec![w], false),
                Err((patch, true)) => {
                    // a smooth patch of several surfaces (a bore whose rims are rounded into the
                    // faces): the cylinders in it, one by one
                    let inside = |t: u32| patch_of[t as usize] == k as u32;
                    let walls: Vec<Wall> =
                        cylinders_in(mesh, &normals_areas, &neighbours, &patch, inside)
                            .into_iter()
                            .filter_map(|part| wall_of(mesh, &normals_areas, part).ok())
                            .collect();
                    let split = !walls.is_empty();
                    (walls, split)
                }
                Err(_) => (Vec::new(), false),
            }
        })
        .collect();
    // whether a cylinder came out of splitting a smooth patch
    let split = per_patch.iter().any(|(_, split)| *split);
    let walls: Vec<Wall> = per_patch.into_iter().flat_map(|(w, _)| w).collect();
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
        .par_iter()
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

#[cfg(test)]
mod tests {
    use super::sorted_by_key;

    /// The radix sort gives the order of the standard library's stable sort: keys of every size
    /// (f64 bits of angles in [0, 2π], small integers, repeats), equal keys in their order.
    #[test]
    fn the_radix_sort_is_a_stable_sort() {
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let angles: Vec<(u64, usize)> = (0..5000)
            .map(|i| ((next() % 1000) as f64 * std::f64::consts::TAU / 1000.0, i))
            .map(|(a, i)| (a.to_bits(), i))
            .collect();
        let small: Vec<(u64, usize)> = (0..5000).map(|i| (next() % 7, i)).collect();
        let wide: Vec<(u64, usize)> = (0..5000).map(|i| (next(), i)).collect();
        for items in [angles, small, wide, Vec::new()] {
            let mut expected = items.clone();
            expected.sort_by_key(|x| x.0);
            assert_eq!(sorted_by_key(items, |x| x.0), expected);
        }
    }
}
