//! What `rodstudy solve` writes: the JSON document (warnings; the requested node and element sets,
//! the reaction totals and the eigenvalues per step, the last step's also at the top level) and
//! one VTU file per step (ASCII VTK XML, C3D10 as quadratic and C3D4 as linear tetrahedra,
//! coordinates in the deck's units; point data: deck node id, U, RF, S and E — S and E as
//! ParaView's symmetric tensor `[xx, yy, zz, xy, yz, xz]`, the order written into each array as
//! its component names — von Mises, and the mode shapes of an eigen step).

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
        "elements": sol.elements.len(),
        "dofs": sol.dofs,
        "warnings": sol.warnings,
        "stress_extrapolation": match extrapolation {
            Extrapolation::Exact => "exact",
            Extrapolation::CalculiX => "calculix",
        },
        "reactions": "RF = K u, the internal force at every DOF of the node (as ccx's RF)",
        "components": {"U": ["ux", "uy", "uz"], "S": ["sxx", "syy", "szz", "sxy", "sxz", "syz"], "E": ["exx", "eyy", "ezz", "exy", "exz", "eyz"], "RF": ["fx", "fy", "fz"]},
        "node_sets": last.node_sets,
        "element_sets": last.element_sets,
        "reaction_totals": last.reaction_totals,
        "steps": sol.steps,
    })
}

fn array(s: &mut String, name: &str, ty: &str, comps: usize, values: impl Iterator<Item = String>) {
    named_array(s, name, ty, &[], comps, values);
}

/// A data array whose components are named (`ComponentName0`, … as VTK and ParaView read them).
fn named_array(
    s: &mut String,
    name: &str,
    ty: &str,
    names: &[&str],
    comps: usize,
    values: impl Iterator<Item = String>,
) {
    let labels: String = names
        .iter()
        .enumerate()
        .map(|(k, n)| format!(r#" ComponentName{k}="{n}""#))
        .collect();
    let _ = writeln!(
        s,
        r#"<DataArray type="{ty}" Name="{name}" NumberOfComponents="{comps}"{labels} format="ascii">"#
    );
    let v: Vec<String> = values.collect();
    for chunk in v.chunks(6 * comps.max(1)) {
        s.push_str(&chunk.join(" "));
        s.push('\n');
    }
    s.push_str("</DataArray>\n");
}

/// Writes step `k` (0-based) of `sol` to `path`: the nodes used by elements, the elements.
pub fn write_step_vtu(path: &Path, sol: &DeckSolution, k: usize) -> Result<()> {
    let step = &sol.steps[k];
    let used: Vec<usize> = (0..sol.node_ids.len()).filter(|&n| sol.used[n]).collect();
    let mut point_of = vec![usize::MAX; sol.node_ids.len()];
    for (p, &n) in used.iter().enumerate() {
        point_of[n] = p;
    }
    let (np, nc) = (used.len(), sol.elements.len());
    let g = |v: f64| format!("{v:e}");
    let mut out = String::with_capacity(200 * np + 100 * nc);
    out.push_str("<?xml version=\"1.0\"?>\n<!-- rodstudy solve: deck units; S and E components xx yy zz xy yz xz (ParaView's order) -->\n");
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
        used.iter().map(|&n| sol.node_ids[n].to_string()),
    );
    let wants = |v: &str| step.file_vars.is_empty() || step.file_vars.iter().any(|x| x == v);
    let xyz = ["x", "y", "z"];
    if wants("U") {
        named_array(
            &mut out,
            "U",
            "Float64",
            &xyz,
            3,
            used.iter().flat_map(|&n| step.u[n]).map(g),
        );
    }
    if wants("RF") {
        named_array(
            &mut out,
            "RF",
            "Float64",
            &xyz,
            3,
            used.iter().flat_map(|&n| step.rf[n]).map(g),
        );
    }
    // CalculiX order [xx, yy, zz, xy, xz, yz] -> ParaView's [xx, yy, zz, xy, yz, xz]
    let pv = |t: &[f64; 6]| [t[0], t[1], t[2], t[3], t[5], t[4]];
    let tensor = ["xx", "yy", "zz", "xy", "yz", "xz"];
    if wants("S") {
        named_array(
            &mut out,
            "S",
            "Float64",
            &tensor,
            6,
            used.iter().flat_map(|&n| pv(&step.s[n])).map(g),
        );
        array(
            &mut out,
            "S_von_mises",
            "Float64",
            1,
            used.iter().map(|&n| g(von_mises(&pv(&step.s[n])))),
        );
    }
    if wants("E") {
        named_array(
            &mut out,
            "E",
            "Float64",
            &tensor,
            6,
            used.iter().flat_map(|&n| pv(&step.e[n])).map(g),
        );
    }
    for (m, mode) in step.modes.iter().enumerate() {
        named_array(
            &mut out,
            &format!("mode_{}", m + 1),
            "Float64",
            &xyz,
            3,
            used.iter().flat_map(|&n| mode[n]).map(g),
        );
    }
    out.push_str("</PointData>\n<Points>\n");
    array(
        &mut out,
        "Points",
        "Float64",
        3,
        used.iter().flat_map(|&n| sol.nodes[n]).map(g),
    );
    out.push_str("</Points>\n<Cells>\n");
    array(
        &mut out,
        "connectivity",
        "Int64",
        1,
        sol.elements
            .iter()
            .flat_map(|(_, nodes)| nodes.iter().map(|&n| point_of[n].to_string())),
    );
    let mut offset = 0;
    array(
        &mut out,
        "offsets",
        "Int64",
        1,
        sol.elements.iter().map(|(_, nodes)| {
            offset += nodes.len();
            offset.to_string()
        }),
    );
    // VTK_TETRA (10) for C3D4, VTK_QUADRATIC_TETRA (24) for C3D10
    array(
        &mut out,
        "types",
        "UInt8",
        1,
        sol.elements
            .iter()
            .map(|(_, nodes)| if nodes.len() == 4 { "10" } else { "24" }.to_string()),
    );
    out.push_str("</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    std::fs::write(path, out).map_err(|e| FemError::Io {
        path: path.to_path_buf(),
        error: e,
    })
}
