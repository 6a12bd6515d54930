//! The mesh subset of Abaqus/CalculiX input decks (`.inp`), read natively: `*NODE` and
//! `*ELEMENT, TYPE=C3D10` (and its variants C3D10H, C3D10I, C3D10M, C3D10MH), or
//! `TYPE=C3D4`/`C3D4H` (linear tetrahedra, promoted to straight-sided tet10 as the meshio path
//! does).
//!
//! Format: the CalculiX CrunchiX user's manual (ccx 2.20), "Input deck format" and the keyword
//! cards `*NODE` (`id, x, y, z` per line) and `*ELEMENT` (`id, n1, ..., n10`, continued on the
//! next line when it does not fit); the Abaqus Analysis User's Guide, "Three-dimensional solid
//! element library". Keywords start with `*`, `**` starts a comment line, keywords and parameter
//! names are case-insensitive.
//!
//! Node order of C3D10 (CalculiX manual, "Three-dimensional elements: C3D10"; Abaqus, "Solid
//! element library", node ordering of the 10-node tetrahedron): corners 1-4, then the midside
//! nodes of edges 1-2, 2-3, 3-1, 1-4, 2-4, 3-4, which is VTK's tetra10 order (edges 01, 12, 02, 03,
//! 13, 23) shifted to 1-based: no permutation (meshio's Abaqus reader does none either).
//!
//! Nodes are numbered in file order, elements kept in file order (element ids are not used), as
//! meshio reads them. What is refused, with the line number:
//! * keywords that bring or move mesh data this reader would otherwise miss: `*INCLUDE`, `*NGEN`,
//!   `*NFILL`, `*NCOPY`, `*NMAP`, `*ELGEN`, `*ELCOPY`, `*SYSTEM`, `*PART`, `*INSTANCE`,
//!   `*ASSEMBLY`, and `*NODE`/`*ELEMENT` with `INPUT=` or `*NODE, SYSTEM=` (meshio ignores all
//!   of these but `*INCLUDE`, and would silently read a different mesh);
//! * volume elements other than tetrahedra (`TYPE=C3D8`, `C3D20`, `C3D6`, `C3D15`, ...: the
//!   meshio path silently drops them, losing material);
//! * an `*ELEMENT` before any `*NODE`, an undefined or repeated node id, a node line without
//!   exactly three coordinates, an incomplete element, or one
//!   that ends inside a line, a number that does not parse.
//!
//! What is ignored, as meshio ignores it: every other keyword with its data lines (`*HEADING`,
//! `*NSET`, `*ELSET`, `*MATERIAL`, `*ELASTIC`, `*SOLID SECTION`, `*BOUNDARY`, `*STEP`, `*CLOAD`,
//! `*NODE FILE`, ...), and elements of other dimensions (surface, shell, beam, truss: `TYPE=S6`,
//! `CPS3`, `T3D2`, ...), which the meshio path drops after reading. Two deliberate differences
//! from meshio: several `*NODE` blocks are all read (meshio keeps only the last one), and a `**`
//! comment inside a data block is only a comment (meshio ends the block there).

use std::collections::HashMap;
use std::path::Path;

use super::raw_volume::{FileLabel, RawVolume};
use crate::fem::error::{FemError, Result};

/// Keywords carrying mesh data that are not read natively.
const REFUSED: [&str; 11] = [
    "INCLUDE", "NGEN", "NFILL", "NCOPY", "NMAP", "ELGEN", "ELCOPY", "SYSTEM", "PART", "INSTANCE",
    "ASSEMBLY",
];

enum Block {
    None,
    Nodes,
    /// Elements of `n` nodes kept as tet10 (`true`) or tet4 (`false`), or dropped (`None`).
    Elements(Option<bool>, usize),
}

/// Reads the tetrahedra of an Abaqus/CalculiX `.inp` file; see the module documentation.
pub fn read_inp(path: &Path) -> Result<RawVolume> {
    let text = std::fs::read_to_string(path).map_err(|e| FemError::io(path, e))?;
    let perr = |line: usize, message: String| FemError::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut raw = RawVolume::default();
    let mut ids: HashMap<i64, usize> = HashMap::new();
    let mut block = Block::None;
    // tokens of the element being read (it may span lines) and the line it started on
    let mut pending: Vec<i64> = Vec::with_capacity(11);
    let mut pending_line = 0;
    let flush = |pending: &Vec<i64>, line: usize| -> Result<()> {
        if pending.is_empty() {
            Ok(())
        } else {
            Err(perr(
                line,
                format!("incomplete element: {} numbers", pending.len()),
            ))
        }
    };
    for (i, l) in text.lines().enumerate() {
        let ln = i + 1;
        let t = l.trim();
        if t.is_empty() || t.starts_with("**") {
            continue;
        }
        if let Some(card) = t.strip_prefix('*') {
            flush(&pending, pending_line)?;
            let mut parts = card.split(',');
            let keyword = parts.next().unwrap_or("").trim().to_ascii_uppercase();
            let mut params: HashMap<String, String> = HashMap::new();
            for p in parts {
                let (k, v) = p.split_once('=').unwrap_or((p, ""));
                params.insert(k.trim().to_ascii_uppercase(), v.trim().to_string());
            }
            if REFUSED.contains(&keyword.as_str()) {
                return Err(perr(
                    ln,
                    format!(
                        "*{keyword} is not read natively (only *NODE and *ELEMENT carry the mesh \
                         here): write the mesh out in full, or convert it to .msh or .vtu"
                    ),
                ));
            }
            block = match keyword.as_str() {
                "NODE" => {
                    for bad in ["INPUT", "SYSTEM"] {
                        if params.contains_key(bad) {
                            return Err(perr(ln, format!("*NODE, {bad}= is not read natively")));
                        }
                    }
                    Block::Nodes
                }
                "ELEMENT" => {
                    if params.contains_key("INPUT") {
                        return Err(perr(ln, "*ELEMENT, INPUT= is not read natively".into()));
                    }
                    if raw.nodes.is_empty() {
                        return Err(perr(ln, "*ELEMENT before any *NODE".into()));
                    }
                    let ty = params
                        .get("TYPE")
                        .ok_or_else(|| perr(ln, "*ELEMENT without TYPE=".into()))?
                        .to_ascii_uppercase();
                    match ty.as_str() {
                        "C3D10" | "C3D10H" | "C3D10I" | "C3D10M" | "C3D10MH" => {
                            Block::Elements(Some(true), 10)
                        }
                        "C3D4" | "C3D4H" => Block::Elements(Some(false), 4),
                        v if v.starts_with("C3D") => {
                            return Err(perr(
                                ln,
                                format!(
                                    "element type {v}: only tetrahedra (C3D10, C3D4) can be used"
                                ),
                            ));
                        }
                        _ => {
                            raw.dropped.push(ty.clone());
                            Block::Elements(None, 0)
                        }
                    }
                }
                _ => Block::None,
            };
            continue;
        }
        match block {
            Block::None | Block::Elements(None, _) => {}
            Block::Nodes => {
                let fields: Vec<&str> = t.trim_end_matches(',').split(',').collect();
                if fields.len() != 4 {
                    return Err(perr(
                        ln,
                        format!(
                            "a node line is 'id, x, y, z': found {} fields",
                            fields.len()
                        ),
                    ));
                }
                let id: i64 = fields[0]
                    .trim()
                    .parse()
                    .map_err(|_| perr(ln, format!("bad node id '{}'", fields[0].trim())))?;
                let mut p = [0.0; 3];
                for (j, f) in fields[1..].iter().enumerate() {
                    p[j] = f
                        .trim()
                        .parse()
                        .map_err(|_| perr(ln, format!("bad coordinate '{}'", f.trim())))?;
                }
                if ids.insert(id, raw.nodes.len()).is_some() {
                    return Err(perr(ln, format!("node {id} defined twice")));
                }
                raw.nodes.push(p);
                raw.node_labels.push(FileLabel { id, line: ln });
            }
            Block::Elements(Some(quadratic), n) => {
                let tokens: Vec<&str> = t
                    .split(',')
                    .map(str::trim)
                    .filter(|f| !f.is_empty())
                    .collect();
                for (k, f) in tokens.iter().enumerate() {
                    if pending.is_empty() {
                        pending_line = ln;
                    }
                    let v: i64 = f
                        .parse()
                        .map_err(|_| perr(ln, format!("bad integer '{f}'")))?;
                    if !pending.is_empty() {
                        // a node id: looked up now, so that the error names this line
                        if !ids.contains_key(&v) {
                            return Err(perr(
                                ln,
                                format!("element {} refers to undefined node {v}", pending[0]),
                            ));
                        }
                    }
                    pending.push(v);
                    if pending.len() == n + 1 {
                        let node = |a: usize| ids[&pending[1 + a]];
                        if quadratic {
                            raw.tet10.push(std::array::from_fn(node));
                        } else {
                            raw.tet4.push(std::array::from_fn(node));
                        }
                        raw.tet_labels.push(FileLabel {
                            id: pending[0],
                            line: pending_line,
                        });
                        pending.clear();
                        // an element ends with its line (it may span lines, not share one)
                        if k + 1 < tokens.len() {
                            return Err(perr(
                                ln,
                                format!(
                                    "{} numbers after the end of an element (id and {n} nodes)",
                                    tokens.len() - k - 1
                                ),
                            ));
                        }
                    }
                }
            }
        }
    }
    flush(&pending, pending_line)?;
    Ok(raw)
}
