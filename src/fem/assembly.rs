//! DOF numbering, sparsity pattern and parallel assembly of the global stiffness matrix.
//!
//! Only the free DOFs get equations (prescribed ones are eliminated; a non-zero prescribed value
//! moves −K_fp u_p to the right-hand side). Equations are numbered node by node, so every column of
//! the upper triangle lists its rows grouped by neighbour node in ascending order; an element entry
//! is located with one binary search per node pair.
//!
//! Parallel assembly (rayon) by element colouring: elements of one colour share no node, hence no
//! matrix entry and no right-hand-side entry, so a colour is assembled in parallel without locks and
//! the sum into every entry happens in a fixed order (colour by colour): the result does not depend
//! on the number of threads.

use rayon::prelude::*;

use super::element::{QuadratureChoice, check_jacobian, element_stiffness, is_straight};
use super::error::{FemError, Result};
use super::material::Material;
use super::mesh::TetMesh;

const NONE: usize = usize::MAX;

/// Map from DOFs (3 per node: x, y, z) to equations; prescribed DOFs carry a value.
#[derive(Clone, Debug, PartialEq)]
pub struct DofMap {
    eq: Vec<usize>,
    value: Vec<f64>,
    n_eq: usize,
}

impl DofMap {
    /// `n_dofs` DOFs of which `prescribed` (DOF, value in m) are prescribed. A DOF prescribed twice
    /// with different values is an error.
    pub fn new(n_dofs: usize, prescribed: &[(usize, f64)]) -> Result<Self> {
        let mut is_p = vec![false; n_dofs];
        let mut value = vec![0.0; n_dofs];
        for &(d, v) in prescribed {
            if d >= n_dofs {
                return Err(FemError::InvalidInput(format!(
                    "prescribed DOF {d} out of range ({n_dofs} DOFs)"
                )));
            }
            if !v.is_finite() || (is_p[d] && value[d] != v) {
                return Err(FemError::InvalidInput(format!(
                    "DOF {d} prescribed as {} and {v}",
                    value[d]
                )));
            }
            is_p[d] = true;
            value[d] = v;
        }
        let mut eq = vec![NONE; n_dofs];
        let mut n_eq = 0;
        for d in 0..n_dofs {
            if !is_p[d] {
                eq[d] = n_eq;
                n_eq += 1;
            }
        }
        Ok(DofMap { eq, value, n_eq })
    }

    /// Equation of a DOF, `None` when prescribed.
    pub fn eq(&self, dof: usize) -> Option<usize> {
        (self.eq[dof] != NONE).then_some(self.eq[dof])
    }

    /// Prescribed value of a DOF (0 for free DOFs).
    pub fn value(&self, dof: usize) -> f64 {
        self.value[dof]
    }

    /// Number of equations (free DOFs).
    pub fn n_eq(&self) -> usize {
        self.n_eq
    }

    /// Number of DOFs.
    pub fn n_dofs(&self) -> usize {
        self.eq.len()
    }

    /// Whether any prescribed value is non-zero.
    pub fn has_nonzero_prescribed(&self) -> bool {
        self.value.iter().any(|v| *v != 0.0)
    }
}

/// Symmetric sparse matrix stored as its upper triangle in compressed sparse columns (rows sorted).
#[derive(Clone, Debug)]
pub struct SparseSym {
    /// Dimension.
    pub n: usize,
    /// Column pointers (n + 1).
    pub col_ptr: Vec<usize>,
    /// Row indices (≤ column), sorted within each column.
    pub row_idx: Vec<usize>,
    /// Values.
    pub values: Vec<f64>,
}

impl SparseSym {
    /// Stored entries (upper triangle including the diagonal).
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// y = A x for the full symmetric matrix.
    pub fn mul(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.n];
        for c in 0..self.n {
            for p in self.col_ptr[c]..self.col_ptr[c + 1] {
                let (r, v) = (self.row_idx[p], self.values[p]);
                y[r] += v * x[c];
                if r != c {
                    y[c] += v * x[r];
                }
            }
        }
        y
    }
}

/// The assembled system.
#[derive(Clone, Debug)]
pub struct Assembled {
    /// Stiffness of the free DOFs (upper triangle).
    pub k: SparseSym,
    /// −K_fp u_p (length n_eq); all zero when the prescribed values are zero.
    pub dirichlet_rhs: Vec<f64>,
    /// Number of element colours.
    pub colours: usize,
    /// Number of curved elements.
    pub curved_elements: usize,
    /// Smallest det J over all checked points.
    pub min_det_j: f64,
}

/// Node adjacency (sorted, including the node itself) in compressed rows.
struct Adjacency {
    ptr: Vec<usize>,
    idx: Vec<usize>,
}

impl Adjacency {
    fn new(mesh: &TetMesh) -> Self {
        let mut lists: Vec<Vec<usize>> = vec![Vec::new(); mesh.n_nodes()];
        for el in mesh.elements() {
            for &a in el {
                lists[a].extend_from_slice(el);
            }
        }
        let mut ptr = Vec::with_capacity(mesh.n_nodes() + 1);
        ptr.push(0);
        let mut idx = Vec::new();
        for l in &mut lists {
            l.sort_unstable();
            l.dedup();
            idx.extend_from_slice(l);
            ptr.push(idx.len());
        }
        Adjacency { ptr, idx }
    }

    fn of(&self, n: usize) -> &[usize] {
        &self.idx[self.ptr[n]..self.ptr[n + 1]]
    }
}

/// Upper-triangle pattern plus the offsets to locate entries.
struct Pattern {
    adj: Adjacency,
    /// per adjacency entry (n, k): rows contributed to node n's columns by neighbours before k
    prefix: Vec<usize>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
}

impl Pattern {
    fn new(mesh: &TetMesh, dofs: &DofMap) -> Self {
        let adj = Adjacency::new(mesh);
        let free = |m: usize| (0..3).filter(|&d| dofs.eq(3 * m + d).is_some()).count();
        let mut prefix = vec![0; adj.idx.len()];
        let mut col_ptr = Vec::with_capacity(dofs.n_eq() + 1);
        col_ptr.push(0);
        let mut row_idx = Vec::new();
        for n in 0..mesh.n_nodes() {
            let nb = adj.of(n);
            let mut acc = 0;
            for (k, &m) in nb.iter().enumerate() {
                prefix[adj.ptr[n] + k] = acc;
                if m < n {
                    acc += free(m);
                }
            }
            for c in 0..3 {
                if dofs.eq(3 * n + c).is_none() {
                    continue;
                }
                for &m in nb.iter().filter(|&&m| m < n) {
                    row_idx.extend((0..3).filter_map(|d| dofs.eq(3 * m + d)));
                }
                row_idx.extend((0..=c).filter_map(|d| dofs.eq(3 * n + d)));
                col_ptr.push(row_idx.len());
            }
        }
        Pattern {
            adj,
            prefix,
            col_ptr,
            row_idx,
        }
    }

    /// Offset of node m's rows within the columns of node n (m ≤ n, neighbours).
    #[inline]
    fn block_offset(&self, m: usize, n: usize) -> usize {
        let k = self
            .adj
            .of(n)
            .binary_search(&m)
            .expect("node pair in the pattern");
        self.prefix[self.adj.ptr[n] + k]
    }

    /// Position of the entry (row DOF (m, d), column DOF (n, c)), m ≤ n, both free, given
    /// `block_offset(m, n)`.
    #[inline]
    fn locate(
        &self,
        dofs: &DofMap,
        offset: usize,
        m: usize,
        d: usize,
        n: usize,
        c: usize,
    ) -> usize {
        let rank = (0..d).filter(|&e| dofs.eq(3 * m + e).is_some()).count();
        self.col_ptr[dofs.eq[3 * n + c]] + offset + rank
    }
}

/// Greedy element colouring: elements of a colour share no corner node (hence no node at all).
fn colour_elements(mesh: &TetMesh) -> Vec<Vec<usize>> {
    let n = mesh.n_nodes();
    let mut ptr = vec![0usize; n + 1];
    for el in mesh.elements() {
        for &a in &el[..4] {
            ptr[a + 1] += 1;
        }
    }
    for i in 0..n {
        ptr[i + 1] += ptr[i];
    }
    let mut fill = ptr.clone();
    let mut node_els = vec![0usize; ptr[n]];
    for (e, el) in mesh.elements().iter().enumerate() {
        for &a in &el[..4] {
            node_els[fill[a]] = e;
            fill[a] += 1;
        }
    }
    let mut colour = vec![NONE; mesh.n_elements()];
    let mut stamp: Vec<usize> = Vec::new();
    let mut classes: Vec<Vec<usize>> = Vec::new();
    for (e, el) in mesh.elements().iter().enumerate() {
        for &a in &el[..4] {
            for &o in &node_els[ptr[a]..ptr[a + 1]] {
                let c = colour[o];
                if c != NONE {
                    stamp[c] = e + 1;
                }
            }
        }
        let c = (0..stamp.len())
            .find(|&c| stamp[c] != e + 1)
            .unwrap_or_else(|| {
                stamp.push(0);
                classes.push(Vec::new());
                stamp.len() - 1
            });
        colour[e] = c;
        classes[c].push(e);
    }
    classes
}

/// A pointer that threads may write through at disjoint indices.
#[derive(Clone, Copy)]
struct Shared(*mut f64);
// SAFETY: used only for writes at indices that are disjoint between threads (elements of one colour
// share no node, and every index written for an element is determined by its nodes), while the
// underlying Vec is alive and not otherwise accessed.
unsafe impl Send for Shared {}
unsafe impl Sync for Shared {}
impl Shared {
    /// # Safety
    /// `i` in bounds, and no other thread accesses index `i` concurrently.
    #[inline]
    unsafe fn add(&self, i: usize, v: f64) {
        unsafe { *self.0.add(i) += v }
    }
}

/// Assembles the stiffness matrix of the free DOFs (and −K_fp u_p). The Jacobian of every element is
/// checked first (in parallel; the first failing element is reported).
pub fn assemble(
    mesh: &TetMesh,
    material: &Material,
    quadrature: QuadratureChoice,
    dofs: &DofMap,
) -> Result<Assembled> {
    material.validate()?;
    if dofs.n_dofs() != mesh.n_dofs() {
        return Err(FemError::InvalidInput(
            "DOF map does not match the mesh".into(),
        ));
    }
    let checks: Vec<Result<(f64, bool)>> = (0..mesh.n_elements())
        .into_par_iter()
        .map(|e| {
            let x = mesh.element_coords(e);
            Ok((
                check_jacobian(&x, quadrature.rule_for(&x), e)?,
                !is_straight(&x),
            ))
        })
        .collect();
    let mut min_det_j = f64::INFINITY;
    let mut curved_elements = 0;
    for c in checks {
        let (d, curved) = c?;
        min_det_j = min_det_j.min(d);
        curved_elements += usize::from(curved);
    }
    let pattern = Pattern::new(mesh, dofs);
    let classes = colour_elements(mesh);
    let mut values = vec![0.0; pattern.row_idx.len()];
    let mut rhs = vec![0.0; dofs.n_eq()];
    let with_rhs = dofs.has_nonzero_prescribed();
    let vals = Shared(values.as_mut_ptr());
    let rhsp = Shared(rhs.as_mut_ptr());
    for class in &classes {
        class.par_iter().try_for_each(|&e| -> Result<()> {
            let el = &mesh.elements()[e];
            let x = mesh.element_coords(e);
            let ke = element_stiffness(&x, material, quadrature.rule_for(&x), e)?;
            for a in 0..10 {
                for b in 0..10 {
                    let (na, nb) = (el[a], el[b]);
                    let offset = if na <= nb {
                        pattern.block_offset(na, nb)
                    } else {
                        0
                    };
                    for i in 0..3 {
                        let Some(ra) = dofs.eq(3 * na + i) else {
                            continue;
                        };
                        for j in 0..3 {
                            let kv = ke[(3 * a + i, 3 * b + j)];
                            match dofs.eq(3 * nb + j) {
                                Some(cb) if na < nb || (na == nb && ra <= cb) => {
                                    let pos = pattern.locate(dofs, offset, na, i, nb, j);
                                    // SAFETY: colour property, see `Shared`.
                                    unsafe { vals.add(pos, kv) };
                                }
                                None if with_rhs => {
                                    // SAFETY: colour property, see `Shared`.
                                    unsafe { rhsp.add(ra, -kv * dofs.value(3 * nb + j)) };
                                }
                                _ => {}
                            }
                        }
                    }
                }
            }
            Ok(())
        })?;
    }
    let k = SparseSym {
        n: dofs.n_eq(),
        col_ptr: pattern.col_ptr,
        row_idx: pattern.row_idx,
        values,
    };
    Ok(Assembled {
        k,
        dirichlet_rhs: rhs,
        colours: classes.len(),
        curved_elements,
        min_det_j,
    })
}
