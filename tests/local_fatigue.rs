//! Verification of the FKM local fatigue module and the Findley critical plane, each against an
//! independent reference: the Kirsch solution of a hole in a plate (χ*, n_σ), the hand calculation
//! printed in docs/fatigue.md (the factor chain), and closed forms of the Findley criterion.

use std::f64::consts::PI;

use rodstudy::fatigue::factors::support_factor;
use rodstudy::fatigue::findley::{normal_of, plane_parameter};
use rodstudy::fatigue::{
    FindleySettings, GradientOptions, LocalSettings, MaterialGroup, NodeHistory, assess_node,
    depth_gradients, findley, surface_points,
};
use rodstudy::fem::mesh::structured::tet4_to_tet10;
use rodstudy::fem::recovery::recover_stress;
use rodstudy::fem::shape::TET10_EDGES;
use rodstudy::fem::{Material, QuadratureChoice, StaticProblem, TetMesh, solve_static};

/// Half annulus a ≤ r ≤ r_out, 0 ≤ θ ≤ π, two layers of thickness `layer` along z: polar grid
/// (radii graded geometrically), quads split into triangles, prisms into three tetrahedra by the
/// global-index rule; midside nodes of circumferential edges on their circle.
fn half_annulus(a: f64, r_out: f64, n_r: usize, n_t: usize, layer: f64) -> TetMesh {
    let q = (r_out / a).powf(1.0 / n_r as f64);
    let radii: Vec<f64> = (0..=n_r).map(|i| a * q.powi(i as i32)).collect();
    let id2 = |i: usize, j: usize| i + (n_r + 1) * j;
    let n2 = (n_r + 1) * (n_t + 1);
    let mut nodes = Vec::with_capacity(3 * n2);
    for k in 0..3 {
        for j in 0..=n_t {
            let t = PI * j as f64 / n_t as f64;
            for r in &radii {
                nodes.push([r * t.cos(), r * t.sin(), layer * k as f64]);
            }
        }
    }
    let mut tris = Vec::new();
    for j in 0..n_t {
        for i in 0..n_r {
            let (p, qq, r, s) = (id2(i, j), id2(i + 1, j), id2(i + 1, j + 1), id2(i, j + 1));
            tris.push([p, qq, r]);
            tris.push([p, r, s]);
        }
    }
    let mut tets = Vec::new();
    for t in &tris {
        let mut v = *t;
        v.sort_unstable();
        let [a0, b0, c0] = v;
        for k in 0..2 {
            let (lo, hi) = (k * n2, (k + 1) * n2);
            tets.push([a0 + lo, b0 + lo, c0 + lo, c0 + hi]);
            tets.push([a0 + lo, b0 + lo, b0 + hi, c0 + hi]);
            tets.push([a0 + lo, a0 + hi, b0 + hi, c0 + hi]);
        }
    }
    let mesh = tet4_to_tet10(nodes, &tets).unwrap();
    let mut moved = mesh.nodes().to_vec();
    let rad = |p: [f64; 3]| p[0].hypot(p[1]);
    for el in mesh.elements() {
        for (k, [i, j]) in TET10_EDGES.iter().enumerate() {
            let (ri, rj) = (rad(mesh.nodes()[el[*i]]), rad(mesh.nodes()[el[*j]]));
            if (ri - rj).abs() < 1e-12 * a {
                let m = &mut moved[el[4 + k]];
                let f = ri / rad(*m);
                m[0] *= f;
                m[1] *= f;
            }
        }
    }
    mesh.map_nodes(|i, _| moved[i]).unwrap()
}

/// Kirsch's displacement of an infinite plate with a hole of radius `a` under remote tension `s`
/// along x, plane strain (J. R. Barber, *Elasticity*, 3rd ed., §8.4.1; κ = 3 − 4ν).
fn kirsch_displacement(p: [f64; 3], a: f64, s: f64, m: &Material) -> [f64; 2] {
    let (r, t) = (p[0].hypot(p[1]), p[1].atan2(p[0]));
    let mu = m.shear_modulus();
    let kappa = 3.0 - 4.0 * m.poisson_ratio;
    let c = s / (4.0 * mu);
    let (c2, s2) = ((2.0 * t).cos(), (2.0 * t).sin());
    let ur = c
        * (r * ((kappa - 1.0) / 2.0 + c2) + a * a / r * (1.0 + (1.0 + kappa) * c2)
            - a.powi(4) / r.powi(3) * c2);
    let ut = c * ((1.0 - kappa) * a * a / r - r - a.powi(4) / r.powi(3)) * s2;
    [ur * t.cos() - ut * t.sin(), ur * t.sin() + ut * t.cos()]
}

/// At the apex of a hole (a = 10 mm, remote 100 MPa) on an `n_r` × `n_t` mesh: χ* of σ_θ from the
/// recovered field, 1/m, and σ_θ / σ there.
fn hole_edge_gradient(n_r: usize, n_t: usize) -> (f64, f64) {
    let (a, s) = (0.010, 100e6);
    let material = Material::STEEL;
    let layer = a * PI / n_t as f64;
    let mesh = half_annulus(a, 5.0 * a, n_r, n_t, layer);
    let mut prescribed = Vec::new();
    for (i, p) in mesh.nodes().iter().enumerate() {
        prescribed.push((3 * i + 2, 0.0));
        let r = p[0].hypot(p[1]);
        if (r - 5.0 * a).abs() < 1e-9 * a {
            let u = kirsch_displacement(*p, a, s, &material);
            prescribed.push((3 * i, u[0]));
            prescribed.push((3 * i + 1, u[1]));
        } else if p[1].abs() < 1e-12 * a {
            prescribed.push((3 * i + 1, 0.0));
        }
    }
    let sol = solve_static(&StaticProblem {
        mesh: &mesh,
        material,
        prescribed,
        loads: vec![vec![0.0; mesh.n_dofs()]],
        quadrature: QuadratureChoice::Auto,
    })
    .unwrap();
    let rec = recover_stress(&mesh, &material, &sol.displacements[0]).unwrap();
    // the hole's apex at θ = 90°, mid-thickness: there σ_θ = σ_xx = 3 s (Kirsch)
    let node = mesh
        .nodes()
        .iter()
        .position(|p| {
            (p[0]).abs() < 1e-9 * a
                && (p[1] - a).abs() < 1e-9 * a
                && (p[2] - layer).abs() < 1e-9 * a
        })
        .expect("apex node");
    let point = surface_points(&mesh)
        .unwrap()
        .into_iter()
        .find(|p| p.node == node)
        .expect("on the surface");
    // the surface normal found from the faces: −ŷ
    assert!(
        (point.outward_normal[1] + 1.0).abs() < 1e-9,
        "{:?}",
        point.outward_normal
    );
    let g = depth_gradients(&mesh, &[&rec.nodal], &[point], &GradientOptions::default());
    let g = g[0].as_ref().expect("samples inside");
    let chi = g.fields[0].chi_star([1.0, 0.0, 0.0]);
    (chi, g.fields[0].stress[0] / s)
}

#[test]
fn hole_in_a_plate_gradient_and_support_factor_against_kirsch() {
    // Kirsch: σ_θ(r, 90°) = (σ/2)(2 + a²/r² + 3a⁴/r⁴); at r = a: 3σ, dσ_θ/dr = −7σ/a, so
    // χ* = 7/(3a) (233.3 /m for a = 10 mm). FKM's tabulated 2/r for notches in tension is 14 % lower.
    let a = 0.010;
    let exact = 7.0 / (3.0 * a);
    let mut errors = Vec::new();
    let mut chi_fine = 0.0;
    for (n_r, n_t) in [(16, 32), (32, 64)] {
        let (chi, kt) = hole_edge_gradient(n_r, n_t);
        chi_fine = chi;
        let err = chi / exact - 1.0;
        println!(
            "hole a = 10 mm, mesh {n_r} × {n_t}: K_t = {kt:.4} (3), χ* = {chi:.2} /m (exact {exact:.2}), error {:+.2} %",
            100.0 * err
        );
        // the fitted surface stress: within 0.5 % of Kirsch's 3
        assert!((kt - 3.0).abs() < 0.015, "K_t {kt}");
        errors.push(err.abs());
    }
    // both meshes within 1.5 % of Kirsch (measured −0.42 % and +0.99 %: on the coarse mesh the
    // cubic's truncation error, −2 % at a depth of a/5, offsets the field's own error)
    assert!(errors.iter().all(|e| *e < 0.015), "{errors:?}");
    // the support factor follows: n(χ*) of the finer mesh within 0.1 % of n(7/(3a))
    let chi = chi_fine;
    let c = MaterialGroup::Steel.constants();
    let n_fem = support_factor(chi, 470e6, c.a_g, c.b_g_pa);
    let n_exact = support_factor(exact, 470e6, c.a_g, c.b_g_pa);
    let n_fkm = support_factor(2.0 / a, 470e6, c.a_g, c.b_g_pa);
    println!("n_σ: FEM {n_fem:.5}, Kirsch {n_exact:.5}, with χ* = 2/r {n_fkm:.5}");
    assert!((n_fem / n_exact - 1.0).abs() < 1e-3);
    assert!((n_exact - 1.102309).abs() < 1e-6);
}

#[test]
fn factor_chain_reproduces_the_hand_calculation_of_the_docs() {
    // docs/fatigue.md, "A node by hand": σ_xx = 50 + 100 sin ωt, σ_yy = 10 + 30 sin ωt MPa,
    // χ*_1 = 0.5 /mm, χ*_2 = 0.2 /mm; default settings (thesis steel, forged skin, F2, j_D = 1.5)
    let steps = 36;
    let (mut hist, mut grad) = (Vec::new(), Vec::new());
    for i in 0..steps {
        let w = (2.0 * PI * i as f64 / steps as f64).sin();
        let (sx, sy) = ((50.0 + 100.0 * w) * 1e6, (10.0 + 30.0 * w) * 1e6);
        hist.push([sx, sy, 0.0, 0.0, 0.0, 0.0]);
        // dσ/dd of the amplitude part: −χ* σ_a (the mean's gradient does not enter)
        grad.push([-500.0 * 100e6 * w, -200.0 * 30e6 * w, 0.0, 0.0, 0.0, 0.0]);
    }
    let r = assess_node(
        &LocalSettings::default(),
        &NodeHistory {
            stress: &hist,
            depth_gradient: Some(&grad),
            outward_normal: [0.0, 0.0, 1.0],
        },
    );
    let close = |v: f64, hand: f64, what: &str| {
        // the hand values carry six or seven significant digits
        assert!((v / hand - 1.0).abs() < 5e-6, "{what}: {v} vs hand {hand}");
    };
    let (s1, s2) = (&r.sigma1, &r.sigma2);
    close(s1.amplitude_pa, 100e6, "σ1,a");
    close(s1.mean_pa, 50e6, "σ1,m");
    close(s1.strength.chi_star_sigma_per_m, 500.0, "χ*1");
    close(s1.mean_stress_sensitivity, 0.0645, "M_σ");
    close(s1.strength.k_r_sigma, 0.812156, "K_R");
    close(s1.strength.n_sigma, 1.149765, "n1");
    close(s1.strength.k_wk_sigma, 0.970325, "K_WK1");
    close(s1.strength.sigma_wk_pa, 242.1870e6, "σ_WK1");
    close(s1.k_ak, 0.968758, "K_AK1");
    close(s1.sigma_ak_pa, 234.6205e6, "σ_AK1");
    close(s1.utilisation, 0.639330, "a1");
    close(s2.amplitude_pa, 30e6, "σ2,a");
    close(s2.strength.n_sigma, 1.094720, "n2");
    close(s2.strength.sigma_wk_pa, 230.5922e6, "σ_WK2");
    close(s2.k_ak, 0.978953, "K_AK2");
    close(s2.utilisation, 0.199345, "a2");
    close(r.utilisation, 0.566599, "a_BK");
    close(r.safety_factor, 2.647375, "S");
    assert_eq!(r.q, 0.0);
}

/// σ_xx = `sa` sin ωt + `sm`, τ_xy = `ta` sin(ωt + `phase`), `steps` instants.
fn tension_torsion(sa: f64, ta: f64, phase: f64, steps: usize) -> Vec<[f64; 6]> {
    (0..steps)
        .map(|i| {
            let w = 2.0 * PI * i as f64 / steps as f64;
            [sa * w.sin(), 0.0, 0.0, ta * (w + phase).sin(), 0.0, 0.0]
        })
        .collect()
}

#[test]
fn findley_at_the_calibration_limits_and_its_critical_planes() {
    let (sw, tw) = (235e6, 0.577 * 235e6);
    let set = FindleySettings::from_fatigue_limits(sw, tw);
    // fully reversed tension at σ_W: S = 1, plane at θ = ½ atan(1/k) from the axis (40.57°)
    let r = findley(&tension_torsion(sw, 0.0, 0.0, 72), &set);
    assert!((r.factor - 1.0).abs() < 1e-7, "{}", r.factor);
    let theta = 0.5 * (1.0 / set.k).atan();
    assert!(
        (r.normal[0].abs() - theta.cos()).abs() < 1e-4,
        "{:?}",
        r.normal
    );
    // fully reversed torsion at τ_W: S = 1, plane ½ atan(k) = 4.43° off a plane of largest shear
    // (normal x or y), turned towards a principal direction
    let r = findley(&tension_torsion(0.0, tw, 0.0, 72), &set);
    assert!((r.factor - 1.0).abs() < 1e-7, "{}", r.factor);
    assert!(r.normal[2].abs() < 1e-4);
    let from_x = r.normal[1].atan2(r.normal[0]).rem_euclid(PI / 2.0);
    let off = from_x.min(PI / 2.0 - from_x);
    assert!(
        (off - 0.5 * set.k.atan()).abs() < 2e-4,
        "{}",
        off.to_degrees()
    );
    println!(
        "Findley k = {:.5}, f_lim = {:.3} MPa; tension plane {:.3}°, torsion plane {:.3}° off the largest shear",
        set.k,
        set.limit_pa / 1e6,
        theta.to_degrees(),
        off.to_degrees()
    );
}

#[test]
fn findley_in_phase_and_out_of_phase_tension_torsion_against_closed_forms() {
    let set = FindleySettings::from_fatigue_limits(235e6, 0.577 * 235e6);
    let k = set.k;
    let (sa, ta) = (120e6, 70e6);
    // in phase: on the plane at θ in the x–y plane, σ_n = A sin ωt, τ = C sin ωt with
    // A = (σ_a/2)(1 + cos 2θ) + τ_a sin 2θ, C = −(σ_a/2) sin 2θ + τ_a cos 2θ: f = max |C| + k |A|
    let in_phase_ref = (0..200_000)
        .map(|i| {
            let t2 = 2.0 * PI * i as f64 / 200_000.0;
            let a = 0.5 * sa * (1.0 + t2.cos()) + ta * t2.sin();
            let c = -0.5 * sa * t2.sin() + ta * t2.cos();
            c.abs() + k * a.abs()
        })
        .fold(f64::NEG_INFINITY, f64::max);
    let r = findley(&tension_torsion(sa, ta, 0.0, 72), &set);
    println!(
        "in phase: f = {:.4} MPa (closed form {:.4}), S = {:.4}",
        r.parameter_pa / 1e6,
        in_phase_ref / 1e6,
        r.factor
    );
    assert!((r.parameter_pa / in_phase_ref - 1.0).abs() < 1e-7);
    // 90° out of phase: per plane the shear path is the ellipse P sin + Q cos, τ_a its semi-major
    // axis, σ_n,max = √(p² + q²); the reference searches a 0.1° grid of the hemisphere
    let unit_s = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let unit_t = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0];
    let shear = |s: &[f64; 6], n: [f64; 3]| {
        let t = [
            s[0] * n[0] + s[3] * n[1] + s[5] * n[2],
            s[3] * n[0] + s[1] * n[1] + s[4] * n[2],
            s[5] * n[0] + s[4] * n[1] + s[2] * n[2],
        ];
        let sn = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
        ([t[0] - sn * n[0], t[1] - sn * n[1], t[2] - sn * n[2]], sn)
    };
    let mut out_ref = f64::NEG_INFINITY;
    for i in 0..=900 {
        let theta = 0.5 * PI * i as f64 / 900.0;
        for j in 0..3600 {
            let n = normal_of(theta, 2.0 * PI * j as f64 / 3600.0);
            let (p, sp) = shear(&unit_s, n);
            let (q, sq) = shear(&unit_t, n);
            let p = p.map(|v| v * sa);
            let q = q.map(|v| v * ta);
            let (pp, qq, pq) = (
                p.iter().map(|v| v * v).sum::<f64>(),
                q.iter().map(|v| v * v).sum::<f64>(),
                p.iter().zip(&q).map(|(a, b)| a * b).sum::<f64>(),
            );
            let major = (0.5 * (pp + qq) + (0.25 * (pp - qq).powi(2) + pq * pq).sqrt()).sqrt();
            let snmax = (sa * sp).hypot(ta * sq);
            out_ref = out_ref.max(major + k * snmax);
        }
    }
    let hist = tension_torsion(sa, ta, PI / 2.0, 360);
    let r = findley(&hist, &set);
    println!(
        "90° out of phase: f = {:.4} MPa (closed form per plane, 0.1° grid: {:.4}), S = {:.4}; \
         normal {:?}",
        r.parameter_pa / 1e6,
        out_ref / 1e6,
        r.factor,
        r.normal.map(|v| (v * 1e4).round() / 1e4)
    );
    // the history is sampled every 1°: its shear ellipse is inscribed to 1 − cos(0.5°) ≈ 4e-5
    assert!((r.parameter_pa / out_ref - 1.0).abs() < 2e-4);
    // on the critical plane, the parameter recomputed from the history agrees
    let (tau, sn, f) = plane_parameter(&hist, r.normal, k);
    assert!((f - r.parameter_pa).abs() < 1e-6 && (tau + k * sn - f).abs() < 1e-6);
    // pure shear against pure tension of equal von Mises: Findley (k > 0) finds the shear
    // history less severe per von Mises unit than tension only by the calibration ratio
    let s_t = findley(&tension_torsion(100e6, 0.0, 0.0, 72), &set).parameter_pa;
    let s_s = findley(&tension_torsion(0.0, 100e6 / 3f64.sqrt(), 0.0, 72), &set).parameter_pa;
    let expected = ((1.0 + k * k).sqrt() / 3f64.sqrt()) / (0.5 * ((1.0 + k * k).sqrt() + k));
    assert!(
        (s_s / s_t - expected).abs() < 1e-7,
        "{} {}",
        s_s / s_t,
        expected
    );
}
