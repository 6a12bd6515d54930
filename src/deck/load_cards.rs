//! Supports and loads of a deck: `*BOUNDARY` [OP=MOD, FIXED], `*CLOAD`, `*DLOAD` (Pk pressure,
//! GRAV, CENTRIF) and `*DSLOAD` (pressure on an element-face surface). Degrees of freedom of a
//! node with local axes (`*TRANSFORM`) are the local ones, as ccx reads them; [`super::solve`]
//! turns them into global constraints and forces.

use std::path::Path;

use super::cards::Reader;
use super::model::*;
use super::parse::{Card, DataLine, error, int, load, num, push_unique};
use crate::fem::error::Result;

impl Model {
    pub(super) fn read_boundary(&mut self, path: &Path, card: &Card, r: &mut Reader) -> Result<()> {
        if let Some(op) = card.param("OP")
            && !op.eq_ignore_ascii_case("MOD")
        {
            return Err(error(
                path,
                card.line,
                format!("*BOUNDARY, OP={op}: only OP=MOD (supports carry over) is supported"),
            ));
        }
        let fixed = card.has("FIXED");
        // FIXED holds the displacement of the previous step: zero before the first step has
        // been solved, which is all rodstudy accepts
        if fixed && (r.steps_begun > 1 || (r.steps_begun == 1 && !r.in_step)) {
            return Err(error(
                path,
                card.line,
                "*BOUNDARY, FIXED after the first step holds the previous step's displacement, \
                 which is not supported: give the values (or 0) explicitly",
            ));
        }
        for d in &card.data {
            let (name, nodes) = self.node_target(path, d)?;
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
                if fixed {
                    return Err(error(
                        path,
                        d.line,
                        "*BOUNDARY, FIXED takes no value: 'node|nset, first, last'",
                    ));
                }
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
            if !(1..=6).contains(&first) || !(first..=6).contains(&last) {
                return Err(error(
                    path,
                    d.line,
                    format!(
                        "dofs {first}..{last}: only displacements 1-3 exist on solid elements \
                         (rotations 4-6 on a *KINEMATIC coupling's reference node)"
                    ),
                ));
            }
            for &n in &nodes {
                match self.coupling_of(n).map(|c| &c.kind) {
                    Some(CouplingKind::Distributing { .. }) => {
                        return Err(error(
                            path,
                            d.line,
                            format!(
                                "node {} is a *DISTRIBUTING coupling's reference node, which \
                                 only passes its loads on: support the model's own nodes",
                                self.node_ids[n]
                            ),
                        ));
                    }
                    Some(CouplingKind::Kinematic { .. }) => {}
                    None if last > 3 => {
                        return Err(error(
                            path,
                            d.line,
                            format!(
                                "dofs {first}..{last} on node {}: rotations 4-6 exist only on \
                                 the reference node of a *COUPLING with *KINEMATIC above",
                                self.node_ids[n]
                            ),
                        ));
                    }
                    None => {}
                }
            }
            for &n in &nodes {
                for dof in first..=last {
                    r.state.boundary.insert((n, (dof - 1) as usize), value);
                }
            }
            push_unique(r.state.supported_sets.entry(name).or_default(), nodes);
        }
        Ok(())
    }

    pub(super) fn read_cload(&mut self, path: &Path, card: &Card, r: &mut Reader) -> Result<()> {
        if op_new(path, card)? && r.first_cload {
            r.state.cloads.clear();
        }
        r.first_cload = false;
        for d in &card.data {
            let (_, nodes) = self.node_target(path, d)?;
            let f1 = d
                .fields
                .get(1)
                .ok_or_else(|| error(path, d.line, "missing dof"))?;
            let dof = int(path, d.line, f1, "dof")?;
            if !(1..=6).contains(&dof) {
                return Err(error(
                    path,
                    d.line,
                    format!(
                        "dof {dof}: forces are 1-3 (moments 4-6 on a coupling's reference node)"
                    ),
                ));
            }
            if dof > 3 {
                for &n in &nodes {
                    let ok = match self.coupling_of(n).map(|c| &c.kind) {
                        Some(CouplingKind::Kinematic { .. }) => true,
                        Some(CouplingKind::Distributing { moments }) => moments[(dof - 4) as usize],
                        None => false,
                    };
                    if !ok {
                        return Err(error(
                            path,
                            d.line,
                            format!(
                                "a moment (dof {dof}) on node {}: moments act only on the \
                                 reference node of a *COUPLING with *KINEMATIC, or with \
                                 *DISTRIBUTING listing dof {dof}",
                                self.node_ids[n]
                            ),
                        ));
                    }
                }
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
                if r.cloads_here.insert(key) {
                    r.state.cloads.insert(key, v);
                } else {
                    *r.state.cloads.get_mut(&key).expect("given in this step") += v;
                }
            }
        }
        Ok(())
    }

    /// `*DLOAD` (element|elset, Pk|GRAV|CENTRIF, …) and `*DSLOAD` (surface, P, p).
    pub(super) fn read_dload(&mut self, path: &Path, card: &Card, r: &mut Reader) -> Result<()> {
        if op_new(path, card)? && r.first_dload {
            r.state.pressures.clear();
            r.state.gravity.clear();
            r.state.centrif.clear();
        }
        r.first_dload = false;
        for d in &card.data {
            let label = d
                .fields
                .get(1)
                .map(|s| s.to_ascii_uppercase())
                .unwrap_or_default();
            if card.keyword == "DSLOAD" {
                if label != "P" {
                    return Err(error(
                        path,
                        d.line,
                        format!("*DSLOAD label '{label}' is not supported (P: pressure)"),
                    ));
                }
                let faces = self.surface_faces(path, d)?;
                self.add_pressure(path, d, &faces, r)?;
                continue;
            }
            match label.as_str() {
                "P1" | "P2" | "P3" | "P4" => {
                    let face = (label.as_bytes()[1] - b'1') as usize;
                    let faces: Vec<(usize, usize)> = self
                        .element_target(path, d)?
                        .into_iter()
                        .map(|e| (e, face))
                        .collect();
                    self.add_pressure(path, d, &faces, r)?;
                }
                "GRAV" => {
                    let elements = self.element_target(path, d)?;
                    let g = load(path, d, 2, "gravity magnitude")?;
                    let dir = direction(
                        path,
                        d,
                        3,
                        "a GRAV line is 'elset, GRAV, g, nx, ny, nz' with a non-zero direction",
                        6,
                    )?;
                    let this = Grav { g, dir };
                    for &e in &elements {
                        let grav = if r.gravity_here.insert(e) {
                            this
                        } else {
                            r.state.gravity[&e].plus(&this)
                        };
                        r.state.gravity.insert(e, grav);
                    }
                }
                "CENTRIF" => {
                    let elements = self.element_target(path, d)?;
                    let omega2 = load(path, d, 2, "ω² (rotational speed squared)")?;
                    if omega2 < 0.0 {
                        return Err(error(path, d.line, format!("ω² = {omega2} is negative")));
                    }
                    let point = [
                        num(path, d, 3, "axis point x")?,
                        num(path, d, 4, "axis point y")?,
                        num(path, d, 5, "axis point z")?,
                    ];
                    let axis = direction(
                        path,
                        d,
                        6,
                        "a CENTRIF line is 'elset, CENTRIF, ω², x, y, z, nx, ny, nz' with a \
                         non-zero axis",
                        9,
                    )?;
                    let this = Centrif {
                        omega2,
                        point,
                        axis,
                    };
                    for &e in &elements {
                        if r.centrif_here.insert(e) {
                            r.state.centrif.insert(e, this);
                        } else {
                            let c = r.state.centrif[&e];
                            if c.point != point || c.axis != axis {
                                return Err(error(
                                    path,
                                    d.line,
                                    "two CENTRIF loads about different axes on one element in \
                                     one step are not supported",
                                ));
                            }
                            r.state.centrif.get_mut(&e).expect("given").omega2 += omega2;
                        }
                    }
                }
                _ => {
                    return Err(error(
                        path,
                        d.line,
                        format!(
                            "*DLOAD label '{label}' is not supported (P1-P4 on element faces, \
                             GRAV, CENTRIF)"
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    fn add_pressure(
        &self,
        path: &Path,
        d: &DataLine,
        faces: &[(usize, usize)],
        r: &mut Reader,
    ) -> Result<()> {
        let p = load(path, d, 2, "pressure")?;
        if d.fields.len() > 3 {
            return Err(error(
                path,
                d.line,
                "a pressure line is 'element|elset|surface, Pk|P, p'",
            ));
        }
        for &key in faces {
            if r.pressures_here.insert(key) {
                r.state.pressures.insert(key, p);
            } else {
                *r.state.pressures.get_mut(&key).expect("given") += p;
            }
        }
        Ok(())
    }
}

/// Fields k, k+1, k+2 of `d` as a non-zero direction, normalised; `end` fields at most.
fn direction(path: &Path, d: &DataLine, k: usize, usage: &str, end: usize) -> Result<[f64; 3]> {
    let v = [
        num(path, d, k, "nx")?,
        num(path, d, k + 1, "ny")?,
        num(path, d, k + 2, "nz")?,
    ];
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if n == 0.0 || !n.is_finite() || d.fields.len() > end {
        return Err(error(path, d.line, usage.to_string()));
    }
    Ok(v.map(|c| c / n))
}

fn op_new(path: &Path, card: &Card) -> Result<bool> {
    match card.param("OP") {
        None => Ok(false),
        Some(v) if v.eq_ignore_ascii_case("MOD") => Ok(false),
        Some(v) if v.eq_ignore_ascii_case("NEW") => Ok(true),
        Some(v) => Err(error(path, card.line, format!("OP={v}: NEW or MOD"))),
    }
}
