//! Frictionless contact of a tet10 body on rigid pins (`rodstudy::fem::contact`), each test
//! against an independent reference: Lamé's thick cylinder (a pressed pin), the Fourier
//! (Michell) series solution of a rigid pin with clearance in a large plate (a second method),
//! the equilibrium of a body held by two pins, a fresh solve for a factorised system reused, and
//! elastic pins against the rigid pin they tend to as their modulus grows.

use rodstudy::fem::boundary::boundary_faces;
use rodstudy::fem::contact::{
    ContactProblem, ContactSolution, ContactSystem, ContactTolerances, Cylinder, PinElasticity,
    PinHold, PinMotion, check, diameter_change, solve_contact,
};
use rodstudy::fem::mesh::ring::{Ring, ring_tet10};
use rodstudy::fem::mesh::structured::{TwoEyePlate, two_eye_plate};
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

fn norm3(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn pin(faces: Vec<[usize; 6]>, radius: f64, motion: PinMotion) -> Cylinder {
    Cylinder {
        axis_point_m: [0.0; 3],
        axis: [0.0, 0.0, 1.0],
        radius_m: radius,
        faces,
        nominal_bore_radius_m: None,
        motion,
        elastic: None,
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
    let deflections: Vec<Vec<f64>> = s
        .cylinders
        .iter()
        .map(|c| c.pin_deflection_m.clone())
        .collect();
    let (c, r, _) = check(
        p,
        &s.displacements,
        &pressures,
        &pins,
        &deflections,
        &s.restraint.dofs,
    )
    .unwrap();
    c.verify(&p.tolerances).unwrap();
    assert_eq!(r.dofs, s.restraint.dofs);
    assert_eq!(r.force_n, s.restraint.force_n);
    assert_eq!(r.moment_nm, s.restraint.moment_nm);
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

/// The rigid pin with clearance in an infinite plate (plane strain), by a Fourier series method
/// independent of the finite elements: for contact over |θ| < α, returns (Δμ/P, p(0) a/P) —
/// the clearance Δ for which the contact reaches α under the load P per unit thickness, and the
/// peak pressure.
///
/// The radial displacement of the hole r = a under a normal pressure p(θ) = p₀ + Σ p_n cos nθ
/// (Michell's solution; J. R. Barber, *Elasticity*, ch. 9, derived for this test): u_r = p₀ a/(2μ)
/// for n = 0 (here with the outer edge r = b held, u_r = a²(1/a − a/b²) p₀ / (2(λ+μ) a²/b² + 2μ)),
/// u_r = p_n a/(4μ) (κ/(n − 1) + 1/(n + 1)) cos nθ for n ≥ 2 (κ = 3 − 4ν); n = 1 is a rigid
/// translation, absorbed with the pin's own. The pressure is piecewise linear on N intervals of
/// [0, α] and vanishes at α; the gap Δ + u_r(θ) − w cos θ vanishes at the N + 1 nodes and
/// π a p₁ = P: N + 2 linear equations for the N nodal pressures, the pin's translation w and Δ
/// (the approach of A. Noble, M. A. Hussain, *Exact solution of certain dual series for
/// indentation and inclusion problems*, IJES 7 (1969), and of M. Ciavarella, P. Decuzzi,
/// IJSS 38 (2001) 4525–4533, part II, for a pin of another material).
fn pin_in_plate(alpha: f64, nu: f64, b_over_a: f64, n: usize, n_max: usize) -> (f64, f64) {
    let kappa = 3.0 - 4.0 * nu;
    let lam = 2.0 * nu / (1.0 - 2.0 * nu); // μ = 1, a = 1
    let b2 = b_over_a * b_over_a;
    let u0 = (1.0 - 1.0 / b2) / (2.0 * (lam + 1.0) / b2 + 2.0);
    let h = alpha / n as f64;
    let theta: Vec<f64> = (0..=n).map(|i| i as f64 * h).collect();
    let m = |i: usize| if i == 0 { 1.0 } else { 2.0 };
    let kn = |k: usize| {
        let kf = k as f64;
        2.0 * (1.0 - (kf * h).cos()) / (kf * kf * h)
    };
    let dim = n + 2;
    let mut mat = nalgebra::DMatrix::<f64>::zeros(dim, dim);
    let mut rhs = nalgebra::DVector::<f64>::zeros(dim);
    let cn: Vec<f64> = (0..=n_max)
        .map(|k| {
            if k < 2 {
                0.0
            } else {
                let kf = k as f64;
                0.25 * (kappa / (kf - 1.0) + 1.0 / (kf + 1.0)) * kn(k) / std::f64::consts::PI
            }
        })
        .collect();
    // cos(kθ_i) for every node and harmonic
    let cos: Vec<Vec<f64>> = theta
        .iter()
        .map(|t| (0..=n_max).map(|k| (k as f64 * t).cos()).collect())
        .collect();
    for (row, tk) in theta.iter().enumerate() {
        for i in 0..n {
            let series: f64 = (2..=n_max).map(|k| cn[k] * cos[i][k] * cos[row][k]).sum();
            mat[(row, i)] = u0 * m(i) * h / (2.0 * std::f64::consts::PI) + m(i) * series;
        }
        mat[(row, n)] = -tk.cos();
        mat[(row, n + 1)] = 1.0;
    }
    for i in 0..n {
        mat[(n + 1, i)] = m(i) * kn(1) * theta[i].cos();
    }
    rhs[n + 1] = 1.0;
    let x = mat.lu().solve(&rhs).expect("regular");
    (x[n + 1], x[0])
}

#[test]
fn a_pin_with_clearance_in_a_large_plate_matches_the_fourier_series_solution() {
    // plane strain (u_z = 0 everywhere), a = 10 mm, outer edge b = 25 a held, clearance 10 µm
    let (a, b, clearance, t) = (0.010, 0.25, 10e-6, 0.0005);
    let mesh = ring_tet10(&Ring {
        inner_radius: a,
        outer_radius: b,
        thickness: t,
        n_theta: 96,
        n_radial: 14,
        n_z: 1,
        grading: 60.0,
    })
    .unwrap();
    let faces = wall_faces(&mesh, 0.0, a);
    let mut prescribed = Vec::new();
    for (i, x) in mesh.nodes().iter().enumerate() {
        prescribed.push((3 * i + 2, 0.0));
        if (x[0].hypot(x[1]) - b).abs() < 1e-9 {
            prescribed.push((3 * i, 0.0));
            prescribed.push((3 * i + 1, 0.0));
        }
    }
    let mu = E / (2.0 * (1.0 + NU));
    for alpha_deg in [40.0f64, 65.0] {
        let (d_hat, p_hat) = pin_in_plate(alpha_deg.to_radians(), NU, b / a, 160, 4000);
        // the reference's own discretisation error: the same with half the intervals
        let (d_half, p_half) = pin_in_plate(alpha_deg.to_radians(), NU, b / a, 80, 4000);
        let load_per_m = clearance * mu / d_hat;
        let mut p = problem(
            &mesh,
            vec![pin(
                faces.clone(),
                a - clearance,
                PinMotion::Force([load_per_m * t, 0.0, 0.0]),
            )],
        );
        p.prescribed = prescribed.clone();
        let s = solve_contact(&p).unwrap();
        recheck(&p, &s);
        let c = &s.cylinders[0];
        let half = 0.5 * c.arc_deg;
        let peak_ref = p_hat * load_per_m / a;
        eprintln!(
            "α {alpha_deg}°: FE arc ±{half:.2}° ({:?}), peak {:.4e} (nodal {:.4e}) vs {peak_ref:.4e} \
             ({:+.2} %); reference Δμ/P {d_hat:.5} (N/2: {:+.1e}), p a/P {p_hat:.4} (N/2: {:+.1e}); \
             {} iterations, {} columns, penetration {:.2e} of the gap scale, {:?}",
            c.arc_ends_deg,
            c.peak_pressure_pa,
            c.peak_nodal_pressure_pa,
            100.0 * (c.peak_pressure_pa / peak_ref - 1.0),
            d_half / d_hat - 1.0,
            p_half / p_hat - 1.0,
            s.iterations,
            s.columns,
            s.check.penetration_rel,
            s.timings
        );
        // the edge lies between the last active node and the next: one node spacing
        let spacing = 360.0 / 192.0;
        assert!((half - alpha_deg).abs() <= spacing, "{half} vs {alpha_deg}");
        // the reference is converged to < 0.1 % in the peak (N against N/2)
        assert!((c.peak_pressure_pa / peak_ref - 1.0).abs() < 0.01);
        assert!(s.check.penetration_rel < 1e-3);
        if alpha_deg == 40.0 {
            // u_y = 0 on the plane y = 0, which the symmetry of the problem implies: a wall node
            // prescribed across its radius, so the compliance comes from one solve per column
            // instead of the factor's trailing block (compliance.rs). Checked like every solve
            // (equilibrium, complementarity), and the same solution to 3e-5 (the tetrahedra of
            // the ring are not mirror-symmetric about y = 0, so the discrete symmetry is not
            // exact)
            let mut q = p.clone();
            for (i, x) in mesh.nodes().iter().enumerate() {
                if x[1].abs() < 1e-12 {
                    q.prescribed.push((3 * i + 1, 0.0));
                }
            }
            let s2 = solve_contact(&q).unwrap();
            let scale = s.displacements.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = s
                .displacements
                .iter()
                .zip(&s2.displacements)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(diff < 1e-4 * scale, "{diff:e} of {scale:e}");
            assert!((s2.cylinders[0].arc_deg - c.arc_deg).abs() <= 2.0 * spacing);
            assert!((s2.cylinders[0].peak_pressure_pa / c.peak_pressure_pa - 1.0).abs() < 1e-3);
        }
    }
    // zero clearance: the contact arc does not depend on the load (the problem is linear and
    // homogeneous in P); the reference's arc is where its clearance vanishes (bisection)
    let (mut lo, mut hi) = (60f64.to_radians(), 89.5f64.to_radians());
    for _ in 0..14 {
        let mid = 0.5 * (lo + hi);
        if pin_in_plate(mid, NU, b / a, 160, 4000).0 > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let alpha0 = 0.5 * (lo + hi);
    let p_hat0 = pin_in_plate(alpha0, NU, b / a, 160, 4000).1;
    let load_per_m = 1e5;
    let mut p = problem(
        &mesh,
        vec![pin(
            faces.clone(),
            a,
            PinMotion::Force([0.0, -load_per_m * t, 0.0]),
        )],
    );
    p.prescribed = prescribed;
    let s = solve_contact(&p).unwrap();
    recheck(&p, &s);
    let c = &s.cylinders[0];
    let peak_ref = p_hat0 * load_per_m / a;
    // the cosine distribution over ±90° of the same resultant: p₀ = 2P/(π a)
    let cosine = 2.0 * load_per_m / (std::f64::consts::PI * a);
    eprintln!(
        "zero clearance: reference α₀ {:.2}°, FE arc ±{:.2}°, peak {:.4e} vs {peak_ref:.4e} ({:+.2} %),          cosine's {cosine:.4e} ({:+.1} %)",
        alpha0.to_degrees(),
        0.5 * c.arc_deg,
        c.peak_pressure_pa,
        100.0 * (c.peak_pressure_pa / peak_ref - 1.0),
        100.0 * (c.peak_pressure_pa / cosine - 1.0)
    );
    assert!((0.5 * c.arc_deg - alpha0.to_degrees()).abs() <= 360.0 / 192.0);
    assert!((c.peak_pressure_pa / peak_ref - 1.0).abs() < 0.01);
    // the resultant points along the force, the peak at its direction
    assert!(c.peak_angle_deg.abs() < 2.0, "{}", c.peak_angle_deg);
}

/// The plate with two bores of `two_eye_plate` (curved bore walls), its bore walls.
fn two_eye() -> (TetMesh, Vec<[usize; 6]>, Vec<[usize; 6]>, TwoEyePlate) {
    let plate = TwoEyePlate {
        curved: true,
        n_side: 6,
        ..TwoEyePlate::default()
    };
    let mesh = two_eye_plate(&plate).unwrap();
    let fa = wall_faces(&mesh, 0.0, plate.bore_a_radius);
    let fb = wall_faces(&mesh, plate.length, plate.bore_b_radius);
    (mesh, fa, fb, plate)
}

#[test]
fn a_body_held_by_two_pins_carries_the_pin_force_and_its_free_motions_carry_nothing() {
    // pin A (clearance 20 µm) pushes along AB towards B; pin B (clearance 10 µm) holds the body
    let (mesh, fa, fb, plate) = two_eye();
    let force = [20e3, 0.0, 0.0];
    let pa = pin(fa, plate.bore_a_radius - 20e-6, PinMotion::Force(force));
    let mut pb = pin(fb, plate.bore_b_radius - 10e-6, PinMotion::Fixed);
    pb.axis_point_m = [plate.length, 0.0, 0.0];
    let p = problem(&mesh, vec![pa, pb]);
    let s = solve_contact(&p).unwrap();
    recheck(&p, &s);
    let (a, b) = (&s.cylinders[0], &s.cylinders[1]);
    eprintln!(
        "two pins: A arc {:.1}° peak {:.3e} Pa, B arc {:.1}° peak {:.3e} Pa; restraint {:?}; \
         {} iterations, {} of {} columns; {:?}",
        a.arc_deg,
        a.peak_pressure_pa,
        b.arc_deg,
        b.peak_pressure_pa,
        s.restraint,
        s.iterations,
        s.columns,
        s.rows,
        s.timings
    );
    // the contact forces on the body: F at A (to 1e-10, the solver's own check) and −F at B
    // (equilibrium of the body; nothing else holds it but the free motions' support)
    for (j, fj) in force.iter().enumerate() {
        assert!((a.resultant_n[j] - fj).abs() <= 1e-10 * 20e3);
        assert!((b.resultant_n[j] + fj).abs() <= 1e-8 * 20e3);
    }
    // the rotation about B and the sliding along the axis are held by a support that carries
    // nothing: the force balances along AB
    assert_eq!(s.restraint.free_motions, 2);
    assert!(s.restraint.reaction_rel < 1e-8, "{:?}", s.restraint);
    // A presses towards +x (its arc centred on the force), B is pressed on its −x side
    assert!(a.arc_deg > 0.0 && a.arc_deg < 180.0 && a.peak_angle_deg.abs() < 10.0);
    assert!(b.arc_deg > 0.0 && b.arc_deg < 180.0);
    // the loaded bore ovalises as a pin-loaded lug's hole does: longer along the force,
    // narrower across it
    let d = diameter_change(&mesh, &p.cylinders[0], &s.displacements, force).unwrap();
    eprintln!(
        "bore A diameter change along {:.3e} m, across {:.3e} m",
        d.along_m, d.across_m
    );
    assert!(d.along_m > 0.0 && d.across_m < 0.0, "{d:?}");

    // a transverse force at A is not in balance about B: refused, unless the caller accepts
    // the support's reaction, which is then the moment F·L about B's axis
    let mut q = p.clone();
    q.cylinders[0].motion = PinMotion::Force([0.0, 5e3, 0.0]);
    let err = solve_contact(&q).unwrap_err().to_string();
    assert!(err.contains("not in balance"), "{err}");
    q.tolerances.free_mode_reaction_rel = None;
    let s = solve_contact(&q).unwrap();
    // the support's reaction is a pure couple about B's axis, −(A − B) × F = 5e3 L ẑ (statics
    // of the body: pin B's radial contact forces have no moment about its axis); pin A still
    // carries its whole force
    let r = &s.restraint;
    eprintln!("transverse: restraint {r:?}");
    assert!(norm3(r.force_n) < 1e-8 * 5e3, "{r:?}");
    assert!(
        (r.moment_nm[2] - 5e3 * plate.length).abs() < 1e-8 * 5e3 * plate.length,
        "{r:?}"
    );
    assert!((s.cylinders[0].resultant_n[1] - 5e3).abs() < 1e-10 * 5e3);
}

#[test]
fn a_factorised_system_serves_other_pin_forces_as_a_fresh_solve_does() {
    // pin A pushed along AB, then pulled back and pushed obliquely, on one factorisation: each
    // solve equals solve_contact of the same problem; a column of S is computed once
    let (mesh, fa, fb, plate) = two_eye();
    let pa = pin(
        fa,
        plate.bore_a_radius - 20e-6,
        PinMotion::Force([20e3, 0.0, 0.0]),
    );
    let mut pb = pin(fb, plate.bore_b_radius - 10e-6, PinMotion::Fixed);
    pb.axis_point_m = [plate.length, 0.0, 0.0];
    let mut p = problem(&mesh, vec![pa, pb]);
    p.tolerances.free_mode_reaction_rel = None;
    let system = ContactSystem::new(&p).unwrap();
    let mut computed = Vec::new();
    for force in [
        [20e3, 0.0, 0.0],
        [-15e3, 0.0, 0.0],
        [20e3, 2e3, 0.0],
        [20e3, 0.0, 0.0],
    ] {
        let mut q = p.clone();
        q.cylinders[0].motion = PinMotion::Force(force);
        let reused = system.solve(&q).unwrap();
        let fresh = solve_contact(&q).unwrap();
        recheck(&q, &reused);
        let scale = fresh
            .displacements
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()));
        let du = reused
            .displacements
            .iter()
            .zip(&fresh.displacements)
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        assert!(du <= 1e-9 * scale, "{force:?}: {du:e} of {scale:e}");
        for (a, b) in reused.cylinders.iter().zip(&fresh.cylinders) {
            assert_eq!(a.arc_deg, b.arc_deg, "{force:?}");
            assert!((a.peak_pressure_pa - b.peak_pressure_pa).abs() <= 1e-9 * b.peak_pressure_pa);
        }
        assert_eq!(reused.timings.factorisation_s, 0.0);
        computed.push(reused.columns);
    }
    // the first push computes its columns; the same push again needs none
    assert!(computed[0] > 0 && computed[3] == 0, "{computed:?}");
    // another pin, another mesh or other supports are not the system's
    let mut other = p.clone();
    other.cylinders[1].radius_m -= 1e-6;
    let err = system.solve(&other).unwrap_err().to_string();
    assert!(err.contains("other pins"), "{err}");
    let mut other = p.clone();
    other.prescribed.push((2, 0.0));
    assert!(system.solve(&other).is_err());
}

/// The two-eye plate on pins A (20 kN along AB, 20 µm clearance) and B (fixed, 10 µm), both of
/// `elastic` (`None`: rigid).
fn two_pins(elastic: Option<PinElasticity>) -> (ContactSolution, f64) {
    let (mesh, fa, fb, plate) = two_eye();
    let mut pa = pin(
        fa,
        plate.bore_a_radius - 20e-6,
        PinMotion::Force([20e3, 0.0, 0.0]),
    );
    let mut pb = pin(fb, plate.bore_b_radius - 10e-6, PinMotion::Fixed);
    pb.axis_point_m = [plate.length, 0.0, 0.0];
    pa.elastic = elastic;
    pb.elastic = elastic;
    let p = problem(&mesh, vec![pa, pb]);
    let s = solve_contact(&p).unwrap();
    // equilibrium, complementarity on the gaps with the pins' deflection, no penetration
    recheck(&p, &s);
    let u_max = s.displacements.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    (s, u_max)
}

#[test]
fn an_elastic_pin_tends_to_the_rigid_pin_as_its_modulus_grows() {
    let (rigid, _) = two_pins(None);
    let stiff = |factor: f64, hold: PinHold| PinElasticity {
        material: Material {
            youngs_modulus_pa: factor * E,
            poisson_ratio: NU,
        },
        hold,
        inner_ratio: 0.2,
    };
    for hold in [PinHold::Core, PinHold::Ends] {
        let mut last = f64::INFINITY;
        for factor in [1.0, 1e2, 1e4] {
            let (s, u_max) = two_pins(Some(stiff(factor, hold)));
            let (a, r) = (&s.cylinders[0], &rigid.cylinders[0]);
            let du = s
                .displacements
                .iter()
                .zip(&rigid.displacements)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
                / u_max;
            let deflection = a
                .pin_deflection_m
                .iter()
                .fold(0.0f64, |m, v| m.max(v.abs()));
            eprintln!(
                "{hold:?} E × {factor:e}: peak pressure {:.4e} Pa (rigid {:.4e}), arc {:.1}° \
                 ({:.1}°), pin A {:.4e} m ({:.4e}), pin deflection {deflection:.3e} m, \
                 displacement off by {du:.2e} of its largest",
                a.peak_pressure_pa,
                r.peak_pressure_pa,
                a.arc_deg,
                r.arc_deg,
                a.pin_displacement_m[0],
                r.pin_displacement_m[0],
            );
            // the pin's own compliance widens the arc and lets the pin travel further; held at a
            // core it lowers the peak, held at its ends it bends and loads the bore's faces
            // more; the difference falls with the modulus, as 1/E
            assert!(a.arc_deg >= r.arc_deg - 1e-9);
            if hold == PinHold::Core {
                assert!(a.peak_pressure_pa <= r.peak_pressure_pa * (1.0 + 1e-9));
            }
            assert!(a.pin_displacement_m[0] >= r.pin_displacement_m[0]);
            assert!(du < last, "{du} after {last}");
            if factor == 1.0 {
                assert!(du > 1e-3, "a steel pin changes nothing: {du}");
            }
            last = du;
        }
        assert!(last < 1e-3, "{hold:?}: {last}");
    }
}

#[test]
fn a_pin_pressing_on_a_missing_wall_is_refused() {
    // pin A's wall is the half x < 0 only; a force along +x has nothing to press on
    let (mesh, fa, fb, plate) = two_eye();
    let half: Vec<[usize; 6]> = fa
        .into_iter()
        .filter(|f| f[..3].iter().all(|&n| mesh.nodes()[n][0] < 1e-9))
        .collect();
    let pa = pin(
        half,
        plate.bore_a_radius - 20e-6,
        PinMotion::Force([1e3, 0.0, 0.0]),
    );
    let mut pb = pin(fb, plate.bore_b_radius - 10e-6, PinMotion::Fixed);
    pb.axis_point_m = [plate.length, 0.0, 0.0];
    let err = solve_contact(&problem(&mesh, vec![pa, pb])).unwrap_err();
    eprintln!("{err}");
    assert!(matches!(err, rodstudy::fem::FemError::Solver(_)), "{err}");
}

#[test]
#[ignore = "a benchmark: cargo test --release --test contact -- --ignored --nocapture"]
fn contact_against_linear_cost() {
    for n in [6, 10] {
        let b = rodstudy::bench::contact::bench_contact(n, 3).unwrap();
        eprintln!("{b:?}");
    }
}
