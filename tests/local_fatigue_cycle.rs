//! The wiring of the local (FKM) fatigue assessment into the cycle: unit load cases on a box with
//! a known linear stress field, superposed over a cycle, give at the judged surface nodes the
//! factor chain computed here by hand from FKM's formulas, and Findley's closed form for a
//! uniaxial cycle with a mean.

use std::f64::consts::PI;

use rodstudy::config::MaterialConfig;
use rodstudy::fem::body_force::mesh_mass_properties;
use rodstudy::fem::mesh::structured::box_tet10;
use rodstudy::rod::cycle::{PinBasis, Terms, UnitSolutions, local_fatigue};

#[test]
fn bar_with_a_bending_gradient_gives_the_hand_calculated_factor_chain() {
    // box 20 × 20 × 10 mm; unit case 0: σ_xx = 1 Pa · (1 − χ (l_z − z)), falling under the top
    // face z = l_z with the related gradient χ; unit case 1: σ_xx = 1 Pa, uniform
    let (lx, lz) = (0.02, 0.01);
    let mesh = box_tet10(lx, lx, lz, 4, 4, 3).unwrap();
    let chi = 400.0; // 1/m: 0.4 /mm, the middle branch of n(χ*)
    let bend: Vec<[f64; 6]> = mesh
        .nodes()
        .iter()
        .map(|p| [1.0 - chi * (lz - p[2]), 0.0, 0.0, 0.0, 0.0, 0.0])
        .collect();
    let uniform = vec![[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]; mesh.n_nodes()];
    let zero = vec![[0.0; 6]; mesh.n_nodes()];
    // judged: the top face away from its edges (the other faces carry σ_xx without a gradient
    // along their normals, or normal to them)
    let judged: Vec<bool> = mesh
        .nodes()
        .iter()
        .map(|p| {
            (p[2] - lz).abs() < 1e-12
                && p[0] > 1e-9
                && p[0] < lx - 1e-9
                && p[1] > 1e-9
                && p[1] < lx - 1e-9
        })
        .collect();
    let units = UnitSolutions {
        stresses: vec![
            bend,
            uniform,
            zero.clone(),
            zero.clone(),
            zero.clone(),
            zero,
        ],
        displacements: vec![vec![0.0; 3 * mesh.n_nodes()]; 6],
        reactions_n: vec![[0.0; 3]; 6],
        loads: vec![vec![0.0; 3 * mesh.n_nodes()]; 6],
        mass: mesh_mass_properties(&mesh, 7800.0),
        judged,
        pin: PinBasis::Linear,
        stats: Default::default(),
        timings: Default::default(),
    };
    // the cycle: σ_xx = σ_a sin ωt (bending) + σ_m (uniform) at the top face
    let (sa, sm) = (60e6, 25e6);
    let terms: Vec<Terms> = (0..360)
        .map(|i| {
            let t = 2.0 * PI * i as f64 / 360.0;
            [
                (0, sa * t.sin()),
                (1, sm),
                (2, 0.0),
                (3, 0.0),
                (4, 0.0),
                (5, 0.0),
            ]
        })
        .collect();
    let settings = MaterialConfig::default().local_settings();
    let local = local_fatigue(&mesh, &units, &terms, 0, &settings).unwrap();
    let c = local.critical();
    assert!(c.judged && c.has_gradient);

    // by hand, FKM 6th ed. (docs/fatigue.md), steel R_m 470 MPa, R_z 200 µm, untreated
    let rm = 470.0;
    let chi_mm = chi * 1e-3;
    // support factor, 0.1 < χ* ≤ 1 /mm: n = 1 + √χ* · 10^−(a_G + R_m/b_G), a_G 0.5, b_G 2700
    let n = 1.0 + chi_mm.sqrt() * 10f64.powf(-(0.5 + rm / 2700.0));
    // roughness: K_R = 1 − a_R lg(R_z) lg(2 R_m / R_m,N,min), a_R 0.22, R_m,N,min 400 MPa
    let k_r = 1.0 - 0.22 * 200f64.log10() * (2.0 * rm / 400.0).log10();
    // design factor with K̃_f = 2, K_V = K_S = K_NL,E = 1
    let k_wk = (1.0 / n) * (1.0 + 0.5 * (1.0 / k_r - 1.0));
    let sigma_wk = 0.45 * rm / k_wk;
    // M_σ = 0.35 · 10⁻³ R_m − 0.1; F2 in region II: K_AK = 1/(1 + M σ_m/σ_a)
    let m = 0.35e-3 * rm - 0.1;
    let k_ak = 1.0 / (1.0 + m * sm / sa);
    // S = j_D / a_BK = σ_AK / σ_a
    let s_hand = k_ak * sigma_wk / (sa * 1e-6);

    let a = &c.assessment;
    let rel = |x: f64, y: f64| (x - y).abs() / y.abs();
    assert!(rel(a.sigma1.strength.chi_star_sigma_per_m, chi) < 1e-6);
    assert!(rel(a.sigma1.strength.n_sigma, n) < 1e-9);
    assert!(rel(a.sigma1.strength.k_r_sigma, k_r) < 1e-12);
    assert!(rel(a.sigma1.strength.sigma_wk_pa * 1e-6, sigma_wk) < 1e-6);
    assert!(rel(a.sigma1.k_ak, k_ak) < 1e-9);
    assert!(rel(a.sigma1.amplitude_pa, sa) < 1e-9);
    assert!(rel(a.sigma1.mean_pa, sm) < 1e-9);
    assert!(
        rel(a.safety_factor, s_hand) < 1e-6,
        "{} vs {s_hand}",
        a.safety_factor
    );
    // every judged node has the same history: the smallest factor is this one, and the per-node
    // field holds it there; off the surface ∞
    assert_eq!(local.safety_factor[c.node], a.safety_factor);
    let interior = (0..mesh.n_nodes())
        .find(|&i| {
            let p = mesh.nodes()[i];
            p.iter().all(|&v| v > 1e-9) && p[0] < lx - 1e-9 && p[1] < lx - 1e-9 && p[2] < lz - 1e-9
        })
        .unwrap();
    assert!(local.safety_factor[interior].is_infinite());

    // Findley at the critical node, uniaxial σ(t) = σ_m + σ_a sin ωt with limits σ_WK and
    // f_W,τ σ_WK: f = k (σ_m + σ_a)/2 + √((σ_a/2)² + (k (σ_m + σ_a)/2)²) (the maximum over the
    // plane angle of (σ_a/2) sin 2θ + k (σ_m + σ_a)(1 + cos 2θ)/2)
    let f = local
        .findley
        .iter()
        .find(|f| f.node == c.node)
        .expect("the critical node is checked");
    let k = f.settings.k;
    let smax = sm + sa;
    let f_hand = 0.5 * k * smax + ((0.5 * sa).powi(2) + (0.5 * k * smax).powi(2)).sqrt();
    assert!(rel(f.result.parameter_pa, f_hand) < 1e-6);
    let r: f64 = 0.577;
    let k_hand = (2.0 * r - 1.0) / (2.0 * (r * (1.0 - r)).sqrt());
    assert!(rel(k, k_hand) < 1e-12);
    let limit = r * sigma_wk * 1e6 * (1.0 + k_hand * k_hand).sqrt();
    assert!(rel(f.result.factor, limit / f_hand) < 1e-5);
    // the Goodman node (0, a corner off the judged set) is checked too
    assert!(local.findley.iter().any(|f| f.node == 0));
}
