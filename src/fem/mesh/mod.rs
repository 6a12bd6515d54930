//! The quadratic tetrahedral mesh (SI: metres), and structured meshes made in Rust for
//! verification ([`structured`]); meshes of parts come from [`crate::mesher`].
//!
//! Element node order: VTK's tetra10 (see [`crate::fem::shape`]).

pub mod mirror;
pub mod pieces;
pub mod ring;
pub mod structured;

use super::element::{ElementCoords, QuadratureChoice, check_jacobian, is_straight};
use super::error::{FemError, Result};
use super::shape::TET10_EDGES;

/// A mesh of 10-node tetrahedra. Coordinates in metres; connectivity in VTK tetra10 order.
/// Construction validates indices, coordinates and midside-node placement.
#[derive(Clone, Debug)]
pub struct TetMesh {
    nodes: Vec<[f64; 3]>,
    elements: Vec<[usize; 10]>,
}

impl TetMesh {
    /// Builds and validates a mesh: at least one element, node indices in range, finite coordinates,
    /// ten distinct nodes per element, four non-coincident corners, every node used, and every midside
    /// node where it fits its own edge better than any exchange with another edge's node would (catches a
    /// wrong node order, e.g. gmsh's, and lets a curved element's node bulge onto a fillet).
    pub fn new(nodes: Vec<[f64; 3]>, elements: Vec<[usize; 10]>) -> Result<Self> {
        if elements.is_empty() {
            return Err(FemError::InvalidMesh("no elements".into()));
        }
        if let Some((i, p)) = nodes
            .iter()
            .enumerate()
            .find(|(_, p)| !p.iter().all(|v| v.is_finite()))
        {
            return Err(FemError::InvalidMesh(format!(
                "node {i} has a non-finite coordinate {p:?}"
            )));
        }
        let mut used = vec![false; nodes.len()];
        for (e, el) in elements.iter().enumerate() {
            for (a, &n) in el.iter().enumerate() {
                if n >= nodes.len() {
                    return Err(FemError::InvalidMesh(format!(
                        "element {e}: node {a} refers to node {n}, but the mesh has {} nodes",
                        nodes.len()
                    )));
                }
                if el[..a].contains(&n) {
                    return Err(FemError::InvalidMesh(format!(
                        "element {e}: node {n} appears twice"
                    )));
                }
                used[n] = true;
            }
            let x: ElementCoords = std::array::from_fn(|a| nodes[el[a]]);
            check_midside(&x, e, el)?;
        }
        if let Some(n) = used.iter().position(|u| !u) {
            return Err(FemError::InvalidMesh(format!(
                "node {n} is not used by any element"
            )));
        }
        Ok(TetMesh { nodes, elements })
    }

    /// Node coordinates, m.
    pub fn nodes(&self) -> &[[f64; 3]] {
        &self.nodes
    }

    /// Element connectivity (VTK tetra10 order).
    pub fn elements(&self) -> &[[usize; 10]] {
        &self.elements
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Number of elements.
    pub fn n_elements(&self) -> usize {
        self.elements.len()
    }

    /// Number of degrees of freedom (3 per node).
    pub fn n_dofs(&self) -> usize {
        3 * self.nodes.len()
    }

    /// Coordinates of the nodes of element `e`.
    pub fn element_coords(&self, e: usize) -> ElementCoords {
        let el = &self.elements[e];
        std::array::from_fn(|a| self.nodes[el[a]])
    }

    /// The displacements of the ten nodes of element `e`, from `u` (3 per node).
    pub fn element_displacements(&self, e: usize, u: &[f64]) -> [[f64; 3]; 10] {
        let el = &self.elements[e];
        std::array::from_fn(|a| std::array::from_fn(|j| u[3 * el[a] + j]))
    }

    /// Mean length of the corner-to-corner edges over all elements (each edge counted per element), m:
    /// the characteristic element size.
    pub fn mean_edge_length(&self) -> f64 {
        let mut s = 0.0;
        for el in &self.elements {
            for [a, b] in TET10_EDGES {
                s += dist(self.nodes[el[a]], self.nodes[el[b]]);
            }
        }
        s / (6 * self.elements.len()) as f64
    }

    /// Number of curved elements (a midside node off its edge midpoint).
    pub fn curved_elements(&self) -> usize {
        (0..self.elements.len())
            .filter(|&e| !is_straight(&self.element_coords(e)))
            .count()
    }

    /// Checks det J > 0 at the quadrature points `choice` uses and at the nodes of every element;
    /// returns the smallest det J found. The solver does the same check during assembly.
    pub fn check_jacobians(&self, choice: QuadratureChoice) -> Result<f64> {
        let mut min = f64::INFINITY;
        for e in 0..self.elements.len() {
            let x = self.element_coords(e);
            min = min.min(check_jacobian(&x, choice.rule_for(&x), e)?);
        }
        Ok(min)
    }

    /// Axis-aligned bounding box (min, max), m.
    pub fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.nodes {
            for j in 0..3 {
                lo[j] = lo[j].min(p[j]);
                hi[j] = hi[j].max(p[j]);
            }
        }
        (lo, hi)
    }

    /// The same mesh with every node moved by `f` (validated again).
    pub fn map_nodes(&self, f: impl Fn(usize, [f64; 3]) -> [f64; 3]) -> Result<TetMesh> {
        let nodes = self
            .nodes
            .iter()
            .enumerate()
            .map(|(i, p)| f(i, *p))
            .collect();
        TetMesh::new(nodes, self.elements.clone())
    }
}

pub(crate) fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn check_midside(x: &ElementCoords, e: usize, el: &[usize; 10]) -> Result<()> {
    let mids: [[f64; 3]; 6] = std::array::from_fn(|k| {
        let [a, b] = TET10_EDGES[k];
        std::array::from_fn(|j| 0.5 * (x[a][j] + x[b][j]))
    });
    for k in 0..6 {
        let own = dist(x[4 + k], mids[k]);
        let [a, b] = TET10_EDGES[k];
        let len = dist(x[a], x[b]);
        if len == 0.0 {
            return Err(FemError::InvalidMesh(format!(
                "element {e}: corners {a} and {b} coincide (nodes {} and {})",
                el[a], el[b]
            )));
        }
        // a wrong node order swaps midside nodes between edges (gmsh's order differs from VTK's
        // by the swap of the last two): flagged when exchanging this node with another edge's
        // would fit both edges better. A curved element's midside node may sit nearer another
        // edge's midpoint on a tight fillet without any swap fitting better.
        if (0..6).any(|m| {
            m != k
                && dist(x[4 + k], mids[m]) + dist(x[4 + m], mids[k]) < own + dist(x[4 + m], mids[m])
        }) {
            return Err(FemError::MidsideNodeOrder {
                element: e,
                local: 4 + k,
                node: el[4 + k],
                edge: [a, b],
            });
        }
    }
    Ok(())
}
