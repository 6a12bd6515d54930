//! Linear (eigenvalue) buckling: the smallest positive load factor λ of
//!
//! (K + λ K_σ) φ = 0,  i.e.  K φ = λ (−K_σ) φ,
//!
//! where K is the linear stiffness of the free DOFs and K_σ the geometric stiffness of the
//! stress state σ⁰ of the reference load ([`super::geometric_stiffness`]; K.-J. Bathe, *Finite
//! Element Procedures*, 2nd ed., §6.8.2 "linearized buckling analysis"; R. D. Cook et al.,
//! *Concepts and Applications of FEA*, 4th ed., §18.6). The load λ·f is the buckling load of the
//! linearised (pre-buckling deformation neglected) problem.
//!
//! **Eigen-solver.** With μ = 1/λ the problem is the standard one A φ = μ φ for A = K⁻¹(−K_σ),
//! symmetric in the K inner product; the smallest positive λ is the largest positive μ. Inverse
//! subspace iteration with Rayleigh–Ritz (Bathe §11.6; the "shift-and-invert" form with zero
//! shift, so that the one Cholesky factor of K — the one the static solve already used — serves
//! every iteration): a block X of p vectors,
//!
//! 1. Y = −K_σ X, X̄ = K⁻¹ Y (one multi-right-hand-side solve with the factor of K; after the
//!    first iteration Y is carried over as (−K_σ X̄) Z from step 3, Bathe §11.6.3, so that each
//!    iteration multiplies by K_σ once);
//! 2. the projections K_r = X̄ᵀ K X̄ = X̄ᵀ Y and G_r = X̄ᵀ (−K_σ) X̄;
//! 3. the small dense problem G_r z = μ K_r z (K_r = L Lᵀ, the symmetric eigenproblem of
//!    L⁻¹ G_r L⁻ᵀ, nalgebra), X ← X̄ Z, K-orthonormal;
//!
//! until the largest positive Ritz value changes by at most `tolerance` (relative) between
//! iterations. The block converges to the p eigenvalues of largest |μ| at the rate
//! |μ_{p+1}/μ_i| per iteration; both signs occur (a negative λ is the buckling factor of the
//! reversed load). When no positive Ritz value is found the load stiffens every mode the block
//! found (a tensile stress state) and the problem is refused.

use std::time::Instant;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::assembly::{DofMap, SparseSym, assemble};
use super::element::QuadratureChoice;
use super::error::{FemError, Result};
use super::geometric_stiffness::{GeometricKernel, geometric_kernel};
use super::material::Material;
use super::mesh::TetMesh;
use super::ordering::nested_dissection;
use super::solver::{CholeskyFactor, SymbolicFactor};
use super::statics::FactorisedSystem;

/// Options of [`solve_buckling`].
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct BucklingOptions {
    /// Vectors in the block of the subspace iteration.
    pub block: usize,
    /// Convergence: relative change of λ₁ between iterations.
    pub tolerance: f64,
    /// Most iterations.
    pub max_iterations: usize,
    /// Quadrature of K_σ (its integrand g_aᵀ σ g_b is cubic on a straight tet10: the 14-point
    /// degree-5 rule integrates it exactly; the 4-point rule is what C3D10 codes use).
    pub geometric_quadrature: QuadratureChoice,
}

impl Default for BucklingOptions {
    fn default() -> Self {
        BucklingOptions {
            block: 6,
            tolerance: 1e-8,
            max_iterations: 300,
            geometric_quadrature: QuadratureChoice::Degree5,
        }
    }
}

/// A linear buckling problem: the static problem whose stress is the pre-stress.
#[derive(Clone, Debug)]
pub struct BucklingProblem<'a> {
    /// The mesh (m).
    pub mesh: &'a TetMesh,
    /// The material.
    pub material: Material,
    /// Fixed DOFs (3 · node + component); the value must be zero (supports, not displacements).
    pub fixed_dofs: Vec<usize>,
    /// The reference load: nodal forces, 3 per node (N).
    pub load: Vec<f64>,
    /// Quadrature of K.
    pub quadrature: QuadratureChoice,
}

/// The result of [`solve_buckling`].
#[derive(Clone, Debug)]
pub struct BucklingSolution {
    /// λ₁: the smallest positive load factor (the buckling load is λ₁ times the reference load).
    pub load_factor: f64,
    /// The mode φ₁, 3 per node, scaled to a largest component of +1.
    pub mode: Vec<f64>,
    /// The Ritz values of the last iteration as load factors 1/μ, ascending by |λ| among the
    /// positive ones first (the higher ones are estimates, converged less than λ₁).
    pub ritz_load_factors: Vec<f64>,
    /// Iterations made.
    pub iterations: usize,
    /// ‖K φ + λ K_σ φ‖ / ‖K φ‖ of the returned pair.
    pub residual_rel: f64,
    /// The static displacements of the reference load (3 per node, m).
    pub displacements: Vec<f64>,
    /// Equations (free DOFs).
    pub equations: usize,
    /// Wall time: assembly and factorisation of K with the static solve, K_σ, the iteration, s.
    pub static_s: f64,
    pub geometric_s: f64,
    pub iteration_s: f64,
}

/// Assembles K_σ of the free DOFs of `dofs` on the pattern of `k` (upper triangle), from
/// the full displacement vector `u` of the pre-stress.
pub fn assemble_geometric(
    mesh: &TetMesh,
    material: &Material,
    quadrature: QuadratureChoice,
    dofs: &DofMap,
    k: &SparseSym,
    u: &[f64],
) -> Result<SparseSym> {
    let mut values = vec![0.0; k.row_idx.len()];
    let locate = |r: usize, c: usize| -> usize {
        let (s, e) = (k.col_ptr[c], k.col_ptr[c + 1]);
        s + k.row_idx[s..e]
            .binary_search(&r)
            .expect("K_σ shares the pattern of K")
    };
    const CHUNK: usize = 1 << 15;
    for start in (0..mesh.n_elements()).step_by(CHUNK) {
        let end = (start + CHUNK).min(mesh.n_elements());
        let kernels: Vec<GeometricKernel> = (start..end)
            .into_par_iter()
            .map(|e| {
                let x = mesh.element_coords(e);
                let ue = mesh.element_displacements(e, u);
                geometric_kernel(&x, &ue, material, quadrature.rule_for(&x), e)
            })
            .collect::<Result<_>>()?;
        for (e, h) in (start..end).zip(&kernels) {
            let el = &mesh.elements()[e];
            for a in 0..10 {
                for b in 0..10 {
                    for i in 0..3 {
                        let (Some(r), Some(c)) = (dofs.eq(3 * el[a] + i), dofs.eq(3 * el[b] + i))
                        else {
                            continue;
                        };
                        if r <= c {
                            values[locate(r, c)] += h[(a, b)];
                        }
                    }
                }
            }
        }
    }
    Ok(SparseSym {
        n: k.n,
        col_ptr: k.col_ptr.clone(),
        row_idx: k.row_idx.clone(),
        values,
    })
}

/// y = A X for the `p` columns of `x` (column after column), in parallel over the columns.
fn mul_block(a: &SparseSym, x: &[f64], p: usize) -> Vec<f64> {
    let n = a.n;
    let cols: Vec<Vec<f64>> = (0..p)
        .into_par_iter()
        .map(|j| a.mul(&x[j * n..(j + 1) * n]))
        .collect();
    cols.concat()
}

/// XᵀY for two n × p blocks (column-major).
fn gram(x: &[f64], y: &[f64], n: usize, p: usize) -> nalgebra::DMatrix<f64> {
    nalgebra::DMatrix::from_fn(p, p, |i, j| {
        x[i * n..(i + 1) * n]
            .iter()
            .zip(&y[j * n..(j + 1) * n])
            .map(|(a, b)| a * b)
            .sum()
    })
}

/// Deterministic start vectors: the first the load's direction pattern, the others a fixed
/// pseudo-random sequence (a 64-bit linear congruential generator), so results are reproducible.
fn start_block(b: &[f64], n: usize, p: usize) -> Vec<f64> {
    let mut x = vec![0.0; n * p];
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    for (k, v) in x.iter_mut().enumerate() {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let r = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        *v = if k < n { b[k] + 1e-3 * r } else { r };
    }
    x
}

/// The checks of a problem and its options before any work.
fn check_problem(problem: &BucklingProblem, options: &BucklingOptions) -> Result<()> {
    let n_dofs = problem.mesh.n_dofs();
    if problem.load.len() != n_dofs {
        return Err(FemError::InvalidInput(format!(
            "the load has {} entries, the mesh {n_dofs} DOFs",
            problem.load.len()
        )));
    }
    if options.block == 0 || options.max_iterations == 0 {
        return Err(FemError::InvalidInput(
            "the buckling iteration needs a block of at least one vector".into(),
        ));
    }
    Ok(())
}

/// Solves the buckling problem: see the module documentation.
pub fn solve_buckling(
    problem: &BucklingProblem,
    options: &BucklingOptions,
) -> Result<BucklingSolution> {
    check_problem(problem, options)?;
    let mesh = problem.mesh;
    let n_dofs = mesh.n_dofs();
    let t0 = Instant::now();
    let prescribed: Vec<(usize, f64)> = problem.fixed_dofs.iter().map(|&d| (d, 0.0)).collect();
    let dofs = DofMap::new(n_dofs, &prescribed)?;
    if dofs.n_eq() == 0 {
        return Err(FemError::InvalidInput("every DOF is prescribed".into()));
    }
    let asm = assemble(mesh, &problem.material, problem.quadrature, &dofs)?;
    let symbolic = {
        let order = nested_dissection(mesh, &dofs)?;
        SymbolicFactor::analyse(&asm.k, Some(&order))?
    };
    let factor = CholeskyFactor::factorise(&symbolic, &asm.k)?;
    let system = FactorisedSystem {
        dofs,
        k: asm.k,
        factor,
    };
    buckling_on(problem, &system, options, t0)
}

/// [`solve_buckling`] on the factorised K of a static solve with the same mesh, material,
/// quadrature and supports ([`super::statics::solve_static_keeping`]): no assembly and no
/// factorisation of K again, and the same K to the bit. A system whose supports differ from the
/// problem's is refused.
pub fn solve_buckling_with(
    problem: &BucklingProblem,
    system: &FactorisedSystem,
    options: &BucklingOptions,
) -> Result<BucklingSolution> {
    let t0 = Instant::now();
    check_problem(problem, options)?;
    let prescribed: Vec<(usize, f64)> = problem.fixed_dofs.iter().map(|&d| (d, 0.0)).collect();
    if DofMap::new(problem.mesh.n_dofs(), &prescribed)? != system.dofs {
        return Err(FemError::InvalidInput(
            "the factorised system has other supports than the buckling problem".into(),
        ));
    }
    buckling_on(problem, system, options, t0)
}

/// The pre-stress, K_σ and the iteration on a factorised K (`t0`: when the analysis started).
fn buckling_on(
    problem: &BucklingProblem,
    system: &FactorisedSystem,
    options: &BucklingOptions,
    t0: Instant,
) -> Result<BucklingSolution> {
    let mesh = problem.mesh;
    let n_dofs = mesh.n_dofs();
    let (dofs, factor) = (&system.dofs, &system.factor);
    let n = dofs.n_eq();
    // the pre-stress: the static solution of the reference load, with the same factor
    let mut b = vec![0.0; n];
    for (d, f) in problem.load.iter().enumerate() {
        if let Some(q) = dofs.eq(d) {
            b[q] += f;
        }
    }
    if b.iter().all(|v| *v == 0.0) {
        return Err(FemError::InvalidInput(
            "the buckling load is zero on the free DOFs".into(),
        ));
    }
    let mut uf = b.clone();
    factor.solve_in_place(&mut uf, 1);
    let full = |x: &[f64]| -> Vec<f64> {
        (0..n_dofs)
            .map(|d| dofs.eq(d).map_or(0.0, |q| x[q]))
            .collect()
    };
    let u = full(&uf);
    let static_s = t0.elapsed().as_secs_f64();

    let t1 = Instant::now();
    let mut ks = assemble_geometric(
        mesh,
        &problem.material,
        options.geometric_quadrature,
        dofs,
        &system.k,
        &u,
    )?;
    // G = −K_σ: K φ = λ G φ
    for v in &mut ks.values {
        *v = -*v;
    }
    let g = ks;
    let geometric_s = t1.elapsed().as_secs_f64();

    let t2 = Instant::now();
    let p = options.block.min(n);
    let mut x = start_block(&uf, n, p);
    let mut previous: Option<f64> = None;
    let mut ritz: Vec<f64> = Vec::new();
    let mut lambda = f64::NAN;
    let mut iterations = 0;
    let mut converged = false;
    let mut largest_previous = f64::NAN;
    // Y = G X; after the first iteration carried over as (G X̄) Q (Bathe §11.6.3), so that each
    // iteration multiplies by G once
    let mut y = mul_block(&g, &x, p);
    for it in 1..=options.max_iterations {
        iterations = it;
        let mut xb = y.clone();
        factor.solve_in_place(&mut xb, p);
        let kr = gram(&xb, &y, n, p);
        let gx = mul_block(&g, &xb, p);
        let gr = gram(&xb, &gx, n, p);
        let kr = 0.5 * (&kr + kr.transpose());
        let gr = 0.5 * (&gr + gr.transpose());
        let chol = nalgebra::Cholesky::new(kr).ok_or_else(|| {
            FemError::Solver(
                "buckling: the projected stiffness is not positive definite (the block \
                 collapsed: −K_σ has fewer than `block` independent directions)"
                    .into(),
            )
        })?;
        let l = chol.l();
        let linv = l
            .clone()
            .try_inverse()
            .ok_or_else(|| FemError::Solver("buckling: singular projected stiffness".into()))?;
        let c = &linv * &gr * linv.transpose();
        let c = 0.5 * (&c + c.transpose());
        let eig = nalgebra::SymmetricEigen::new(c);
        // descending μ: the largest positive first
        let mut order: Vec<usize> = (0..p).collect();
        order.sort_by(|&i, &j| eig.eigenvalues[j].total_cmp(&eig.eigenvalues[i]));
        let z = linv.transpose() * &eig.eigenvectors;
        // X = X̄ Q and Y = (G X̄) Q, Q the Ritz vectors in descending μ
        let combine = |block: &[f64]| -> Vec<f64> {
            let mut out = vec![0.0; n * p];
            for (k, &col) in order.iter().enumerate() {
                let o = &mut out[k * n..(k + 1) * n];
                for m in 0..p {
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
        y = combine(&gx);
        let mus: Vec<f64> = order.iter().map(|&i| eig.eigenvalues[i]).collect();
        let scale = mus.iter().fold(0.0f64, |a, m| a.max(m.abs()));
        ritz = mus.iter().map(|m| 1.0 / m).collect();
        let largest = mus[0];
        if largest > 1e-9 * scale {
            lambda = 1.0 / largest;
            if let Some(prev) = previous
                && (lambda - prev).abs() <= options.tolerance * lambda
            {
                converged = true;
                break;
            }
            previous = Some(lambda);
        } else {
            // no positive Ritz value: stop once the block's dominant value has settled
            let dominant = mus[p - 1];
            if (dominant - largest_previous).abs() <= options.tolerance * dominant.abs() {
                return Err(FemError::InvalidInput(format!(
                    "no positive buckling load factor: the load stiffens every mode found (a \
                     tensile stress state; the {p} eigenvalues of largest magnitude are all \
                     negative, the nearest λ = {:.4e} is the factor of the reversed load)",
                    1.0 / dominant
                )));
            }
            largest_previous = dominant;
            previous = None;
        }
    }
    if !converged {
        return Err(FemError::Solver(format!(
            "buckling: the subspace iteration did not converge to {:.0e} in {} iterations \
             (last λ₁ = {lambda:.6e})",
            options.tolerance, options.max_iterations
        )));
    }
    // the mode, its residual, its scale
    let phi = &x[..n];
    let kphi = system.k.mul(phi);
    let gphi = g.mul(phi);
    let num: f64 = kphi
        .iter()
        .zip(&gphi)
        .map(|(a, b)| (a - lambda * b).powi(2))
        .sum::<f64>()
        .sqrt();
    let den: f64 = kphi.iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut mode = full(phi);
    let big = mode
        .iter()
        .copied()
        .fold(0.0f64, |a, v| if v.abs() > a.abs() { v } else { a });
    if big != 0.0 {
        for v in &mut mode {
            *v /= big;
        }
    }
    let mut ritz_sorted = ritz;
    ritz_sorted.sort_by(|a, b| {
        (*a < 0.0)
            .cmp(&(*b < 0.0))
            .then(a.abs().total_cmp(&b.abs()))
    });
    Ok(BucklingSolution {
        load_factor: lambda,
        mode,
        ritz_load_factors: ritz_sorted,
        iterations,
        residual_rel: if den > 0.0 { num / den } else { num },
        displacements: u,
        equations: n,
        static_s,
        geometric_s,
        iteration_s: t2.elapsed().as_secs_f64(),
    })
}

/// The first buckling mode of a body and its load factor.
#[derive(Clone, Debug)]
pub struct BucklingMode {
    /// λ₁.
    pub load_factor: f64,
    /// The reference load (the compression), N.
    pub load_n: f64,
    /// φ₁, 3 per node, largest component +1.
    pub mode: Vec<f64>,
}
