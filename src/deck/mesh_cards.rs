//! The mesh cards of a deck (`*NODE`, `*ELEMENT`, `*NSET`, `*ELSET`) and the look-ups of nodes,
//! elements and sets that the other cards name.

use std::path::Path;

use super::model::*;
use super::parse::{Card, DataLine, coordinate, error, int, push_unique, required};
use crate::fem::error::Result;

impl Model {
    pub(super) fn read_nodes(&mut self, path: &Path, card: &Card) -> Result<()> {
        let mut added = Vec::new();
        for d in &card.data {
            // `id, x, y` is read with z = 0, as ccx and Abaqus read it
            if !(3..=4).contains(&d.fields.len()) {
                return Err(error(
                    path,
                    d.line,
                    format!(
                        "a node line is 'id, x, y[, z]': found {} fields",
                        d.fields.len()
                    ),
                ));
            }
            let id = int(path, d.line, &d.fields[0], "node id")?;
            let p = [
                coordinate(path, d, 1, "x")?,
                coordinate(path, d, 2, "y")?,
                if d.fields.len() == 4 {
                    coordinate(path, d, 3, "z")?
                } else {
                    0.0
                },
            ];
            // a node defined twice keeps its first definition (the refusal is listed with the
            // deck's others, and its elements still find the node they name)
            if self.node_index.contains_key(&id) {
                return Err(error(path, d.line, format!("node {id} defined twice")));
            }
            self.node_index.insert(id, self.nodes.len());
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

    pub(super) fn read_elements(&mut self, path: &Path, card: &Card) -> Result<()> {
        let ty = required(path, card, "TYPE")?.to_ascii_uppercase();
        let (kind, n) = match ty.as_str() {
            "C3D10" => (ElementKind::Tet10, 10),
            "C3D4" => (ElementKind::Tet4, 4),
            _ => {
                return Err(error(
                    path,
                    card.line,
                    format!(
                        "element type {ty} is not supported (solid tetrahedra C3D10 and C3D4 \
                         only; hexahedra such as C3D20/C3D8, shells and beams are refused)"
                    ),
                ));
            }
        };
        let mut added = Vec::new();
        let mut pending: Vec<i64> = Vec::new();
        let mut start = 0;
        for d in &card.data {
            if pending.is_empty() {
                start = d.line;
            }
            for f in &d.fields {
                if f.is_empty() {
                    return Err(error(
                        path,
                        d.line,
                        "an empty field in an element line (`id, n1, n2, ...`): remove the \
                         extra comma or fill in the node",
                    ));
                }
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
                    if nodes.contains(&i) {
                        return Err(error(
                            path,
                            start,
                            format!(
                                "element {id} lists node {nid} twice: its {n} nodes must be \
                                 distinct; check the element's connectivity"
                            ),
                        ));
                    }
                    nodes.push(i);
                }
                // four corners at four places (a distance that underflows is none)
                for a in 0..4 {
                    for b in a + 1..4 {
                        let (p, q) = (self.nodes[nodes[a]], self.nodes[nodes[b]]);
                        let d2: f64 = (0..3).map(|j| (p[j] - q[j]).powi(2)).sum();
                        if d2.sqrt() == 0.0 {
                            return Err(error(
                                path,
                                start,
                                format!(
                                    "element {id}: its corners {} and {} (nodes {} and {}) \
                                     coincide: an element needs four corners at distinct \
                                     places; check the nodes' coordinates",
                                    a + 1,
                                    b + 1,
                                    pending[1 + a],
                                    pending[1 + b]
                                ),
                            ));
                        }
                    }
                }
                if self.element_index.contains_key(&id) {
                    return Err(error(path, start, format!("element {id} defined twice")));
                }
                self.element_index.insert(id, self.elements.len());
                added.push(self.elements.len());
                self.elements.push(Element {
                    id,
                    kind,
                    nodes,
                    line: start,
                });
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

    pub(super) fn read_set(&mut self, path: &Path, card: &Card) -> Result<()> {
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

    pub(super) fn lookup(&self, path: &Path, line: usize, nodes: bool, id: i64) -> Result<usize> {
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
    pub(super) fn node_target(&self, path: &Path, d: &DataLine) -> Result<(String, Vec<usize>)> {
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
    pub(super) fn element_target(&self, path: &Path, d: &DataLine) -> Result<Vec<usize>> {
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
