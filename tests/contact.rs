//! Frictionless contact of a tet10 body on rigid pins (`rodstudy::fem::contact`), each test
//! against an independent reference: Lamé's thick cylinder (a pressed pin), the Fourier
//! (Michell) series solution of a rigid pin with clearance in a large plate (a second method),
//! and the equilibrium of a body held by two pins.

use rodstudy::fem::boundary::boundary_faces;
use rodstudy::fem::contact::{
    ContactProblem, ContactSolution, ContactTolerances, Cylinder, PinMotion, check,
    diameter_change, solve_contact,
};
use rodstudy::fem::mesh::ring::{Ring, ring_tet10};
use rodstudy::fem::stress::stress_field;
use rodstudy::fem::{Material, QuadratureChoice, TetMesh};

const E: f64 = 210e9;
const NU: f64 = 0.3;

/// The boundary faces whose six nodes lie at distance `r` from the z axis through (cx, 0).
fn wall_faces(mesh: &TetMesh, cx: f64, r: f64) -> Vec<[usize; 6]> {
    boundary_faces(mesh)
        .unwrap()
        .into_iter()
        .map(|f| f.nodes)
        .filter(|f| {
            f.iter().all(|&n| {
                let p = mesh.nodes()[n];
                ((p[0] - cx).hypot(p[1]) - r).abs() < 1e-9 * r
            })
        })
        .collect()
}

fn pin(faces: Vec<[usize; 6]>, radius: f64, motion: PinMotion) -> Cylinder {
    Cylinder {
        axis_point_m: [0.0; 3],
        axis: [0.0, 0.0, 1.0],
        radius_m: radius,
        faces,
        nominal_bore_radius_m: None,
        motion,
    }
}

fn problem(mesh: &TetMesh, cylinders: Vec<Cylinder>) -> ContactProblem<'_> {
    ContactProblem {
        mesh,
        material: Material {
            youngs_modulus_pa: E,
            poisson_ratio: NU,
        },
        quadrature: QuadratureChoice::Auto,
        prescribed: Vec::new(),
        loads: Vec::new(),
        cylinders,
        tolerances: ContactTolerances::default(),
    }
}

/// The check recomputed from the solution's fields passes and agrees with the solver's.
fn recheck(p: &ContactProblem, s: &ContactSolution) {
    let pressures: Vec<Vec<f64>> = s.cylinders.iter().map(|c| c.pressure_pa.clone()).collect();
    let pins: Vec<[f64; 3]> = s.cylinders.iter().map(|c| c.pin_displacement_m).collect();
    let (c, r) = check(p, &s.displacements, &pressures, &pins, &s.restraint.dofs).unwrap();
    c.verify(&p.tolerances).unwrap();
    assert_eq!(r, s.restraint);
    for cyl in &s.cylinders {
        assert!(cyl.max_tensile_pressure_pa <= 0.0);
    }
}

#[test]
fn a_pressed_pin_in_a_thick_ring_gives_lames_pressure_and_hoop_stress() {
    // a free disc a = 10 mm, b = 20 mm, 2 mm thick, on a rigid pin 10 µm oversize. The plane
    // stress Lamé field (constant ε_z) is the exact 3D solution of a disc with free faces.
    let (a, b, delta) = (0.010, 0.020, 10e-6);
    let mesh = ring_tet10(&Ring {
        inner_radius: a,
        outer_radius: b,
        thickness: 0.0005,
        n_theta: 128,
        n_radial: 12,
        n_z: 1,
        grading: 6.0,
    })
    .unwrap();
    let faces = wall_faces(&mesh, 0.0, a);
    let p = problem(&mesh, vec![pin(faces, a + delta, PinMotion::Fixed)]);
    let s = solve_contact(&p).unwrap();
    recheck(&p, &s);
    // Lamé (Timoshenko & Goodier, Theory of Elasticity, §28), plane stress λ* = 2λμ/(λ + 2μ):
    // u = A r + B/r, σ_r(b) = 0 → B = (λ* + μ) A b²/μ, u(a) = δ;
    // p = 2(λ* + μ) A (b²/a² − 1), σ_θ(a) = 2(λ* + μ) A (1 + b²/a²)
    let mu = E / (2.0 * (1.0 + NU));
    let lam = E * NU / ((1.0 + NU) * (1.0 - 2.0 * NU));
    let ls = 2.0 * lam * mu / (lam + 2.0 * mu);
    let big_a = delta / (a + (ls + mu) * b * b / (mu * a));
    let p_ref = 2.0 * (ls + mu) * big_a * (b * b / (a * a) - 1.0);
    let hoop_ref = 2.0 * (ls + mu) * big_a * (1.0 + b * b / (a * a));
    let c = &s.cylinders[0];
    assert_eq!(c.arc_deg, 360.0);
    let p_err = c
        .smoothed_pressure_pa
        .iter()
        .map(|v| (v / p_ref - 1.0).abs())
        .fold(0.0, f64::max);
    let stress = stress_field(&mesh, &p.material, &s.displacements).unwrap();
    let hoop_err = c
        .nodes
        .iter()
        .map(|&n| {
            let x = mesh.nodes()[n];
            let t = x[1].atan2(x[0]);
            let (sn, cs) = t.sin_cos();
            let sg = stress.averaged[n];
            let hoop = sg[0] * sn * sn + sg[1] * cs * cs - 2.0 * sg[3] * sn * cs;
            (hoop / hoop_ref - 1.0).abs()
        })
        .fold(0.0, f64::max);
    let (pmin, pmax) = c
        .pressure_pa
        .iter()
        .fold((f64::MAX, 0.0f64), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
    {
        let mut corner = vec![false; mesh.n_nodes()];
        for el in mesh.elements() {
            for &n in &el[..4] {
                corner[n] = true;
            }
        }
        let (mut sc, mut nc, mut sm, mut nm) = (0.0, 0, 0.0, 0);
        let (mut cmin, mut cmax, mut mmin, mut mmax) = (9.0f64, 0.0f64, 9.0f64, 0.0f64);
        for (i, &n) in c.nodes.iter().enumerate() {
            let v = c.pressure_pa[i] / p_ref;
            let z = mesh.nodes()[n][2];
            if corner[n] {
                sc += v;
                nc += 1;
                cmin = cmin.min(v);
                cmax = cmax.max(v);
            } else {
                sm += v;
                nm += 1;
                mmin = mmin.min(v);
                mmax = mmax.max(v);
            }
            let _ = z;
        }
        eprintln!(
            "corners {:.5} [{cmin:.5},{cmax:.5}] mids {:.5} [{mmin:.5},{mmax:.5}]",
            sc / nc as f64,
            sm / nm as f64
        );
    }
    eprintln!(
        "pressure range {:.5} … {:.5} of Lamé's",
        pmin / p_ref,
        pmax / p_ref
    );
    eprintln!(
        "{:?}\nLamé: p {:.4e} Pa (ref {p_ref:.4e}, max err {p_err:.2e}), hoop max err {hoop_err:.2e}, \
         {} rows, {} iterations, restraint {:.1e}, penetration {:.2e} m, ovality {:?}",
        s.timings,
        c.peak_pressure_pa,
        s.rows,
        s.iterations,
        s.restraint.reaction_rel,
        c.penetration_max_m,
        diameter_change(&mesh, &p.cylinders[0], &s.displacements, [1.0, 0.0, 0.0]).unwrap()
    );
    assert!(p_err < 5e-3, "pressure error {p_err:.2e}");
    assert!(hoop_err < 5e-3, "hoop stress error {hoop_err:.2e}");
    // the diameter grows by 2δ all round
    let d = diameter_change(&mesh, &p.cylinders[0], &s.displacements, [1.0, 0.0, 0.0]).unwrap();
    assert!((d.along_m / (2.0 * delta) - 1.0).abs() < 1e-6, "{d:?}");
    assert!((d.across_m / (2.0 * delta) - 1.0).abs() < 1e-6, "{d:?}");
}
