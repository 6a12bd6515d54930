//! Reader and writer of the `.rodmesh` hand-off format written by `pipeline/mesh_rod.py`:
//!
//! ```text
//! rodmesh 1
//! # comment lines start with '#'
//! units mm            (or m)
//! nodes N
//! x y z               (N lines)
//! tet10 M
//! n0 n1 ... n9        (M lines, 0-based, VTK tetra10 order)
//! ```
//!
//! Coordinates are converted from the file's units to metres here, at the reader edge.

use std::fmt::Write as _;
use std::path::Path;

use crate::fem::TetMesh;
use crate::fem::error::{FemError, Result};

/// Reads a `.rodmesh` file into a validated mesh in metres.
pub fn read_rodmesh(path: &Path) -> Result<TetMesh> {
    let text = std::fs::read_to_string(path).map_err(|e| FemError::io(path, e))?;
    let perr = |line: usize, message: String| FemError::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let mut next = |what: &str| {
        lines
            .next()
            .ok_or_else(|| perr(0, format!("unexpected end of file, expected {what}")))
    };

    let (ln, head) = next("the header")?;
    if head != "rodmesh 1" {
        return Err(perr(
            ln,
            format!("expected header 'rodmesh 1', found '{head}'"),
        ));
    }
    let (ln, units) = next("'units mm|m'")?;
    let scale = match units.split_whitespace().collect::<Vec<_>>().as_slice() {
        ["units", "mm"] => 1e-3,
        ["units", "m"] => 1.0,
        _ => {
            return Err(perr(
                ln,
                format!("expected 'units mm' or 'units m', found '{units}'"),
            ));
        }
    };
    let count = |ln: usize, l: &str, key: &str| -> Result<usize> {
        match l.split_whitespace().collect::<Vec<_>>().as_slice() {
            [k, n] if *k == key => n
                .parse()
                .map_err(|_| perr(ln, format!("bad count in '{l}'"))),
            _ => Err(perr(ln, format!("expected '{key} COUNT', found '{l}'"))),
        }
    };
    let (ln, l) = next("'nodes N'")?;
    let n_nodes = count(ln, l, "nodes")?;
    let mut nodes = Vec::with_capacity(n_nodes);
    for _ in 0..n_nodes {
        let (ln, l) = next("a node line")?;
        let v: Vec<f64> = l
            .split_whitespace()
            .map(|s| s.parse::<f64>())
            .collect::<std::result::Result<_, _>>()
            .map_err(|_| perr(ln, format!("bad node coordinates '{l}'")))?;
        if v.len() != 3 {
            return Err(perr(
                ln,
                format!("expected 3 coordinates, found {}", v.len()),
            ));
        }
        nodes.push([v[0] * scale, v[1] * scale, v[2] * scale]);
    }
    let (ln, l) = next("'tet10 M'")?;
    let n_el = count(ln, l, "tet10")?;
    let mut elements = Vec::with_capacity(n_el);
    for _ in 0..n_el {
        let (ln, l) = next("an element line")?;
        let v: Vec<usize> = l
            .split_whitespace()
            .map(|s| s.parse::<usize>())
            .collect::<std::result::Result<_, _>>()
            .map_err(|_| perr(ln, format!("bad element line '{l}'")))?;
        let el: [usize; 10] = v.try_into().map_err(|v: Vec<usize>| {
            perr(ln, format!("expected 10 node indices, found {}", v.len()))
        })?;
        elements.push(el);
    }
    if let Some((ln, l)) = lines.next() {
        return Err(perr(
            ln,
            format!("unexpected content after the elements: '{l}'"),
        ));
    }
    TetMesh::new(nodes, elements).map_err(|e| perr(0, e.to_string()))
}

/// Writes `mesh` as a `.rodmesh` file in millimetres (exact round trip of the f64 values scaled by 1000).
pub fn write_rodmesh(mesh: &TetMesh, path: &Path) -> Result<()> {
    let mut s = String::with_capacity(64 * mesh.n_nodes() + 64 * mesh.n_elements());
    s.push_str("rodmesh 1\n# written by rodstudy\nunits mm\n");
    let _ = writeln!(s, "nodes {}", mesh.n_nodes());
    for p in mesh.nodes() {
        let _ = writeln!(s, "{:?} {:?} {:?}", p[0] * 1e3, p[1] * 1e3, p[2] * 1e3);
    }
    let _ = writeln!(s, "tet10 {}", mesh.n_elements());
    for el in mesh.elements() {
        let line: Vec<String> = el.iter().map(|n| n.to_string()).collect();
        s.push_str(&line.join(" "));
        s.push('\n');
    }
    std::fs::write(path, s).map_err(|e| FemError::io(path, e))
}
