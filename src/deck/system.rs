//! A deck's model as the discrete system ccx solves: the element integration points and
//! materials, the constraints of a step (supports, in local axes where the node has them,
//! `*EQUATION`s, unused nodes held), and its load vector.
//!
//! * Pressure on a face (`*DLOAD Pk`, `*DSLOAD`): f_a = −∫ N_a p n dA, on a C3D10's 6-node face with
//!   the 3-point rule CalculiX uses (`gauss2d5`: (1/6, 1/6), (2/3, 1/6), (1/6, 2/3), weights 1/6;
//!   `e_c3d.f`), on a C3D4's flat face −p A n / 3 per corner (one point, as ccx).
//! * Gravity (`GRAV`): f_a = Σ_ip N_a ρ g n dV; centrifugal (`CENTRIF`): f_a = Σ_ip N_a ρ ω² r dV,
//!   r the point's distance vector from the axis (manual, "*DLOAD": CENTRIF, ω², a point on the
//!   axis, its direction); both on the element's integration points, as ccx.
//! * Local axes (`*TRANSFORM`, manual): u = R u_local, R's columns the local axes at the node
//!   (rectangular: x along a, y in the (a, b) plane; cylindrical about the axis a → b: radial,
//!   tangential, axial); a support on local DOF k is the constraint e_kᵀ u = value, a force on it
//!   the global force value · e_k.

use std::collections::{BTreeMap, HashSet};
use std::path::Path;

use super::coupling::{distribute, kinematic_constraints};
use super::model::{CouplingKind, Model, Step, Transform};
use crate::fem::boundary::face_point;
use crate::fem::constraints::{Constraint, Reduction};
use crate::fem::error::{FemError, Result};
use crate::fem::material::Material;
use crate::fem::shape::TET10_FACES;
use crate::fem::solid_element::{IntegrationPoint, SolidKind, integration_points};

/// CalculiX's face rule for C3D10 (`gauss2d5`): 3 points, degree 2.
const FACE_POINTS: [[f64; 2]; 3] = [
    [1.0 / 6.0, 1.0 / 6.0],
    [2.0 / 3.0, 1.0 / 6.0],
    [1.0 / 6.0, 2.0 / 3.0],
];
const FACE_WEIGHT: f64 = 1.0 / 6.0;

/// The elements of a deck ready for assembly.
pub struct DeckSystem {
    /// Per element its deck node indices.
    pub connectivity: Vec<Vec<usize>>,
    /// Per element its integration points.
    pub points: Vec<Vec<IntegrationPoint>>,
    /// Per element its material and density.
    pub material: Vec<(Material, Option<f64>)>,
    /// Per deck node: used by an element.
    pub used: Vec<bool>,
    /// Elements negative at a corner and positive at their integration points (deck ids).
    pub inverted_corners: Vec<i64>,
}

/// The integration points and materials of every element; every element inverted at an
/// integration point refused at once, every one inverted only at a corner listed.
pub fn deck_system(path: &Path, model: &Model) -> Result<DeckSystem> {
    let mut points = Vec::with_capacity(model.elements.len());
    let mut bad = Vec::new();
    let mut inverted_corners = Vec::new();
    for (e, el) in model.elements.iter().enumerate() {
        let x: Vec<[f64; 3]> = el.nodes.iter().map(|&n| model.nodes[n]).collect();
        match integration_points(el.kind, &x, e) {
            Ok(p) => {
                if !crate::fem::solid_element::inverted_corners(el.kind, &x).is_empty() {
                    inverted_corners.push(el.id);
                }
                points.push(p);
            }
            Err(_) => bad.push(format!("element {} (line {})", el.id, el.line)),
        }
    }
    if !bad.is_empty() {
        return Err(FemError::Parse {
            path: path.to_path_buf(),
            line: model
                .elements
                .iter()
                .find(|e| format!("element {} (line {})", e.id, e.line) == bad[0])
                .map_or(0, |e| e.line),
            message: format!(
                "{} element(s) inverted or degenerate at an integration point (Jacobian \
                 determinant ≤ 0): {}; check the element's node order (corners 1-2-3 \
                 anticlockwise seen from corner 4, then the midside nodes of edges 1-2, 2-3, 3-1, \
                 1-4, 2-4, 3-4) and its nodes' coordinates",
                bad.len(),
                bad.join(", ")
            ),
        });
    }
    let material = element_materials(model)?;
    let mut used = vec![false; model.nodes.len()];
    for el in &model.elements {
        for &n in &el.nodes {
            used[n] = true;
        }
    }
    Ok(DeckSystem {
        connectivity: model.elements.iter().map(|e| e.nodes.clone()).collect(),
        points,
        material,
        used,
        inverted_corners,
    })
}

/// Each element's material (E, ν as [`Material`]) and density, from its section.
fn element_materials(model: &Model) -> Result<Vec<(Material, Option<f64>)>> {
    let mut out: Vec<Option<(Material, Option<f64>, usize)>> = vec![None; model.elements.len()];
    for (s, sec) in model.sections.iter().enumerate() {
        let err = |m: String| FemError::Parse {
            path: sec.file.clone(),
            line: sec.line,
            message: format!("*SOLID SECTION: {m}"),
        };
        let mat = model
            .materials
            .get(&sec.material)
            .ok_or_else(|| err(format!("material {} is not defined", sec.material)))?;
        let (e, nu) = mat
            .elastic
            .ok_or_else(|| err(format!("material {} has no *ELASTIC", sec.material)))?;
        let material = Material {
            youngs_modulus_pa: e,
            poisson_ratio: nu,
        };
        material.validate()?;
        for &el in &model.elsets[&sec.elset] {
            if let Some((_, _, s0)) = out[el] {
                return Err(err(format!(
                    "element {} is already in the section of line {}",
                    model.elements[el].id, model.sections[s0].line
                )));
            }
            out[el] = Some((material, mat.density, s));
        }
    }
    out.into_iter()
        .enumerate()
        .map(|(e, m)| {
            m.map(|(a, b, _)| (a, b)).ok_or_else(|| {
                FemError::InvalidInput(format!(
                    "element {} (line {}) is in no *SOLID SECTION",
                    model.elements[e].id, model.elements[e].line
                ))
            })
        })
        .collect()
}

/// The local axes (columns of R) of `t` at `x`.
pub fn local_axes(t: &Transform, x: [f64; 3]) -> Option<[[f64; 3]; 3]> {
    let unit = |v: [f64; 3]| {
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        (n > 0.0).then(|| v.map(|c| c / n))
    };
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    match *t {
        Transform::Rectangular { a, b } => {
            let e1 = unit(a)?;
            let e2 = unit(std::array::from_fn(|j| b[j] - dot(b, e1) * e1[j]))?;
            Some([e1, e2, cross(e1, e2)])
        }
        Transform::Cylindrical { a, b } => {
            let e3 = unit(std::array::from_fn(|j| b[j] - a[j]))?;
            let d: [f64; 3] = std::array::from_fn(|j| x[j] - a[j]);
            let along = dot(d, e3);
            let r: [f64; 3] = std::array::from_fn(|j| d[j] - along * e3[j]);
            let scale = (dot(d, d)).sqrt().max(f64::MIN_POSITIVE);
            if (dot(r, r)).sqrt() <= 1e-12 * scale {
                return None;
            }
            let e1 = unit(r)?;
            Some([e1, cross(e3, e1), e3])
        }
    }
}

/// The axes of node `n`: its transform's, or none (global).
fn node_axes(path: &Path, model: &Model, n: usize) -> Result<Option<[[f64; 3]; 3]>> {
    match model.transforms.get(&n) {
        None => Ok(None),
        Some(t) => local_axes(t, model.nodes[n])
            .map(Some)
            .ok_or_else(|| FemError::Parse {
                path: path.to_path_buf(),
                line: 0,
                message: format!(
                    "node {} lies on the axis of its cylindrical *TRANSFORM: its radial and \
                     tangential directions are undefined",
                    model.node_ids[n]
                ),
            }),
    }
}

/// The constraints of `step`: equations, supports (local where transformed), and the nodes no
/// element and no equation uses held at zero.
pub fn step_reduction(
    path: &Path,
    model: &Model,
    sys: &DeckSystem,
    step: &Step,
) -> Result<Reduction> {
    let mut constraints = Vec::new();
    for (terms, line) in &model.equations {
        // a DOF of a node with local axes is the local one (manual, "*EQUATION")
        let mut global = Vec::new();
        for &(n, j, c) in terms {
            match node_axes(path, model, n)? {
                None => global.push((3 * n + j, c)),
                Some(axes) => global.extend(
                    (0..3)
                        .map(|i| (3 * n + i, c * axes[j][i]))
                        .filter(|t| t.1 != 0.0),
                ),
            }
        }
        constraints.push(Constraint {
            terms: global,
            value: 0.0,
            label: format!("{}: *EQUATION of line {line}", path.display()),
        });
    }
    constraints.extend(kinematic_constraints(path, model));
    let linked = linked_dofs(&constraints);
    for (&(n, j), &v) in &step.boundary {
        let (n, j) = rotation_dof(model, n, j);
        let mut terms: Vec<(usize, f64)> = match node_axes(path, model, n)? {
            None => vec![(3 * n + j, 1.0)],
            Some(axes) => (0..3)
                .map(|i| (3 * n + i, axes[j][i]))
                .filter(|t| t.1 != 0.0)
                .collect(),
        };
        terms.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
        constraints.push(Constraint {
            terms,
            value: v,
            label: format!(
                "{}: *BOUNDARY on node {} dof {}",
                path.display(),
                model.node_ids[n],
                j + 1
            ),
        });
    }
    let supported: HashSet<usize> = step
        .boundary
        .keys()
        .map(|&(n, j)| {
            let (n, j) = rotation_dof(model, n, j);
            3 * n + j
        })
        .collect();
    for n in 0..model.nodes.len() {
        if sys.used[n] {
            continue;
        }
        for d in (3 * n..3 * n + 3).filter(|d| !linked.contains(d) && !supported.contains(d)) {
            constraints.push(Constraint {
                terms: vec![(d, 1.0)],
                value: 0.0,
                label: "a DOF of no element and no equation".into(),
            });
        }
    }
    Reduction::new(3 * model.nodes.len(), &constraints)
}

/// The DOFs that `constraints` (equations, couplings) tie to others: those of a node of no
/// element stay free (the rest of such a node is held at zero).
fn linked_dofs(constraints: &[Constraint]) -> HashSet<usize> {
    constraints
        .iter()
        .filter(|c| c.terms.len() > 1)
        .flat_map(|c| c.terms.iter().map(|t| t.0))
        .collect()
}

/// Node and DOF (0–2) of DOF `j` (0–5) of node `n`: a rotation (3–5) of a kinematic coupling's
/// reference node is a DOF of its rotation node.
fn rotation_dof(model: &Model, n: usize, j: usize) -> (usize, usize) {
    if j < 3 {
        return (n, j);
    }
    match model.coupling_of(n).map(|c| &c.kind) {
        Some(CouplingKind::Kinematic { rotation_node, .. }) => (*rotation_node, j - 3),
        _ => unreachable!("the deck reader admits rotations on kinematic reference nodes only"),
    }
}

/// The load vector of `step` (3 per deck node, global axes).
pub fn step_loads(
    path: &Path,
    model: &Model,
    sys: &DeckSystem,
    step: &Step,
    number: usize,
) -> Result<Vec<f64>> {
    let mut f = vec![0.0; 3 * model.nodes.len()];
    let mut carried: BTreeMap<usize, [f64; 6]> = BTreeMap::new();
    let kinematic = kinematic_constraints(path, model);
    let linked = linked_dofs(&kinematic);
    let tied = |n: usize| {
        sys.used[n]
            || (0..3).any(|j| linked.contains(&(3 * n + j)))
            || model
                .equations
                .iter()
                .any(|(t, _)| t.len() > 1 && t.iter().any(|x| x.0 == n))
    };
    for (&(n, j), &v) in &step.cloads {
        if let Some(c) = model.coupling_of(n)
            && matches!(c.kind, CouplingKind::Distributing { .. })
        {
            carried.entry(n).or_default()[j] += v;
            continue;
        }
        let (n, j) = rotation_dof(model, n, j);
        if !tied(n) {
            return Err(FemError::InvalidInput(format!(
                "step {number}: *CLOAD on node {}, which no element uses",
                model.node_ids[n]
            )));
        }
        match node_axes(path, model, n)? {
            None => f[3 * n + j] += v,
            Some(axes) => {
                for i in 0..3 {
                    f[3 * n + i] += v * axes[j][i];
                }
            }
        }
    }
    for (n, v) in carried {
        let c = model.coupling_of(n).expect("a reference node");
        distribute(model, c, [v[0], v[1], v[2]], [v[3], v[4], v[5]], &mut f)?;
    }
    for (&(e, face), &p) in &step.pressures {
        let el = &model.elements[e];
        let local = TET10_FACES[face];
        match el.kind {
            SolidKind::Tet10 => {
                let nodes: [usize; 6] = std::array::from_fn(|a| el.nodes[local[a]]);
                let x: [[f64; 3]; 6] = std::array::from_fn(|a| model.nodes[nodes[a]]);
                for q in &FACE_POINTS {
                    let (_, c, n) = face_point(&x, *q);
                    for a in 0..6 {
                        for j in 0..3 {
                            f[3 * nodes[a] + j] -= FACE_WEIGHT * n[a] * p * c[j];
                        }
                    }
                }
            }
            SolidKind::Tet4 => {
                let nodes: [usize; 3] = std::array::from_fn(|a| el.nodes[local[a]]);
                let x: [[f64; 3]; 3] = std::array::from_fn(|a| model.nodes[nodes[a]]);
                let u: [f64; 3] = std::array::from_fn(|j| x[1][j] - x[0][j]);
                let v: [f64; 3] = std::array::from_fn(|j| x[2][j] - x[0][j]);
                // (u × v)/2 = A n
                let an = [
                    0.5 * (u[1] * v[2] - u[2] * v[1]),
                    0.5 * (u[2] * v[0] - u[0] * v[2]),
                    0.5 * (u[0] * v[1] - u[1] * v[0]),
                ];
                for &node in &nodes {
                    for j in 0..3 {
                        f[3 * node + j] -= p * an[j] / 3.0;
                    }
                }
            }
        }
    }
    let density = |e: usize, what: &str| {
        sys.material[e].1.ok_or_else(|| {
            FemError::InvalidInput(format!(
                "step {number}: {what} on element {}, whose material has no *DENSITY",
                model.elements[e].id
            ))
        })
    };
    let mut body = |e: usize, force: &dyn Fn([f64; 3]) -> [f64; 3]| {
        let el = &model.elements[e];
        for p in &sys.points[e] {
            let x: [f64; 3] = std::array::from_fn(|j| {
                el.nodes
                    .iter()
                    .zip(&p.n)
                    .map(|(&n, w)| w * model.nodes[n][j])
                    .sum()
            });
            let b = force(x);
            for (a, &n) in el.nodes.iter().enumerate() {
                for j in 0..3 {
                    f[3 * n + j] += p.dv * p.n[a] * b[j];
                }
            }
        }
    };
    for (&e, g) in &step.gravity {
        let rho = density(e, "GRAV")?;
        body(e, &|_| g.dir.map(|d| rho * g.g * d));
    }
    for (&e, c) in &step.centrif {
        let rho = density(e, "CENTRIF")?;
        body(e, &|x| {
            let d: [f64; 3] = std::array::from_fn(|j| x[j] - c.point[j]);
            let along = d[0] * c.axis[0] + d[1] * c.axis[1] + d[2] * c.axis[2];
            std::array::from_fn(|j| rho * c.omega2 * (d[j] - along * c.axis[j]))
        });
    }
    Ok(f)
}

/// Per node set of `step`'s requests, merged (several requests on one set print all their
/// variables).
pub fn merged_requests(step: &Step) -> BTreeMap<&String, (Vec<&String>, super::model::Totals)> {
    let mut requests: BTreeMap<&String, (Vec<&String>, super::model::Totals)> = BTreeMap::new();
    for (name, vars, totals) in &step.node_print {
        let r = requests.entry(name).or_default();
        r.0.extend(vars);
        if *totals != super::model::Totals::No {
            r.1 = *totals;
        }
    }
    requests
}
