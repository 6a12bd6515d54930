//! Surfaces, local axes and equations of a deck:
//!
//! * `*SURFACE, NAME=` [TYPE=ELEMENT]: `element|elset, S1…S4` (the faces of the manual's "C3D10"
//!   and "C3D4": S1 = 1-2-3, S2 = 1-4-2, S3 = 2-4-3, S4 = 3-4-1, the faces of P1–P4);
//!   TYPE=NODE: `node|nset[, weight]` (read as a node set of the same name; weights refused);
//! * `*TRANSFORM, NSET=` [TYPE=R|C]: `a1, a2, a3, b1, b2, b3` (manual, "*TRANSFORM": rectangular:
//!   local x along a, local y in the plane of a and b; cylindrical: the axis through the points a
//!   and b, local axes radial, tangential, axial);
//! * `*EQUATION`: a line with the number of terms, then `node, dof, coefficient` triples (any
//!   number per line): Σ c u = 0, the first term's DOF dependent (manual, "*EQUATION").

use std::path::Path;

use super::model::*;
use super::parse::{Card, DataLine, error, int, num, push_unique, required};
use crate::fem::error::Result;

impl Model {
    pub(super) fn read_surface(&mut self, path: &Path, card: &Card) -> Result<()> {
        let name = required(path, card, "NAME")?.to_ascii_uppercase();
        let ty = card.param("TYPE").unwrap_or("ELEMENT").to_ascii_uppercase();
        match ty.as_str() {
            "ELEMENT" => {
                let mut faces = Vec::new();
                for d in &card.data {
                    let elements = self.element_target(path, d)?;
                    let label = d
                        .fields
                        .get(1)
                        .map(|s| s.to_ascii_uppercase())
                        .unwrap_or_default();
                    let face = match label.as_str() {
                        "S1" | "S2" | "S3" | "S4" => (label.as_bytes()[1] - b'1') as usize,
                        _ => {
                            return Err(error(
                                path,
                                d.line,
                                format!(
                                    "surface face '{label}': a tetrahedron's faces are S1-S4 (an \
                                     element-face line is 'element|elset, Sk')"
                                ),
                            ));
                        }
                    };
                    if d.fields.len() > 2 {
                        return Err(error(
                            path,
                            d.line,
                            "an element-face line is 'element|elset, Sk'",
                        ));
                    }
                    faces.extend(elements.into_iter().map(|e| (e, face)));
                }
                let list = self.element_surfaces.entry(name).or_default();
                for f in faces {
                    if !list.contains(&f) {
                        list.push(f);
                    }
                }
            }
            "NODE" => {
                let mut nodes = Vec::new();
                for d in &card.data {
                    if d.fields.len() > 1 {
                        return Err(error(
                            path,
                            d.line,
                            "weights on a node surface are not supported: 'node|nset'",
                        ));
                    }
                    nodes.extend(self.node_target(path, d)?.1);
                }
                push_unique(self.nsets.entry(name).or_default(), nodes);
            }
            _ => {
                return Err(error(
                    path,
                    card.line,
                    format!("*SURFACE, TYPE={ty}: ELEMENT or NODE"),
                ));
            }
        }
        Ok(())
    }

    /// The first field of a data line as an element-face surface.
    pub(super) fn surface_faces(&self, path: &Path, d: &DataLine) -> Result<Vec<(usize, usize)>> {
        let f = d.fields.first().map(String::as_str).unwrap_or("");
        self.element_surfaces
            .get(&f.to_ascii_uppercase())
            .cloned()
            .ok_or_else(|| {
                error(
                    path,
                    d.line,
                    format!("element-face surface '{f}' is not defined (*SURFACE, TYPE=ELEMENT)"),
                )
            })
    }

    pub(super) fn read_transform(&mut self, path: &Path, card: &Card) -> Result<()> {
        let set = required(path, card, "NSET")?.to_ascii_uppercase();
        let nodes = self
            .nsets
            .get(&set)
            .cloned()
            .ok_or_else(|| error(path, card.line, format!("node set {set} is not defined")))?;
        let d = &card.data[0];
        if d.fields.len() != 6 {
            return Err(error(
                path,
                d.line,
                "a *TRANSFORM line is 'a1, a2, a3, b1, b2, b3'",
            ));
        }
        let v: Vec<f64> = (0..6)
            .map(|k| num(path, d, k, "coordinate"))
            .collect::<Result<_>>()?;
        let a = [v[0], v[1], v[2]];
        let b = [v[3], v[4], v[5]];
        let ty = card.param("TYPE").unwrap_or("R").to_ascii_uppercase();
        let t = match ty.as_str() {
            "R" => {
                let cross = [
                    a[1] * b[2] - a[2] * b[1],
                    a[2] * b[0] - a[0] * b[2],
                    a[0] * b[1] - a[1] * b[0],
                ];
                if cross
                    .iter()
                    .all(|c| c.abs() < 1e-12 * (norm(a) * norm(b)).max(f64::MIN_POSITIVE))
                {
                    return Err(error(
                        path,
                        d.line,
                        "TYPE=R: a and b must be non-zero and not parallel",
                    ));
                }
                Transform::Rectangular { a, b }
            }
            "C" => {
                if norm([b[0] - a[0], b[1] - a[1], b[2] - a[2]]) == 0.0 {
                    return Err(error(
                        path,
                        d.line,
                        "TYPE=C: the axis points a and b coincide",
                    ));
                }
                Transform::Cylindrical { a, b }
            }
            _ => {
                return Err(error(
                    path,
                    card.line,
                    format!("*TRANSFORM, TYPE={ty}: R or C"),
                ));
            }
        };
        for n in nodes {
            self.transforms.insert(n, t);
        }
        Ok(())
    }

    pub(super) fn read_equation(&mut self, path: &Path, card: &Card) -> Result<()> {
        let mut lines = card.data.iter();
        while let Some(head) = lines.next() {
            if head.fields.len() != 1 {
                return Err(error(
                    path,
                    head.line,
                    "an *EQUATION starts with a line holding its number of terms",
                ));
            }
            let count = int(path, head.line, &head.fields[0], "number of terms")?;
            if count < 1 {
                return Err(error(
                    path,
                    head.line,
                    "an equation needs at least one term",
                ));
            }
            let mut terms = Vec::new();
            while terms.len() < count as usize {
                let d = lines.next().ok_or_else(|| {
                    error(
                        path,
                        head.line,
                        format!("an equation of {count} terms has only {}", terms.len()),
                    )
                })?;
                if d.fields.len() % 3 != 0 {
                    return Err(error(
                        path,
                        d.line,
                        "equation terms are 'node, dof, coefficient' triples",
                    ));
                }
                for k in (0..d.fields.len()).step_by(3) {
                    let id = int(path, d.line, &d.fields[k], "node")?;
                    let n = self.lookup(path, d.line, true, id)?;
                    let dof = int(path, d.line, &d.fields[k + 1], "dof")?;
                    if !(1..=3).contains(&dof) {
                        return Err(error(
                            path,
                            d.line,
                            format!("dof {dof}: only displacements 1-3 exist on solid elements"),
                        ));
                    }
                    let c = num(path, d, k + 2, "coefficient")?;
                    terms.push((n, (dof - 1) as usize, c));
                }
            }
            if terms.len() != count as usize {
                return Err(error(
                    path,
                    head.line,
                    format!("an equation of {count} terms has {}", terms.len()),
                ));
            }
            if terms[0].2 == 0.0 {
                return Err(error(
                    path,
                    head.line,
                    "the first coefficient of an equation (its dependent DOF's) is zero",
                ));
            }
            self.equations.push((terms, head.line));
        }
        Ok(())
    }
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
