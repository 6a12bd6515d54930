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
//! **Eigen-solver.** With μ = 1/λ the smallest positive λ is the largest positive μ of
//! K⁻¹(−K_σ): inverse subspace iteration with Rayleigh–Ritz on the one Cholesky factor of K —
//! the one the static solve already used — ([`super::subspace`]), here with a block of
//! `options.block` vectors started from the load's pattern, converged on λ₁ alone. When no
//! positive Ritz value is found the load stiffens every mode the block found (a tensile stress
//! state) and the problem is refused.

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
use super::subspace::subspace_iteration;

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
    let pairs = subspace_iteration(
        factor,
        &g,
        start_block(&uf, n, p),
        1,
        options.tolerance,
        options.max_iterations,
    )
    .map_err(|e| match e {
        FemError::InvalidInput(m) => FemError::InvalidInput(format!(
            "no positive buckling load factor: the load stiffens every mode found (a tensile \
             stress state; {m}, the factor of the reversed load)"
        )),
        FemError::Solver(m) => FemError::Solver(format!("buckling: {m}")),
        other => other,
    })?;
    let (lambda, iterations, ritz) = (pairs.values[0], pairs.iterations, pairs.ritz);
    // the mode, its residual, its scale
    let phi = &pairs.vectors[0];
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
