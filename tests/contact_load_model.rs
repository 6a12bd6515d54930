//! Contact as a load model of the rod's static cases (`[fem] bore_load = "contact"`) and in the
//! cycle, on the two-eye plate: each path against another that shares none of its wiring.
//!
//! - the F_x case under contact equals the direct contact solve of the rod
//!   (`solve_rod_contact`, pin B in contact) on the same mesh and clearances;
//! - a half model (u_z = 0 on the plane, half the force, mirrored) equals the whole plate;
//! - the cycle's contact instants on a half model (one factorisation for all instants) equal the
//!   whole's;
//! - a cycle instant without inertia equals the static F_x contact case of the same force;
//! - every solve balances (the post-processing refuses a reaction that does not) and presses
//!   without tension; the F_y case clamps bore B and leaves pin A's arc on the force's side.

use rodstudy::fem::contact::ContactTolerances;
use rodstudy::fem::element::QuadratureChoice;
use rodstudy::fem::material::Material;
use rodstudy::fem::mesh::TetMesh;
use rodstudy::fem::mesh::mirror::mirror;
use rodstudy::fem::mesh::structured::{TwoEyePlate, two_eye_plate};
use rodstudy::mechanism::RodFrameInstant;
use rodstudy::rod::contact_load::{PinContact, solve_rod_contact};
use rodstudy::rod::cycle::contact_instants::{contact_instants, instants_that_matter};
use rodstudy::rod::cycle::{CycleInstant, CycleOptions, DEFAULT_DIRECTION_STEP_DEG};
use rodstudy::rod::fatigue::MeanStress;
use rodstudy::rod::half_model::solve_rod_on;
use rodstudy::rod::judged::{DEFAULT_FIXED_BAND_M, DEFAULT_SINGULAR_BAND_M};
use rodstudy::rod::pin_load::BoreLoad;
use rodstudy::rod::records::HalfModel;
use rodstudy::rod::solve::solve_rod_fields;
use rodstudy::rod::{BoreSpec, RodOptions};

const FORCE_N: f64 = 20e3;
const CLEARANCE_M: f64 = 10e-6;

fn plate(thickness: f64, n_z: usize) -> (TwoEyePlate, TetMesh) {
    let p = TwoEyePlate {
        curved: true,
        n_side: 5,
        thickness,
        n_z,
        ..TwoEyePlate::default()
    };
    let mesh = two_eye_plate(&p).unwrap();
    (p, mesh)
}

/// The half z ≥ 0 of a plate `t` thick: a plate of half the thickness moved up by a quarter (its
/// mirror is the whole).
fn half_plate(t: f64) -> (TwoEyePlate, TetMesh) {
    let (p, h) = plate(t / 2.0, 2);
    let nodes: Vec<[f64; 3]> = h
        .nodes()
        .iter()
        .map(|x| [x[0], x[1], x[2] + t / 4.0])
        .collect();
    (p, TetMesh::new(nodes, h.elements().to_vec()).unwrap())
}

fn contact_spec(p: &TwoEyePlate) -> BoreSpec {
    BoreSpec {
        fixed_centre_m: [p.length, 0.0, 0.0],
        bore_load: BoreLoad::Contact,
        clearance_a_m: Some(CLEARANCE_M),
        clearance_b_m: Some(CLEARANCE_M),
        ..BoreSpec::default()
    }
}

#[test]
fn the_contact_load_case_is_the_direct_contact_solve_and_balances() {
    let (p, mesh) = plate(0.04, 4);
    let spec = contact_spec(&p);
    let options = RodOptions::default();
    let s = solve_rod_fields(&mesh, &Material::STEEL, &spec, FORCE_N, &options).unwrap();
    let fx = &s.result.cases["fx"];
    let direct = solve_rod_contact(
        &mesh,
        &Material::STEEL,
        &spec,
        &PinContact {
            force_n: [FORCE_N, 0.0, 0.0],
            clearance_a_m: CLEARANCE_M,
            clearance_b_m: CLEARANCE_M,
            tolerances: ContactTolerances::default(),
            elastic: None,
        },
        &options,
    )
    .unwrap();
    let rel = (fx.max_von_mises_away_from_fixed_mpa * 1e6 / direct.judged_peak.value - 1.0).abs();
    assert!(
        rel < 1e-9,
        "F_x under contact {rel:e} from the direct solve"
    );
    let k = fx.contact.as_ref().expect("a contact record");
    assert!((k.arc_a_deg - direct.bore_a.arc_deg).abs() < 1e-9);
    assert!(k.arc_b_deg.is_some() && k.max_tensile_pressure_mpa == 0.0);
    assert!(fx.reaction_balance_rel < 1e-6 && fx.resultant_error_rel < 1e-10);
    // the pressed arc is centred on the force, narrower than the cosine's half bore
    assert!(k.arc_a_deg > 10.0 && k.arc_a_deg < 180.0, "{}", k.arc_a_deg);
    assert!(k.arc_a_ends_deg[0] < 0.0 && k.arc_a_ends_deg[1] > 0.0);
    // F_y: bore B clamped, pin A pressed on the +y side
    let fy = &s.result.cases["fy"];
    let ky = fy.contact.as_ref().unwrap();
    assert!(ky.arc_b_deg.is_none() && ky.arc_a_deg < 180.0);
    assert!(fy.reaction_balance_rel < 1e-6);
    // the contact fields: pressure only on the walls, positive somewhere
    let fields = &s.contact_fields[0];
    assert!(fields.pressure_pa.iter().all(|p| *p >= 0.0));
    assert!(fields.pressure_pa.iter().any(|p| *p > 0.0));
}

#[test]
fn a_half_model_under_contact_is_the_whole_plate() {
    let (p, half) = half_plate(0.04);
    let whole = mirror(&half, 0.0, 1e-9).unwrap().whole;
    let spec = contact_spec(&p);
    let w = solve_rod_fields(
        &whole,
        &Material::STEEL,
        &spec,
        FORCE_N,
        &RodOptions::default(),
    )
    .unwrap();
    let options = RodOptions {
        mirror_plane_z_m: Some(0.0),
        ..RodOptions::default()
    };
    let (_, m) = solve_rod_on(half, &Material::STEEL, &spec, FORCE_N, &options).unwrap();
    for name in ["fx", "fy"] {
        let (a, b) = (&w.result.cases[name], &m.result.cases[name]);
        let rel =
            (a.max_von_mises_away_from_fixed_mpa / b.max_von_mises_away_from_fixed_mpa - 1.0).abs();
        assert!(rel < 1e-6, "{name}: whole {a:?} half {b:?}");
        let (ka, kb) = (a.contact.as_ref().unwrap(), b.contact.as_ref().unwrap());
        assert!((ka.arc_a_deg - kb.arc_a_deg).abs() < 1e-6, "{name}");
        assert!((ka.peak_pressure_a_mpa / kb.peak_pressure_a_mpa - 1.0).abs() < 1e-6);
    }
}

#[test]
fn the_cycles_contact_instants_on_a_half_model_are_the_wholes() {
    let (p, half) = half_plate(0.04);
    let m = mirror(&half, 0.0, 1e-9).unwrap();
    let spec = contact_spec(&p);
    // three instants with inertia along the rod, each in balance (the plate is symmetric about
    // y = 0: the body force along x has no moment about B), so that the support of the rotation
    // about pin B carries nothing, as in the study
    let instants: Vec<RodFrameInstant> =
        [(0.0, -12e3, -900.0), (180.0, 15e3, 600.0), (90.0, 5e3, 2e3)]
            .iter()
            .map(|&(angle, fx, ax)| RodFrameInstant {
                crank_angle_deg: angle,
                time_s: 0.0,
                a_a_m_s2: [ax, 0.0],
                omega3_rad_s: 0.0,
                alpha3_rad_s2: 0.0,
                gravity_m_s2: [0.0, 0.0],
                f_a_on_rod_n: [fx, 0.0],
                f_b_on_rod_n: [-fx, 0.0],
                gas_force_n: 0.0,
            })
            .collect();
    let history: Vec<CycleInstant> = instants
        .iter()
        .map(|i| CycleInstant {
            crank_angle_deg: i.crank_angle_deg,
            time_s: 0.0,
            max_von_mises_away_from_fixed_mpa: 1.0,
            reaction_b_n: [0.0; 3],
            dynamics_f_b_n: [0.0; 3],
        })
        .collect();
    let which: Vec<(usize, String)> = (0..3).map(|k| (k, format!("instant {k}"))).collect();
    let whole_options = cycle_options(None);
    let half_options = cycle_options(Some(HalfModel {
        plane_z_mm: 0.0,
        nodes: half.n_nodes(),
        elements: half.n_elements(),
        plane_nodes: m.plane_nodes.len(),
    }));
    let solve = |options: &CycleOptions| {
        contact_instants(
            &m.whole,
            &Material::STEEL,
            &spec,
            options,
            &instants,
            &history,
            &which,
        )
        .unwrap()
        .instants
    };
    let (w, h) = (solve(&whole_options), solve(&half_options));
    for (a, b) in w.iter().zip(&h) {
        eprintln!(
            "{}: whole {:.4} MPa (arcs {:.1}°, {:.1}°), half {:.4} MPa",
            a.reason, a.contact_mpa, a.arc_a_deg, a.arc_b_deg, b.contact_mpa
        );
        assert!(
            (a.contact_mpa / b.contact_mpa - 1.0).abs() < 1e-8,
            "{a:?}\n{b:?}"
        );
        assert!(
            (a.arc_a_deg - b.arc_a_deg).abs() < 1e-8 && (a.arc_b_deg - b.arc_b_deg).abs() < 1e-8
        );
        assert!((a.peak_pressure_a_mpa / b.peak_pressure_a_mpa - 1.0).abs() < 1e-8);
        assert!((a.peak_pressure_b_mpa / b.peak_pressure_b_mpa - 1.0).abs() < 1e-8);
        assert!(a.restraint_moment_rel < 1e-8 && b.restraint_moment_rel < 1e-8);
    }
}

fn cycle_options(half_model: Option<HalfModel>) -> CycleOptions {
    CycleOptions {
        density_kg_m3: 7850.0,
        fixed_band_m: DEFAULT_FIXED_BAND_M,
        singular_edges_m: Vec::new(),
        singular_band_m: DEFAULT_SINGULAR_BAND_M,
        endurance_pa: 235e6,
        ultimate_pa: 470e6,
        mean_stress: MeanStress::default(),
        quadrature: QuadratureChoice::Auto,
        direction_step_deg: DEFAULT_DIRECTION_STEP_DEG,
        half_model,
    }
}

#[test]
fn a_cycle_instant_without_inertia_is_the_static_contact_case() {
    let (p, mesh) = plate(0.04, 4);
    let spec = contact_spec(&p);
    let direct = solve_rod_contact(
        &mesh,
        &Material::STEEL,
        &spec,
        &PinContact {
            force_n: [FORCE_N, 0.0, 0.0],
            clearance_a_m: CLEARANCE_M,
            clearance_b_m: CLEARANCE_M,
            tolerances: ContactTolerances::default(),
            elastic: None,
        },
        &RodOptions::default(),
    )
    .unwrap();
    let instant = RodFrameInstant {
        crank_angle_deg: 180.0,
        time_s: 0.0,
        a_a_m_s2: [0.0; 2],
        omega3_rad_s: 0.0,
        alpha3_rad_s2: 0.0,
        gravity_m_s2: [0.0; 2],
        f_a_on_rod_n: [FORCE_N, 0.0],
        f_b_on_rod_n: [-FORCE_N, 0.0],
        gas_force_n: 0.0,
    };
    let options = cycle_options(None);
    let linear = CycleInstant {
        crank_angle_deg: 180.0,
        time_s: 0.0,
        max_von_mises_away_from_fixed_mpa: 1.0,
        reaction_b_n: [0.0; 3],
        dynamics_f_b_n: [0.0; 3],
    };
    let r = contact_instants(
        &mesh,
        &Material::STEEL,
        &spec,
        &options,
        &[instant],
        &[linear],
        &[(0, "peak compression".into())],
    )
    .unwrap()
    .instants;
    let rel = (r[0].contact_mpa * 1e6 / direct.judged_peak.value - 1.0).abs();
    assert!(rel < 1e-9, "{rel:e}: {:?}", r[0]);
    assert!((r[0].arc_a_deg - direct.bore_a.arc_deg).abs() < 1e-9);
    assert!(r[0].restraint_moment_rel < 1e-8, "{:?}", r[0]);
}

#[test]
fn the_instants_that_matter_are_the_peaks_with_neighbours_merged() {
    // F_A = (F cos φ, 0.3 F sin 2φ): tension at 0°, compression at 180°, transverse at 45°, …
    let f = 5e3;
    let instants: Vec<RodFrameInstant> = (0..360)
        .map(|k| {
            let phi = (k as f64).to_radians();
            RodFrameInstant {
                crank_angle_deg: k as f64,
                time_s: 0.0,
                a_a_m_s2: [0.0; 2],
                omega3_rad_s: 0.0,
                alpha3_rad_s2: 0.0,
                gravity_m_s2: [0.0; 2],
                f_a_on_rod_n: [-f * phi.cos(), 0.3 * f * (2.0 * phi).sin()],
                f_b_on_rod_n: [0.0; 2],
                gas_force_n: 0.0,
            }
        })
        .collect();
    // the linear worst 1° from the peak tension (a neighbour: merged), then 359° (across the end)
    for (worst, expect_first) in [(1, 1usize), (359, 359)] {
        let which = instants_that_matter(&instants, worst);
        let angles: Vec<f64> = which
            .iter()
            .map(|(k, _)| instants[*k].crank_angle_deg)
            .collect();
        assert_eq!(which.len(), 3, "{which:?}");
        assert!(angles.contains(&(expect_first as f64)) && angles.contains(&180.0));
        let tension = which.iter().find(|(k, _)| *k == expect_first).unwrap();
        assert!(tension.1.contains("worst linear") && tension.1.contains("peak tension"));
        assert!(which.iter().any(|(_, r)| r == "peak transverse"));
    }
}
