//! The lowest eigenpairs of K φ = λ B φ, K symmetric positive definite (factorised), B symmetric
//! (the mass matrix M for natural frequencies, λ = ω²; −K_σ for linear buckling, λ the load
//! factor, [`super::buckling`]; B may be indefinite), by inverse subspace iteration with
//! Rayleigh–Ritz (K.-J. Bathe, *Finite Element Procedures*, 2nd ed., §11.6): with μ = 1/λ, a
//! block X of q vectors,
//!
//! 1. X̄ = K⁻¹ Y, Y = B X (one multi-right-hand-side solve with the factor; after the first
//!    iteration Y is carried over as (B X̄) Z from step 3, Bathe §11.6.3, so that each iteration
//!    multiplies by B once);
//! 2. K_r = X̄ᵀ K X̄ = X̄ᵀ Y, B_r = X̄ᵀ B X̄;
//! 3. B_r z = μ K_r z (K_r = L Lᵀ, the symmetric eigenproblem of L⁻¹ B_r L⁻ᵀ, nalgebra);
//!    X ← X̄ Z, K-orthonormal, in descending μ;
//!
//! until the wanted p largest positive μ (the p smallest positive λ) each change by at most
//! `tolerance` (relative) between iterations. The block converges to the eigenvalues of largest
//! |μ| at the rate |μ_{q+1}/μ_i| per iteration; both signs occur when B is indefinite (a negative
//! buckling factor is that of the reversed load). When the block holds no positive μ and its
//! dominant negative one has settled, there is no positive λ within reach and the problem is
//! refused. [`lowest_eigenpairs`] chooses the block (q = min(n, max(2p, p + 8)), Bathe's choice)
//! and its start (a reference vector, B's diagonal, a fixed pseudo-random fill);
//! [`subspace_iteration`] takes the caller's.

use nalgebra::DMatrix;
use rayon::prelude::*;

use super::assembly::SparseSym;
use super::error::{FemError, Result};
use super::solver::CholeskyFactor;

/// The converged pairs.
#[derive(Clone, Debug)]
pub struct EigenPairs {
    /// λ_1 ≤ λ_2 ≤ … (positive), as many as asked for where found.
    pub values: Vec<f64>,
    /// φ_k (length n), K-orthonormal (φᵀ K φ = 1), i.e. B-normalised to φᵀ B φ = 1/λ.
    pub vectors: Vec<Vec<f64>>,
    /// Every Ritz value of the last iteration as λ = 1/μ, in descending μ (the positive ones
    /// first, the higher ones converged less than the wanted).
    pub ritz: Vec<f64>,
    /// Iterations made.
    pub iterations: usize,
}

/// Y = A X for the `q` columns of `x` (column after column), in parallel over the columns.
fn mul_block(a: &SparseSym, x: &[f64], q: usize) -> Vec<f64> {
    let n = a.n;
    let cols: Vec<Vec<f64>> = (0..q)
        .into_par_iter()
        .map(|k| a.mul(&x[k * n..(k + 1) * n]))
        .collect();
    cols.concat()
}

fn gram(a: &[f64], b: &[f64], n: usize, q: usize) -> DMatrix<f64> {
    DMatrix::from_fn(q, q, |i, j| {
        a[i * n..(i + 1) * n]
            .iter()
            .zip(&b[j * n..(j + 1) * n])
            .map(|(x, y)| x * y)
            .sum()
    })
}

/// The `p` smallest positive λ of K φ = λ B φ (`factor` of K, `b`), from the start vector
/// `start` (length n; e.g. the static solution) and a deterministic fill of the block.
pub fn lowest_eigenpairs(
    factor: &CholeskyFactor,
    b: &SparseSym,
    start: &[f64],
    p: usize,
    tolerance: f64,
    max_iterations: usize,
) -> Result<EigenPairs> {
    let n = b.n;
    if p == 0 || n == 0 {
        return Err(FemError::InvalidInput(
            "no eigenvalue asked for, or no free DOF".into(),
        ));
    }
    let q = n.min((2 * p).max(p + 8));
    // start block: the given vector, B's diagonal, unit vectors spread over the DOFs
    let mut x = vec![0.0; n * q];
    let mut diag = vec![0.0; n];
    for (c, d) in diag.iter_mut().enumerate() {
        for k in b.col_ptr[c]..b.col_ptr[c + 1] {
            if b.row_idx[k] == c {
                *d = b.values[k].abs();
            }
        }
    }
    x[..n].copy_from_slice(start);
    if q > 1 {
        x[n..2 * n].copy_from_slice(&diag);
    }
    for k in 2..q {
        for i in 0..n {
            // a fixed pseudo-random pattern (no RNG state: reproducible)
            let mut h = ((k * n + i) as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
            // splitmix64's finaliser
            h = (h ^ (h >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            h = (h ^ (h >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            h ^= h >> 31;
            x[k * n + i] = ((h >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * (1.0 + diag[i]);
        }
    }
    subspace_iteration(factor, b, x, p, tolerance, max_iterations)
}

/// Ritz values μ below this fraction of the largest |μ| count as zero, not positive.
const POSITIVE_FLOOR: f64 = 1e-9;

/// The subspace iteration from the start block `x` (its q = `x.len() / n` columns one after
/// the other): the `p` smallest positive λ of K φ = λ B φ, converged to `tolerance` (relative
/// change of each between iterations).
pub fn subspace_iteration(
    factor: &CholeskyFactor,
    b: &SparseSym,
    mut x: Vec<f64>,
    p: usize,
    tolerance: f64,
    max_iterations: usize,
) -> Result<EigenPairs> {
    let n = b.n;
    if n == 0 || p == 0 || x.len() < n || !x.len().is_multiple_of(n) || max_iterations == 0 {
        return Err(FemError::InvalidInput(format!(
            "subspace iteration: a start block of {} entries for {n} DOFs and {p} eigenvalues",
            x.len()
        )));
    }
    let q = x.len() / n;
    let mut y = mul_block(b, &x, q);
    let mut previous: Vec<f64> = Vec::new();
    let mut dominant_previous = f64::NAN;
    for it in 1..=max_iterations {
        let mut xb = y.clone();
        factor.solve_in_place(&mut xb, q);
        let kr = gram(&xb, &y, n, q);
        let bx = mul_block(b, &xb, q);
        let br = gram(&xb, &bx, n, q);
        let kr = 0.5 * (&kr + kr.transpose());
        let br = 0.5 * (&br + br.transpose());
        let chol = nalgebra::Cholesky::new(kr.clone()).ok_or_else(|| {
            FemError::Solver(format!(
                "eigenvalues: the projected stiffness is not positive definite in iteration {it} \
                 (the block collapsed: B has fewer independent directions than the block; \
                 diagonal {:?})",
                kr.diagonal().as_slice()
            ))
        })?;
        let linv = chol
            .l()
            .try_inverse()
            .ok_or_else(|| FemError::Solver("eigenvalues: singular projected stiffness".into()))?;
        let c = &linv * &br * linv.transpose();
        let eig = nalgebra::SymmetricEigen::new(0.5 * (&c + c.transpose()));
        let mut order: Vec<usize> = (0..q).collect();
        order.sort_by(|&i, &j| eig.eigenvalues[j].total_cmp(&eig.eigenvalues[i]));
        let z = linv.transpose() * &eig.eigenvectors;
        let combine = |block: &[f64]| -> Vec<f64> {
            let mut out = vec![0.0; n * q];
            for (k, &col) in order.iter().enumerate() {
                let o = &mut out[k * n..(k + 1) * n];
                for m in 0..q {
                    let w = z[(m, col)];
                    if w != 0.0 {
                        for (o, v) in o.iter_mut().zip(&block[m * n..(m + 1) * n]) {
                            *o += w * v;
                        }
                    }
                }
            }
            out
        };
        x = combine(&xb);
        y = combine(&bx);
        let mus: Vec<f64> = order.iter().map(|&i| eig.eigenvalues[i]).collect();
        let scale = mus.iter().fold(0.0f64, |a, m| a.max(m.abs()));
        let lambdas: Vec<f64> = mus
            .iter()
            .take_while(|m| **m > POSITIVE_FLOOR * scale)
            .take(p)
            .map(|m| 1.0 / m)
            .collect();
        if lambdas.is_empty() {
            // no positive Ritz value: stop once the block's dominant value has settled
            let dominant = mus[q - 1];
            if (dominant - dominant_previous).abs() <= tolerance * dominant.abs() {
                return Err(FemError::InvalidInput(format!(
                    "no positive eigenvalue: the {q} of largest magnitude are all negative, the \
                     nearest λ = {:.4e}",
                    1.0 / dominant
                )));
            }
            dominant_previous = dominant;
        }
        let converged = !lambdas.is_empty()
            && lambdas.len() == previous.len()
            && lambdas
                .iter()
                .zip(&previous)
                .all(|(a, b)| (a - b).abs() <= tolerance * a.abs());
        if converged {
            let vectors = (0..lambdas.len())
                .map(|k| x[k * n..(k + 1) * n].to_vec())
                .collect();
            return Ok(EigenPairs {
                values: lambdas,
                vectors,
                ritz: mus.iter().map(|m| 1.0 / m).collect(),
                iterations: it,
            });
        }
        previous = lambdas;
    }
    Err(FemError::Solver(format!(
        "eigenvalues: the subspace iteration did not converge to {tolerance:.0e} in \
         {max_iterations} iterations (last values {previous:?})"
    )))
}
