use super::*;
use crate::fem::body_force::{BodyShape, body_force_load, mesh_mass_properties};
use crate::fem::boundary::boundary_faces;
use crate::fem::element::QuadratureChoice;
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;
use crate::fem::mesh::structured::{TwoEyePlate, two_eye_plate};
use crate::fem::statics::{StaticProblem, solve_static};
use crate::fem::stress::stress_field;
use crate::mechanism::{MechanismParams, rod_frame_cycle};
use crate::rod::bores::{BoreSpec, find_bores};
use crate::rod::fatigue::MeanStress;
use crate::rod::pin_load::{BoreLoad, pin_load};

const RHO: f64 = 7800.0;

fn options() -> CycleOptions {
    CycleOptions {
        density_kg_m3: RHO,
        fixed_band_m: 0.006,
        singular_edges_m: vec![],
        singular_band_m: 0.003,
        endurance_pa: 235e6,
        ultimate_pa: 470e6,
        mean_stress: MeanStress::Goodman,
        quadrature: QuadratureChoice::Auto,
        direction_step_deg: DEFAULT_DIRECTION_STEP_DEG,
        half_model: None,
    }
}

fn steel() -> Material {
    Material {
        youngs_modulus_pa: 210e9,
        poisson_ratio: 0.3,
    }
}

/// The plate rod of the FEM tests (bores 50 / 25 mm, 180 mm apart), its unit solutions and
/// 360 instants of the spec's mechanism with the plate's own mass properties.
fn plate_cycle() -> (TetMesh, UnitSolutions, Vec<RodFrameInstant>) {
    let mesh = two_eye_plate(&TwoEyePlate::default()).unwrap();
    let units = unit_solutions(&mesh, &steel(), &BoreSpec::default(), &options()).unwrap();
    let rod = rod_inertia_of(&units.mass);
    let instants = rod_frame_cycle(
        &MechanismParams::default(),
        &rod,
        40.0 * std::f64::consts::PI,
        360,
    )
    .unwrap();
    (mesh, units, instants)
}

/// The largest difference between the superposed stress and a direct solve of the same
/// instant's load (pin load as `bores` says, body forces), over the instants `ks` and every
/// node and component, relative to the largest stress component of the direct solve; and
/// the largest relative difference of the judged peak von Mises.
fn superposition_vs_direct(
    mesh: &TetMesh,
    units: &UnitSolutions,
    instants: &[RodFrameInstant],
    bores: &BoreSpec,
    ks: &[usize],
) -> (f64, f64) {
    let boundary = boundary_faces(mesh).unwrap();
    let (loaded, fixed) = find_bores(mesh, &boundary, bores).unwrap();
    let prescribed: Vec<(usize, f64)> = fixed
        .nodes
        .iter()
        .flat_map(|&n| (0..3).map(move |j| (3 * n + j, 0.0)))
        .collect();
    let (mut worst, mut worst_peak) = (0.0f64, 0.0f64);
    for &k in ks {
        let c = units.terms(&instants[k]).unwrap();
        // the load assembled directly for this instant: the pin load of F_A, body force ρ(g − a_P)
        let mut f = vec![0.0; mesh.n_dofs()];
        let fa = instants[k].f_a_on_rod_n;
        let pin = pin_load(
            mesh,
            &loaded.faces,
            bores.loaded_centre_m,
            [0.0, 0.0, 1.0],
            [fa[0], fa[1], 0.0],
            bores.bore_load,
        )
        .unwrap();
        let a = &instants[k];
        for (shape, coef) in [
            (BodyShape::UniformX, a.gravity_m_s2[0] - a.a_a_m_s2[0]),
            (BodyShape::UniformY, a.gravity_m_s2[1] - a.a_a_m_s2[1]),
            (BodyShape::Centrifugal, a.omega3_rad_s.powi(2)),
            (BodyShape::AngularAccel, -a.alpha3_rad_s2),
        ] {
            for (fi, bi) in f.iter_mut().zip(body_force_load(mesh, RHO, shape)) {
                *fi += coef * bi;
            }
        }
        for (fi, pi) in f.iter_mut().zip(&pin.forces) {
            *fi += pi;
        }
        let direct = solve_static(&StaticProblem {
            mesh,
            material: steel(),
            prescribed: prescribed.clone(),
            loads: vec![f],
            quadrature: QuadratureChoice::Auto,
        })
        .unwrap();
        let s_direct = stress_field(mesh, &steel(), &direct.displacements[0])
            .unwrap()
            .averaged;
        let scale = s_direct
            .iter()
            .flat_map(|s| s.iter().map(|v| v.abs()))
            .fold(0.0, f64::max);
        let (mut peak_d, mut peak_s) = (0.0f64, 0.0f64);
        for (n, sd) in s_direct.iter().enumerate() {
            let ss = units.stress_at(n, &c);
            for j in 0..6 {
                worst = worst.max((ss[j] - sd[j]).abs() / scale);
            }
            if units.judged[n] {
                peak_d = peak_d.max(von_mises(sd));
                peak_s = peak_s.max(von_mises(&ss));
            }
        }
        worst_peak = worst_peak.max((peak_s - peak_d).abs() / peak_d);
    }
    (worst, worst_peak)
}

#[test]
fn superposition_equals_a_direct_solve() {
    let (mesh, units, instants) = plate_cycle();
    let (worst, _) = superposition_vs_direct(
        &mesh,
        &units,
        &instants,
        &BoreSpec::default(),
        &[0, 37, 90, 181, 300],
    );
    // measured 2e-15 … 1e-13
    assert!(worst < 1e-10, "superposition vs direct: {worst:e}");
}

#[test]
fn cosine_bore_load_interpolates_between_directions_at_second_order() {
    let mesh = two_eye_plate(&TwoEyePlate::default()).unwrap();
    let bores = BoreSpec {
        bore_load: BoreLoad::Cosine,
        ..BoreSpec::default()
    };
    let mass = mesh_mass_properties(&mesh, RHO);
    let instants = rod_frame_cycle(
        &MechanismParams::default(),
        &rod_inertia_of(&mass),
        40.0 * std::f64::consts::PI,
        360,
    )
    .unwrap();
    let ks = [0, 37, 90, 181, 300];
    let mut errors = Vec::new();
    for step in [20.0, 10.0, 5.0] {
        let opts = CycleOptions {
            direction_step_deg: step,
            ..options()
        };
        let units = unit_solutions_for(&mesh, &steel(), &bores, &opts, &instants).unwrap();
        let PinBasis::Directions { case_of, .. } = &units.pin else {
            panic!("a cosine load has direction cases");
        };
        let solved = case_of.iter().flatten().count();
        assert!(solved >= 2 && solved <= case_of.len());
        // the resultant of the interpolated pin load is F_A exactly: the reaction at B is
        // still the piston pin's force
        let cycle = combine(&units, &instants, &opts).unwrap();
        assert!(
            cycle.reaction_mismatch_rel < 1e-9,
            "{step}°: {:e}",
            cycle.reaction_mismatch_rel
        );
        let (worst, peak) = superposition_vs_direct(&mesh, &units, &instants, &bores, &ks);
        eprintln!(
            "cosine, {step}° ({solved} of {} directions solved): field {worst:.2e}, judged peak {peak:.2e}",
            case_of.len()
        );
        errors.push((worst, peak));
    }
    // measured on this plate (22.5° faces around the bore): field 2.8e-2 / 6.4e-3 / 4.8e-3 and
    // judged peak 1.4e-2 / 3.2e-3 / 1.9e-3 at 20° / 10° / 5°. From 20° to 10° the error falls
    // at second order; below the face width the discrete cosine itself (its edge at 90° moves
    // across quadrature points) sets a floor, so 5° gains less
    assert!(errors[1].0 < errors[0].0 / 3.0, "{errors:?}");
    assert!(
        errors[2].0 < errors[1].0 && errors[2].1 < errors[1].1,
        "{errors:?}"
    );
    assert!(errors[2].0 < 1e-2 && errors[2].1 < 3e-3, "{errors:?}");
    // an instant whose force points exactly along a unit direction has no interpolation error
    let mut along = instants[90];
    let m = along.f_a_on_rod_n[0].hypot(along.f_a_on_rod_n[1]);
    along.f_a_on_rod_n = [0.0, -m];
    let opts = options();
    let units = unit_solutions(&mesh, &steel(), &bores, &opts).unwrap();
    let (exact, _) = superposition_vs_direct(&mesh, &units, &[along], &bores, &[0]);
    assert!(exact < 1e-10, "{exact:e}");
}

#[test]
fn the_reaction_at_b_is_the_piston_pins_force_at_every_instant() {
    let (_, units, instants) = plate_cycle();
    let cycle = combine(&units, &instants, &options()).unwrap();
    assert_eq!(cycle.history.len(), 360);
    assert_eq!(cycle.history[0].crank_angle_deg, 0.0);
    // the mesh's own mass properties in the dynamics: equilibrium to round-off
    assert!(
        cycle.reaction_mismatch_rel < 1e-9,
        "{:e}",
        cycle.reaction_mismatch_rel
    );
    // with the mass off by 1 % the check sees it (it is not a tautology)
    let mut heavier = units.mass;
    heavier.mass_kg *= 1.01;
    let wrong = rod_frame_cycle(
        &MechanismParams::default(),
        &rod_inertia_of(&heavier),
        40.0 * std::f64::consts::PI,
        360,
    )
    .unwrap();
    let off = combine(&units, &wrong, &options()).unwrap();
    assert!(
        off.reaction_mismatch_rel > 1e-4,
        "{:e}",
        off.reaction_mismatch_rel
    );
}

#[test]
fn maxima_and_fatigue_are_consistent_with_the_history() {
    let (_, units, instants) = plate_cycle();
    let cycle = combine(&units, &instants, &options()).unwrap();
    let k = cycle.max_instant;
    let n = cycle.max_node;
    let vm = von_mises(&units.stress_at(n, &units.terms(&instants[k]).unwrap()));
    assert!((vm * 1e-6 - cycle.history[k].max_von_mises_away_from_fixed_mpa).abs() < 1e-9);
    for h in &cycle.history {
        assert!(h.max_von_mises_away_from_fixed_mpa <= vm * 1e-6 + 1e-12);
    }
    assert!(units.judged[n] && units.judged[cycle.fatigue_node]);
    // the per-node maximum over the cycle bounds every instant's value
    assert!(cycle.max_von_mises_pa[n] >= vm - 1e-6);
    // the fatigue factor of the critical node from its own alternating and mean stress
    let f = cycle.fatigue_node;
    let expect = super::super::fatigue::goodman_safety_factor(
        cycle.alternating_pa[f],
        cycle.mean_pa[f],
        235e6,
        470e6,
    );
    assert_eq!(cycle.fatigue_safety_factor[f], expect);
    assert!(expect.is_finite() && expect > 0.0);
}
