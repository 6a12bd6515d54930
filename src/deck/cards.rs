//! The cards of a deck read into a [`Model`], keyword by keyword (the subset listed in
//! [`super::model`]); every keyword, parameter and data form outside it is refused with its line.

use std::collections::BTreeSet;
use std::path::Path;

use super::model::*;
use super::parse::{Card, error, int, load, num, push_unique, required};
use crate::fem::error::Result;

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

impl Model {
    /// Builds the model from the cards of `path`.
    pub fn from_cards(path: &Path, cards: &[Card]) -> Result<Model> {
        let mut m = Model::default();
        let mut material: Option<String> = None;
        // supports and loads of the model section and of the steps so far
        let mut state = Step::default();
        let mut in_step = false;
        let mut first_cload = true;
        let mut first_dload = true;
        // loads given in the current step: a repeat within the step adds to them (as ccx does), a
        // repeat in a later step replaces the earlier step's value
        let mut cloads_here = BTreeSet::new();
        let mut pressures_here = BTreeSet::new();
        let mut gravity_here = BTreeSet::new();
        // output requests: the first card of a kind within a step replaces the requests of that
        // kind; a step without one keeps the previous step's (ccx's manual, *NODE PRINT, *EL PRINT,
        // *NODE FILE, *EL FILE)
        let mut first_request = [true; 4];
        let mut node_file: Vec<String> = Vec::new();
        let mut el_file: Vec<String> = Vec::new();
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
                    // a solid is stable (its strain energy positive) only for E > 0 and
                    // −1 < ν < 0.5
                    if e <= 0.0 {
                        return Err(error(
                            path,
                            d.line,
                            format!(
                                "Young's modulus {e} is not positive: no material has E ≤ 0; \
                                 the line is 'E, ν'"
                            ),
                        ));
                    }
                    if !(nu > -1.0 && nu < 0.5) {
                        return Err(error(
                            path,
                            d.line,
                            format!(
                                "Poisson's ratio {nu} lies outside (−1, 0.5), where no stable \
                                 solid lies; the line is 'E, ν'"
                            ),
                        ));
                    }
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
                    if rho < 0.0 {
                        return Err(error(
                            path,
                            d.line,
                            format!("density {rho} is negative: a mass density is ≥ 0"),
                        ));
                    }
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
                    cloads_here.clear();
                    pressures_here.clear();
                    gravity_here.clear();
                    first_request = [true; 4];
                    state.line = card.line;
                    state.static_seen = false;
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
                        let v = load(path, d, 2, "load")?;
                        if d.fields.len() > 3 {
                            return Err(error(
                                path,
                                d.line,
                                "a *CLOAD line is 'node|nset, dof, value'",
                            ));
                        }
                        for &n in &nodes {
                            let key = (n, (dof - 1) as usize);
                            if cloads_here.insert(key) {
                                state.cloads.insert(key, v);
                            } else {
                                *state.cloads.get_mut(&key).expect("given in this step") += v;
                            }
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
                                let p = load(path, d, 2, "pressure")?;
                                if d.fields.len() > 3 {
                                    return Err(error(
                                        path,
                                        d.line,
                                        "a pressure line is 'element|elset, Pk, p'",
                                    ));
                                }
                                for &e in &elements {
                                    if pressures_here.insert((e, face)) {
                                        state.pressures.insert((e, face), p);
                                    } else {
                                        *state.pressures.get_mut(&(e, face)).expect("given") += p;
                                    }
                                }
                            }
                            "GRAV" => {
                                let g = load(path, d, 2, "gravity magnitude")?;
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
                                let this = Grav {
                                    g,
                                    dir: dir.map(|v| v / n),
                                };
                                for &e in &elements {
                                    let grav = if gravity_here.insert(e) {
                                        this
                                    } else {
                                        state.gravity[&e].plus(&this)
                                    };
                                    state.gravity.insert(e, grav);
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
                    let kind = ["NODE PRINT", "EL PRINT", "NODE FILE", "EL FILE"]
                        .iter()
                        .position(|k| *k == kw)
                        .expect("one of the four");
                    if std::mem::replace(&mut first_request[kind], false) {
                        match kind {
                            0 => state.node_print.clear(),
                            1 => state.el_print.clear(),
                            2 => node_file.clear(),
                            _ => el_file.clear(),
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
                            let list = if kind == 2 {
                                &mut node_file
                            } else {
                                &mut el_file
                            };
                            for v in vars {
                                if !list.contains(&v) {
                                    list.push(v);
                                }
                            }
                        }
                    }
                    state.file_vars = node_file.clone();
                    for v in &el_file {
                        if !state.file_vars.contains(v) {
                            state.file_vars.push(v.clone());
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
            return Err(error(
                path,
                0,
                "no C3D10/C3D4 elements: a deck needs *NODE and *ELEMENT, TYPE=C3D10 (or C3D4) \
                 cards (an empty or cut-off file has none)",
            ));
        }
        if m.steps.is_empty() {
            return Err(error(
                path,
                0,
                "no *STEP: a deck needs a *STEP with *STATIC, its loads and *END STEP",
            ));
        }
        Ok(m)
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
