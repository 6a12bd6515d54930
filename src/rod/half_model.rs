//! The half model of a mirror-symmetric rod (`[fem] symmetry`): the half z ≥ c meshed and
//! solved with half the pin loads and u_z = 0 on the plane z = c, then mirrored into the whole
//! ([`crate::fem::mesh::mirror`]), on which the stresses, estimates and peaks are formed as for any
//! mesh. One tolerance decides which nodes lie on the plane: [`MIRROR_PLANE_TOLERANCE_REL`] of the
//! mesh's extent ([`mirror_plane_tolerance`]).

use super::bores::BoreSpec;
use super::records::HalfModel;
use super::solve::{
    RodOptions, RodSolution, RodStatic, bores_and_direction, rod_fields, solve_rod_fields,
    static_cases,
};
use crate::fem::error::Result;
use crate::fem::load::SurfaceLoad;
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;
use crate::fem::statics::StaticSolution;

/// [`solve_rod_fields`] on `mesh`, or, when `options` names a symmetry plane
/// ([`RodOptions::mirror_plane_z_m`]), on the half model `mesh` is: solved with half the pin loads
/// and u_z = 0 on the plane, then mirrored into the whole ([`crate::fem::mesh::mirror`]), on which the
/// stresses, estimates and peaks are formed as for any mesh. Returns the mesh the solution is on
/// (the whole, for a half model).
pub fn solve_rod_on(
    mesh: TetMesh,
    material: &Material,
    bores: &BoreSpec,
    force_n: f64,
    options: &RodOptions,
) -> Result<(TetMesh, RodSolution)> {
    let Some(c) = options.mirror_plane_z_m else {
        let solution = solve_rod_fields(&mesh, material, bores, force_n, options)?;
        return Ok((mesh, solution));
    };
    let m = crate::fem::mesh::mirror::mirror(&mesh, c, mirror_plane_tolerance(&mesh))?;
    let held: Vec<usize> = m.plane_nodes.iter().map(|&n| 3 * n + 2).collect();
    let half = static_cases(&mesh, material, bores, force_n, options, 0.5, &held)?;
    let whole = mirrored_static(&m, half, bores)?;
    let mut solution = rod_fields(whole, options)?;
    solution.result.half_model = Some(HalfModel {
        plane_z_mm: c * 1e3,
        nodes: mesh.n_nodes(),
        elements: mesh.n_elements(),
        plane_nodes: m.plane_nodes.len(),
    });
    solution.mirror_source = Some(m.source);
    Ok((m.whole, solution))
}

/// Nodes of a half model within this fraction of its extent from the symmetry plane, on a face
/// there, are the plane's.
pub const MIRROR_PLANE_TOLERANCE_REL: f64 = 1e-7;

/// How far from the symmetry plane a node of the half model `mesh` may lie and still be on it:
/// [`MIRROR_PLANE_TOLERANCE_REL`] times the mesh's largest extent (m).
pub fn mirror_plane_tolerance(mesh: &TetMesh) -> f64 {
    let (lo, hi) = mesh.bounding_box();
    let extent = (0..3).map(|j| hi[j] - lo[j]).fold(0.0, f64::max);
    MIRROR_PLANE_TOLERANCE_REL * extent
}

/// The static solution of a half model (`half`, on the half of `m`) as the whole's: the
/// displacements mirrored, the loads and reactions of both halves, the bores found on the whole.
fn mirrored_static<'a>(
    m: &'a crate::fem::mesh::mirror::MirroredMesh,
    half: RodStatic<'_>,
    bores: &BoreSpec,
) -> Result<RodStatic<'a>> {
    let (loaded, fixed, _, _) = bores_and_direction(&m.whole, bores)?;
    let loads = half
        .loads
        .iter()
        .map(|l| {
            let forces = m.mirror_forces(&l.forces);
            let mut resultant_n = [0.0; 3];
            for (d, f) in forces.iter().enumerate() {
                resultant_n[d % 3] += f;
            }
            SurfaceLoad {
                forces,
                area_m2: 2.0 * l.area_m2,
                traction_pa: l.traction_pa,
                resultant_n,
                resultant_error_rel: l.resultant_error_rel,
            }
        })
        .collect();
    let sol = StaticSolution {
        displacements: half
            .sol
            .displacements
            .iter()
            .map(|u| m.mirror_vector(u))
            .collect(),
        reactions: half
            .sol
            .reactions
            .iter()
            .map(|r| m.mirror_forces(r))
            .collect(),
        ..half.sol
    };
    Ok(RodStatic {
        mesh: &m.whole,
        material: half.material,
        bores: half.bores,
        t_all: half.t_all,
        loaded,
        fixed,
        cases: half.cases,
        loads,
        sol,
        system: None,
        contact: half.contact.into_iter().map(|c| c.mirrored(m)).collect(),
    })
}
