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
//! Step semantics as ccx's (checked against ccx 2.20): supports and loads carry over from step to
//! step; a load on a node and dof (face, for *DLOAD; element, for GRAV) given again within the same
//! step adds to the first (two lines, two cards, or a node in two loaded sets), given in a later
//! step it replaces the earlier step's value; a repeated support replaces the earlier one; OP=NEW on
//! the first *CLOAD (*DLOAD) of a step removes all earlier concentrated (distributed) loads. The
//! first *NODE PRINT (*EL PRINT, *NODE FILE, *EL FILE) of a step replaces the requests of that kind,
//! and a step without one keeps the previous step's. Numbers must be finite (`nan`, `inf` and
//! overflows are refused with their line), and physical: E > 0, −1 < ν < 0.5, ρ ≥ 0, a load
//! (force, pressure, gravity) at most [`super::parse::MAX_LOAD`] in magnitude, a coordinate at
//! most [`super::parse::MAX_COORDINATE`]; an element lists distinct nodes, its corners at distinct
//! places. Set names are case-insensitive (kept upper-cased, as ccx prints them).

use std::collections::{BTreeMap, HashMap};

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
    /// Line of the element's data.
    pub line: usize,
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

impl Grav {
    /// The body force of `self` and `other` together (two GRAV lines on one element in a step).
    pub fn plus(&self, other: &Grav) -> Grav {
        let v: [f64; 3] = std::array::from_fn(|j| self.g * self.dir[j] + other.g * other.dir[j]);
        let g = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if g == 0.0 {
            Grav {
                g: 0.0,
                dir: [0.0, 0.0, 1.0],
            }
        } else {
            Grav {
                g,
                dir: v.map(|c| c / g),
            }
        }
    }
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
    pub(super) node_index: HashMap<i64, usize>,
    pub(super) element_index: HashMap<i64, usize>,
}

impl Model {
    /// Index of node `id`.
    pub fn node(&self, id: i64) -> Option<usize> {
        self.node_index.get(&id).copied()
    }
}
