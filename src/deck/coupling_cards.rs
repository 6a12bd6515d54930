//! Couplings to a reference node (manual, "*COUPLING", "*KINEMATIC", "*DISTRIBUTING"; theory in
//! its section "Kinematic and Distributing Coupling"):
//!
//! * `*COUPLING, REF NODE=, SURFACE=[, CONSTRAINT NAME=]`, followed at once by
//! * `*KINEMATIC`: lines `first[, last]` (DOFs 1–3): those DOFs of every node of the surface
//!   (element faces or a node surface) follow the reference node's rigid-body motion; the
//!   reference node's rotations (DOFs 4–6) are three DOFs of a node added after the deck's
//!   nodes, as ccx adds its rotational node;
//! * `*DISTRIBUTING`: lines `first[, last]` (DOFs 1–6; the forces 1–3 are always distributed,
//!   the moments 4–6 when listed): the reference node's `*CLOAD` force and moment become point
//!   loads on the nodes of an element-face surface (ccx 2.20's distributing coupling loads,
//!   `couplings.f`; [`super::coupling`]).
//!
//! Refused: `ORIENTATION=` (local axes), `*DISTRIBUTING, CYCLIC SYMMETRY`, a node surface under
//! `*DISTRIBUTING` (ccx refuses it too), a node that is the reference of two couplings, local
//! axes (`*TRANSFORM`) on a reference node or on a kinematic coupling's surface, and supports on
//! a distributing coupling's reference node (its displacement is not defined: ccx prints 0).

use std::path::Path;

use super::cards::Reader;
use super::model::*;
use super::parse::{Card, error, int, push_unique};
use crate::fem::error::Result;
use crate::fem::shape::TET10_FACES;

/// The value of a parameter written with or without its blanks (`REF NODE` or `REFNODE`, as ccx
/// reads both).
fn param_any<'a>(card: &'a Card, name: &str) -> Option<&'a str> {
    let squeeze = |s: &str| s.replace(' ', "");
    card.params
        .iter()
        .find(|(k, _)| squeeze(k) == squeeze(name))
        .map(|(_, v)| v.as_str())
}

impl Model {
    pub(super) fn read_coupling(&mut self, path: &Path, card: &Card, r: &mut Reader) -> Result<()> {
        if param_any(card, "ORIENTATION").is_some() {
            return Err(error(
                path,
                card.line,
                "*COUPLING, ORIENTATION: local axes are not supported (the DOFs are global)",
            ));
        }
        let reference = param_any(card, "REF NODE")
            .ok_or_else(|| error(path, card.line, "*COUPLING needs REF NODE="))?;
        let id = int(path, card.line, reference, "REF NODE")?;
        let reference = self.lookup(path, card.line, true, id)?;
        if self.coupling_of(reference).is_some() {
            return Err(error(
                path,
                card.line,
                format!("node {id} is already the reference node of a *COUPLING: one each"),
            ));
        }
        let surface = param_any(card, "SURFACE")
            .ok_or_else(|| error(path, card.line, "*COUPLING needs SURFACE="))?
            .to_ascii_uppercase();
        if !self.element_surfaces.contains_key(&surface) && !self.nsets.contains_key(&surface) {
            return Err(error(
                path,
                card.line,
                format!("surface {surface} is not defined (*SURFACE before *COUPLING)"),
            ));
        }
        r.coupling = Some((reference, surface, card.line));
        Ok(())
    }

    /// `*KINEMATIC` or `*DISTRIBUTING` after its `*COUPLING`.
    pub(super) fn read_coupling_kind(
        &mut self,
        path: &Path,
        card: &Card,
        r: &mut Reader,
    ) -> Result<()> {
        let kw = card.keyword.as_str();
        let Some((reference, surface, line)) = r.coupling.take() else {
            return Err(error(
                path,
                card.line,
                format!("*{kw} without a *COUPLING card just above it"),
            ));
        };
        let mut listed = [false; 6];
        let top = if kw == "KINEMATIC" { 3 } else { 6 };
        for d in &card.data {
            if d.fields.is_empty() || d.fields.len() > 2 {
                return Err(error(
                    path,
                    d.line,
                    format!("a *{kw} line is 'first[, last]'"),
                ));
            }
            let first = int(path, d.line, &d.fields[0], "first dof")?;
            let last = match d.fields.get(1).filter(|f| !f.is_empty()) {
                Some(f) => int(path, d.line, f, "last dof")?,
                None => first,
            };
            if !(1..=top).contains(&first) || !(first..=top).contains(&last) {
                return Err(error(
                    path,
                    d.line,
                    format!("dofs {first}..{last}: *{kw} takes DOFs 1 to {top}"),
                ));
            }
            for k in first..=last {
                listed[(k - 1) as usize] = true;
            }
        }
        let faces = self
            .element_surfaces
            .get(&surface)
            .cloned()
            .unwrap_or_default();
        let mut nodes = Vec::new();
        if faces.is_empty() {
            if kw == "DISTRIBUTING" {
                return Err(error(
                    path,
                    line,
                    format!(
                        "*DISTRIBUTING needs an element-face surface (*SURFACE, TYPE=ELEMENT): \
                         {} is a node surface, which carries no areas to weigh the nodes",
                        surface
                    ),
                ));
            }
            push_unique(&mut nodes, self.nsets[&surface].iter().copied());
        } else {
            for &(e, f) in &faces {
                let el = &self.elements[e];
                let corners = if el.nodes.len() == 10 { 6 } else { 3 };
                push_unique(
                    &mut nodes,
                    TET10_FACES[f][..corners].iter().map(|&a| el.nodes[a]),
                );
            }
        }
        if nodes.contains(&reference) {
            return Err(error(
                path,
                line,
                "the reference node lies on the coupling's own surface: give a node of its own",
            ));
        }
        let kind = if kw == "KINEMATIC" {
            if !listed[..3].iter().any(|b| *b) {
                return Err(error(path, card.line, "*KINEMATIC without data lines"));
            }
            CouplingKind::Kinematic {
                dofs: [listed[0], listed[1], listed[2]],
                rotation_node: usize::MAX,
            }
        } else {
            if card
                .params
                .iter()
                .any(|(k, _)| k.replace(' ', "") == "CYCLICSYMMETRY")
            {
                return Err(error(
                    path,
                    card.line,
                    "*DISTRIBUTING, CYCLIC SYMMETRY is not supported",
                ));
            }
            CouplingKind::Distributing {
                moments: [listed[3], listed[4], listed[5]],
            }
        };
        self.couplings.push(Coupling {
            reference,
            surface,
            faces,
            nodes,
            kind,
            line,
            file: card.file.clone(),
        });
        Ok(())
    }

    /// After the last card: the rotation nodes of the kinematic couplings (ids after the
    /// largest), and the checks that need the whole deck.
    pub(super) fn finish_couplings(&mut self) -> Vec<crate::fem::error::FemError> {
        let mut refusals = Vec::new();
        let mut next = self.node_ids.iter().copied().max().unwrap_or(0);
        for k in 0..self.couplings.len() {
            let c = &self.couplings[k];
            let (reference, line, file) = (c.reference, c.line, c.file.clone());
            let transformed = if matches!(c.kind, CouplingKind::Kinematic { .. }) {
                c.nodes
                    .iter()
                    .chain([&reference])
                    .find(|n| self.transforms.contains_key(n))
            } else {
                Some(&reference).filter(|n| self.transforms.contains_key(n))
            };
            if let Some(&n) = transformed {
                refusals.push(error(
                    &file,
                    line,
                    format!(
                        "node {} of the *COUPLING has local axes (*TRANSFORM), which a coupling \
                         does not support: the coupling's DOFs are global",
                        self.node_ids[n]
                    ),
                ));
            }
            if let CouplingKind::Kinematic { .. } = c.kind {
                next += 1;
                let at = self.nodes.len();
                self.nodes.push(self.nodes[reference]);
                self.node_ids.push(next);
                self.node_index.insert(next, at);
                if let CouplingKind::Kinematic { rotation_node, .. } = &mut self.couplings[k].kind {
                    *rotation_node = at;
                }
            }
        }
        refusals
    }
}
