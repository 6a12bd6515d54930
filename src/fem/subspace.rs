//! The lowest eigenpairs of K φ = λ B φ, K symmetric positive definite (factorised), B symmetric
//! (the mass matrix M for natural frequencies, λ = ω²; −K_σ for linear buckling, λ the load
//! factor; B may be indefinite), by inverse subspace iteration with Rayleigh–Ritz (K.-J. Bathe,
//! *Finite Element Procedures*, 2nd ed., §11.6; the same iteration as [`super::buckling`]):
//! with μ = 1/λ, a block X of q vectors,
//!
//! 1. X̄ = K⁻¹ (B X) (one multi-right-hand-side solve with the factor);
//! 2. K_r = X̄ᵀ K X̄ = X̄ᵀ (B X), B_r = X̄ᵀ B X̄;
//! 3. B_r z = μ K_r z (K_r = L Lᵀ, the symmetric eigenproblem of L⁻¹ B_r L⁻ᵀ, nalgebra); X ← X̄ Z;
//!
//! until the wanted p largest positive μ (the p smallest positive λ) each change by at most
//! `tolerance` (relative) between iterations. The block has q = min(n, max(2p, p + 8)) vectors
//! (Bathe's choice), started from B's diagonal pattern and the reference vector given.

use nalgebra::DMatrix;

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
    /// Iterations made.
    pub iterations: usize,
}

fn mul_block(a: &SparseSym, x: &[f64], q: usize) -> Vec<f64> {
    let n = a.n;
    (0..q).flat_map(|k| a.mul(&x[k * n..(k + 1) * n])).collect()
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
    let mut y = mul_block(b, &x, q);
    let mut previous: Vec<f64> = Vec::new();
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
            .take_while(|m| **m > 1e-12 * scale)
            .take(p)
            .map(|m| 1.0 / m)
            .collect();
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
