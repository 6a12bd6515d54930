//! What `rodstudy solve` writes: the JSON document (the requested node and element sets and the
//! reaction totals per step, the last step's also at the top level) and one VTU file per step
//! (ASCII VTK XML, quadratic tetrahedra, coordinates in the deck's units; point data: deck node id,
//! U, RF and S — S as ParaView's symmetric tensor `[xx, yy, zz, xy, yz, xz]` — and von Mises).

use std::fmt::Write as _;
use std::path::Path;

use serde_json::{Value, json};

use super::solve::DeckSolution;
use crate::fem::error::{FemError, Result};
use crate::fem::material::von_mises;
use crate::fem::nodal_stress::Extrapolation;

/// The JSON document of a solved deck.
pub fn json_document(deck: &Path, sol: &DeckSolution, extrapolation: Extrapolation) -> Value {
    let last = sol.steps.last().expect("a deck has a step");
    json!({
        "deck": deck.display().to_string(),
        "nodes": sol.node_ids.len(),
        "elements": sol.element_ids.len(),
        "dofs": sol.mesh.n_dofs(),
        "material": {"E": sol.material.youngs_modulus_pa, "nu": sol.material.poisson_ratio},
        "stress_extrapolation": match extrapolation {
            Extrapolation::Exact => "exact",
            Extrapolation::CalculiX => "calculix",
        },
        "components": {"U": ["ux", "uy", "uz"], "S": ["sxx", "syy", "szz", "sxy", "sxz", "syz"], "RF": ["fx", "fy", "fz"]},
        "node_sets": last.node_sets,
        "element_sets": last.element_sets,
        "reaction_totals": last.reaction_totals,
        "steps": sol.steps,
    })
}

fn array(s: &mut String, name: &str, ty: &str, comps: usize, values: impl Iterator<Item = String>) {
    let _ = writeln!(
        s,
        r#"<DataArray type="{ty}" Name="{name}" NumberOfComponents="{comps}" format="ascii">"#
    );
    let v: Vec<String> = values.collect();
    for chunk in v.chunks(6 * comps.max(1)) {
        s.push_str(&chunk.join(" "));
        s.push('\n');
    }
    s.push_str("</DataArray>\n");
}

/// Writes step `k` (0-based) of `sol` to `path`.
pub fn write_step_vtu(path: &Path, sol: &DeckSolution, k: usize) -> Result<()> {
    let step = &sol.steps[k];
    let mesh = &sol.mesh;
    let (np, nc) = (mesh.n_nodes(), mesh.n_elements());
    // values at mesh nodes: deck nodes' values; added (C3D4 midside) nodes from their corners are
    // not needed by the deck's outputs and are given the mean of the deck nodes around them in
    // the solution field, i.e. written as zero-marked (node id 0) with interpolated displacement
    let mut u = vec![[0.0; 3]; np];
    let mut rf = vec![[0.0; 3]; np];
    let mut s = vec![[0.0; 6]; np];
    for (m, d) in sol.deck_node.iter().enumerate() {
        if let Some(d) = d {
            u[m] = step.u[*d];
            rf[m] = step.rf[*d];
            s[m] = step.s[*d];
        }
    }
    for el in mesh.elements() {
        for (k, [a, b]) in crate::fem::shape::TET10_EDGES.iter().enumerate() {
            let m = el[4 + k];
            if sol.deck_node[m].is_none() {
                let (p, q) = (el[*a], el[*b]);
                u[m] = std::array::from_fn(|j| 0.5 * (u[p][j] + u[q][j]));
                s[m] = std::array::from_fn(|j| 0.5 * (s[p][j] + s[q][j]));
            }
        }
    }
    let g = |v: f64| format!("{v:e}");
    let mut out = String::with_capacity(200 * np + 100 * nc);
    out.push_str("<?xml version=\"1.0\"?>\n<!-- rodstudy solve: deck units -->\n");
    out.push_str("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n");
    let _ = writeln!(
        out,
        "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{np}\" NumberOfCells=\"{nc}\">\n<PointData>"
    );
    array(
        &mut out,
        "node_id",
        "Int64",
        1,
        sol.deck_node
            .iter()
            .map(|d| d.map_or(0, |d| sol.node_ids[d]).to_string()),
    );
    let wants = |v: &str| step.file_vars.is_empty() || step.file_vars.iter().any(|x| x == v);
    if wants("U") {
        array(
            &mut out,
            "U",
            "Float64",
            3,
            u.iter().flatten().map(|v| g(*v)),
        );
    }
    if wants("RF") {
        array(
            &mut out,
            "RF",
            "Float64",
            3,
            rf.iter().flatten().map(|v| g(*v)),
        );
    }
    if wants("S") {
        // CalculiX order [xx, yy, zz, xy, xz, yz] -> ParaView's [xx, yy, zz, xy, yz, xz]
        let pv = |t: &[f64; 6]| [t[0], t[1], t[2], t[3], t[5], t[4]];
        array(&mut out, "S", "Float64", 6, s.iter().flat_map(pv).map(g));
        array(
            &mut out,
            "S_von_mises",
            "Float64",
            1,
            s.iter()
                .map(|t| g(von_mises(&[t[0], t[1], t[2], t[3], t[5], t[4]]))),
        );
    }
    out.push_str("</PointData>\n<Points>\n");
    array(
        &mut out,
        "Points",
        "Float64",
        3,
        mesh.nodes().iter().flatten().map(|v| g(*v)),
    );
    out.push_str("</Points>\n<Cells>\n");
    array(
        &mut out,
        "connectivity",
        "Int64",
        1,
        mesh.elements().iter().flatten().map(|v| v.to_string()),
    );
    array(
        &mut out,
        "offsets",
        "Int64",
        1,
        (1..=nc).map(|i| (10 * i).to_string()),
    );
    array(
        &mut out,
        "types",
        "UInt8",
        1,
        (0..nc).map(|_| "24".to_string()),
    );
    out.push_str("</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    std::fs::write(path, out).map_err(|e| FemError::Io {
        path: path.to_path_buf(),
        error: e,
    })
}
