//! The six unit load cases of the cycle and their solutions on one factorisation (the module
//! documentation of [`super`] gives the superposition): the pin force as two unit cases, or, under
//! a cosine bore load, one case per direction of a fan ([`PinBasis`]); four body-force cases.

use rayon::prelude::*;

use crate::fem::body_force::{
    BodyShape, MeshMassProperties, body_force_load, mesh_mass_properties,
};
use crate::fem::boundary::boundary_faces;
use crate::fem::element::QuadratureChoice;
use crate::fem::error::{FemError, Result};
use crate::fem::load::uniform_traction_with_resultant;
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;
use crate::fem::statics::{SolveStats, StaticProblem, Timings, solve_static};
use crate::fem::stress::stress_field;
use crate::mechanism::RodFrameInstant;
use crate::rod::bores::{BoreSpec, find_bores};
use crate::rod::fatigue::MeanStress;
use crate::rod::judged::{Bands, judged_nodes};
use crate::rod::pin_load::{BoreLoad, pin_load};

/// The six unit load cases, in the order of [`coefficients`].
pub const UNIT_CASES: [&str; 6] = [
    "pin force x (1 N)",
    "pin force y (1 N)",
    "uniform body force x (ρ · 1 m/s²)",
    "uniform body force y (ρ · 1 m/s²)",
    "centrifugal about A (ρ r, ω² = 1)",
    "angular about A (ρ ẑ × r, α = 1)",
];

/// The coefficients of the unit cases at one instant: F_Ax, F_Ay, (g − a_A)_x, (g − a_A)_y, ω₃²,
/// −α₃.
pub fn coefficients(inst: &RodFrameInstant) -> [f64; 6] {
    let g = inst.gravity_m_s2;
    let a = inst.a_a_m_s2;
    [
        inst.f_a_on_rod_n[0],
        inst.f_a_on_rod_n[1],
        g[0] - a[0],
        g[1] - a[1],
        inst.omega3_rad_s * inst.omega3_rad_s,
        -inst.alpha3_rad_s2,
    ]
}

/// Settings of the cycle analysis.
#[derive(Clone, Debug)]
pub struct CycleOptions {
    /// Density of the rod, kg/m³.
    pub density_kg_m3: f64,
    /// Nodes closer than this to the fixed bore are left out of the judged maxima, m.
    pub fixed_band_m: f64,
    /// Sharp re-entrant edges (segments, m), and the band around them left out, m.
    pub singular_edges_m: Vec<[[f64; 3]; 2]>,
    pub singular_band_m: f64,
    /// Endurance limit and ultimate strength, Pa, and the mean-stress correction.
    pub endurance_pa: f64,
    pub ultimate_pa: f64,
    pub mean_stress: MeanStress,
    pub quadrature: QuadratureChoice,
    /// With a cosine bore load: the spacing of the pin's unit directions, degrees (must divide
    /// 360; [`DEFAULT_DIRECTION_STEP_DEG`]).
    pub direction_step_deg: f64,
    /// The half model the mesh was mirrored from, if it was: the cycle's contact instants are
    /// solved on it ([`super::contact_instants`]).
    pub half_model: Option<crate::rod::records::HalfModel>,
}

/// The default spacing of the cosine bore load's unit directions: 5° (72 directions).
pub const DEFAULT_DIRECTION_STEP_DEG: f64 = 5.0;

/// How the pin force enters the unit cases.
#[derive(Clone, Debug, PartialEq)]
pub enum PinBasis {
    /// Uniform traction, linear in the force: cases 0 and 1 are 1 N along x and y.
    Linear,
    /// Cosine bearing pressure: cases 0–3 are the body forces, then one case of 1 N per solved
    /// direction θ_j = j · `step_deg`; `case_of[j]` is its case index (`None`: not solved).
    Directions {
        step_deg: f64,
        case_of: Vec<Option<usize>>,
    },
}

/// The unit solutions: nodal stresses (averaged, Pa) and the reaction at B (N) per unit case.
#[derive(Clone, Debug)]
pub struct UnitSolutions {
    /// `stresses[k][n]`: case k, node n.
    pub stresses: Vec<Vec<[f64; 6]>>,
    /// Displacements per case, 3 per node (m).
    pub displacements: Vec<Vec<f64>>,
    /// Sum of the reactions at the fixed bore per case (the force of the support on the rod), N.
    pub reactions_n: Vec<[f64; 3]>,
    /// The nodal loads per case (N), for checks.
    pub loads: Vec<Vec<f64>>,
    /// The mesh's mass properties (the loads' ones).
    pub mass: MeshMassProperties,
    /// Nodes outside the bands (judged).
    pub judged: Vec<bool>,
    /// Which cases the pin force uses.
    pub pin: PinBasis,
    pub stats: SolveStats,
    pub timings: Timings,
}

/// Solves the unit cases on `mesh` (rod frame, m) with one factorisation: the six of a uniform
/// bore load, or with a cosine bore load the four body forces and the pin in every direction
/// (see the module documentation; [`unit_solutions_for`] solves only the directions a cycle uses).
pub fn unit_solutions(
    mesh: &TetMesh,
    material: &Material,
    bores: &BoreSpec,
    options: &CycleOptions,
) -> Result<UnitSolutions> {
    unit_solutions_with(mesh, material, bores, options, None)
}

/// [`unit_solutions`] for the cycle `instants`: with a cosine bore load only the unit directions
/// next to a force direction of the cycle are solved.
pub fn unit_solutions_for(
    mesh: &TetMesh,
    material: &Material,
    bores: &BoreSpec,
    options: &CycleOptions,
    instants: &[RodFrameInstant],
) -> Result<UnitSolutions> {
    unit_solutions_with(mesh, material, bores, options, Some(instants))
}

/// The number of unit directions of a step (360 / step, which must be a whole number ≥ 4).
fn directions_of(step_deg: f64) -> Result<usize> {
    let n = 360.0 / step_deg;
    if !(n.is_finite() && n >= 4.0 && (n - n.round()).abs() < 1e-9) {
        return Err(FemError::InvalidInput(format!(
            "the cosine bore load's direction step must divide 360° into at least 4, got {step_deg}°"
        )));
    }
    Ok(n.round() as usize)
}

/// The two neighbouring unit directions of the force `f` (rod frame, N) and its exact
/// decomposition in them: ((j, a), (j + 1 mod n, b)), see the module documentation.
fn direction_weights(f: [f64; 2], step_deg: f64, n: usize) -> ((usize, f64), (usize, f64)) {
    let mag = f[0].hypot(f[1]);
    if mag == 0.0 {
        return ((0, 0.0), (1 % n, 0.0));
    }
    let step = step_deg.to_radians();
    let theta = f[1].atan2(f[0]).rem_euclid(std::f64::consts::TAU);
    let j = ((theta / step).floor() as usize).min(n - 1);
    let t0 = j as f64 * step;
    let sd = step.sin();
    let a = mag * (t0 + step - theta).sin() / sd;
    let b = mag * (theta - t0).sin() / sd;
    ((j, a), ((j + 1) % n, b))
}

fn unit_solutions_with(
    mesh: &TetMesh,
    material: &Material,
    bores: &BoreSpec,
    options: &CycleOptions,
    instants: Option<&[RodFrameInstant]>,
) -> Result<UnitSolutions> {
    material.validate()?;
    if !(options.density_kg_m3.is_finite() && options.density_kg_m3 > 0.0) {
        return Err(FemError::InvalidInput(format!(
            "density must be > 0, got {}",
            options.density_kg_m3
        )));
    }
    let boundary = boundary_faces(mesh)?;
    let (loaded, fixed) = find_bores(mesh, &boundary, bores)?;
    let rho = options.density_kg_m3;
    let body = |loads: &mut Vec<Vec<f64>>| {
        for shape in [
            BodyShape::UniformX,
            BodyShape::UniformY,
            BodyShape::Centrifugal,
            BodyShape::AngularAccel,
        ] {
            loads.push(body_force_load(mesh, rho, shape));
        }
    };
    let mut loads = Vec::with_capacity(6);
    let pin = match bores.bore_load.linear() {
        BoreLoad::Uniform => {
            for d in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
                loads.push(uniform_traction_with_resultant(mesh, &loaded.faces, d)?.forces);
            }
            body(&mut loads);
            PinBasis::Linear
        }
        BoreLoad::Cosine | BoreLoad::Contact => {
            body(&mut loads);
            let step_deg = options.direction_step_deg;
            let n = directions_of(step_deg)?;
            let mut used = vec![instants.is_none(); n];
            for inst in instants.unwrap_or_default() {
                let ((j, _), (j1, _)) = direction_weights(inst.f_a_on_rod_n, step_deg, n);
                used[j] = true;
                used[j1] = true;
            }
            let axis = bores.unit_axis()?;
            let mut case_of = vec![None; n];
            for (j, u) in used.iter().enumerate() {
                if !*u {
                    continue;
                }
                let (s, c) = (j as f64 * step_deg).to_radians().sin_cos();
                let load = pin_load(
                    mesh,
                    &loaded.faces,
                    bores.loaded_centre_m,
                    axis,
                    [c, s, 0.0],
                    BoreLoad::Cosine,
                )?;
                case_of[j] = Some(loads.len());
                loads.push(load.forces);
            }
            PinBasis::Directions { step_deg, case_of }
        }
    };
    let prescribed: Vec<(usize, f64)> = fixed
        .nodes
        .iter()
        .flat_map(|&n| (0..3).map(move |j| (3 * n + j, 0.0)))
        .collect();
    let sol = solve_static(&StaticProblem {
        mesh,
        material: *material,
        prescribed,
        loads: loads.clone(),
        quadrature: options.quadrature,
    })?;
    let t = std::time::Instant::now();
    let stresses = sol
        .displacements
        .par_iter()
        .map(|u| stress_field(mesh, material, u).map(|f| f.averaged))
        .collect::<Result<Vec<_>>>()?;
    let reactions_n = sol
        .reactions
        .iter()
        .map(|r| {
            let mut s = [0.0; 3];
            for (d, v) in r.iter().enumerate() {
                s[d % 3] += v;
            }
            s
        })
        .collect();
    let judged = judged_nodes(
        mesh,
        &Bands {
            fixed_faces: &fixed.faces,
            fixed_band_m: options.fixed_band_m,
            singular_edges_m: &options.singular_edges_m,
            singular_band_m: options.singular_band_m,
        },
    )
    .judged;
    let mut timings = sol.timings;
    timings.stress_s = t.elapsed().as_secs_f64();
    Ok(UnitSolutions {
        stresses,
        displacements: sol.displacements,
        reactions_n,
        loads,
        mass: mesh_mass_properties(mesh, rho),
        judged,
        pin,
        stats: sol.stats,
        timings,
    })
}

/// The six (case, coefficient) terms of one instant's load.
pub type Terms = [(usize, f64); 6];

impl UnitSolutions {
    /// The terms of the load at instant `inst`: with a uniform bore load the cases in the order
    /// of [`UNIT_CASES`] with [`coefficients`]; with a cosine one the two unit directions around
    /// the force with their weights, then the four body-force cases.
    pub fn terms(&self, inst: &RodFrameInstant) -> Result<Terms> {
        let c = coefficients(inst);
        match &self.pin {
            PinBasis::Linear => Ok(std::array::from_fn(|k| (k, c[k]))),
            PinBasis::Directions { step_deg, case_of } => {
                let ((j, a), (j1, b)) =
                    direction_weights(inst.f_a_on_rod_n, *step_deg, case_of.len());
                let case = |j: usize| {
                    case_of[j].ok_or_else(|| {
                        FemError::InvalidInput(format!(
                            "the pin's unit case at {}° was not solved for this cycle",
                            j as f64 * step_deg
                        ))
                    })
                };
                Ok([
                    (case(j)?, a),
                    (case(j1)?, b),
                    (0, c[2]),
                    (1, c[3]),
                    (2, c[4]),
                    (3, c[5]),
                ])
            }
        }
    }
    /// The stress at node `n` for the terms `t` (Pa).
    pub fn stress_at(&self, n: usize, t: &Terms) -> [f64; 6] {
        let mut s = [0.0; 6];
        for (k, ck) in t {
            let sk = &self.stresses[*k][n];
            for j in 0..6 {
                s[j] += ck * sk[j];
            }
        }
        s
    }
    /// The reaction at B for the terms `t` (N).
    pub fn reaction(&self, t: &Terms) -> [f64; 3] {
        let mut r = [0.0; 3];
        for (k, ck) in t {
            for (r, v) in r.iter_mut().zip(&self.reactions_n[*k]) {
                *r += ck * v;
            }
        }
        r
    }
}
