//! Cost of a contact solve against the linear solve of the same mesh: the two-bore plate
//! ([`crate::fem::mesh::structured::two_eye_plate`], curved bore walls), pin A pushing along AB
//! with a 20 µm clearance, pin B (10 µm) holding the body, against the linear solve with the
//! same force as a uniform traction on bore A and bore B fixed (the thesis' load model).

use std::time::Duration;

use serde::Serialize;

use super::median_time;
use crate::fem::boundary::boundary_faces;
use crate::fem::contact::{
    ContactProblem, ContactTimings, ContactTolerances, Cylinder, PinMotion, solve_contact,
};
use crate::fem::error::Result;
use crate::fem::load::uniform_traction_with_resultant;
use crate::fem::mesh::structured::{TwoEyePlate, two_eye_plate};
use crate::fem::{Material, QuadratureChoice, StaticProblem, solve_static};

/// The timings of [`bench_contact`].
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ContactBench {
    /// Divisions per bore quarter of the plate.
    pub n_side: usize,
    /// Equations of the mesh.
    pub dofs: usize,
    /// Median wall time of the linear solve.
    pub linear: Duration,
    /// Median wall time of the contact solve.
    pub contact: Duration,
    /// contact / linear.
    pub ratio: f64,
    /// Contact rows (pressure nodes).
    pub rows: usize,
    /// Columns of the contact compliance computed.
    pub columns: usize,
    /// Active-set iterations.
    pub iterations: usize,
    /// The phases of the last contact solve.
    #[serde(skip)]
    pub phases: ContactTimings,
}

/// Times both solves `repeats` times on the plate with `n_side` divisions per bore quarter.
pub fn bench_contact(n_side: usize, repeats: usize) -> Result<ContactBench> {
    let plate = TwoEyePlate {
        curved: true,
        n_side,
        n_radial: n_side / 2 + 1,
        n_shank: n_side,
        n_z: n_side / 2 + 1,
        ..TwoEyePlate::default()
    };
    let mesh = two_eye_plate(&plate)?;
    let faces = boundary_faces(&mesh)?;
    let wall = |cx: f64, r: f64| -> Vec<[usize; 6]> {
        faces
            .iter()
            .map(|f| f.nodes)
            .filter(|f| {
                f.iter().all(|&n| {
                    let p = mesh.nodes()[n];
                    ((p[0] - cx).hypot(p[1]) - r).abs() < 1e-9 * r
                })
            })
            .collect()
    };
    let (fa, fb) = (
        wall(0.0, plate.bore_a_radius),
        wall(plate.length, plate.bore_b_radius),
    );
    let force = [20e3, 0.0, 0.0];
    let material = Material::STEEL;
    let mut fixed: Vec<usize> = fb.iter().flatten().copied().collect();
    fixed.sort_unstable();
    fixed.dedup();
    let linear = StaticProblem {
        mesh: &mesh,
        material,
        prescribed: fixed
            .iter()
            .flat_map(|&n| (0..3).map(move |j| (3 * n + j, 0.0)))
            .collect(),
        loads: vec![uniform_traction_with_resultant(&mesh, &fa, force)?.forces],
        quadrature: QuadratureChoice::Auto,
    };
    let contact = ContactProblem {
        mesh: &mesh,
        material,
        quadrature: QuadratureChoice::Auto,
        prescribed: Vec::new(),
        loads: Vec::new(),
        cylinders: vec![
            Cylinder {
                axis_point_m: [0.0; 3],
                axis: [0.0, 0.0, 1.0],
                radius_m: plate.bore_a_radius - 20e-6,
                faces: fa,
                nominal_bore_radius_m: None,
                motion: PinMotion::Force(force),
                elastic: None,
            },
            Cylinder {
                axis_point_m: [plate.length, 0.0, 0.0],
                axis: [0.0, 0.0, 1.0],
                radius_m: plate.bore_b_radius - 10e-6,
                faces: fb,
                nominal_bore_radius_m: None,
                motion: PinMotion::Fixed,
                elastic: None,
            },
        ],
        tolerances: ContactTolerances::default(),
    };
    let (t_lin, lin) = median_time(repeats, || solve_static(&linear));
    let dofs = lin?.stats.equations;
    let (t_con, con) = median_time(repeats, || solve_contact(&contact));
    let con = con?;
    Ok(ContactBench {
        n_side,
        dofs,
        linear: t_lin,
        contact: t_con,
        ratio: t_con.as_secs_f64() / t_lin.as_secs_f64(),
        rows: con.rows,
        columns: con.columns,
        iterations: con.iterations,
        phases: con.timings,
    })
}

/// The rod solves of [`bench_contact_rod`].
#[derive(Clone, Copy, Debug, Serialize)]
pub struct RodContactBench {
    /// Nodes of the mesh.
    pub nodes: usize,
    /// Median wall time of the static cases (bores, loads, assembly, factorisation, two solves).
    pub linear: Duration,
    /// Median wall time of the contact solve of the F_x case (bores, contact, stress field).
    pub contact: Duration,
    /// contact / linear.
    pub ratio: f64,
    /// Contact rows and columns computed.
    pub rows: usize,
    pub columns: usize,
    /// The phases of the last contact solve.
    #[serde(skip)]
    pub phases: ContactTimings,
}

/// A design's rod on a mesh in the rod frame, millimetres (as the mesher writes it,
/// `mesh/fixed/rod.msh`): the static cases ([`crate::rod::solve::solve_rod_static`]) against
/// [`crate::rod::contact_load::solve_rod_contact`] with `force_n` along AB, 10 µm clearances.
pub fn bench_contact_rod(
    design_file: &std::path::Path,
    mesh_file: &std::path::Path,
    force_n: f64,
    repeats: usize,
) -> anyhow::Result<RodContactBench> {
    use crate::rod::contact_load::{PinContact, solve_rod_contact};
    use crate::rod::solve::{RodOptions, solve_rod_static};
    let design = crate::stages::mass::load(design_file)?;
    let bores = crate::stages::rod_surface::rod_frame_surface(&design, false).bores();
    let mesh = crate::mesher::read_volume_mesh_native(mesh_file, "mm")?;
    let config = crate::config::StudyConfig::load(None)?;
    let material = Material::from(&config.fem);
    let options = RodOptions::default();
    let (t_lin, lin) = median_time(repeats, || {
        solve_rod_static(&mesh, &material, &bores, force_n, &options).map(|_| ())
    });
    lin?;
    let pins = PinContact {
        force_n: [force_n, 0.0, 0.0],
        clearance_a_m: 10e-6,
        clearance_b_m: 10e-6,
        tolerances: ContactTolerances::default(),
        elastic: None,
    };
    let (t_con, con) = median_time(repeats, || {
        solve_rod_contact(&mesh, &material, &bores, &pins, &options)
    });
    let con = con?;
    Ok(RodContactBench {
        nodes: mesh.n_nodes(),
        linear: t_lin,
        contact: t_con,
        ratio: t_con.as_secs_f64() / t_lin.as_secs_f64(),
        rows: con.solution.rows,
        columns: con.solution.columns,
        phases: con.solution.timings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bench_runs_on_a_small_plate() {
        let b = bench_contact(4, 1).unwrap();
        assert!(b.columns <= b.rows && b.ratio > 0.0, "{b:?}");
    }
}
