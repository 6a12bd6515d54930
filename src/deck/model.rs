//! The model a deck describes: nodes, elements, sets, surfaces, materials and sections, local axes
//! (`*TRANSFORM`), equations, supports, loads and output requests per step, with the line each
//! came from. The accepted subset, keyword by keyword with its parameters and what is refused, is
//! the table of `docs/solve.md`; [`super::cards`] reads it and refuses everything else with its
//! line (all refusals of a deck at once).
//!
//! Semantics as ccx's (CalculiX CrunchiX user's manual, ccx 2.20, one section per keyword;
//! checked against ccx 2.20): supports and loads carry over from step to step; a load on a node
//! and dof (face, for pressure; element, for GRAV and CENTRIF) given again within the same step
//! adds to the first, given in a later step it replaces the earlier step's value; a repeated
//! support replaces the earlier one; OP=NEW on the first *CLOAD (*DLOAD/*DSLOAD) of a step removes
//! all earlier concentrated (distributed) loads. The first *NODE PRINT (*EL PRINT, *NODE FILE,
//! *EL FILE) of a step replaces the requests of that kind, and a step without one keeps the
//! previous step's. Numbers must be finite and physical (E > 0, −1 < ν < 0.5, ρ ≥ 0, a load at
//! most [`super::parse::MAX_LOAD`], a coordinate at most [`super::parse::MAX_COORDINATE`]); an
//! element lists distinct nodes, its corners at distinct places. Set names are case-insensitive
//! (kept upper-cased, as ccx prints them).

use std::collections::{BTreeMap, HashMap};

pub use crate::fem::solid_element::SolidKind as ElementKind;

/// An element: id, kind and node indices (10 or 4).
#[derive(Clone, Debug)]
pub struct Element {
    /// Deck id.
    pub id: i64,
    /// C3D10 or C3D4.
    pub kind: ElementKind,
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
    /// File of `*MATERIAL`.
    pub file: std::path::PathBuf,
}

/// A `*SOLID SECTION`: an element set and its material.
#[derive(Clone, Debug)]
pub struct Section {
    /// Element set (upper case).
    pub elset: String,
    /// Material name (upper case).
    pub material: String,
    /// Line of the card.
    pub line: usize,
    /// File of the card.
    pub file: std::path::PathBuf,
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

/// A body force ρ ω² r per volume about an axis (`*DLOAD …, CENTRIF, ω², x, y, z, nx, ny, nz`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Centrif {
    /// ω².
    pub omega2: f64,
    /// A point on the axis.
    pub point: [f64; 3],
    /// The axis direction (unit).
    pub axis: [f64; 3],
}

/// The analysis of a step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Analysis {
    /// `*STATIC`: linear static.
    #[default]
    Static,
    /// `*BUCKLE`: the lowest `modes` buckling factors of the step's loads.
    Buckle {
        /// Buckling factors wanted.
        modes: usize,
        /// Relative accuracy of the factors.
        accuracy: f64,
    },
    /// `*FREQUENCY`: the lowest `modes` natural frequencies (at most `upper`, cycles/time).
    Frequency {
        /// Frequencies wanted.
        modes: usize,
        /// Lower bound (cycles per time; ccx's shift).
        lower: f64,
        /// Upper bound (cycles per time), if given.
        upper: Option<f64>,
    },
}

/// Local axes of a node (`*TRANSFORM`): the rotation R whose columns are the local axes in global
/// components at a point (constant for TYPE=R, depending on the point for TYPE=C).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Transform {
    /// Rectangular: local x along a, local y in the (a, b) plane, z = x × y.
    Rectangular {
        /// a.
        a: [f64; 3],
        /// b.
        b: [f64; 3],
    },
    /// Cylindrical about the axis through a and b: local (r, θ, z).
    Cylindrical {
        /// a (on the axis).
        a: [f64; 3],
        /// b (on the axis, towards +z).
        b: [f64; 3],
    },
}

/// The totals of a *NODE PRINT request.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Totals {
    /// Values per node only.
    #[default]
    No,
    /// Values per node and their sum.
    Yes,
    /// The sum only.
    Only,
}

/// An equation: terms (node, dof 0–2, coefficient) and the line of its first data line.
pub type Equation = (Vec<(usize, usize, f64)>, usize);

/// What a `*COUPLING` does with its reference node.
#[derive(Clone, Debug, PartialEq)]
pub enum CouplingKind {
    /// `*KINEMATIC`: the listed displacement DOFs (0–2) of every surface node follow the
    /// reference node rigidly, u_i = u_R + θ × (x_i − x_R) (linearised rigid-body motion).
    Kinematic {
        /// DOFs constrained (0–2).
        dofs: [bool; 3],
        /// The node whose three DOFs are the reference node's rotations θ (added after the
        /// deck's nodes, as ccx adds its rotational node).
        rotation_node: usize,
    },
    /// `*DISTRIBUTING`: the reference node's force (and the listed moments) applied to the
    /// surface's nodes as point loads with area weights (ccx's distributing coupling).
    Distributing {
        /// Moments about x, y, z distributed (DOFs 4–6 listed).
        moments: [bool; 3],
    },
}

/// A `*COUPLING` with its `*KINEMATIC` or `*DISTRIBUTING` card.
#[derive(Clone, Debug, PartialEq)]
pub struct Coupling {
    /// The reference node.
    pub reference: usize,
    /// The surface's name (upper case).
    pub surface: String,
    /// Its element faces (element, face 0–3), empty for a node surface.
    pub faces: Vec<(usize, usize)>,
    /// Its nodes (first occurrence order, no repeats).
    pub nodes: Vec<usize>,
    /// Kinematic or distributing.
    pub kind: CouplingKind,
    /// Line of `*COUPLING`.
    pub line: usize,
    /// File of `*COUPLING`.
    pub file: std::path::PathBuf,
}

/// The pressure–overclosure law of a `*SURFACE BEHAVIOR`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactLaw {
    /// HARD: no penetration, no tension (solved exactly; ccx's penalty slope K, if given, is
    /// only reported).
    Hard,
    /// LINEAR: p = K · overclosure, no tension.
    Linear {
        /// K (pressure per length).
        k: f64,
    },
}

/// A `*CONTACT PAIR` (TYPE=SURFACE TO SURFACE, frictionless, small sliding).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactPair {
    /// Its `*SURFACE INTERACTION` (upper case).
    pub interaction: String,
    /// The slave (dependent) element-face surface.
    pub slave: String,
    /// The master (independent) element-face surface.
    pub master: String,
    /// Line of the data line.
    pub line: usize,
    /// File of the card.
    pub file: std::path::PathBuf,
}

/// A step's state: supports, loads (accumulated over the earlier steps) and output requests.
#[derive(Clone, Debug, Default)]
pub struct Step {
    /// Line of `*STEP`.
    pub line: usize,
    /// Prescribed displacements (node, dof 0–2; 3–5: rotations of a kinematic coupling's
    /// reference node) → value.
    pub boundary: BTreeMap<(usize, usize), f64>,
    /// Supported node sets (for the reaction totals): name → nodes; single nodes as `NODE <id>`.
    pub supported_sets: BTreeMap<String, Vec<usize>>,
    /// Concentrated loads (node, dof 0–2; 3–5: moments on a coupling's reference node) → value.
    pub cloads: BTreeMap<(usize, usize), f64>,
    /// Pressures (element, face 0–3) → p.
    pub pressures: BTreeMap<(usize, usize), f64>,
    /// Body forces per element.
    pub gravity: BTreeMap<usize, Grav>,
    /// Centrifugal loads per element.
    pub centrif: BTreeMap<usize, Centrif>,
    /// `*NODE PRINT` requests: node set name → variables (U, S, E, RF) and TOTALS.
    pub node_print: Vec<(String, Vec<String>, Totals)>,
    /// `*EL PRINT` requests: element set name → variables (S, E).
    pub el_print: Vec<(String, Vec<String>)>,
    /// Variables of `*NODE FILE`/`*EL FILE` (U, S, E, RF).
    pub file_vars: Vec<String>,
    /// The analysis (`None` before its card).
    pub analysis: Option<Analysis>,
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
    /// Node sets (upper-cased names) → node indices (first occurrence order, no repeats).
    pub nsets: BTreeMap<String, Vec<usize>>,
    /// Element sets → element indices.
    pub elsets: BTreeMap<String, Vec<usize>>,
    /// Materials by (upper-cased) name.
    pub materials: BTreeMap<String, MaterialDef>,
    /// Sections.
    pub sections: Vec<Section>,
    /// Element-face surfaces (`*SURFACE, TYPE=ELEMENT`): name → (element, face 0–3).
    pub element_surfaces: BTreeMap<String, Vec<(usize, usize)>>,
    /// Local axes per node (`*TRANSFORM`).
    pub transforms: BTreeMap<usize, Transform>,
    /// Equations (`*EQUATION`): terms (node, dof 0–2, coefficient) and the line.
    pub equations: Vec<Equation>,
    /// Surface interactions by (upper-cased) name: their law (`None` before `*SURFACE
    /// BEHAVIOR`) and line.
    pub interactions: BTreeMap<String, (Option<ContactLaw>, usize)>,
    /// Contact pairs.
    pub contact_pairs: Vec<ContactPair>,
    /// Couplings to reference nodes (`*COUPLING` with `*KINEMATIC` or `*DISTRIBUTING`).
    pub couplings: Vec<Coupling>,
    /// Warnings: what is read but changes nothing, or is skipped (with its line).
    pub warnings: Vec<String>,
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

    /// The coupling whose reference node is `n`, if any.
    pub fn coupling_of(&self, n: usize) -> Option<&Coupling> {
        self.couplings.iter().find(|c| c.reference == n)
    }
}
