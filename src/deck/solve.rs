//! A deck's model to rodstudy's [`StaticProblem`] and back: one linear static solve per step,
//! nodal results per deck node, the requested node and element sets, reaction totals.
//!
//! * Element matrices with the 4-point rule on every element ([`QuadratureChoice::Degree2`]), the
//!   rule CalculiX integrates C3D10 with (`gauss3d5`, manual "C3D10": "4 integration points"); on
//!   straight-sided elements it is exact, on curved ones it is CalculiX's choice, kept so that the
//!   two codes solve the same discrete problem.
//! * Pressure on a face (`*DLOAD Pk`): the consistent nodal forces f_a = −∫ N_a p n dA on the
//!   6-node face, with the 3-point degree-2 triangle rule CalculiX uses for C3D10 faces
//!   (`mint2d=3`, `gauss2d5`: points (1/6, 1/6), (2/3, 1/6), (1/6, 2/3), weights 1/6; ccx source
//!   `e_c3d.f`): exact on a straight face, CalculiX's approximation on a curved one. Gravity (`GRAV`): f_a = ∫ N_a ρ g n dV with the
//!   4-point rule (exact on straight-sided elements).
//! * Nodal stresses as CalculiX forms them ([`crate::fem::nodal_stress`]).
//! * RF: the reaction K u − f at the supported DOFs, zero at free ones (ccx's *NODE PRINT RF prints
//!   the internal force K u at every DOF: equal at supported DOFs without applied load; at a free
//!   DOF ccx shows the applied load).
//!
//! Units: as in the deck (no conversion); stress components in CalculiX's order
//! `[sxx, syy, szz, sxy, sxz, syz]`.

use std::collections::{BTreeMap, HashMap};
use std::time::Instant;

use serde::Serialize;

use super::model::{ElementKind, Model, Step};
use crate::fem::boundary::face_point;
use crate::fem::element::shape_gradients;
use crate::fem::error::{FemError, Result};
use crate::fem::nodal_stress::{Extrapolation, calculix_nodal_stress};
use crate::fem::quadrature::TET4;
use crate::fem::shape::{TET10_EDGES, TET10_FACES, tet10_shape};
use crate::fem::statics::{SolveStats, Timings};
use crate::fem::{Material, QuadratureChoice, StaticProblem, TetMesh, solve_static};

/// CalculiX's face rule for C3D10 (`gauss2d5`): 3 points, degree 2.
const FACE_POINTS: [[f64; 2]; 3] = [
    [1.0 / 6.0, 1.0 / 6.0],
    [2.0 / 3.0, 1.0 / 6.0],
    [1.0 / 6.0, 2.0 / 3.0],
];
const FACE_WEIGHT: f64 = 1.0 / 6.0;

/// Options of [`solve_model`].
#[derive(Clone, Copy, Debug, Default)]
pub struct SolveOptions {
    /// Corner extrapolation of the nodal stresses.
    pub extrapolation: Extrapolation,
}

/// Values of one requested node set.
#[derive(Clone, Debug, Serialize)]
pub struct NodeSetOut {
    /// Node ids.
    pub nodes: Vec<i64>,
    /// Displacements.
    #[serde(rename = "U", skip_serializing_if = "Option::is_none")]
    pub u: Option<Vec<[f64; 3]>>,
    /// Nodal stresses `[sxx, syy, szz, sxy, sxz, syz]`.
    #[serde(rename = "S", skip_serializing_if = "Option::is_none")]
    pub s: Option<Vec<[f64; 6]>>,
    /// Reactions.
    #[serde(rename = "RF", skip_serializing_if = "Option::is_none")]
    pub rf: Option<Vec<[f64; 3]>>,
    /// Sum of RF over the set (TOTALS=YES/ONLY).
    #[serde(rename = "RF_total", skip_serializing_if = "Option::is_none")]
    pub rf_total: Option<[f64; 3]>,
}

/// Stresses at the integration points of one requested element set.
#[derive(Clone, Debug, Serialize)]
pub struct ElementSetOut {
    /// Element ids.
    pub elements: Vec<i64>,
    /// Per element, the four integration points' `[sxx, syy, szz, sxy, sxz, syz]`.
    #[serde(rename = "S")]
    pub s: Vec<[[f64; 6]; 4]>,
}

/// The results of one step.
#[derive(Clone, Debug, Serialize)]
pub struct StepResult {
    /// 1-based step number.
    pub step: usize,
    /// Line of its `*STEP`.
    pub line: usize,
    /// Requested node sets (`*NODE PRINT`).
    pub node_sets: BTreeMap<String, NodeSetOut>,
    /// Requested element sets (`*EL PRINT`).
    pub element_sets: BTreeMap<String, ElementSetOut>,
    /// Σ RF per supported node set (single nodes as `NODE <id>`).
    pub reaction_totals: BTreeMap<String, [f64; 3]>,
    /// Σ of the applied nodal loads (CLOAD, DLOAD).
    pub applied_total: [f64; 3],
    /// ‖K u − f‖/‖f‖ on the free DOFs.
    pub residual_rel: f64,
    /// Solver sizes.
    pub stats: SolveStats,
    /// Solver times (stress recovery in `stress_s`).
    pub timings: Timings,
    /// Variables of `*NODE FILE`/`*EL FILE` (for the VTU file).
    #[serde(skip)]
    pub file_vars: Vec<String>,
    /// Displacements per deck node.
    #[serde(skip)]
    pub u: Vec<[f64; 3]>,
    /// Reactions per deck node.
    #[serde(skip)]
    pub rf: Vec<[f64; 3]>,
    /// Nodal stresses per deck node (CalculiX order).
    #[serde(skip)]
    pub s: Vec<[f64; 6]>,
}

/// The solved deck.
#[derive(Clone, Debug)]
pub struct DeckSolution {
    /// The mesh solved (C3D4 promoted; mesh node i is deck node `deck_node[i]` or an added
    /// midside node).
    pub mesh: TetMesh,
    /// Per mesh node: its deck node index, if any.
    pub deck_node: Vec<Option<usize>>,
    /// Node ids of the deck (file order).
    pub node_ids: Vec<i64>,
    /// Element ids (file order = mesh order).
    pub element_ids: Vec<i64>,
    /// The material.
    pub material: Material,
    /// Per step.
    pub steps: Vec<StepResult>,
}

fn ccx_order(s: &[f64; 6]) -> [f64; 6] {
    [s[0], s[1], s[2], s[3], s[5], s[4]]
}

/// Solves every step of `model`.
pub fn solve_model(model: &Model, options: SolveOptions) -> Result<DeckSolution> {
    let (mesh, deck_node, mesh_of, midsides) =
        build_mesh(model).map_err(|e| with_deck_element(model, e))?;
    let (material, density) = element_materials(model)?;
    let mut steps = Vec::with_capacity(model.steps.len());
    for (k, step) in model.steps.iter().enumerate() {
        steps.push(
            solve_step(
                model,
                &MeshOfDeck {
                    mesh: &mesh,
                    mesh_of: &mesh_of,
                    midsides: &midsides,
                },
                material,
                &density,
                step,
                k + 1,
                options,
            )
            .map_err(|e| with_deck_element(model, e))?,
        );
    }
    Ok(DeckSolution {
        mesh,
        deck_node,
        node_ids: model.node_ids.clone(),
        element_ids: model.elements.iter().map(|e| e.id).collect(),
        material,
        steps,
    })
}

/// An element's error (an inverted element, midside nodes out of order) named by the deck's
/// element id and line instead of its position.
fn with_deck_element(model: &Model, e: FemError) -> FemError {
    let element = match &e {
        FemError::NegativeJacobian { element, .. } | FemError::MidsideNodeOrder { element, .. } => {
            *element
        }
        _ => return e,
    };
    let Some(el) = model.elements.get(element) else {
        return e;
    };
    let message = e.to_string();
    let detail = message
        .split_once(": ")
        .map_or(message.as_str(), |(_, rest)| rest);
    FemError::InvalidInput(format!(
        "element {} (line {}): {detail}; check the element's node order (corners 1-2-3 anticlockwise \
         seen from corner 4, then the midside nodes \
         of edges 1-2, 2-3, 3-1, 1-4, 2-4, 3-4) and its nodes' coordinates",
        el.id, el.line
    ))
}

/// The added midside node of a C3D4 edge and the edge's two corners (mesh node indices).
type Midside = (usize, usize, usize);

type MeshParts = (
    TetMesh,
    Vec<Option<usize>>,
    Vec<Option<usize>>,
    Vec<Midside>,
);

/// The mesh a step is solved on and how its nodes relate to the deck's.
struct MeshOfDeck<'a> {
    mesh: &'a TetMesh,
    /// Per deck node its mesh node.
    mesh_of: &'a [Option<usize>],
    /// The midside nodes added to C3D4 edges.
    midsides: &'a [Midside],
}

/// The tet10 mesh: the deck nodes used by elements (file order), then added midside nodes of
/// C3D4 edges. Returns the mesh, per mesh node its deck node, per deck node its mesh node, and the
/// added midside nodes with their edges.
fn build_mesh(model: &Model) -> Result<MeshParts> {
    let mut mesh_of: Vec<Option<usize>> = vec![None; model.nodes.len()];
    for e in &model.elements {
        for &n in &e.nodes {
            mesh_of[n] = Some(0);
        }
    }
    let mut nodes = Vec::new();
    let mut deck_node = Vec::new();
    for (i, m) in mesh_of.iter_mut().enumerate() {
        if m.is_some() {
            *m = Some(nodes.len());
            nodes.push(model.nodes[i]);
            deck_node.push(Some(i));
        }
    }
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    let mut midsides = Vec::new();
    let mut elements = Vec::with_capacity(model.elements.len());
    for e in &model.elements {
        let c = |a: usize| mesh_of[e.nodes[a]].expect("used");
        let el: [usize; 10] = match model.kind {
            Some(ElementKind::C3d4) => {
                let mut el = [0; 10];
                for (a, slot) in el.iter_mut().take(4).enumerate() {
                    *slot = c(a);
                }
                for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
                    let key = (el[*a].min(el[*b]), el[*a].max(el[*b]));
                    el[4 + k] = *edges.entry(key).or_insert_with(|| {
                        let (p, q) = (nodes[key.0], nodes[key.1]);
                        nodes.push(std::array::from_fn(|j| 0.5 * (p[j] + q[j])));
                        deck_node.push(None);
                        midsides.push((nodes.len() - 1, key.0, key.1));
                        nodes.len() - 1
                    });
                }
                el
            }
            _ => std::array::from_fn(c),
        };
        elements.push(el);
    }
    let mesh = TetMesh::new(nodes, elements)?;
    Ok((mesh, deck_node, mesh_of, midsides))
}

/// The one elastic material of the sections, and each element's density.
fn element_materials(model: &Model) -> Result<(Material, Vec<Option<f64>>)> {
    let mut section_of: Vec<Option<usize>> = vec![None; model.elements.len()];
    let mut elastic: Option<((f64, f64), String)> = None;
    let mut density = vec![None; model.elements.len()];
    for (s, (elset, name, line)) in model.sections.iter().enumerate() {
        let err = |m: String| FemError::InvalidInput(format!("*SOLID SECTION (line {line}): {m}"));
        let mat = model
            .materials
            .get(name)
            .ok_or_else(|| err(format!("material {name} is not defined")))?;
        let el = mat
            .elastic
            .ok_or_else(|| err(format!("material {name} has no *ELASTIC")))?;
        match &elastic {
            None => elastic = Some((el, name.clone())),
            Some((e0, n0)) if *e0 != el => {
                return Err(err(format!(
                    "material {name} differs from {n0}: one elastic material per deck is supported"
                )));
            }
            _ => {}
        }
        for &e in &model.elsets[elset] {
            if let Some(s0) = section_of[e] {
                return Err(err(format!(
                    "element {} is already in the section of line {}",
                    model.elements[e].id, model.sections[s0].2
                )));
            }
            section_of[e] = Some(s);
            density[e] = mat.density;
        }
    }
    if let Some(e) = section_of.iter().position(Option::is_none) {
        return Err(FemError::InvalidInput(format!(
            "element {} is in no *SOLID SECTION",
            model.elements[e].id
        )));
    }
    let ((e, nu), _) = elastic.expect("at least one section");
    let material = Material {
        youngs_modulus_pa: e,
        poisson_ratio: nu,
    };
    material.validate()?;
    Ok((material, density))
}

/// Largest relative residual ‖K u − f‖ / ‖f‖ of a step's solution: above it the supports leave
/// a rigid-body motion free and the factorisation went through on round-off pivots.
const MAX_RESIDUAL_REL: f64 = 1e-6;

fn solve_step(
    model: &Model,
    on: &MeshOfDeck<'_>,
    material: Material,
    density: &[Option<f64>],
    step: &Step,
    number: usize,
    options: SolveOptions,
) -> Result<StepResult> {
    let MeshOfDeck {
        mesh,
        mesh_of,
        midsides,
    } = *on;
    let id = |n: usize| model.node_ids[n];
    let mut prescribed: Vec<(usize, f64)> = step
        .boundary
        .iter()
        .filter_map(|(&(n, dof), &v)| mesh_of[n].map(|m| (3 * m + dof, v)))
        .collect();
    // A C3D4 edge is straight and its displacement linear (ccx's C3D4): the midside node added to
    // an edge whose two corners are prescribed in a dof is prescribed at their mean in that dof,
    // so that a support on a face holds the whole face
    let given: HashMap<usize, f64> = prescribed.iter().copied().collect();
    for &(m, a, b) in midsides {
        for j in 0..3 {
            if let (Some(va), Some(vb)) = (given.get(&(3 * a + j)), given.get(&(3 * b + j))) {
                prescribed.push((3 * m + j, 0.5 * (va + vb)));
            }
        }
    }
    let mut f = vec![0.0; mesh.n_dofs()];
    for (&(n, dof), &v) in &step.cloads {
        let m = mesh_of[n].ok_or_else(|| {
            FemError::InvalidInput(format!(
                "step {number}: *CLOAD on node {}, which no element uses",
                id(n)
            ))
        })?;
        f[3 * m + dof] += v;
    }
    for (&(e, face), &p) in &step.pressures {
        let el = &mesh.elements()[e];
        let fnodes: [usize; 6] = std::array::from_fn(|a| el[TET10_FACES[face][a]]);
        let x: [[f64; 3]; 6] = std::array::from_fn(|a| mesh.nodes()[fnodes[a]]);
        for q in &FACE_POINTS {
            let w = FACE_WEIGHT;
            let (_, c, n) = face_point(&x, *q);
            for a in 0..6 {
                for j in 0..3 {
                    f[3 * fnodes[a] + j] -= w * n[a] * p * c[j];
                }
            }
        }
    }
    for (&e, g) in &step.gravity {
        let rho = density[e].ok_or_else(|| {
            FemError::InvalidInput(format!(
                "step {number}: GRAV on element {}, whose material has no *DENSITY",
                model.elements[e].id
            ))
        })?;
        let x = mesh.element_coords(e);
        let el = &mesh.elements()[e];
        for (xi, w) in TET4.points.iter().zip(TET4.weights) {
            let (_, det) = shape_gradients(&x, *xi, e, "integration point")?;
            let n = tet10_shape(*xi);
            for a in 0..10 {
                for j in 0..3 {
                    f[3 * el[a] + j] += w * det * n[a] * rho * g.g * g.dir[j];
                }
            }
        }
    }
    let mut applied_total = [0.0; 3];
    for (i, v) in f.iter().enumerate() {
        applied_total[i % 3] += v;
    }
    let problem = StaticProblem {
        mesh,
        material,
        prescribed,
        loads: vec![f],
        quadrature: QuadratureChoice::Degree2,
    };
    // the solver's refusal (a mechanism) names the step; an element's (an inverted one) goes
    // to with_deck_element unchanged
    let sol = solve_static(&problem).map_err(|e| match e {
        FemError::Solver(m) => {
            FemError::InvalidInput(format!("step {number} (line {}): {m}", step.line))
        }
        e => e,
    })?;
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    // a solution beyond f64's range is the data's (loads, constants, coordinates out of any
    // physical range), never the supports'
    let overflow = |what: &str| {
        let largest = problem.loads[0].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        FemError::InvalidInput(format!(
            "step {number} (line {}): the solution overflows f64 (non-finite {what}; largest \
             nodal load {largest:.3e}): the loads, the material constants or the node \
             coordinates are out of range: check their values and units (*CLOAD, *DLOAD, \
             *ELASTIC, *NODE)",
            step.line
        ))
    };
    if !(sol.residual_rel[0].is_finite() && finite(&sol.displacements[0])) {
        return Err(overflow("displacements or residual"));
    }
    if sol.residual_rel[0] > MAX_RESIDUAL_REL {
        return Err(FemError::InvalidInput(format!(
            "step {number}: the solution does not satisfy K u = f (relative residual {:.1e}): the \
             supports leave a rigid-body motion free (a mechanism); support the model against \
             translation and rotation in all three directions (*BOUNDARY)",
            sol.residual_rel[0]
        )));
    }
    let ts = Instant::now();
    let u = &sol.displacements[0];
    let stress = calculix_nodal_stress(mesh, &material, u, options.extrapolation)?;
    if !finite(stress.nodal.as_flattened()) {
        return Err(overflow("stresses"));
    }
    let mut timings = sol.timings;
    timings.stress_s = ts.elapsed().as_secs_f64();
    // an added midside node's reaction goes half to each corner of its edge (the constraint
    // u_m = (u_a + u_b) / 2 in virtual work), so that the deck's nodes carry every reaction
    let mut r = sol.reactions[0].clone();
    for &(m, a, b) in midsides {
        for j in 0..3 {
            let half = 0.5 * std::mem::take(&mut r[3 * m + j]);
            r[3 * a + j] += half;
            r[3 * b + j] += half;
        }
    }
    let r = &r;
    let nn = model.nodes.len();
    let pick3 = |v: &[f64], n: usize| -> [f64; 3] {
        mesh_of[n].map_or([0.0; 3], |m| [v[3 * m], v[3 * m + 1], v[3 * m + 2]])
    };
    let ud: Vec<[f64; 3]> = (0..nn).map(|n| pick3(u, n)).collect();
    let rf: Vec<[f64; 3]> = (0..nn).map(|n| pick3(r, n)).collect();
    let s: Vec<[f64; 6]> = (0..nn)
        .map(|n| mesh_of[n].map_or([0.0; 6], |m| ccx_order(&stress.nodal[m])))
        .collect();
    let sum3 = |nodes: &[usize]| -> [f64; 3] {
        let mut t = [0.0; 3];
        for &n in nodes {
            for j in 0..3 {
                t[j] += rf[n][j];
            }
        }
        t
    };
    // several requests on one set (U on one card, RF on another) print all their variables
    let mut requests: BTreeMap<&String, (Vec<&String>, bool)> = BTreeMap::new();
    for (name, vars, totals) in &step.node_print {
        let r = requests.entry(name).or_default();
        r.0.extend(vars);
        r.1 |= *totals;
    }
    let mut node_sets = BTreeMap::new();
    for (name, (vars, totals)) in requests {
        let nodes = &model.nsets[name];
        let has = |v: &str| vars.iter().any(|x| *x == v);
        node_sets.insert(
            name.clone(),
            NodeSetOut {
                nodes: nodes.iter().map(|&n| id(n)).collect(),
                u: has("U").then(|| nodes.iter().map(|&n| ud[n]).collect()),
                s: has("S").then(|| nodes.iter().map(|&n| s[n]).collect()),
                rf: has("RF").then(|| nodes.iter().map(|&n| rf[n]).collect()),
                rf_total: (has("RF") && totals).then(|| sum3(nodes)),
            },
        );
    }
    let mut element_sets = BTreeMap::new();
    for (name, _) in &step.el_print {
        let els = &model.elsets[name];
        element_sets.insert(
            name.clone(),
            ElementSetOut {
                elements: els.iter().map(|&e| model.elements[e].id).collect(),
                s: els
                    .iter()
                    .map(|&e| stress.integration_points[e].map(|v| ccx_order(&v)))
                    .collect(),
            },
        );
    }
    let reaction_totals = step
        .supported_sets
        .iter()
        .map(|(name, nodes)| (name.clone(), sum3(nodes)))
        .collect();
    Ok(StepResult {
        step: number,
        line: step.line,
        node_sets,
        element_sets,
        reaction_totals,
        applied_total,
        residual_rel: sol.residual_rel[0],
        stats: sol.stats,
        timings,
        file_vars: step.file_vars.clone(),
        u: ud,
        rf,
        s,
    })
}
