//! Linear static analysis: K u = f with prescribed displacements, several load cases from one
//! factorisation; reactions at the prescribed DOFs (K u − f there, from the element matrices of the
//! elements that touch them) and the residual of the solve.

use std::time::Instant;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::assembly::{DofMap, SparseSym, assemble};
use super::element::{QuadratureChoice, element_stiffness};
use super::error::{FemError, Result};
use super::material::Material;
use super::mesh::TetMesh;
use super::ordering::nested_dissection;
use super::solver::{CholeskyFactor, SymbolicFactor};

/// A linear static problem on a mesh.
#[derive(Clone, Debug)]
pub struct StaticProblem<'a> {
    /// The mesh (m).
    pub mesh: &'a TetMesh,
    /// The material.
    pub material: Material,
    /// Prescribed displacements (DOF = 3 · node + component, value in m), the same in every load case.
    pub prescribed: Vec<(usize, f64)>,
    /// Load cases: nodal forces, 3 per node (N).
    pub loads: Vec<Vec<f64>>,
    /// Element quadrature.
    pub quadrature: QuadratureChoice,
}

/// Wall-clock times of the stages, seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Timings {
    /// Jacobian checks, pattern, colouring and parallel assembly.
    pub assembly_s: f64,
    /// Symbolic Cholesky (ordering, elimination tree).
    pub symbolic_s: f64,
    /// Numeric Cholesky.
    pub factorisation_s: f64,
    /// Triangular solves for all load cases, reactions, residuals.
    pub solve_s: f64,
    /// Stress recovery and post-processing (filled by the caller that does it).
    pub stress_s: f64,
}

/// Size and structure figures of a solve.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SolveStats {
    /// All DOFs (3 per node).
    pub dofs: usize,
    /// Free DOFs (equations).
    pub equations: usize,
    /// Stored entries of K (upper triangle).
    pub nnz_k: usize,
    /// Stored entries of the Cholesky factor.
    pub nnz_l: usize,
    /// Element colours of the parallel assembly.
    pub colours: usize,
    /// Curved elements (integrated with the 14-point rule under `Auto`).
    pub curved_elements: usize,
    /// Smallest Jacobian determinant found.
    pub min_det_j: f64,
}

/// Displacements, reactions and diagnostics per load case.
#[derive(Clone, Debug)]
pub struct StaticSolution {
    /// Displacements, 3 per node (m), per load case.
    pub displacements: Vec<Vec<f64>>,
    /// Reactions (K u − f), 3 per node (N), non-zero only at prescribed DOFs, per load case.
    pub reactions: Vec<Vec<f64>>,
    /// ‖K_ff u_f − b‖ / ‖b‖ per load case.
    pub residual_rel: Vec<f64>,
    /// Sizes.
    pub stats: SolveStats,
    /// Times.
    pub timings: Timings,
}

/// The factorised stiffness of a static solve, kept for another analysis on the same mesh,
/// material, quadrature and supports (a buckling analysis: [`super::buckling`]), which
/// then needs neither the assembly nor the factorisation again.
#[derive(Debug)]
pub struct FactorisedSystem {
    /// The equations (the supports' DOFs prescribed).
    pub dofs: DofMap,
    /// K of the free DOFs (upper triangle).
    pub k: SparseSym,
    /// Its Cholesky factor.
    pub factor: CholeskyFactor,
}

/// Solves `problem`.
pub fn solve_static(problem: &StaticProblem) -> Result<StaticSolution> {
    solve_static_keeping(problem).map(|(solution, _)| solution)
}

/// [`solve_static`], returning the factorised system too.
pub fn solve_static_keeping(problem: &StaticProblem) -> Result<(StaticSolution, FactorisedSystem)> {
    solve_static_reusing(problem, None)
}

/// [`solve_static_keeping`] with the symbolic analysis (ordering, elimination tree) of another solve
/// reused where K has its pattern (the same mesh connectivity and supports: the same mesh with its
/// boundary moved, [`super::smooth`]); analysed afresh where it does not.
pub fn solve_static_reusing(
    problem: &StaticProblem,
    symbolic: Option<&SymbolicFactor>,
) -> Result<(StaticSolution, FactorisedSystem)> {
    let mesh = problem.mesh;
    let n_dofs = mesh.n_dofs();
    if problem.loads.is_empty() {
        return Err(FemError::InvalidInput("no load case".into()));
    }
    if let Some(l) = problem.loads.iter().find(|l| l.len() != n_dofs) {
        return Err(FemError::InvalidInput(format!(
            "a load vector has {} entries, the mesh {n_dofs} DOFs",
            l.len()
        )));
    }
    let dofs = DofMap::new(n_dofs, &problem.prescribed)?;
    if dofs.n_eq() == 0 {
        return Err(FemError::InvalidInput("every DOF is prescribed".into()));
    }
    let mut timings = Timings::default();
    let t = Instant::now();
    let asm = assemble(mesh, &problem.material, problem.quadrature, &dofs)?;
    timings.assembly_s = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let symbolic = match symbolic {
        Some(s) if s.matches(&asm.k) => s.clone(),
        _ => {
            let order = nested_dissection(mesh, &dofs)?;
            SymbolicFactor::analyse(&asm.k, Some(&order))?
        }
    };
    timings.symbolic_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let factor = CholeskyFactor::factorise(&symbolic, &asm.k)?;
    timings.factorisation_s = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let n_eq = dofs.n_eq();
    let ncases = problem.loads.len();
    let mut rhs = vec![0.0; n_eq * ncases];
    for (c, load) in problem.loads.iter().enumerate() {
        let col = &mut rhs[c * n_eq..(c + 1) * n_eq];
        col.copy_from_slice(&asm.dirichlet_rhs);
        for (d, f) in load.iter().enumerate() {
            if let Some(q) = dofs.eq(d) {
                col[q] += f;
            }
        }
    }
    let b = rhs.clone();
    factor.solve_in_place(&mut rhs, ncases);
    let mut displacements = Vec::with_capacity(ncases);
    let mut residual_rel = Vec::with_capacity(ncases);
    for c in 0..ncases {
        let x = &rhs[c * n_eq..(c + 1) * n_eq];
        let bc = &b[c * n_eq..(c + 1) * n_eq];
        let kx = asm.k.mul(x);
        let r: f64 = kx
            .iter()
            .zip(bc)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        let bn: f64 = bc.iter().map(|v| v * v).sum::<f64>().sqrt();
        residual_rel.push(if bn > 0.0 { r / bn } else { r });
        displacements.push(
            (0..n_dofs)
                .map(|d| dofs.eq(d).map_or(dofs.value(d), |q| x[q]))
                .collect::<Vec<f64>>(),
        );
    }
    let reactions = reactions(problem, &dofs, &displacements)?;
    timings.solve_s = t.elapsed().as_secs_f64();
    let stats = SolveStats {
        dofs: n_dofs,
        equations: n_eq,
        nnz_k: asm.k.nnz(),
        nnz_l: symbolic.nnz_l(),
        colours: asm.colours,
        curved_elements: asm.curved_elements,
        min_det_j: asm.min_det_j,
    };
    Ok((
        StaticSolution {
            displacements,
            reactions,
            residual_rel,
            stats,
            timings,
        },
        FactorisedSystem {
            dofs,
            k: asm.k,
            factor,
        },
    ))
}

/// K u − f at the prescribed DOFs, from the elements that have a prescribed DOF.
fn reactions(problem: &StaticProblem, dofs: &DofMap, us: &[Vec<f64>]) -> Result<Vec<Vec<f64>>> {
    let mesh = problem.mesh;
    let touching: Vec<usize> = (0..mesh.n_elements())
        .filter(|&e| {
            mesh.elements()[e]
                .iter()
                .any(|&n| (0..3).any(|j| dofs.eq(3 * n + j).is_none()))
        })
        .collect();
    let contribs: Vec<Vec<[f64; 30]>> = touching
        .par_iter()
        .map(|&e| {
            let x = mesh.element_coords(e);
            let ke = element_stiffness(&x, &problem.material, problem.quadrature.rule_for(&x), e)?;
            let el = &mesh.elements()[e];
            Ok(us
                .iter()
                .map(|u| {
                    let ue = nalgebra::SVector::<f64, 30>::from_fn(|i, _| u[3 * el[i / 3] + i % 3]);
                    let f = ke * ue;
                    std::array::from_fn(|i| f[i])
                })
                .collect())
        })
        .collect::<Result<_>>()?;
    let mut out = vec![vec![0.0; mesh.n_dofs()]; us.len()];
    for (k, &e) in touching.iter().enumerate() {
        let el = &mesh.elements()[e];
        for (c, f) in contribs[k].iter().enumerate() {
            for (i, v) in f.iter().enumerate() {
                let d = 3 * el[i / 3] + i % 3;
                if dofs.eq(d).is_none() {
                    out[c][d] += v;
                }
            }
        }
    }
    for (c, load) in problem.loads.iter().enumerate() {
        for d in 0..mesh.n_dofs() {
            if dofs.eq(d).is_none() {
                out[c][d] -= load[d];
            }
        }
    }
    Ok(out)
}
