//! Exact mass properties of a closed triangulated solid by the divergence theorem.
//!
//! Each oriented boundary triangle (a, b, c) spans a signed tetrahedron with a reference point
//! p; summing over the triangles gives the integrals over the solid exactly (up to round-off).
//! With the corners taken relative to p, a tetrahedron (0, a, b, c) has
//!
//! - V = a · (b × c) / 6,
//! - ∫ x dV = V (a + b + c) / 4,
//! - ∫ x xᵀ dV = V/20 (a aᵀ + b bᵀ + c cᵀ + s sᵀ), s = a + b + c
//!
//! (the moment formulas of a simplex, e.g. Tonon, J. Math. Stat. 1(1), 2004, eq. for the
//! canonical tetrahedron; the same as Mirtich, J. Graphics Tools 1(2), 1996, for polyhedra).
//! The reference point is the bounding-box centre for the volume and centroid, then the centroid
//! itself for the second moments, so a mesh far from the origin loses no digits to cancellation.
//! The inertia tensor about the centroid follows as I = ρ (tr(S) 𝟙 − S), S = ∫ x xᵀ dV.

use super::weld::IndexedMesh;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use rayon::prelude::*;

/// Volume integrals of a solid about a reference point p: ∫dV, ∫(x−p)dV, ∫(x−p)(x−p)ᵀdV.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeMoments {
    pub volume: f64,
    pub first: Vector3<f64>,
    pub second: Matrix3<f64>,
}

/// Triangles per parallel work item; partial sums are added in a fixed order, so the result
/// does not depend on thread scheduling.
const CHUNK: usize = 8192;

/// Running sums of one pass: the volume, the first moment and the second moment as its upper
/// triangle (xx, xy, xz, yy, yz, zz).
#[derive(Clone, Copy)]
struct Sums {
    volume: f64,
    first: [f64; 3],
    second: [f64; 6],
}

/// The (row, column) of each entry of [`Sums::second`].
const UPPER: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

impl Sums {
    const ZERO: Self = Sums {
        volume: 0.0,
        first: [0.0; 3],
        second: [0.0; 6],
    };

    fn add(mut self, other: &Self) -> Self {
        self.volume += other.volume;
        for (sum, x) in self.first.iter_mut().zip(other.first) {
            *sum += x;
        }
        for (sum, x) in self.second.iter_mut().zip(other.second) {
            *sum += x;
        }
        self
    }
}

/// How far a pass of [`sums`] goes: the volume only, also the first moment, or all three.
const VOLUME: u8 = 0;
const FIRST: u8 = 1;
const SECOND: u8 = 2;

/// The corners of a triangle relative to the reference point `r`.
#[inline(always)]
fn relative_corners(mesh: &IndexedMesh, tri: &[u32; 3], r: &[f64; 3]) -> [[f64; 3]; 3] {
    // Spelled out: `array::map` is not always inlined.
    let corner = |i: u32| {
        let v = &mesh.vertices[i as usize];
        [v.x - r[0], v.y - r[1], v.z - r[2]]
    };
    [corner(tri[0]), corner(tri[1]), corner(tri[2])]
}

/// The signed volume a · (b × c) / 6 of the tetrahedron (reference, a, b, c).
#[inline(always)]
fn tetrahedron_volume([a, b, c]: &[[f64; 3]; 3]) -> f64 {
    let cross = [
        b[1] * c[2] - b[2] * c[1],
        b[2] * c[0] - b[0] * c[2],
        b[0] * c[1] - b[1] * c[0],
    ];
    (a[0] * cross[0] + a[1] * cross[1] + a[2] * cross[2]) / 6.0
}

/// The sums over the tetrahedra (reference, a, b, c) of the formulas in the module docs, up to
/// the moment `ORDER`, in plain f64 arithmetic: each operation is the one nalgebra's vector and
/// matrix expressions perform, in the same order (sum of products left to right, outer products
/// `aᵢ·aⱼ`), so the digits are those of the straightforward nalgebra code; the second moment's
/// symmetry is used (its entry (i, j) is bit for bit its entry (j, i)), so six entries are
/// summed rather than nine.
fn sums<const ORDER: u8>(mesh: &IndexedMesh, reference: Vector3<f64>) -> Sums {
    let r = [reference.x, reference.y, reference.z];
    let partial: Vec<Sums> = mesh
        .triangles
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut acc = Sums::ZERO;
            for tri in chunk {
                let corners = relative_corners(mesh, tri, &r);
                let volume = tetrahedron_volume(&corners);
                acc.volume += volume;
                if ORDER >= FIRST {
                    let [a, b, c] = corners;
                    let s = [a[0] + b[0] + c[0], a[1] + b[1] + c[1], a[2] + b[2] + c[2]];
                    let q = volume / 4.0;
                    for (sum, s) in acc.first.iter_mut().zip(s) {
                        *sum += s * q;
                    }
                    if ORDER >= SECOND {
                        let q = volume / 20.0;
                        for (k, &(i, j)) in UPPER.iter().enumerate() {
                            acc.second[k] +=
                                (a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + s[i] * s[j]) * q;
                        }
                    }
                }
            }
            acc
        })
        .collect();
    partial.iter().fold(Sums::ZERO, Sums::add)
}

/// The volume moments of the solid bounded by `mesh` about `reference` (see module docs).
pub fn volume_moments(mesh: &IndexedMesh, reference: Vector3<f64>) -> VolumeMoments {
    let s = sums::<SECOND>(mesh, reference);
    let [xx, xy, xz, yy, yz, zz] = s.second;
    VolumeMoments {
        volume: s.volume,
        first: Vector3::from(s.first),
        second: Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz),
    }
}

/// Signed enclosed volume (positive for an outward-oriented closed surface): the volume of
/// [`volume_moments`] about the bounding-box centre, to the last digit.
pub fn signed_volume(mesh: &IndexedMesh) -> f64 {
    sums::<VOLUME>(mesh, bounding_box_centre(mesh)).volume
}

/// [`signed_volume`] (to the last digit) and, in the same pass over the triangles (one fetch of
/// their corners for both), the triangles for which `flag(vertex indices, corners)` holds, in
/// increasing order.
pub fn signed_volume_and_flagged(
    mesh: &IndexedMesh,
    flag: impl Fn(&[u32; 3], &[Vector3<f64>; 3]) -> bool + Sync,
) -> (f64, Vec<usize>) {
    let reference = bounding_box_centre(mesh);
    let r = [reference.x, reference.y, reference.z];
    let partial: Vec<(f64, Vec<usize>)> = mesh
        .triangles
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(k, chunk)| {
            let mut volume = 0.0;
            let mut flagged = Vec::new();
            for (i, tri) in chunk.iter().enumerate() {
                let corners = [
                    mesh.vertices[tri[0] as usize],
                    mesh.vertices[tri[1] as usize],
                    mesh.vertices[tri[2] as usize],
                ];
                if flag(tri, &corners) {
                    flagged.push(k * CHUNK + i);
                }
                volume += tetrahedron_volume(&relative_corners(mesh, tri, &r));
            }
            (volume, flagged)
        })
        .collect();
    let volume = partial.iter().fold(0.0, |v, (p, _)| v + p);
    (volume, partial.into_iter().flat_map(|(_, f)| f).collect())
}

fn bounding_box_centre(mesh: &IndexedMesh) -> Vector3<f64> {
    let (lo, hi) = mesh.bounding_box();
    (lo + hi) / 2.0
}

/// Mass properties of a homogeneous solid, in the units of the mesh and density given
/// (SI when the mesh is in metres and the density in kg/m³).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    pub volume: f64,
    pub mass: f64,
    pub centroid: Vector3<f64>,
    /// Inertia tensor about the centroid, in the mesh's axes.
    pub inertia: Matrix3<f64>,
    /// Principal moments about the centroid, ascending.
    pub principal_moments: Vector3<f64>,
    /// Principal axes as the columns, in the order of `principal_moments`; a right-handed frame.
    pub principal_axes: Matrix3<f64>,
}

impl MassProperties {
    /// Integrates the solid bounded by a validated, outward-oriented `mesh`.
    pub fn of_mesh(mesh: &IndexedMesh, density: f64) -> Self {
        let near = bounding_box_centre(mesh);
        let rough = sums::<FIRST>(mesh, near);
        let volume = rough.volume;
        let centroid = near + Vector3::from(rough.first) / volume;
        // Second pass about the centroid itself: no parallel-axis subtraction needed.
        let about_centroid = volume_moments(mesh, centroid);
        let s = about_centroid.second;
        let inertia = (Matrix3::identity() * s.trace() - s) * density;
        let (principal_moments, principal_axes) = principal(&inertia);
        MassProperties {
            volume,
            mass: volume * density,
            centroid,
            inertia,
            principal_moments,
            principal_axes,
        }
    }

    /// From integrals computed elsewhere (e.g. OpenCASCADE's exact volume integrals of a STEP
    /// solid): `volume`, `centroid` and the second-moment tensor about the centroid at unit
    /// density, `inertia_unit_density` (I_ii = ∫ squared distance to axis i dV, I_ij = −∫ x_i x_j
    /// dV), all in metres.
    pub fn from_integrals(
        volume: f64,
        centroid: Vector3<f64>,
        inertia_unit_density: Matrix3<f64>,
        density: f64,
    ) -> Self {
        let inertia = inertia_unit_density * density;
        let (principal_moments, principal_axes) = principal(&inertia);
        MassProperties {
            volume,
            mass: volume * density,
            centroid,
            inertia,
            principal_moments,
            principal_axes,
        }
    }

    /// Moment of inertia about the axis through the centroid along the unit vector `axis`.
    pub fn moment_about(&self, axis: &Vector3<f64>) -> f64 {
        axis.dot(&(self.inertia * axis))
    }
}

/// Eigen-decomposition of a symmetric inertia tensor: ascending moments and a right-handed
/// frame of axes, each of the first two with its largest component positive.
fn principal(inertia: &Matrix3<f64>) -> (Vector3<f64>, Matrix3<f64>) {
    let eigen = SymmetricEigen::new(*inertia);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| eigen.eigenvalues[i].total_cmp(&eigen.eigenvalues[j]));
    let axis = |k: usize| {
        let v: Vector3<f64> = eigen.eigenvectors.column(order[k]).into();
        let largest = v.iamax();
        if v[largest] < 0.0 { -v } else { v }
    };
    let (e0, e1) = (axis(0), axis(1));
    let axes = Matrix3::from_columns(&[e0, e1, e0.cross(&e1)]);
    let moments = Vector3::new(
        eigen.eigenvalues[order[0]],
        eigen.eigenvalues[order[1]],
        eigen.eigenvalues[order[2]],
    );
    (moments, axes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitives::{
        cuboid, hollow_cylinder, polygon_prism_properties, torus, transformed, voxel_rod,
    };
    use crate::geometry::validate::validate;
    use nalgebra::Rotation3;
    use std::f64::consts::PI;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    /// A rotation with no special alignment to the axes.
    fn skew_rotation() -> Matrix3<f64> {
        *Rotation3::from_euler_angles(0.3, -1.1, 2.4).matrix()
    }

    /// The moments as the nalgebra expressions of the formulas give them (a second spelling of
    /// the plain-f64 kernel), chunked and summed in the same order.
    fn nalgebra_moments(mesh: &IndexedMesh, reference: Vector3<f64>) -> VolumeMoments {
        let zero = VolumeMoments {
            volume: 0.0,
            first: Vector3::zeros(),
            second: Matrix3::zeros(),
        };
        let add = |mut acc: VolumeMoments, other: &VolumeMoments| {
            acc.volume += other.volume;
            acc.first += other.first;
            acc.second += other.second;
            acc
        };
        let partial: Vec<VolumeMoments> = mesh
            .triangles
            .chunks(CHUNK)
            .map(|chunk| {
                chunk.iter().fold(zero, |acc, tri| {
                    let [a, b, c] = tri.map(|i| mesh.vertices[i as usize] - reference);
                    let volume = a.dot(&b.cross(&c)) / 6.0;
                    let s = a + b + c;
                    let outer = a * a.transpose() + b * b.transpose() + c * c.transpose();
                    let term = VolumeMoments {
                        volume,
                        first: s * (volume / 4.0),
                        second: (outer + s * s.transpose()) * (volume / 20.0),
                    };
                    add(acc, &term)
                })
            })
            .collect();
        partial.iter().fold(zero, add)
    }

    #[test]
    fn the_kernel_gives_the_digits_of_the_nalgebra_expressions() {
        let bits = |m: &VolumeMoments| {
            let mut b = vec![m.volume.to_bits()];
            b.extend(m.first.iter().map(|x| x.to_bits()));
            b.extend(m.second.iter().map(|x| x.to_bits()));
            b
        };
        let rod = voxel_rod().0;
        let far = transformed(&rod, &skew_rotation(), Vector3::new(1.0e4, -7.0e3, 5.0e3));
        // More than one chunk, so that the order of the partial sums counts too.
        let big_torus = torus(0.1, 0.03, 300, 100);
        assert!(big_torus.triangles.len() > 3 * CHUNK);
        for mesh in [rod, far, big_torus, hollow_cylinder(0.04, 0.025, 0.03, 64)] {
            let (lo, hi) = mesh.bounding_box();
            for reference in [
                (lo + hi) / 2.0,
                Vector3::zeros(),
                Vector3::new(0.3, -0.2, 0.1),
            ] {
                let ours = volume_moments(&mesh, reference);
                let expected = nalgebra_moments(&mesh, reference);
                assert_eq!(bits(&ours), bits(&expected));
            }
            let expected = nalgebra_moments(&mesh, (lo + hi) / 2.0).volume;
            assert_eq!(signed_volume(&mesh).to_bits(), expected.to_bits());
            let (volume, flagged) = signed_volume_and_flagged(&mesh, |_, _| false);
            assert_eq!(volume.to_bits(), expected.to_bits());
            assert!(flagged.is_empty());
            let odd = signed_volume_and_flagged(&mesh, |t, _| t[0] % 2 == 1).1;
            let expected_odd: Vec<usize> = (0..mesh.triangles.len())
                .filter(|&t| mesh.triangles[t][0] % 2 == 1)
                .collect();
            assert_eq!(odd, expected_odd);
        }
    }

    #[test]
    fn box_matches_closed_form() {
        let (a, b, c, rho) = (0.18, 0.05, 0.04, 7800.0);
        let centre = Vector3::new(0.09, 0.01, -0.02);
        let p = MassProperties::of_mesh(&cuboid(Vector3::new(a, b, c), centre), rho);
        let m = rho * a * b * c;
        assert!(rel(p.volume, a * b * c) < 1e-14);
        assert!((p.centroid - centre).norm() < 1e-16);
        let expected =
            Matrix3::from_diagonal(&Vector3::new(b * b + c * c, a * a + c * c, a * a + b * b))
                * (m / 12.0);
        assert!((p.inertia - expected).norm() < 1e-14 * expected.norm());
        // Principal moments ascending: about x (long) is the smallest.
        assert!(rel(p.principal_moments[0], expected[(0, 0)]) < 1e-13);
        assert!((p.principal_axes.column(0).abs() - Vector3::x()).norm() < 1e-12);
    }

    #[test]
    fn hollow_cylinder_is_exact_for_its_polygon_and_converges_at_second_order() {
        let (outer, inner, h) = (0.04, 0.025, 0.03);
        let smooth_volume = PI * (outer * outer - inner * inner) * h;
        let mut errors = Vec::new();
        for n in [16, 32, 64, 128, 256] {
            let p = MassProperties::of_mesh(&hollow_cylinder(outer, inner, h, n), 1.0);
            let (v, izz, ixx) = polygon_prism_properties(outer, inner, h, n);
            assert!(rel(p.volume, v) < 1e-13, "n = {n}");
            assert!(rel(p.inertia[(2, 2)], izz) < 1e-13, "n = {n}");
            assert!(rel(p.inertia[(0, 0)], ixx) < 1e-13, "n = {n}");
            assert!(rel(p.inertia[(1, 1)], ixx) < 1e-13, "n = {n}");
            errors.push((n, rel(p.volume, smooth_volume)));
        }
        // Tessellation error against the smooth tube: O(1/n²), rate 2 (2π²/(3n²) leading term).
        for w in errors.windows(2) {
            let rate = (w[0].1 / w[1].1).log2();
            assert!(
                (rate - 2.0).abs() < 0.01,
                "rate {rate} between n = {} and {}",
                w[0].0,
                w[1].0
            );
        }
        let (n, e) = errors[errors.len() - 1];
        assert!(rel(e, 2.0 * PI * PI / (3.0 * (n * n) as f64)) < 1e-3);
    }

    #[test]
    fn torus_converges_to_the_smooth_torus() {
        let (big, small) = (0.1, 0.03);
        let mut last = f64::INFINITY;
        for n in [32, 64, 128, 256] {
            let p = MassProperties::of_mesh(&torus(big, small, 2 * n, n), 1.0);
            let v = 2.0 * PI * PI * big * small * small;
            let izz = v * (big * big + 0.75 * small * small);
            let ixx = v * (big * big / 2.0 + 5.0 / 8.0 * small * small);
            let e = rel(p.volume, v)
                .max(rel(p.inertia[(2, 2)], izz))
                .max(rel(p.inertia[(0, 0)], ixx));
            assert!(
                e < last / 3.5,
                "n = {n}: error {e} did not fall by ~4 from {last}"
            );
            last = e;
        }
        assert!(last < 2e-4);
    }

    /// The rod-like compound solid against the sum over its cells (an independent computation).
    #[test]
    fn voxel_rod_matches_the_sum_over_its_cells() {
        let (mesh, centres, h) = voxel_rod();
        let mesh = validate(mesh).unwrap().mesh;
        let rho = 7800.0;
        let p = MassProperties::of_mesh(&mesh, rho);
        let m_cell = rho * h * h * h;
        let mass = m_cell * centres.len() as f64;
        let g = centres.iter().sum::<Vector3<f64>>() / centres.len() as f64;
        let mut inertia = Matrix3::zeros();
        for c in &centres {
            let d = c - g;
            inertia += Matrix3::identity() * (m_cell * h * h / 6.0)
                + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * m_cell;
        }
        assert!(rel(p.mass, mass) < 1e-12);
        assert!((p.centroid - g).norm() < 1e-14);
        assert!((p.inertia - inertia).norm() < 1e-11 * inertia.norm());
        // It is rod-like: long-axis moment an order of magnitude below the pin-axis moment.
        assert!(p.inertia[(2, 2)] > 8.0 * p.inertia[(0, 0)]);
    }

    /// Moved 10 km away and turned: the integration relative to a nearby point keeps the digits
    /// (the naive sum about the origin would not: shown for contrast).
    #[test]
    fn far_away_and_rotated_meshes_lose_no_digits() {
        let (mesh, _, _) = voxel_rod();
        let base = MassProperties::of_mesh(&mesh, 7800.0);
        let rotation = skew_rotation();
        let shift = Vector3::new(1.0e4, -7.0e3, 5.0e3);
        let moved = MassProperties::of_mesh(&transformed(&mesh, &rotation, shift), 7800.0);
        assert!(rel(moved.mass, base.mass) < 1e-10);
        assert!((moved.centroid - (rotation * base.centroid + shift)).norm() < 1e-9);
        let expected = rotation * base.inertia * rotation.transpose();
        assert!((moved.inertia - expected).norm() < 1e-8 * expected.norm());
        assert!(
            (moved.principal_moments - base.principal_moments).norm()
                < 1e-8 * base.principal_moments.norm()
        );

        let naive = volume_moments(&transformed(&mesh, &rotation, shift), Vector3::zeros());
        let naive_second_about_g = naive.second / naive.volume
            - (naive.first / naive.volume) * (naive.first / naive.volume).transpose();
        let s = base.inertia.trace() / 2.0 * Matrix3::identity() - base.inertia;
        let naive_error = (naive_second_about_g * base.mass - s).norm() / s.norm();
        assert!(
            naive_error > 1e-3,
            "the naive origin-based sum should have lost digits ({naive_error})"
        );
    }

    #[test]
    fn parry3d_agrees_on_the_test_solids() {
        use parry3d_f64::mass_properties::MassProperties as Parry;
        use parry3d_f64::math::Vector as PVec;
        let rod = validate(voxel_rod().0).unwrap().mesh;
        for mesh in [
            rod,
            torus(0.1, 0.03, 96, 48),
            hollow_cylinder(0.04, 0.025, 0.03, 64),
        ] {
            let ours = MassProperties::of_mesh(&mesh, 7800.0);
            let vertices: Vec<PVec> = mesh
                .vertices
                .iter()
                .map(|v| PVec::new(v.x, v.y, v.z))
                .collect();
            let theirs = Parry::from_trimesh(7800.0, &vertices, &mesh.triangles);
            assert!(rel(ours.mass, theirs.mass()) < 1e-9);
            let c = theirs.local_com;
            assert!((ours.centroid - Vector3::new(c.x, c.y, c.z)).norm() < 1e-9);
            let i = theirs.reconstruct_inertia_matrix();
            for r in 0..3 {
                for k in 0..3 {
                    let theirs_rk = i.col(k)[r];
                    assert!((ours.inertia[(r, k)] - theirs_rk).abs() < 1e-8 * ours.inertia.norm());
                }
            }
        }
    }
}
