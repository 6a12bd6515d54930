//! Sparse direct solution with faer's Cholesky factorisation (LLᵀ): a nested-dissection ordering
//! from the mesh ([`super::ordering`]; faer's approximate minimum degree without one), supernodal
//! when the flop count warrants it, factorised on one thread (on the whole rayon pool above
//! [`PARALLEL_FLOPS`]), solved on the global rayon pool. The
//! symbolic analysis is kept in a reference-counted [`SymbolicFactor`] and can be reused for any
//! matrix with the same pattern; all load cases are solved together from one factorisation.

use std::sync::Arc;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use super::assembly::SparseSym;
use super::error::{FemError, Result};

/// Symbolic Cholesky analysis (ordering, elimination tree, supernodes) of a sparsity pattern.
#[derive(Clone, Debug)]
pub struct SymbolicFactor {
    inner: Arc<SymbolicCholesky<usize>>,
    /// A fingerprint of the pattern analysed ([`fingerprint`]), to check a reuse.
    pattern: u64,
}

impl SymbolicFactor {
    /// Analyses the pattern of `a` (upper triangle) in the fill-reducing order `fwd`
    /// (`fwd[new] = old`, e.g. [`super::ordering::nested_dissection`]), or faer's approximate
    /// minimum degree when `None`.
    pub fn analyse(a: &SparseSym, fwd: Option<&[usize]>) -> Result<Self> {
        let sym = symbolic_ref(a);
        let inv = fwd.map(|f| {
            let mut inv = vec![0; a.n];
            for (new, &old) in f.iter().enumerate() {
                inv[old] = new;
            }
            inv
        });
        let ordering = match (fwd, &inv) {
            (Some(f), Some(i)) => SymmetricOrdering::Custom(PermRef::new_checked(f, i, a.n)),
            _ => SymmetricOrdering::Amd,
        };
        let inner = factorize_symbolic_cholesky(
            sym,
            Side::Upper,
            ordering,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| FemError::Solver(format!("symbolic Cholesky failed: {e:?}")))?;
        Ok(SymbolicFactor {
            inner: Arc::new(inner),
            pattern: fingerprint(a),
        })
    }

    /// Dimension.
    pub fn n(&self) -> usize {
        self.inner.nrows()
    }

    /// Whether `a` has the pattern this analysis was made from (its dimension, and a fingerprint
    /// of its upper-triangle structure).
    pub fn matches(&self, a: &SparseSym) -> bool {
        self.inner.nrows() == a.n && self.pattern == fingerprint(a)
    }

    /// Number of stored entries of the factor L (fill-in included).
    pub fn nnz_l(&self) -> usize {
        self.inner.len_val()
    }

    /// Floating-point operations of the numeric factorisation, estimated from the supernodes: a
    /// supernode of w columns with m rows below its diagonal block costs w³/3 (its dense
    /// Cholesky) + m·w² (the triangular solve below it) + m²·w (its update of the ancestors)
    /// (George & Liu, *Computer Solution of Large Sparse Positive Definite Systems*, 1981, §2.2
    /// for the column counts). A simplicial factor (small problems): Σ_j c_j², c_j the entries of
    /// column j.
    pub fn flops(&self) -> f64 {
        use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
        match self.inner.raw() {
            SymbolicCholeskyRaw::Supernodal(sn) => {
                let rows = sn.col_ptr_for_row_idx();
                (0..sn.n_supernodes())
                    .map(|s| {
                        let w = (sn.supernode_end()[s] - sn.supernode_begin()[s]) as f64;
                        let m = (rows[s + 1] - rows[s]) as f64;
                        w * w * w / 3.0 + m * w * w + m * m * w
                    })
                    .sum()
            }
            SymbolicCholeskyRaw::Simplicial(sp) => sp
                .col_ptr()
                .windows(2)
                .map(|c| ((c[1] - c[0]) as f64).powi(2))
                .sum(),
        }
    }
}

/// A 64-bit fingerprint of the pattern of `a` (FNV-1a over the column pointers and row indices).
fn fingerprint(a: &SparseSym) -> u64 {
    a.col_ptr
        .iter()
        .chain(&a.row_idx)
        .fold(0xcbf2_9ce4_8422_2325u64, |h, &v| {
            (h ^ v as u64).wrapping_mul(0x0000_0100_0000_01b3)
        })
}

fn symbolic_ref(a: &SparseSym) -> SymbolicSparseColMatRef<'_, usize> {
    SymbolicSparseColMatRef::new_checked(a.n, a.n, &a.col_ptr, None, &a.row_idx)
}

/// Factorisations of at least this many floating-point operations ([`SymbolicFactor::flops`])
/// use every thread of the rayon pool, smaller ones one: on the 2-core machine, in the adaptive
/// loop, design 1's refined second mesh (1.2e11 flops) factorised in 2.24–2.31 s on two threads
/// against 2.80–2.83 s on one, its 2.7e10 and 3.0e10 meshes in 1.06–1.09 s against 0.84–0.93 s
/// (docs/fem.md). faer's parallel factorisation gives the same bits.
pub const PARALLEL_FLOPS: f64 = 7e10;

/// A numeric Cholesky factor.
#[derive(Debug)]
pub struct CholeskyFactor {
    symbolic: SymbolicFactor,
    l_values: Vec<f64>,
}

impl CholeskyFactor {
    /// Factorises `a` (whose pattern `symbolic` was made from). A matrix that is not positive
    /// definite (a model that is not fully supported) is an error.
    pub fn factorise(symbolic: &SymbolicFactor, a: &SparseSym) -> Result<Self> {
        // sequential below PARALLEL_FLOPS: on the 2-core machine faer's parallel dense kernels
        // cost more than they gain on a rod's usual supernodes (72 kDOF: 0.48 s against 0.63 s;
        // 169 kDOF: 2.26 s against 2.33 s), and the study already runs designs side by side
        let par = if symbolic.flops() >= PARALLEL_FLOPS {
            Par::rayon(0)
        } else {
            Par::Seq
        };
        Self::factorise_with(symbolic, a, par)
    }

    /// [`Self::factorise`] with the parallelism given.
    fn factorise_with(symbolic: &SymbolicFactor, a: &SparseSym, par: Par) -> Result<Self> {
        if symbolic.n() != a.n {
            return Err(FemError::Solver(
                "symbolic factor of another dimension".into(),
            ));
        }
        let s = &*symbolic.inner;
        let mut l_values = Vec::new();
        l_values.try_reserve_exact(s.len_val()).map_err(|_| {
            FemError::Solver(format!(
                "out of memory for a factor of {} entries",
                s.len_val()
            ))
        })?;
        l_values.resize(s.len_val(), 0.0);
        let mut mem =
            MemBuffer::try_new(s.factorize_numeric_llt_scratch::<f64>(par, Default::default()))
                .map_err(|_| {
                    FemError::Solver("out of memory for the factorisation workspace".into())
                })?;
        let mat = SparseColMatRef::new(symbolic_ref(a), &a.values);
        s.factorize_numeric_llt::<f64>(
            &mut l_values,
            mat,
            Side::Upper,
            LltRegularization::default(),
            par,
            MemStack::new(&mut mem),
            Default::default(),
        )
        .map_err(|e| {
            FemError::Solver(format!(
                "stiffness matrix is not positive definite ({e:?}): the model is not fully supported \
                 (rigid-body motion) or the material/mesh is degenerate"
            ))
        })?;
        Ok(CholeskyFactor {
            symbolic: symbolic.clone(),
            l_values,
        })
    }

    /// Solves A X = B in place for `ncols` right-hand sides stored column after column in `rhs`.
    pub fn solve_in_place(&self, rhs: &mut [f64], ncols: usize) {
        let n = self.symbolic.n();
        assert_eq!(rhs.len(), n * ncols, "right-hand side size");
        let par = faer::get_global_parallelism();
        let s = &*self.symbolic.inner;
        let llt = LltRef::new(s, &self.l_values);
        let mut mem = MemBuffer::new(s.solve_in_place_scratch::<f64>(ncols, par));
        let b = MatMut::from_column_major_slice_mut(rhs, n, ncols);
        llt.solve_in_place_with_conj(Conj::No, b, par, MemStack::new(&mut mem));
    }

    /// The last `m` rows and columns of L, in the factor's order: with P K Pᵀ = L Lᵀ and the
    /// partition of the ordered unknowns into (first n − m, last m), the trailing block L₂₂ is
    /// the Cholesky factor of the Schur complement K₂₂ − K₂₁ K₁₁⁻¹ K₁₂, so that
    /// (K⁻¹)₂₂ = L₂₂⁻ᵀ L₂₂⁻¹ (Golub & Van Loan, *Matrix Computations*, 4th ed., §4.2.7 and
    /// §3.2.11). Returns the equations of those rows (`old[i]`: the equation at trailing row i)
    /// and L₂₂ (dense, lower triangular; its strict upper triangle zero).
    pub fn trailing_block(&self, m: usize) -> (Vec<usize>, faer::Mat<f64>) {
        use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
        use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;
        let s = &*self.symbolic.inner;
        let n = s.nrows();
        let start = n - m.min(n);
        let m = n - start;
        let old: Vec<usize> = match s.perm() {
            Some(p) => p.arrays().0[start..].to_vec(),
            None => (start..n).collect(),
        };
        let mut l = faer::Mat::<f64>::zeros(m, m);
        match s.raw() {
            SymbolicCholeskyRaw::Supernodal(sn) => {
                let llt = SupernodalLltRef::new(sn, &self.l_values);
                for k in 0..sn.n_supernodes() {
                    let (b, e) = (sn.supernode_begin()[k], sn.supernode_end()[k]);
                    if e <= start {
                        continue;
                    }
                    let node = llt.supernode(k);
                    let (val, pattern) = (node.val(), node.pattern());
                    let w = e - b;
                    for c in b.max(start)..e {
                        for r in 0..val.nrows() {
                            let row = if r < w { b + r } else { pattern[r - w] };
                            if row >= c {
                                l[(row - start, c - start)] = val[(r, c - b)];
                            }
                        }
                    }
                }
            }
            SymbolicCholeskyRaw::Simplicial(sp) => {
                let (col_ptr, row_idx) = (sp.col_ptr(), sp.row_idx());
                for c in start..n {
                    for p in col_ptr[c]..col_ptr[c + 1] {
                        if row_idx[p] >= c {
                            l[(row_idx[p] - start, c - start)] = self.l_values[p];
                        }
                    }
                }
            }
        }
        (old, l)
    }

    /// The symbolic analysis used.
    pub fn symbolic(&self) -> &SymbolicFactor {
        &self.symbolic
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The upper triangle of a symmetric matrix from its (row ≤ column) entries.
    fn upper(n: usize, entry: impl Fn(usize, usize) -> Option<f64>) -> SparseSym {
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            for i in 0..=j {
                if let Some(v) = entry(i, j) {
                    row_idx.push(i);
                    values.push(v);
                }
            }
            col_ptr.push(row_idx.len());
        }
        SparseSym {
            n,
            col_ptr,
            row_idx,
            values,
        }
    }

    #[test]
    fn the_flop_count_is_a_dense_choleskys_on_a_dense_matrix_and_linear_on_a_band() {
        // dense n × n: one supernode (or n columns of n − j entries), n³/3 to leading order
        let n = 60;
        let dense = upper(n, |i, j| Some(if i == j { 2.0 * n as f64 } else { 1.0 }));
        let f = SymbolicFactor::analyse(&dense, None).unwrap().flops();
        let n3 = (n * n * n) as f64 / 3.0;
        assert!((f / n3 - 1.0).abs() < 0.1, "{f:e} against {n3:e}");
        // tridiagonal: no fill, a few operations per column
        let n = 2000;
        let band = upper(n, |i, j| match j - i {
            0 => Some(2.0),
            1 => Some(-1.0),
            _ => None,
        });
        let f = SymbolicFactor::analyse(&band, None).unwrap().flops();
        assert!(f > n as f64 && f < 10.0 * n as f64, "{f:e}");
    }

    #[test]
    fn the_trailing_block_is_the_factor_of_the_schur_complement() {
        // a 1D Laplacian plus a coupling of the ends, both factor kinds: (K⁻¹)₂₂ from the
        // trailing block against K⁻¹'s columns solved directly
        for n in [12, 400] {
            let a = upper(n, |i, j| match j - i {
                0 => Some(3.0),
                1 => Some(-1.0),
                d if d == n - 1 => Some(-0.5),
                _ => None,
            });
            let order: Vec<usize> = (0..n).rev().collect();
            let sym = SymbolicFactor::analyse(&a, Some(&order)).unwrap();
            let f = CholeskyFactor::factorise(&sym, &a).unwrap();
            let m = 5;
            let (old, l) = f.trailing_block(m);
            let mut x = faer::Mat::<f64>::identity(m, m);
            faer::linalg::triangular_solve::solve_lower_triangular_in_place(
                l.as_ref(),
                x.as_mut(),
                Par::Seq,
            );
            let inv = x.transpose() * &x;
            for (c, &oc) in old.iter().enumerate() {
                let mut e = vec![0.0; n];
                e[oc] = 1.0;
                f.solve_in_place(&mut e, 1);
                for (r, &or) in old.iter().enumerate() {
                    assert!((inv[(r, c)] - e[or]).abs() < 1e-13, "n {n}: {r} {c}");
                }
            }
        }
    }

    #[test]
    fn the_parallel_factorisation_gives_the_sequential_bits() {
        // a 3D 7-point Laplacian (plus the identity), 18³ unknowns, in the natural order
        let m = 18;
        let idx = |x: usize, y: usize, z: usize| x + m * (y + m * z);
        let n = m * m * m;
        let a = upper(n, |i, j| {
            if i == j {
                return Some(7.0);
            }
            let (xi, yi, zi) = (i % m, (i / m) % m, i / (m * m));
            let (xj, yj, zj) = (j % m, (j / m) % m, j / (m * m));
            let neighbour = [
                idx(xi + 1, yi, zi),
                idx(xi, yi + 1, zi),
                idx(xi, yi, zi + 1),
            ];
            ((xi + 1 < m && neighbour[0] == j && yi == yj && zi == zj)
                || (yi + 1 < m && neighbour[1] == j && xi == xj && zi == zj)
                || (zi + 1 < m && neighbour[2] == j && xi == xj && yi == yj))
                .then_some(-1.0)
        });
        let sym = SymbolicFactor::analyse(&a, None).unwrap();
        let seq = CholeskyFactor::factorise_with(&sym, &a, Par::Seq).unwrap();
        let par = CholeskyFactor::factorise_with(&sym, &a, Par::rayon(2)).unwrap();
        assert!(
            seq.l_values
                .iter()
                .zip(&par.l_values)
                .all(|(x, y)| x.to_bits() == y.to_bits())
        );
        let (mut x, mut y) = (vec![1.0; n], vec![1.0; n]);
        seq.solve_in_place(&mut x, 1);
        par.solve_in_place(&mut y, 1);
        assert_eq!(x, y);
    }
}
