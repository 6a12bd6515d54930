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
