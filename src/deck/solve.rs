//! A deck's steps solved: per step the constraints u = T q + g ([`super::system`]), the reduced
//! stiffness Tᵀ K T factorised once, then
//!
//! * `*STATIC`: Tᵀ K T q = Tᵀ (f − K g);
//! * `*BUCKLE`: the static solution of the step's loads, its stress σ⁰ at the integration points,
//!   and the lowest factors λ of Tᵀ K T φ = λ Tᵀ (−K_σ(σ⁰)) T φ (ccx's buckling factors; the
//!   manual, "*BUCKLE");
//! * `*FREQUENCY`: the lowest eigenvalues ω² of Tᵀ K T φ = ω² Tᵀ M T φ with the consistent mass
//!   (the manual, "*FREQUENCY": eigenvalue ω², ω in rad/time, ω/2π in cycles/time);
//!
//! the eigenpairs by [`crate::fem::subspace`]. Reported per node as ccx reports them: U, S and E
//! ([`super::fields`]), and RF = K u, the internal force at every DOF of the node (ccx's RF: equal
//! to the reaction at a support without load on it; at a loaded or free node it shows the load
//! the node takes, e.g. the self-weight share of a supported node). Units as in the deck;
//! stress and strain components in CalculiX's printed order `[xx, yy, zz, xy, xz, yz]`.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use serde::Serialize;

use super::contact::{ContactOut, contact_forces};
use super::fields::field;
use super::model::{Analysis, Model, Step, Totals};
use super::system::{DeckSystem, deck_system, merged_requests, step_loads, step_reduction};
use crate::fem::assembly::SparseSym;
use crate::fem::constraints::Reduction;
use crate::fem::error::{FemError, Result};
use crate::fem::nodal_stress::Extrapolation;
use crate::fem::reduced_system::{ReducedPattern, element_product, factorise};
use crate::fem::solid_element::{geometric_stiffness, mass, stiffness};
use crate::fem::solver::CholeskyFactor;
use crate::fem::subspace::lowest_eigenpairs;

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
    /// Nodal strains `[exx, eyy, ezz, exy, exz, eyz]` (tensor shears).
    #[serde(rename = "E", skip_serializing_if = "Option::is_none")]
    pub e: Option<Vec<[f64; 6]>>,
    /// RF = K u per node.
    #[serde(rename = "RF", skip_serializing_if = "Option::is_none")]
    pub rf: Option<Vec<[f64; 3]>>,
    /// Sum of RF over the set (TOTALS=YES/ONLY).
    #[serde(rename = "RF_total", skip_serializing_if = "Option::is_none")]
    pub rf_total: Option<[f64; 3]>,
}

/// Integration-point values of one requested element set.
#[derive(Clone, Debug, Serialize)]
pub struct ElementSetOut {
    /// Element ids.
    pub elements: Vec<i64>,
    /// Per element its integration points' stresses (4 for C3D10, 1 for C3D4).
    #[serde(rename = "S", skip_serializing_if = "Option::is_none")]
    pub s: Option<Vec<Vec<[f64; 6]>>>,
    /// Per element its integration points' strains.
    #[serde(rename = "E", skip_serializing_if = "Option::is_none")]
    pub e: Option<Vec<Vec<[f64; 6]>>>,
}

/// The eigenvalues of a `*BUCKLE` or `*FREQUENCY` step.
#[derive(Clone, Debug, Serialize)]
pub struct EigenOut {
    /// Buckling factors (ascending), for *BUCKLE.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub buckling_factors: Vec<f64>,
    /// Eigenvalues ω² (ascending), for *FREQUENCY.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub eigenvalues: Vec<f64>,
    /// Frequencies ω/2π (cycles per time), for *FREQUENCY.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub frequencies: Vec<f64>,
    /// Subspace iterations made.
    pub iterations: usize,
}

/// The results of one step.
#[derive(Clone, Debug, Serialize)]
pub struct StepResult {
    /// 1-based step number.
    pub step: usize,
    /// Line of its `*STEP`.
    pub line: usize,
    /// "static", "buckle" or "frequency".
    pub analysis: &'static str,
    /// Buckling factors or frequencies.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub eigen: Option<EigenOut>,
    /// Requested node sets (`*NODE PRINT`).
    pub node_sets: BTreeMap<String, NodeSetOut>,
    /// Requested element sets (`*EL PRINT`).
    pub element_sets: BTreeMap<String, ElementSetOut>,
    /// The contact of the step's `*CONTACT PAIR`s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact: Option<ContactOut>,
    /// Σ RF (= K u) per supported node set (single nodes as `NODE <id>`).
    pub reaction_totals: BTreeMap<String, [f64; 3]>,
    /// Σ of the applied nodal loads.
    pub applied_total: [f64; 3],
    /// ‖Tᵀ K T q − b‖/‖b‖ of the static solution.
    pub residual_rel: f64,
    /// Independent DOFs (equations).
    pub equations: usize,
    /// Seconds: assembly and factorisation (none when the step reuses the previous step's
    /// factor), solve and results.
    pub wall_s: f64,
    /// Variables of `*NODE FILE`/`*EL FILE` (for the VTU file).
    #[serde(skip)]
    pub file_vars: Vec<String>,
    /// Displacements per deck node (static; the static pre-load's for *BUCKLE).
    #[serde(skip)]
    pub u: Vec<[f64; 3]>,
    /// RF per deck node.
    #[serde(skip)]
    pub rf: Vec<[f64; 3]>,
    /// Nodal stresses per deck node (CalculiX order).
    #[serde(skip)]
    pub s: Vec<[f64; 6]>,
    /// Nodal strains per deck node (CalculiX order).
    #[serde(skip)]
    pub e: Vec<[f64; 6]>,
    /// Mode shapes per deck node (largest component 1), for eigen steps.
    #[serde(skip)]
    pub modes: Vec<Vec<[f64; 3]>>,
}

/// The solved deck.
#[derive(Clone, Debug)]
pub struct DeckSolution {
    /// Node ids of the deck (file order).
    pub node_ids: Vec<i64>,
    /// Node coordinates.
    pub nodes: Vec<[f64; 3]>,
    /// Per element: id and deck node indices (4 or 10).
    pub elements: Vec<(i64, Vec<usize>)>,
    /// Per deck node: used by an element.
    pub used: Vec<bool>,
    /// 3 × the nodes used by elements.
    pub dofs: usize,
    /// What was read and not used, or skipped, and elements inverted at a corner.
    pub warnings: Vec<String>,
    /// Per step.
    pub steps: Vec<StepResult>,
}

fn ccx_order(s: &[f64; 6]) -> [f64; 6] {
    [s[0], s[1], s[2], s[3], s[5], s[4]]
}

/// Largest relative residual of a static solution: above it the supports leave a rigid-body
/// motion free and the factorisation went through on round-off pivots.
const MAX_RESIDUAL_REL: f64 = 1e-6;

/// Solves every step of `model` (read from `path`, which names it in errors).
pub fn solve_model(model: &Model, options: SolveOptions) -> Result<DeckSolution> {
    solve_model_at(Path::new("deck"), model, options)
}

/// [`solve_model`], errors naming `path`.
pub fn solve_model_at(path: &Path, model: &Model, options: SolveOptions) -> Result<DeckSolution> {
    let sys = deck_system(path, model)?;
    let mut warnings = model.warnings.clone();
    if !sys.inverted_corners.is_empty() {
        warnings.push(format!(
            "{} element(s) with a negative Jacobian determinant at a corner and a positive one at \
             every integration point, solved as ccx solves them (their corner stresses are \
             extrapolated from the integration points; check their midside nodes): elements {}",
            sys.inverted_corners.len(),
            sys.inverted_corners
                .iter()
                .map(i64::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    let mut steps = Vec::with_capacity(model.steps.len());
    let mut last: Option<StepSystem> = None;
    for (k, step) in model.steps.iter().enumerate() {
        let number = k + 1;
        let t = Instant::now();
        let at = at_step(number, step);
        let reduction = step_reduction(path, model, &sys, step)?;
        let system = match last.take() {
            Some(s) if s.reduction == reduction => s,
            _ => step_system(model, &sys, reduction).map_err(|e| at(e.to_string()))?,
        };
        let mut result = solve_step(path, model, &sys, &system, step, number, options)?;
        // the step's time includes the building of its system
        result.wall_s = t.elapsed().as_secs_f64();
        steps.push(result);
        last = Some(system);
    }
    Ok(DeckSolution {
        node_ids: model.node_ids.clone(),
        nodes: model.nodes.clone(),
        elements: model
            .elements
            .iter()
            .map(|e| (e.id, e.nodes.clone()))
            .collect(),
        dofs: 3 * sys.used.iter().filter(|u| **u).count(),
        used: sys.used,
        warnings,
        steps,
    })
}

/// The reduced stiffness of a step's constraints, factorised; a later step with the same
/// constraints (supports, local axes, equations and prescribed values) uses it again.
struct StepSystem {
    reduction: Reduction,
    pattern: ReducedPattern,
    k: SparseSym,
    dirichlet: Vec<f64>,
    factor: CholeskyFactor,
}

fn step_system(model: &Model, sys: &DeckSystem, reduction: Reduction) -> Result<StepSystem> {
    let pattern = ReducedPattern::new(model.nodes.len(), &sys.connectivity, &reduction);
    let (k, dirichlet) = pattern.assemble(&sys.connectivity, &reduction, |e| {
        Ok(stiffness(&sys.points[e], &sys.material[e].0))
    })?;
    let factor = factorise(&k, model.nodes.len(), &sys.connectivity, &reduction)?;
    Ok(StepSystem {
        reduction,
        pattern,
        k,
        dirichlet,
        factor,
    })
}

/// Errors of step `number`, naming its line.
fn at_step(number: usize, step: &Step) -> impl Fn(String) -> FemError + '_ {
    move |m: String| FemError::InvalidInput(format!("step {number} (line {}): {m}", step.line))
}

fn solve_step(
    path: &Path,
    model: &Model,
    sys: &DeckSystem,
    system: &StepSystem,
    step: &Step,
    number: usize,
    options: SolveOptions,
) -> Result<StepResult> {
    let t = Instant::now();
    let at = at_step(number, step);
    let StepSystem {
        reduction,
        pattern,
        k,
        dirichlet,
        factor,
    } = system;
    let k_of = |e: usize| Ok(stiffness(&sys.points[e], &sys.material[e].0));
    let analysis = step.analysis.unwrap_or_default();
    let mut f = step_loads(path, model, sys, step, number)?;
    if matches!(analysis, Analysis::Frequency { .. }) {
        // a frequency step has no loads (ccx ignores them)
        f.fill(0.0);
    }
    let mut applied_total = [0.0; 3];
    for (i, v) in f.iter().enumerate() {
        applied_total[i % 3] += v;
    }
    let mut b = reduction.restrict(&f);
    for (bi, di) in b.iter_mut().zip(dirichlet) {
        *bi += di;
    }
    let mut q = b.clone();
    factor.solve_in_place(&mut q, 1);
    let mut contact = None;
    if !model.contact_pairs.is_empty() {
        if !matches!(analysis, Analysis::Static) {
            return Err(at(
                "*CONTACT PAIR in a *BUCKLE or *FREQUENCY step is not supported (contact is \
                 solved in *STATIC steps)"
                    .into(),
            ));
        }
        let u0 = reduction.expand(&q);
        let (fc, out) =
            contact_forces(model, reduction, factor, &u0).map_err(|e| at(e.to_string()))?;
        for (fi, c) in f.iter_mut().zip(&fc) {
            *fi += c;
        }
        b = reduction.restrict(&f);
        for (bi, di) in b.iter_mut().zip(dirichlet) {
            *bi += di;
        }
        q = b.clone();
        factor.solve_in_place(&mut q, 1);
        contact = Some(out);
    }
    let kq = k.mul(&q);
    let rnorm = kq
        .iter()
        .zip(&b)
        .map(|(a, c)| (a - c).powi(2))
        .sum::<f64>()
        .sqrt();
    let bnorm = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    let residual_rel = if bnorm > 0.0 { rnorm / bnorm } else { rnorm };
    let u = reduction.expand(&q);
    if !(residual_rel.is_finite() && u.iter().all(|v| v.is_finite())) {
        let largest = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        return Err(at(format!(
            "the solution overflows f64 (non-finite displacements or residual; largest nodal \
             load {largest:.3e}): the loads, the material constants or the node coordinates are \
             out of range: check their values and units (*CLOAD, *DLOAD, *ELASTIC, *NODE)"
        )));
    }
    if residual_rel > MAX_RESIDUAL_REL {
        return Err(at(format!(
            "the solution does not satisfy K u = f (relative residual {residual_rel:.1e}): the \
             supports leave a rigid-body motion free (a mechanism); support the model against \
             translation and rotation in all three directions (*BOUNDARY)"
        )));
    }
    let rf_full = element_product(&sys.connectivity, 3 * model.nodes.len(), &u, k_of)?;
    let stress = field(sys, &u, true, options.extrapolation);
    let strain = field(sys, &u, false, options.extrapolation);
    if !stress.nodal.iter().flatten().all(|v| v.is_finite()) {
        return Err(at(
            "the stresses overflow f64: check the loads and units (*CLOAD, *DLOAD, *ELASTIC)"
                .into(),
        ));
    }
    // eigen steps
    let mut modes_full: Vec<Vec<f64>> = Vec::new();
    let eigen = match analysis {
        Analysis::Static => None,
        Analysis::Buckle { modes, accuracy } => {
            let (g, _) = pattern.assemble(&sys.connectivity, reduction, |e| {
                let neg: Vec<[f64; 6]> = stress.points[e].iter().map(|s| s.map(|v| -v)).collect();
                Ok(geometric_stiffness(&sys.points[e], &neg))
            })?;
            let tol = (accuracy * 1e-6).min(1e-9);
            let pairs = lowest_eigenpairs(factor, &g, &q, modes, tol, 1000).map_err(|e| {
                at(format!(
                    "*BUCKLE: {e} (no positive buckling factor: the loads stiffen the model, e.g. \
                     tension)"
                ))
            })?;
            modes_full = pairs.vectors.iter().map(|v| reduction.expand(v)).collect();
            Some(EigenOut {
                buckling_factors: pairs.values,
                eigenvalues: Vec::new(),
                frequencies: Vec::new(),
                iterations: pairs.iterations,
            })
        }
        Analysis::Frequency {
            modes,
            lower,
            upper,
        } => {
            let mut rho_missing = None;
            let (m, _) = pattern.assemble(&sys.connectivity, reduction, |e| {
                let rho = sys.material[e].1.unwrap_or_else(|| {
                    rho_missing.get_or_insert(e);
                    0.0
                });
                Ok(mass(&sys.points[e], rho))
            })?;
            if let Some(e) = rho_missing {
                return Err(at(format!(
                    "*FREQUENCY: element {} has a material without *DENSITY",
                    model.elements[e].id
                )));
            }
            let start: Vec<f64> = (0..m.n).map(|i| 1.0 + (i % 3) as f64).collect();
            let pairs = lowest_eigenpairs(factor, &m, &start, modes, 1e-10, 1000)
                .map_err(|e| at(format!("*FREQUENCY: {e}")))?;
            let two_pi = 2.0 * std::f64::consts::PI;
            let mut values = Vec::new();
            for (lam, v) in pairs.values.iter().zip(&pairs.vectors) {
                let fr = lam.sqrt() / two_pi;
                if lower > 0.0 && fr < lower {
                    return Err(at(format!(
                        "*FREQUENCY: the frequency {fr:.6e} lies below the lower bound {lower}: \
                         ccx would compute the frequencies nearest the bound (a shift), which is \
                         not supported; give a lower bound of 0"
                    )));
                }
                if upper.is_some_and(|up| up > lower && fr > up) {
                    break;
                }
                values.push(*lam);
                modes_full.push(reduction.expand(v));
            }
            Some(EigenOut {
                buckling_factors: Vec::new(),
                frequencies: values.iter().map(|l| l.sqrt() / two_pi).collect(),
                eigenvalues: values,
                iterations: pairs.iterations,
            })
        }
    };
    let nn = model.nodes.len();
    let pick3 = |v: &[f64], n: usize| [v[3 * n], v[3 * n + 1], v[3 * n + 2]];
    let ud: Vec<[f64; 3]> = (0..nn).map(|n| pick3(&u, n)).collect();
    let rf: Vec<[f64; 3]> = (0..nn)
        .map(|n| {
            if sys.used[n] {
                pick3(&rf_full, n)
            } else {
                [0.0; 3]
            }
        })
        .collect();
    let s: Vec<[f64; 6]> = stress.nodal.iter().map(ccx_order).collect();
    let e: Vec<[f64; 6]> = strain.nodal.iter().map(ccx_order).collect();
    let modes: Vec<Vec<[f64; 3]>> = modes_full
        .iter()
        .map(|v| {
            let big = v
                .iter()
                .copied()
                .fold(0.0f64, |a, x| if x.abs() > a.abs() { x } else { a });
            let scale = if big != 0.0 { 1.0 / big } else { 1.0 };
            (0..nn).map(|n| pick3(v, n).map(|c| c * scale)).collect()
        })
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
    let id = |n: usize| model.node_ids[n];
    let mut node_sets = BTreeMap::new();
    for (name, (vars, totals)) in merged_requests(step) {
        let nodes = &model.nsets[name];
        let has = |v: &str| vars.iter().any(|x| *x == v);
        let each = totals != Totals::Only;
        node_sets.insert(
            name.clone(),
            NodeSetOut {
                nodes: nodes.iter().map(|&n| id(n)).collect(),
                u: (each && has("U")).then(|| nodes.iter().map(|&n| ud[n]).collect()),
                s: (each && has("S")).then(|| nodes.iter().map(|&n| s[n]).collect()),
                e: (each && has("E")).then(|| nodes.iter().map(|&n| e[n]).collect()),
                rf: (each && has("RF")).then(|| nodes.iter().map(|&n| rf[n]).collect()),
                rf_total: (has("RF") && totals != Totals::No).then(|| sum3(nodes)),
            },
        );
    }
    let mut element_sets = BTreeMap::new();
    for (name, vars) in &step.el_print {
        let els = &model.elsets[name];
        let has = |v: &str| vars.iter().any(|x| x == v);
        let pick = |f: &super::fields::Field| -> Vec<Vec<[f64; 6]>> {
            els.iter()
                .map(|&e| f.points[e].iter().map(ccx_order).collect())
                .collect()
        };
        element_sets.insert(
            name.clone(),
            ElementSetOut {
                elements: els.iter().map(|&e| model.elements[e].id).collect(),
                s: has("S").then(|| pick(&stress)),
                e: has("E").then(|| pick(&strain)),
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
        analysis: match analysis {
            Analysis::Static => "static",
            Analysis::Buckle { .. } => "buckle",
            Analysis::Frequency { .. } => "frequency",
        },
        eigen,
        contact,
        node_sets,
        element_sets,
        reaction_totals,
        applied_total,
        residual_rel,
        equations: reduction.n_eq(),
        wall_s: t.elapsed().as_secs_f64(),
        file_vars: step.file_vars.clone(),
        u: ud,
        rf,
        s,
        e,
        modes,
    })
}
