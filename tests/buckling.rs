//! Verification of linear buckling: the smallest positive λ of
//! (K + λ K_σ) φ = 0 ([`rodstudy::fem::buckling`]).
//!
//! 1. A slender prismatic column, fixed at one end and loaded in compression at the other,
//!    against Euler's fixed–free load π²EI/(4L²) (S. P. Timoshenko, J. M. Gere, *Theory of Elastic
//!    Stability*, 2nd ed., §2.1), within 1 %.
//! 2. The same column in tension: refused, with its message.
//! 3. Design 1 at 8 mm against CalculiX `*BUCKLE` on the identical mesh, supports and nodal loads
//!    (`pipeline/ccx_peer.py --buckle`), within 1 % (needs Python with gmsh and `ccx`).
//! 4. Stage 3's buckling run beside its geometry check (`stages::fem::fem_and_buckling`) is the
//!    analysis run after it on the same mesh and factorisation, to the bit (needs gmsh).

use std::path::{Path, PathBuf};

use rodstudy::fem::boundary::boundary_faces;
use rodstudy::fem::buckling::{BucklingOptions, BucklingProblem, solve_buckling};
use rodstudy::fem::load::uniform_traction_with_resultant;
use rodstudy::fem::mesh::structured::box_tet10;
use rodstudy::fem::*;
use rodstudy::mesher::{mesh_stl, write_rodmesh};
use rodstudy::rod::buckling::rod_buckling;
use rodstudy::rod::*;

/// Column [0, L] × [0, b] × [0, b], fixed (all DOFs) on x = 0, a uniform traction of resultant
/// `force` (N, along x) on the face x = L.
fn column(l: f64, b: f64, nx: usize, nb: usize, force: f64) -> (TetMesh, Vec<usize>, Vec<f64>) {
    let mesh = box_tet10(l, b, b, nx, nb, nb).unwrap();
    let fixed: Vec<usize> = mesh
        .nodes()
        .iter()
        .enumerate()
        .filter(|(_, p)| p[0].abs() < 1e-12)
        .flat_map(|(i, _)| (0..3).map(move |j| 3 * i + j))
        .collect();
    let end: Vec<[usize; 6]> = boundary_faces(&mesh)
        .unwrap()
        .into_iter()
        .filter(|f| {
            f.nodes
                .iter()
                .all(|&n| (mesh.nodes()[n][0] - l).abs() < 1e-12)
        })
        .map(|f| f.nodes)
        .collect();
    let load = uniform_traction_with_resultant(&mesh, &end, [force, 0.0, 0.0])
        .unwrap()
        .forces;
    (mesh, fixed, load)
}

#[test]
fn slender_column_against_euler_fixed_free() {
    // reference: Euler, fixed–free column, P_cr = π² E I / (4 L²) (Timoshenko & Gere §2.1)
    let (l, b) = (0.5, 0.02); // L/b = 25
    let p = 1000.0; // N, compression
    let (mesh, fixed_dofs, load) = column(l, b, 100, 4, -p);
    let material = Material::STEEL;
    let problem = BucklingProblem {
        mesh: &mesh,
        material,
        fixed_dofs,
        load,
        quadrature: QuadratureChoice::Auto,
    };
    let sol = solve_buckling(&problem, &BucklingOptions::default()).unwrap();
    let i = b.powi(4) / 12.0;
    let euler = std::f64::consts::PI.powi(2) * material.youngs_modulus_pa * i / (4.0 * l * l);
    let fe = sol.load_factor * p;
    let rel = (fe - euler) / euler;
    eprintln!(
        "column L/b = {}: FE {fe:.2} N, Euler {euler:.2} N, {:+.3} %; {} iterations, residual {:.1e}, \
         Ritz λ {:?}; {} equations, static {:.2} s, K_σ {:.2} s, iteration {:.2} s",
        l / b,
        100.0 * rel,
        sol.iterations,
        sol.residual_rel,
        sol.ritz_load_factors,
        sol.equations,
        sol.static_s,
        sol.geometric_s,
        sol.iteration_s
    );
    assert!(rel.abs() < 0.01, "FE {fe} N against Euler {euler} N");
    assert!(sol.residual_rel < 1e-3, "residual {}", sol.residual_rel);
    // the square section: the two bending modes share the load (the second Ritz value; the
    // six-tetrahedra split of the hexahedra is not quite symmetric)
    let second = sol.ritz_load_factors[1] * p;
    assert!((second - fe).abs() < 1e-3 * fe, "{second} against {fe}");
    // the mode is a sway: the free end moves sideways, not along the axis
    let tip = mesh
        .nodes()
        .iter()
        .position(|q| (q[0] - l).abs() < 1e-12)
        .unwrap();
    let lateral = sol.mode[3 * tip + 1].hypot(sol.mode[3 * tip + 2]);
    assert!(lateral > 0.9, "tip lateral {lateral}");
}

#[test]
fn tensile_load_is_refused() {
    // reference: a tensile pre-stress makes K_σ positive semi-definite, so K + λ K_σ stays
    // positive definite for every λ > 0: no buckling (Bathe §6.8.2)
    let (mesh, fixed_dofs, load) = column(0.5, 0.02, 20, 2, 1000.0);
    let problem = BucklingProblem {
        mesh: &mesh,
        material: Material::STEEL,
        fixed_dofs,
        load,
        quadrature: QuadratureChoice::Auto,
    };
    let err = solve_buckling(&problem, &BucklingOptions::default())
        .unwrap_err()
        .to_string();
    eprintln!("{err}");
    assert!(
        err.contains("no positive buckling load factor") && err.contains("tensile"),
        "{err}"
    );
}

/// needs Python (gmsh) and CalculiX `ccx`: design 1 meshed at 8 mm (rod frame: A at the origin, B
/// at x = 180 mm, pins along z), F_x = 7500 N on bore A towards the fixed bore B.
#[test]
fn design1_against_calculix_buckle() {
    // reference: CalculiX 2.x `*BUCKLE` (C3D10, Lanczos) on the identical mesh, supports and
    // consistent nodal forces (pipeline/ccx_peer.py --buckle)
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let py: PathBuf = rodstudy::python_env::python().expect("the pipeline's Python environment");
    let dir = tempfile::tempdir().unwrap();
    let meshed = mesh_stl(
        &py,
        &root.join("pipeline/mesh_rod.py"),
        &root.join("designs/design1.stl"),
        8.0,
        dir.path(),
    )
    .unwrap();
    let force = 7500.0;
    let ours = rod_buckling(
        &meshed.mesh,
        &Material::STEEL,
        &BoreSpec::default(),
        force,
        QuadratureChoice::Auto,
        &BucklingOptions::default(),
        None,
    )
    .unwrap();
    let file = dir.path().join("design1_8mm.rodmesh");
    write_rodmesh(&meshed.mesh, &file).unwrap();
    // under the pipeline's time limit (ccx_peer.py stops ccx a little before it)
    let out = rodstudy::python_env::output_within(
        std::process::Command::new(&py)
            .arg(root.join("pipeline/ccx_peer.py"))
            .arg(&file)
            .args(["--buckle", "--json", "--force", "7500"]),
        rodstudy::python_env::pipeline_timeout(),
    )
    .unwrap();
    assert!(
        out.status.success(),
        "ccx_peer.py --buckle: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let peer: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let ccx = peer["buckling_factor"].as_f64().unwrap();
    let rel = (ours.load_factor - ccx) / ccx;
    eprintln!(
        "design 1 at 8 mm ({} elements, {} equations): ours λ₁ = {:.5} ({} iterations, residual {:.1e}, \
         static {:.2} s, K_σ {:.2} s, iteration {:.2} s; Ritz {:?}), ccx {ccx:.5} ({:.2} s): {:+.3} %",
        meshed.mesh.n_elements(),
        ours.equations,
        ours.load_factor,
        ours.iterations,
        ours.residual_rel,
        ours.static_s,
        ours.geometric_s,
        ours.iteration_s,
        ours.ritz_load_factors,
        peer["ccx_wall_s"].as_f64().unwrap(),
        100.0 * rel
    );
    assert!(ours.load_factor > 1.0, "a rod does not buckle under 7.5 kN");
    assert!(
        rel.abs() < 0.01,
        "ours {} against ccx {ccx}",
        ours.load_factor
    );
}

#[test]
fn the_buckling_beside_the_geometry_check_is_the_one_after_it() {
    use rodstudy::config::StudyConfig;
    use rodstudy::stages;
    use rodstudy::stages::fem::MeshMode;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    let design = stages::mass::load(&root.join("designs/design1.stl")).unwrap();
    let config = StudyConfig::default();
    let load = 7000.0;
    let out = stages::fem::fem_and_buckling(
        &design,
        &stages::fem::FemLoads::of_design(&design, &config)
            .unwrap()
            .with_force(load),
        &config,
        dir.path(),
        &MeshMode::Fixed(8.0),
        true,
        Some(load),
    )
    .unwrap();
    // the STL's geometry check ran, and the buckling beside it
    assert!(out.record.fem.geometry_check.is_some());
    let run = out.buckling_run.as_ref().expect("asked for");
    assert_eq!(run.compression_n, load);
    let beside = run.result.as_ref().unwrap();
    let after =
        stages::fem::buckling(&out.mesh, &config, load, out.solution.system.as_deref()).unwrap();
    assert_eq!(beside.load_factor.to_bits(), after.load_factor.to_bits());
    assert!(beside.load_factor > 1.0, "{}", beside.load_factor);
    assert_eq!(beside.mode, after.mode);
    // without a load asked for, none is run
    let none = stages::fem::fem_and_buckling(
        &design,
        &stages::fem::FemLoads::of_design(&design, &config)
            .unwrap()
            .with_force(load),
        &config,
        &dir.path().join("again"),
        &MeshMode::Fixed(8.0),
        false,
        None,
    )
    .unwrap();
    assert!(none.buckling_run.is_none() && none.solution.system.is_none());
}
