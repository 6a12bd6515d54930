//! Kinematic analysis and inverse dynamics of a zero-DOF system at one time
//! (Nikravesh 1988, kinematic analysis; thesis §3.2): Newton–Raphson on
//! Φ(c, t) = 0, then D ċ = ν (eq. 3.35), D c̈ = γ (eq. 3.36–3.38) and
//! Dᵀλ = M c̈ − h (the decoupled block system of eq. 3.38), all with one LU of
//! the scaled Jacobian; the rank decision near singularity (complete pivoting)
//! and the diagnosis of the dependent joint.

use nalgebra::{Const, DMatrix, DimMin, SMatrix, SVector};

use super::super::error::{DynamicsError, Result};
use super::{MultibodySystem, NamedJoint, Poses};
use crate::linalg::{Factorization, most_dependent_row};

/// Relative pivot of the partial-pivoting LU below which the rank decision is
/// handed to the complete-pivoting LU. Healthy crank–slider Jacobians have
/// ratios of 0.3–1 (0.04 at l/r = 1.001), so the costlier factorisation
/// only runs close to a singular configuration.
pub const RANK_CONFIRM: f64 = 1e-3;

/// Result of the kinematic analysis and inverse dynamics at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KinematicSolution<const N: usize> {
    /// Time (s).
    pub t: f64,
    /// Body coordinates c.
    pub q: SVector<f64, N>,
    /// Velocities ċ.
    pub qd: SVector<f64, N>,
    /// Accelerations c̈.
    pub qdd: SVector<f64, N>,
    /// Lagrange multipliers λ (one per constraint row).
    pub lambda: SVector<f64, N>,
    /// Newton iterations used.
    pub newton_iterations: usize,
    /// Relative pivot of the scaled D at the solution (conditioning indicator).
    pub pivot_ratio: f64,
}

impl<const N: usize> MultibodySystem<N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    fn joint_of_row(&self, row: usize) -> (&NamedJoint, usize) {
        let mut found = &self.joints[0];
        for nj in &self.joints {
            if nj.row <= row {
                found = nj;
            }
        }
        (found, row - found.row)
    }

    fn singular_error(&self, s: &SMatrix<f64, N, N>, ratio: f64, t: f64) -> DynamicsError {
        let d = DMatrix::from_column_slice(N, N, s.as_slice());
        let (row, _) = most_dependent_row(&d);
        let (nj, eq) = self.joint_of_row(row);
        DynamicsError::SingularJacobian {
            t_s: t,
            joint: nj.name.clone(),
            row,
            equation: eq + 1,
            pivot_ratio: ratio,
            threshold: self.options.pivot_threshold,
        }
    }

    /// Factorise the *scaled* Jacobian `s`, refusing a singular one: partial
    /// pivoting first; when its relative pivot comes within
    /// [`RANK_CONFIRM`] of singular, complete pivoting (rank-revealing) decides
    /// and is used instead.
    fn factor(&self, s: &SMatrix<f64, N, N>, t: f64) -> Result<Factorization<N>> {
        let partial = Factorization::Partial(s.lu());
        if partial.pivot_ratio() >= RANK_CONFIRM.max(self.options.pivot_threshold) {
            return Ok(partial);
        }
        let full = Factorization::Full(s.full_piv_lu());
        let ratio = full.pivot_ratio();
        if ratio < self.options.pivot_threshold {
            return Err(self.singular_error(s, ratio, t));
        }
        Ok(full)
    }

    /// Rank diagnosis of D at a configuration: `Err(SingularJacobian)` naming
    /// the dependent joint, or the relative pivot.
    pub fn check_jacobian(&self, q: &SVector<f64, N>, t: f64) -> Result<f64> {
        if self.equations < N {
            // the padded zero rows would always count as dependent
            return self.check_active_rows(q, t);
        }
        let s = self.assemble_jacobian(&self.poses(q), t, true);
        let ratio = Factorization::Full(s.full_piv_lu()).pivot_ratio();
        if ratio < self.options.pivot_threshold {
            return Err(self.singular_error(&s, ratio, t));
        }
        Ok(ratio)
    }

    /// Newton–Raphson on Φ(c, t) = 0 from `guess`; returns the converged
    /// coordinates, their poses, the LU of D there (checked for rank at every
    /// iterate, see [`factor`](Self::factor)) and the iteration count.
    fn newton(
        &self,
        t: f64,
        guess: &SVector<f64, N>,
    ) -> Result<(SVector<f64, N>, Poses<N>, Factorization<N>, usize)> {
        if self.equations < N {
            return Err(DynamicsError::ConstraintCount {
                equations: self.equations,
                coordinates: N,
                detail: format!(
                    "; this system keeps {} degree(s) of freedom (built for forward dynamics)",
                    N - self.equations
                ),
            });
        }
        let tol = self.options.tolerance * self.length_scale;
        let mut q = *guess;
        let mut res = f64::INFINITY;
        let mut worst_row = 0usize;
        for it in 0..=self.options.max_iterations {
            let poses = self.poses(&q);
            let phi = self.eval_phi(&poses, t);
            res = 0.0;
            for r in 0..N {
                let v = (phi[r] * self.row_scale[r]).abs();
                if !v.is_finite() {
                    return Err(DynamicsError::NonFinite {
                        t_s: t,
                        what: "constraint residual",
                    });
                }
                if v > res {
                    res = v;
                    worst_row = r;
                }
            }
            if res > 1e6 * self.length_scale {
                break; // diverging: report below
            }
            let d = self.assemble_jacobian(&poses, t, true);
            let lu = self.factor(&d, t)?;
            if res <= tol {
                return Ok((q, poses, lu, it));
            }
            if it == self.options.max_iterations {
                break;
            }
            let step = lu.solve(&-phi.component_mul(&self.row_scale));
            q += step.component_mul(&self.col_scale);
        }
        let (nj, _) = self.joint_of_row(worst_row);
        Err(DynamicsError::NoConvergence {
            t_s: t,
            iterations: self.options.max_iterations,
            residual: res,
            tolerance: tol,
            joint: nj.name.clone(),
        })
    }

    /// Position, velocity and acceleration analysis plus Lagrange multipliers
    /// at time `t`, Newton started from `guess`.
    pub fn analyze(&self, t: f64, guess: &SVector<f64, N>) -> Result<KinematicSolution<N>> {
        if !t.is_finite() {
            return Err(DynamicsError::NonFinite {
                t_s: t,
                what: "time",
            });
        }
        let (q, poses, lu, iterations) = self.newton(t, guess)?;
        // velocity: D qd = nu
        let qd = lu
            .solve(&self.eval_nu(t).component_mul(&self.row_scale))
            .component_mul(&self.col_scale);
        let twists = self.twists(&qd);
        // acceleration: D qdd = gamma
        let gamma = self.eval_gamma(&poses, &twists, t);
        let qdd = lu
            .solve(&gamma.component_mul(&self.row_scale))
            .component_mul(&self.col_scale);
        // multipliers: D^T lambda = M qdd - h
        let rhs = self.mass.component_mul(&qdd) - self.eval_h(&poses);
        let lambda = lu
            .solve_transpose(&rhs.component_mul(&self.col_scale))
            .component_mul(&self.row_scale);
        for (v, what) in [
            (&qd, "velocities"),
            (&qdd, "accelerations"),
            (&lambda, "Lagrange multipliers"),
        ] {
            if !v.iter().all(|x| x.is_finite()) {
                return Err(DynamicsError::NonFinite { t_s: t, what });
            }
        }
        Ok(KinematicSolution {
            t,
            q,
            qd,
            qdd,
            lambda,
            newton_iterations: iterations,
            pivot_ratio: lu.pivot_ratio(),
        })
    }
}
