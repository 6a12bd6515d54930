//! Assembly of element matrices into the reduced system Tᵀ A T of a [`Reduction`] (u = T q + g,
//! [`super::constraints`]): the sparsity pattern of the independent DOFs from the elements' DOFs
//! through T, then any element matrix (stiffness, mass, geometric stiffness) summed into it, the
//! Dirichlet part −Tᵀ A g on the right-hand side.
//!
//! Entry (q_i, q_j) of Tᵀ A T collects T_{d q_i} A_{d e} T_{e q_j} over the element entries (d, e)
//! (Cook et al., *Concepts and Applications of FEA*, 4th ed., §9.2). The pattern is built node by
//! node (the nodes sharing an element, each node's independent DOFs), so that its memory is that
//! of the matrix; a DOF tied to many (a reference node) gets the union of their neighbours.

use nalgebra::DMatrix;

use super::assembly::SparseSym;
use super::constraints::Reduction;
use super::error::{FemError, Result};
use super::ordering::nested_dissection_reduced;
use super::solver::{CholeskyFactor, SymbolicFactor};

/// The pattern of Tᵀ A T for elements with the given nodes (3 DOFs per node).
#[derive(Clone, Debug)]
pub struct ReducedPattern {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    n: usize,
}

impl ReducedPattern {
    /// The pattern of `elements` (node lists) on `n_nodes` nodes under `reduction`.
    pub fn new(n_nodes: usize, elements: &[Vec<usize>], reduction: &Reduction) -> Self {
        // node adjacency
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); n_nodes];
        for el in elements {
            for &a in el {
                adj[a].extend_from_slice(el);
            }
        }
        for a in &mut adj {
            a.sort_unstable();
            a.dedup();
        }
        // each node's independent DOFs
        let reduced: Vec<Vec<usize>> = (0..n_nodes)
            .map(|n| {
                let mut r: Vec<usize> = (0..3)
                    .flat_map(|j| reduction.row(3 * n + j).iter().map(|&(e, _)| e))
                    .collect();
                r.sort_unstable();
                r.dedup();
                r
            })
            .collect();
        let n = reduction.n_eq();
        let mut cols: Vec<Vec<usize>> = vec![Vec::new(); n];
        let mut union = Vec::new();
        for node in 0..n_nodes {
            if reduced[node].is_empty() {
                continue;
            }
            union.clear();
            for &m in &adj[node] {
                union.extend_from_slice(&reduced[m]);
            }
            union.extend_from_slice(&reduced[node]);
            union.sort_unstable();
            union.dedup();
            for &q in &reduced[node] {
                let upto = union.partition_point(|&r| r <= q);
                cols[q].extend_from_slice(&union[..upto]);
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for (q, c) in cols.iter_mut().enumerate() {
            c.push(q);
            c.sort_unstable();
            c.dedup();
            row_idx.extend_from_slice(c);
            col_ptr.push(row_idx.len());
        }
        ReducedPattern {
            col_ptr,
            row_idx,
            n,
        }
    }

    fn locate(&self, r: usize, c: usize) -> usize {
        let s = &self.row_idx[self.col_ptr[c]..self.col_ptr[c + 1]];
        self.col_ptr[c] + s.binary_search(&r).expect("entry in the pattern")
    }

    /// Tᵀ A T (upper triangle) and −Tᵀ A g of the element matrices `matrix(e)` of `elements`.
    pub fn assemble(
        &self,
        elements: &[Vec<usize>],
        reduction: &Reduction,
        mut matrix: impl FnMut(usize) -> Result<DMatrix<f64>>,
    ) -> Result<(SparseSym, Vec<f64>)> {
        let mut values = vec![0.0; self.row_idx.len()];
        let mut rhs = vec![0.0; self.n];
        let with_rhs = reduction.has_offset();
        for (e, el) in elements.iter().enumerate() {
            let a = matrix(e)?;
            let dofs = element_dofs(el);
            for (i, &di) in dofs.iter().enumerate() {
                let ri = reduction.row(di);
                if ri.is_empty() {
                    continue;
                }
                for (j, &dj) in dofs.iter().enumerate() {
                    let v = a[(i, j)];
                    if v == 0.0 {
                        continue;
                    }
                    for &(qi, ci) in ri {
                        for &(qj, cj) in reduction.row(dj) {
                            if qi <= qj {
                                values[self.locate(qi, qj)] += ci * v * cj;
                            }
                        }
                        if with_rhs {
                            rhs[qi] -= ci * v * reduction.offset(dj);
                        }
                    }
                }
            }
        }
        Ok((
            SparseSym {
                n: self.n,
                col_ptr: self.col_ptr.clone(),
                row_idx: self.row_idx.clone(),
                values,
            },
            rhs,
        ))
    }
}

/// The Cholesky factor of a reduced stiffness `k` of the tetrahedra `elements` on `n_nodes`
/// nodes, in nested-dissection order ([`nested_dissection_reduced`]). A matrix that is not
/// positive definite — supports that leave a rigid-body motion free — is refused.
pub fn factorise<E: AsRef<[usize]>>(
    k: &SparseSym,
    n_nodes: usize,
    elements: &[E],
    reduction: &Reduction,
) -> Result<CholeskyFactor> {
    if k.n == 0 {
        return Err(FemError::InvalidInput("every DOF is constrained".into()));
    }
    let order = nested_dissection_reduced(n_nodes, elements, reduction)?;
    let symbolic = SymbolicFactor::analyse(k, Some(&order))?;
    CholeskyFactor::factorise(&symbolic, k)
}

/// The DOFs of an element's nodes, 3 per node.
fn element_dofs(nodes: &[usize]) -> Vec<usize> {
    nodes
        .iter()
        .flat_map(|&n| (0..3).map(move |j| 3 * n + j))
        .collect()
}

/// Σ_e A_e u_e: the element matrices times the full vector `u`, summed per DOF (internal forces
/// K u for the stiffness).
pub fn element_product(
    elements: &[Vec<usize>],
    n_dofs: usize,
    u: &[f64],
    mut matrix: impl FnMut(usize) -> Result<DMatrix<f64>>,
) -> Result<Vec<f64>> {
    let mut out = vec![0.0; n_dofs];
    for (e, el) in elements.iter().enumerate() {
        let a = matrix(e)?;
        let dofs = element_dofs(el);
        for (i, &di) in dofs.iter().enumerate() {
            out[di] += dofs
                .iter()
                .enumerate()
                .map(|(j, &dj)| a[(i, j)] * u[dj])
                .sum::<f64>();
        }
    }
    Ok(out)
}
