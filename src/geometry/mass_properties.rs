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

impl VolumeMoments {
    const ZERO: Self = VolumeMoments {
        volume: 0.0,
        first: Vector3::new(0.0, 0.0, 0.0),
        second: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    };

    fn add(mut self, other: &Self) -> Self {
        self.volume += other.volume;
        self.first += other.first;
        self.second += other.second;
        self
    }
}

/// Triangles per parallel work item; partial sums are added in a fixed order, so the result
/// does not depend on thread scheduling.
const CHUNK: usize = 8192;

/// The volume moments of the solid bounded by `mesh` about `reference` (see module docs).
pub fn volume_moments(mesh: &IndexedMesh, reference: Vector3<f64>) -> VolumeMoments {
    let partial: Vec<VolumeMoments> = mesh
        .triangles
        .par_chunks(CHUNK)
        .map(|chunk| {
            chunk.iter().fold(VolumeMoments::ZERO, |acc, tri| {
                let [a, b, c] = tri.map(|i| mesh.vertices[i as usize] - reference);
                let volume = a.dot(&b.cross(&c)) / 6.0;
                let s = a + b + c;
                let outer = a * a.transpose() + b * b.transpose() + c * c.transpose();
                acc.add(&VolumeMoments {
                    volume,
                    first: s * (volume / 4.0),
                    second: (outer + s * s.transpose()) * (volume / 20.0),
                })
            })
        })
        .collect();
    partial.iter().fold(VolumeMoments::ZERO, VolumeMoments::add)
}

/// Signed enclosed volume (positive for an outward-oriented closed surface).
pub fn signed_volume(mesh: &IndexedMesh) -> f64 {
    volume_moments(mesh, bounding_box_centre(mesh)).volume
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
        let rough = volume_moments(mesh, near);
        let centroid = near + rough.first / rough.volume;
        // Second pass about the centroid itself: no parallel-axis subtraction needed.
        let about_centroid = volume_moments(mesh, centroid);
        let s = about_centroid.second;
        let inertia = (Matrix3::identity() * s.trace() - s) * density;
        let (principal_moments, principal_axes) = principal(&inertia);
        MassProperties {
            volume: rough.volume,
            mass: rough.volume * density,
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
