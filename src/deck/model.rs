//! The model a deck describes: nodes, tetrahedra, sets, material, section, supports, loads and
//! output requests per step, with the line each came from. Every keyword, parameter and data form
//! outside the subset below is refused with its line number.
//!
//! Keywords (CalculiX CrunchiX user's manual, ccx 2.20, chapter "Input deck format", one section
//! per keyword; the Abaqus Keywords Reference has the same cards):
//! * `*HEADING` (data ignored);
//! * `*NODE` [NSET=]: `id, x, y, z`;
//! * `*ELEMENT, TYPE=C3D10|C3D4` [ELSET=]: `id, n1, ..., n10` (continued on the next line when it
//!   does not fit). C3D10's node order is VTK's tetra10 order (corners, then edges 1-2, 2-3, 3-1,
//!   1-4, 2-4, 3-4; manual, "C3D10"). C3D4 is solved as a straight-sided C3D10 (its midside nodes
//!   added, internal): more accurate than ccx's linear C3D4, not the same numbers. A deck mixing
//!   the two is refused;
//! * `*NSET, NSET=` / `*ELSET, ELSET=` [GENERATE]: ids or names of sets defined before, or with
//!   GENERATE `first, last[, step]`;
//! * `*MATERIAL, NAME=`, `*ELASTIC` [TYPE=ISO]: `E, ν`; `*DENSITY`: `ρ`;
//! * `*SOLID SECTION, ELSET=, MATERIAL=`: every element in exactly one section; all sections of one
//!   elastic material (E, ν) — densities may differ;
//! * `*BOUNDARY` [OP=MOD]: `node|nset, first dof[, last dof[, value]]`, dofs 1–3;
//! * `*STEP` [INC=, NLGEOM=NO], `*STATIC` [SOLVER=] (its data line ignored: linear), `*END STEP`;
//! * `*CLOAD` [OP=MOD|NEW]: `node|nset, dof, value`;
//! * `*DLOAD` [OP=MOD|NEW]: `element|elset, Pk, p` (uniform pressure on face k, positive into the
//!   element; faces by corners as in the manual, "C3D10": P1 = 1-2-3, P2 = 1-4-2, P3 = 2-4-3,
//!   P4 = 3-4-1) or `element|elset, GRAV, g, nx, ny, nz` (body force ρ g n per volume);
//! * `*NODE PRINT, NSET=` [TOTALS=, FREQUENCY=, GLOBAL=]: U, S, RF; `*EL PRINT, ELSET=`
//!   [FREQUENCY=, TOTALS=NO, GLOBAL=]: S (at the integration points); `*NODE FILE`, `*EL FILE`
//!   [FREQUENCY=, OUTPUT=, GLOBAL=]: U, S, RF (the fields of the VTU file).
//!
//! Step semantics as ccx's: supports and loads carry over from step to step; a repeated support or
//! load on the same node and dof (face, for *DLOAD) replaces the earlier one; OP=NEW on the first
//! *CLOAD (*DLOAD) of a step removes all earlier concentrated (distributed) loads. Set names are
//! case-insensitive (kept upper-cased, as ccx prints them).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use super::parse::{Card, DataLine, error};
use crate::fem::error::Result;

/// Element kind of the deck.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ElementKind {
    /// C3D10.
    C3d10,
    /// C3D4 (solved as straight-sided C3D10).
    C3d4,
}

/// An element: id and node indices (10 or 4).
#[derive(Clone, Debug)]
pub struct Element {
    /// Deck id.
    pub id: i64,
    /// Node indices (into [`Model::nodes`]), C3D10 order.
    pub nodes: Vec<usize>,
}

/// A material.
#[derive(Clone, Debug, Default)]
pub struct MaterialDef {
    /// (E, ν), deck units.
    pub elastic: Option<(f64, f64)>,
    /// ρ, deck units.
    pub density: Option<f64>,
    /// Line of `*MATERIAL`.
    pub line: usize,
}

/// A body force: ρ g n per volume on an element.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grav {
    /// Magnitude g.
    pub g: f64,
    /// Direction (as given; ccx normalises it).
    pub dir: [f64; 3],
}

/// A step's state: supports, loads (accumulated over the earlier steps) and output requests.
#[derive(Clone, Debug, Default)]
pub struct Step {
    /// Line of `*STEP`.
    pub line: usize,
    /// Prescribed displacements (node, dof 0–2) → value.
    pub boundary: BTreeMap<(usize, usize), f64>,
    /// Supported node sets (for the reaction totals): name → nodes; single nodes as `NODE <id>`.
    pub supported_sets: BTreeMap<String, Vec<usize>>,
    /// Concentrated loads (node, dof 0–2) → value.
    pub cloads: BTreeMap<(usize, usize), f64>,
    /// Pressures (element, face 0–3) → p.
    pub pressures: BTreeMap<(usize, usize), f64>,
    /// Body forces per element.
    pub gravity: BTreeMap<usize, Grav>,
    /// `*NODE PRINT` requests: node set name → variables (U, S, RF) and TOTALS.
    pub node_print: Vec<(String, Vec<String>, bool)>,
    /// `*EL PRINT` requests: element set name → variables (S).
    pub el_print: Vec<(String, Vec<String>)>,
    /// Variables of `*NODE FILE`/`*EL FILE` (U, S, RF).
    pub file_vars: Vec<String>,
    /// `*STATIC` seen.
    pub static_seen: bool,
}

/// The model of a deck.
#[derive(Clone, Debug, Default)]
pub struct Model {
    /// Node ids, in file order.
    pub node_ids: Vec<i64>,
    /// Coordinates (deck units), in file order.
    pub nodes: Vec<[f64; 3]>,
    /// Elements, in file order.
    pub elements: Vec<Element>,
    /// Element kind (`None` before any element).
    pub kind: Option<ElementKind>,
    /// Node sets (upper-cased names) → node indices (first occurrence order, no repeats).
    pub nsets: BTreeMap<String, Vec<usize>>,
    /// Element sets → element indices.
    pub elsets: BTreeMap<String, Vec<usize>>,
    /// Materials by (upper-cased) name.
    pub materials: BTreeMap<String, MaterialDef>,
    /// Sections: elset name, material name, line.
    pub sections: Vec<(String, String, usize)>,
    /// The steps.
    pub steps: Vec<Step>,
    node_index: HashMap<i64, usize>,
    element_index: HashMap<i64, usize>,
}

/// Parameters each keyword accepts (any other is refused).
fn allowed_params(keyword: &str) -> Option<&'static [&'static str]> {
    Some(match keyword {
        "HEADING" | "DENSITY" | "END STEP" => &[],
        "NODE" => &["NSET"],
        "ELEMENT" => &["TYPE", "ELSET"],
        "NSET" => &["NSET", "GENERATE"],
        "ELSET" => &["ELSET", "GENERATE"],
        "MATERIAL" => &["NAME"],
        "ELASTIC" => &["TYPE"],
        "SOLID SECTION" => &["ELSET", "MATERIAL"],
        "BOUNDARY" => &["OP"],
        "CLOAD" | "DLOAD" => &["OP"],
        "STEP" => &["INC", "NLGEOM"],
        "STATIC" => &["SOLVER"],
        "NODE PRINT" => &["NSET", "TOTALS", "FREQUENCY", "GLOBAL"],
        "EL PRINT" => &["ELSET", "TOTALS", "FREQUENCY", "GLOBAL"],
        "NODE FILE" | "EL FILE" => &["FREQUENCY", "OUTPUT", "GLOBAL"],
        _ => return None,
    })
}

fn num(path: &Path, d: &DataLine, k: usize, what: &str) -> Result<f64> {
    let f = d
        .fields
        .get(k)
        .ok_or_else(|| error(path, d.line, format!("missing {what} (field {})", k + 1)))?;
    // Fortran-style exponents (1.0D+03) are accepted as ccx accepts them
    f.replace(['d', 'D'], "e")
        .parse()
        .map_err(|_| error(path, d.line, format!("{what}: '{f}' is not a number")))
}

fn int(path: &Path, line: usize, f: &str, what: &str) -> Result<i64> {
    f.parse()
        .map_err(|_| error(path, line, format!("{what}: '{f}' is not an integer")))
}

fn required<'a>(path: &Path, card: &'a Card, name: &str) -> Result<&'a str> {
    match card.param(name) {
        Some(v) if !v.is_empty() => Ok(v),
        _ => Err(error(
            path,
            card.line,
            format!("*{} needs {name}=", card.keyword),
        )),
    }
}

fn push_unique(set: &mut Vec<usize>, items: impl IntoIterator<Item = usize>) {
    for i in items {
        if !set.contains(&i) {
            set.push(i);
        }
    }
}

impl Model {
    /// Index of node `id`.
    pub fn node(&self, id: i64) -> Option<usize> {
        self.node_index.get(&id).copied()
    }

    /// Builds the model from the cards of `path`.
    pub fn from_cards(path: &Path, cards: &[Card]) -> Result<Model> {
        let mut m = Model::default();
        let mut material: Option<String> = None;
        // supports and loads of the model section and of the steps so far
        let mut state = Step::default();
        let mut in_step = false;
        let mut first_cload = true;
        let mut first_dload = true;
        for card in cards {
            let kw = card.keyword.as_str();
            let Some(allowed) = allowed_params(kw) else {
                return Err(error(
                    path,
                    card.line,
                    format!(
                        "*{kw} is not supported (rodstudy solves linear static tet models: see \
                         `rodstudy solve --help` for the keywords it reads)"
                    ),
                ));
            };
            if let Some((p, _)) = card
                .params
                .iter()
                .find(|(p, _)| !allowed.contains(&p.as_str()))
            {
                return Err(error(
                    path,
                    card.line,
                    format!("*{kw}: parameter {p} is not supported"),
                ));
            }
            let step_kw = matches!(
                kw,
                "STATIC"
                    | "CLOAD"
                    | "DLOAD"
                    | "NODE PRINT"
                    | "EL PRINT"
                    | "NODE FILE"
                    | "EL FILE"
                    | "END STEP"
            );
            if step_kw && !in_step {
                return Err(error(path, card.line, format!("*{kw} outside a *STEP")));
            }
            if in_step
                && matches!(
                    kw,
                    "NODE"
                        | "ELEMENT"
                        | "NSET"
                        | "ELSET"
                        | "MATERIAL"
                        | "ELASTIC"
                        | "DENSITY"
                        | "SOLID SECTION"
                        | "STEP"
                )
            {
                return Err(error(
                    path,
                    card.line,
                    format!("*{kw} inside a step (missing *END STEP?)"),
                ));
            }
            if !matches!(kw, "ELASTIC" | "DENSITY") {
                if kw != "MATERIAL" {
                    material = None;
                }
            } else if material.is_none() {
                return Err(error(path, card.line, format!("*{kw} outside a *MATERIAL")));
            }
            let needs_data = matches!(
                kw,
                "NSET"
                    | "ELSET"
                    | "ELASTIC"
                    | "DENSITY"
                    | "BOUNDARY"
                    | "CLOAD"
                    | "DLOAD"
                    | "NODE PRINT"
                    | "EL PRINT"
            );
            if needs_data && card.data.is_empty() {
                return Err(error(path, card.line, format!("*{kw} without data lines")));
            }
            let max_data = match kw {
                "MATERIAL" | "STEP" | "END STEP" => 0,
                // a solid section may carry one data line (a thickness, unused for solids)
                "SOLID SECTION" => 1,
                _ => usize::MAX,
            };
            if card.data.len() > max_data {
                return Err(error(
                    path,
                    card.data[max_data].line,
                    format!("*{kw} takes no further data lines"),
                ));
            }
            match kw {
                "HEADING" => {}
                "NODE" => m.read_nodes(path, card)?,
                "ELEMENT" => m.read_elements(path, card)?,
                "NSET" | "ELSET" => m.read_set(path, card)?,
                "MATERIAL" => {
                    let name = required(path, card, "NAME")?.to_ascii_uppercase();
                    if m.materials.contains_key(&name) {
                        return Err(error(
                            path,
                            card.line,
                            format!("material {name} defined twice"),
                        ));
                    }
                    m.materials.insert(
                        name.clone(),
                        MaterialDef {
                            line: card.line,
                            ..Default::default()
                        },
                    );
                    material = Some(name);
                }
                "ELASTIC" => {
                    if let Some(t) = card.param("TYPE")
                        && !t.eq_ignore_ascii_case("ISO")
                    {
                        return Err(error(
                            path,
                            card.line,
                            format!("*ELASTIC, TYPE={t}: only isotropic (TYPE=ISO) is supported"),
                        ));
                    }
                    let d = &card.data[0];
                    if card.data.len() > 1 || d.fields.len() > 3 {
                        return Err(error(
                            path,
                            d.line,
                            "temperature-dependent elastic constants are not supported",
                        ));
                    }
                    let e = num(path, d, 0, "Young's modulus")?;
                    let nu = num(path, d, 1, "Poisson's ratio")?;
                    let mat = m
                        .materials
                        .get_mut(material.as_ref().expect("checked"))
                        .expect("defined");
                    mat.elastic = Some((e, nu));
                }
                "DENSITY" => {
                    let d = &card.data[0];
                    if card.data.len() > 1 || d.fields.len() > 2 {
                        return Err(error(
                            path,
                            d.line,
                            "temperature-dependent density is not supported",
                        ));
                    }
                    let rho = num(path, d, 0, "density")?;
                    let mat = m
                        .materials
                        .get_mut(material.as_ref().expect("checked"))
                        .expect("defined");
                    mat.density = Some(rho);
                }
                "SOLID SECTION" => {
                    let elset = required(path, card, "ELSET")?.to_ascii_uppercase();
                    let mat = required(path, card, "MATERIAL")?.to_ascii_uppercase();
                    if !m.elsets.contains_key(&elset) {
                        return Err(error(
                            path,
                            card.line,
                            format!("element set {elset} is not defined"),
                        ));
                    }
                    m.sections.push((elset, mat, card.line));
                }
                "BOUNDARY" => {
                    if let Some(op) = card.param("OP")
                        && !op.eq_ignore_ascii_case("MOD")
                    {
                        return Err(error(
                            path,
                            card.line,
                            format!(
                                "*BOUNDARY, OP={op}: only OP=MOD (supports carry over) is supported"
                            ),
                        ));
                    }
                    for d in &card.data {
                        let (name, nodes) = m.node_target(path, d)?;
                        let f1 = d
                            .fields
                            .get(1)
                            .ok_or_else(|| error(path, d.line, "missing first dof"))?;
                        let first = int(
                            path,
                            d.line,
                            f1,
                            "first dof (named supports such as ENCASTRE are not supported)",
                        )?;
                        let last = match d.fields.get(2) {
                            Some(f) if !f.is_empty() => int(path, d.line, f, "last dof")?,
                            _ => first,
                        };
                        let value = if d.fields.len() > 3 {
                            num(path, d, 3, "prescribed value")?
                        } else {
                            0.0
                        };
                        if d.fields.len() > 4 {
                            return Err(error(
                                path,
                                d.line,
                                "a *BOUNDARY line is 'node|nset, first, last, value'",
                            ));
                        }
                        if !(1..=3).contains(&first) || !(first..=3).contains(&last) {
                            return Err(error(
                                path,
                                d.line,
                                format!(
                                    "dofs {first}..{last}: only displacements 1-3 exist on solid elements"
                                ),
                            ));
                        }
                        for &n in &nodes {
                            for dof in first..=last {
                                state.boundary.insert((n, (dof - 1) as usize), value);
                            }
                        }
                        push_unique(state.supported_sets.entry(name).or_default(), nodes);
                    }
                }
                "STEP" => {
                    if let Some(v) = card.param("NLGEOM")
                        && !v.eq_ignore_ascii_case("NO")
                    {
                        return Err(error(
                            path,
                            card.line,
                            "*STEP, NLGEOM: only linear analysis is supported",
                        ));
                    }
                    in_step = true;
                    first_cload = true;
                    first_dload = true;
                    state.line = card.line;
                    state.static_seen = false;
                    state.node_print.clear();
                    state.el_print.clear();
                    state.file_vars.clear();
                }
                "STATIC" => {
                    if card.data.len() > 1 {
                        return Err(error(
                            path,
                            card.data[1].line,
                            "*STATIC takes one data line",
                        ));
                    }
                    state.static_seen = true;
                }
                "CLOAD" => {
                    if op_new(path, card)? && first_cload {
                        state.cloads.clear();
                    }
                    first_cload = false;
                    for d in &card.data {
                        let (_, nodes) = m.node_target(path, d)?;
                        let f1 = d
                            .fields
                            .get(1)
                            .ok_or_else(|| error(path, d.line, "missing dof"))?;
                        let dof = int(path, d.line, f1, "dof")?;
                        if !(1..=3).contains(&dof) {
                            return Err(error(
                                path,
                                d.line,
                                format!("dof {dof}: only forces 1-3 exist on solid elements"),
                            ));
                        }
                        let v = num(path, d, 2, "load")?;
                        if d.fields.len() > 3 {
                            return Err(error(
                                path,
                                d.line,
                                "a *CLOAD line is 'node|nset, dof, value'",
                            ));
                        }
                        for &n in &nodes {
                            state.cloads.insert((n, (dof - 1) as usize), v);
                        }
                    }
                }
                "DLOAD" => {
                    if op_new(path, card)? && first_dload {
                        state.pressures.clear();
                        state.gravity.clear();
                    }
                    first_dload = false;
                    for d in &card.data {
                        let elements = m.element_target(path, d)?;
                        let label = d
                            .fields
                            .get(1)
                            .map(|s| s.to_ascii_uppercase())
                            .unwrap_or_default();
                        match label.as_str() {
                            "P1" | "P2" | "P3" | "P4" => {
                                let face = (label.as_bytes()[1] - b'1') as usize;
                                let p = num(path, d, 2, "pressure")?;
                                if d.fields.len() > 3 {
                                    return Err(error(
                                        path,
                                        d.line,
                                        "a pressure line is 'element|elset, Pk, p'",
                                    ));
                                }
                                for &e in &elements {
                                    state.pressures.insert((e, face), p);
                                }
                            }
                            "GRAV" => {
                                let g = num(path, d, 2, "gravity magnitude")?;
                                let dir = [
                                    num(path, d, 3, "nx")?,
                                    num(path, d, 4, "ny")?,
                                    num(path, d, 5, "nz")?,
                                ];
                                let n =
                                    (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
                                if n == 0.0 || !n.is_finite() || d.fields.len() > 6 {
                                    return Err(error(
                                        path,
                                        d.line,
                                        "a GRAV line is 'elset, GRAV, g, nx, ny, nz' with a non-zero direction",
                                    ));
                                }
                                for &e in &elements {
                                    state.gravity.insert(
                                        e,
                                        Grav {
                                            g,
                                            dir: dir.map(|v| v / n),
                                        },
                                    );
                                }
                            }
                            _ => {
                                return Err(error(
                                    path,
                                    d.line,
                                    format!(
                                        "*DLOAD label '{label}' is not supported (P1-P4 on C3D10 faces, GRAV)"
                                    ),
                                ));
                            }
                        }
                    }
                }
                "NODE PRINT" | "EL PRINT" | "NODE FILE" | "EL FILE" => {
                    let mut vars = Vec::new();
                    for d in &card.data {
                        for f in &d.fields {
                            let v = f.to_ascii_uppercase();
                            let ok = match kw {
                                "EL PRINT" => v == "S",
                                _ => matches!(v.as_str(), "U" | "S" | "RF"),
                            };
                            if !ok {
                                return Err(error(
                                    path,
                                    d.line,
                                    format!(
                                        "*{kw}: output variable '{f}' is not supported (U, S, RF)"
                                    ),
                                ));
                            }
                            if !vars.contains(&v) {
                                vars.push(v);
                            }
                        }
                    }
                    match kw {
                        "NODE PRINT" => {
                            let set = required(path, card, "NSET")?.to_ascii_uppercase();
                            if !m.nsets.contains_key(&set) {
                                return Err(error(
                                    path,
                                    card.line,
                                    format!("node set {set} is not defined"),
                                ));
                            }
                            let totals = card
                                .param("TOTALS")
                                .is_some_and(|t| !t.eq_ignore_ascii_case("NO"));
                            state.node_print.push((set, vars, totals));
                        }
                        "EL PRINT" => {
                            let set = required(path, card, "ELSET")?.to_ascii_uppercase();
                            if !m.elsets.contains_key(&set) {
                                return Err(error(
                                    path,
                                    card.line,
                                    format!("element set {set} is not defined"),
                                ));
                            }
                            state.el_print.push((set, vars));
                        }
                        _ => {
                            for v in vars {
                                if !state.file_vars.contains(&v) {
                                    state.file_vars.push(v);
                                }
                            }
                        }
                    }
                }
                "END STEP" => {
                    if !state.static_seen {
                        return Err(error(
                            path,
                            card.line,
                            "a step without *STATIC (only linear static steps are supported)",
                        ));
                    }
                    m.steps.push(state.clone());
                    in_step = false;
                }
                _ => unreachable!("allowed_params covers the keywords"),
            }
        }
        if in_step {
            return Err(error(path, state.line, "*STEP without *END STEP"));
        }
        if m.elements.is_empty() {
            return Err(error(path, 0, "no C3D10/C3D4 elements"));
        }
        if m.steps.is_empty() {
            return Err(error(path, 0, "no *STEP"));
        }
        Ok(m)
    }

    fn read_nodes(&mut self, path: &Path, card: &Card) -> Result<()> {
        let mut added = Vec::new();
        for d in &card.data {
            if d.fields.len() != 4 {
                return Err(error(
                    path,
                    d.line,
                    format!(
                        "a node line is 'id, x, y, z': found {} fields",
                        d.fields.len()
                    ),
                ));
            }
            let id = int(path, d.line, &d.fields[0], "node id")?;
            let p = [
                num(path, d, 1, "x")?,
                num(path, d, 2, "y")?,
                num(path, d, 3, "z")?,
            ];
            if self.node_index.insert(id, self.nodes.len()).is_some() {
                return Err(error(path, d.line, format!("node {id} defined twice")));
            }
            added.push(self.nodes.len());
            self.node_ids.push(id);
            self.nodes.push(p);
        }
        if let Some(set) = card.param("NSET") {
            push_unique(
                self.nsets.entry(set.to_ascii_uppercase()).or_default(),
                added,
            );
        }
        Ok(())
    }

    fn read_elements(&mut self, path: &Path, card: &Card) -> Result<()> {
        let ty = required(path, card, "TYPE")?.to_ascii_uppercase();
        let (kind, n) = match ty.as_str() {
            "C3D10" => (ElementKind::C3d10, 10),
            "C3D4" => (ElementKind::C3d4, 4),
            _ => {
                return Err(error(
                    path,
                    card.line,
                    format!("element type {ty} is not supported (C3D10, C3D4)"),
                ));
            }
        };
        if self.kind.is_some_and(|k| k != kind) {
            return Err(error(
                path,
                card.line,
                "a deck mixing C3D4 and C3D10 is not supported",
            ));
        }
        self.kind = Some(kind);
        let mut added = Vec::new();
        let mut pending: Vec<i64> = Vec::new();
        let mut start = 0;
        for d in &card.data {
            if pending.is_empty() {
                start = d.line;
            }
            for f in d.fields.iter().filter(|f| !f.is_empty()) {
                pending.push(int(path, d.line, f, "element line")?);
            }
            if pending.len() > n + 1 {
                return Err(error(
                    path,
                    d.line,
                    format!(
                        "an element line has {} numbers (id and {n} nodes)",
                        pending.len()
                    ),
                ));
            }
            if pending.len() == n + 1 {
                let id = pending[0];
                let mut nodes = Vec::with_capacity(n);
                for &nid in &pending[1..] {
                    let i = self.node(nid).ok_or_else(|| {
                        error(
                            path,
                            d.line,
                            format!("element {id} refers to undefined node {nid}"),
                        )
                    })?;
                    nodes.push(i);
                }
                if self.element_index.insert(id, self.elements.len()).is_some() {
                    return Err(error(path, start, format!("element {id} defined twice")));
                }
                added.push(self.elements.len());
                self.elements.push(Element { id, nodes });
                pending.clear();
            }
        }
        if !pending.is_empty() {
            return Err(error(
                path,
                start,
                format!("incomplete element: {} numbers", pending.len()),
            ));
        }
        if let Some(set) = card.param("ELSET") {
            push_unique(
                self.elsets.entry(set.to_ascii_uppercase()).or_default(),
                added,
            );
        }
        Ok(())
    }

    fn read_set(&mut self, path: &Path, card: &Card) -> Result<()> {
        let nodes = card.keyword == "NSET";
        let name = required(path, card, if nodes { "NSET" } else { "ELSET" })?.to_ascii_uppercase();
        let mut items = Vec::new();
        for d in &card.data {
            if card.has("GENERATE") {
                if !(2..=3).contains(&d.fields.len()) {
                    return Err(error(path, d.line, "GENERATE takes 'first, last[, step]'"));
                }
                let a = int(path, d.line, &d.fields[0], "first")?;
                let b = int(path, d.line, &d.fields[1], "last")?;
                let s = if d.fields.len() == 3 {
                    int(path, d.line, &d.fields[2], "step")?
                } else {
                    1
                };
                if s <= 0 || b < a {
                    return Err(error(
                        path,
                        d.line,
                        "GENERATE needs first <= last and step > 0",
                    ));
                }
                let mut id = a;
                while id <= b {
                    items.push(self.lookup(path, d.line, nodes, id)?);
                    id += s;
                }
                continue;
            }
            for f in d.fields.iter().filter(|f| !f.is_empty()) {
                if let Ok(id) = f.parse::<i64>() {
                    items.push(self.lookup(path, d.line, nodes, id)?);
                } else {
                    let sets = if nodes { &self.nsets } else { &self.elsets };
                    let other = sets.get(&f.to_ascii_uppercase()).ok_or_else(|| {
                        error(
                            path,
                            d.line,
                            format!("'{f}' is neither an id nor a defined set"),
                        )
                    })?;
                    items.extend(other.iter().copied());
                }
            }
        }
        let sets = if nodes {
            &mut self.nsets
        } else {
            &mut self.elsets
        };
        push_unique(sets.entry(name).or_default(), items);
        Ok(())
    }

    fn lookup(&self, path: &Path, line: usize, nodes: bool, id: i64) -> Result<usize> {
        let (map, what) = if nodes {
            (&self.node_index, "node")
        } else {
            (&self.element_index, "element")
        };
        map.get(&id)
            .copied()
            .ok_or_else(|| error(path, line, format!("{what} {id} is not defined")))
    }

    /// The first field of a data line as a node or a node set: (name for reports, nodes).
    fn node_target(&self, path: &Path, d: &DataLine) -> Result<(String, Vec<usize>)> {
        let f = d.fields.first().map(String::as_str).unwrap_or("");
        if let Ok(id) = f.parse::<i64>() {
            return Ok((
                format!("NODE {id}"),
                vec![self.lookup(path, d.line, true, id)?],
            ));
        }
        let name = f.to_ascii_uppercase();
        let set = self
            .nsets
            .get(&name)
            .ok_or_else(|| error(path, d.line, format!("node set '{f}' is not defined")))?;
        Ok((name, set.clone()))
    }

    /// The first field of a data line as an element or an element set.
    fn element_target(&self, path: &Path, d: &DataLine) -> Result<Vec<usize>> {
        let f = d.fields.first().map(String::as_str).unwrap_or("");
        if let Ok(id) = f.parse::<i64>() {
            return Ok(vec![self.lookup(path, d.line, false, id)?]);
        }
        self.elsets
            .get(&f.to_ascii_uppercase())
            .cloned()
            .ok_or_else(|| error(path, d.line, format!("element set '{f}' is not defined")))
    }
}

fn op_new(path: &Path, card: &Card) -> Result<bool> {
    match card.param("OP") {
        None => Ok(false),
        Some(v) if v.eq_ignore_ascii_case("MOD") => Ok(false),
        Some(v) if v.eq_ignore_ascii_case("NEW") => Ok(true),
        Some(v) => Err(error(path, card.line, format!("OP={v}: NEW or MOD"))),
    }
}
