//! Forward dynamics of a multibody system that keeps degrees of freedom
//! (built with [`MultibodyBuilder::build_with_dof`](super::MultibodyBuilder::build_with_dof)):
//! accelerations and multipliers from the equations of motion, the
//! constraint violation, and projection onto the constraint manifold.
//!
//! With m constraint rows (rows 0..m of the padded N-vectors Φ, D, γ, λ; rows
//! m..N are identically zero):
//!
//! * **equations of motion** (thesis eq. 3.27 with eq. 3.36, in the form of
//!   eq. 3.38; Nikravesh 1988, §13): the index-1 form
//!
//!   [M  −Dᵀ; D  0] [c̈; λ] = [h; γ̃],   γ̃ = γ − 2α (D ċ − ν) − β² Φ,
//!
//!   where α = β = 0 is the plain index-1 form (D c̈ = γ only: Φ and D ċ − ν
//!   drift) and α, β > 0 is Baumgarte's stabilisation (J. Baumgarte, *Comput.
//!   Methods Appl. Mech. Eng.* 1 (1972) 1–16): the violation e = Φ obeys
//!   ë + 2α ė + β² e = 0. M may be singular (the piston's rotational inertia
//!   is 0), so the block system is solved as a whole (LU with partial
//!   pivoting), never through M⁻¹; it is regular when the m rows of D are
//!   independent and M is positive definite on the null space of D.
//!   The solve uses the scaled unknowns C⁻¹c̈ and R⁻¹λ (R, C as in the
//!   [`system`](super::system) docs): [C M C, −Sᵀ; S, 0] with S = R D C.
//! * **projection** onto the manifold Φ = 0, D ċ = ν (coordinate projection,
//!   Hairer, Lubich & Wanner, *Geometric Numerical Integration*, §IV.4; in
//!   multibody codes e.g. Eich 1993, Blajer 2002): the nearest point in the
//!   scaled coordinates ĉ = C⁻¹c, by Gauss–Newton
//!
//!   Δĉ = −Sᵀ (S Sᵀ)⁻¹ R Φ(c),  c ← c + C Δĉ   (until ‖R Φ‖∞ ≤ tol · L),
//!
//!   then the velocities, exactly (the velocity constraint is linear in ċ):
//!
//!   ċ ← ċ − C Sᵀ (S Sᵀ)⁻¹ R (D ċ − ν).
//!
//!   S Sᵀ is m×m; in the padded N×N form the zero rows get a unit diagonal
//!   so that one fixed-size Cholesky factorisation serves both. Its factor's
//!   diagonal is the Gram–Schmidt remainder of each row (in joint order): a
//!   remainder below [`SolverOptions::pivot_threshold`](super::SolverOptions)
//!   times the row's norm is reported as [`DynamicsError::SingularJacobian`]
//!   naming the dependent joint (toggle position, redundant constraint).

use nalgebra::{Const, DMatrix, DimMin, SMatrix, SVector};
use serde::{Deserialize, Serialize};

use super::error::{DynamicsError, Result};
use super::system::MultibodySystem;
use crate::linalg::most_dependent_row;

/// Baumgarte's stabilisation parameters (1/s): D c̈ = γ − 2α (D ċ − ν) − β² Φ.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Baumgarte {
    /// Velocity-level gain α (1/s).
    pub alpha: f64,
    /// Position-level gain β (1/s).
    pub beta: f64,
}

/// Accelerations and multipliers of the index-1 form at one state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForwardSolution<const N: usize> {
    /// c̈.
    pub qdd: SVector<f64, N>,
    /// λ (rows 0..m; the rows m..N are zero).
    pub lambda: SVector<f64, N>,
}

/// Largest constraint violation at one state, each row in its own unit
/// (m for point rows, rad for angle rows; m/s and rad/s for velocities).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ConstraintViolation {
    /// max_i |Φ_i(c, t)|.
    pub position: f64,
    /// max_i |(D ċ − ν)_i|.
    pub velocity: f64,
}

impl ConstraintViolation {
    /// Component-wise maximum of two violations.
    pub fn max(self, other: ConstraintViolation) -> ConstraintViolation {
        ConstraintViolation {
            position: self.position.max(other.position),
            velocity: self.velocity.max(other.velocity),
        }
    }
}

impl<const N: usize> MultibodySystem<N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    /// c̈ and λ from [M −Dᵀ; D 0][c̈; λ] = [h; γ̃] (module docs); `baumgarte`
    /// `None` is the plain index-1 form.
    pub fn forward_dynamics(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        t: f64,
        baumgarte: Option<Baumgarte>,
    ) -> Result<ForwardSolution<N>> {
        let m = self.equations;
        let poses = self.poses(q);
        let s = self.assemble_jacobian(&poses, t, true);
        let mut gamma = self.eval_gamma(&poses, &self.twists(qd), t);
        if let Some(b) = baumgarte {
            let phi = self.eval_phi(&poses, t);
            let d = self.assemble_jacobian(&poses, t, false);
            let vel = d * qd - self.eval_nu(t);
            gamma -= vel * (2.0 * b.alpha) + phi * (b.beta * b.beta);
        }
        let h = self.eval_h(&poses);
        let n = N + m;
        let mut a = DMatrix::<f64>::zeros(n, n);
        let mut rhs = nalgebra::DVector::<f64>::zeros(n);
        for i in 0..N {
            a[(i, i)] = self.mass[i] * self.col_scale[i] * self.col_scale[i];
            rhs[i] = h[i] * self.col_scale[i];
        }
        for r in 0..m {
            for c in 0..N {
                a[(N + r, c)] = s[(r, c)];
                a[(c, N + r)] = -s[(r, c)];
            }
            rhs[N + r] = gamma[r] * self.row_scale[r];
        }
        let lu = a.lu();
        let pivots = lu.lu_internal().diagonal().abs();
        let ratio = pivots.min() / pivots.max();
        if ratio.is_nan() || ratio < self.options().pivot_threshold {
            // near-singular: name the dependent joint if D confirms it
            self.check_active_rows(q, t)?;
        }
        let x = lu.solve(&rhs);
        let mut out = ForwardSolution {
            qdd: SVector::zeros(),
            lambda: SVector::zeros(),
        };
        let ok = x.as_ref().is_some_and(|x| x.iter().all(|v| v.is_finite()));
        let Some(x) = x.filter(|_| ok) else {
            self.check_active_rows(q, t)?;
            return Err(DynamicsError::NonFinite {
                t_s: t,
                what: "accelerations (singular matrix [M -D^T; D 0])",
            });
        };
        for i in 0..N {
            out.qdd[i] = x[i] * self.col_scale[i];
        }
        for r in 0..m {
            out.lambda[r] = x[N + r] * self.row_scale[r];
        }
        Ok(out)
    }

    /// max |Φ_i| and max |(D ċ − ν)_i| at a state.
    pub fn constraint_violation(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        t: f64,
    ) -> ConstraintViolation {
        let poses = self.poses(q);
        let phi = self.eval_phi(&poses, t);
        let d = self.assemble_jacobian(&poses, t, false);
        let vel = d * qd - self.eval_nu(t);
        ConstraintViolation {
            position: phi.amax(),
            velocity: vel.amax(),
        }
    }

    /// Cholesky factor of S Sᵀ (+ unit diagonal on the padded rows), with
    /// the rank check of the module docs.
    fn gram_factor(
        &self,
        s: &SMatrix<f64, N, N>,
        q: &SVector<f64, N>,
        t: f64,
    ) -> Result<nalgebra::Cholesky<f64, Const<N>>> {
        let m = self.equations;
        let mut g = s * s.transpose();
        for r in m..N {
            g[(r, r)] = 1.0;
        }
        let threshold = self.options().pivot_threshold;
        match g.cholesky() {
            Some(ch) => {
                let l = ch.l_dirty();
                let healthy = (0..m).all(|r| l[(r, r)] >= threshold * g[(r, r)].sqrt());
                if healthy {
                    return Ok(ch);
                }
                self.check_active_rows(q, t)?;
                Ok(ch)
            }
            None => {
                self.check_active_rows(q, t)?;
                Err(DynamicsError::NonFinite {
                    t_s: t,
                    what: "constraint Gram matrix D D^T",
                })
            }
        }
    }

    /// Rank diagnosis of the m active rows of the scaled D (Gram–Schmidt in
    /// joint order): `Err(SingularJacobian)` naming the dependent joint, or
    /// the smallest relative remainder.
    pub(super) fn check_active_rows(&self, q: &SVector<f64, N>, t: f64) -> Result<f64> {
        let m = self.equations;
        let s = self.assemble_jacobian(&self.poses(q), t, true);
        let rows = DMatrix::from_fn(m, N, |r, c| s[(r, c)]);
        let (row, ratio) = most_dependent_row(&rows);
        if ratio < self.options().pivot_threshold || !ratio.is_finite() {
            let nj = self
                .joints()
                .iter()
                .rev()
                .find(|j| j.row <= row)
                .unwrap_or(&self.joints()[0]);
            return Err(DynamicsError::SingularJacobian {
                t_s: t,
                joint: nj.name.clone(),
                row,
                equation: row - nj.row + 1,
                pivot_ratio: ratio,
                threshold: self.options().pivot_threshold,
            });
        }
        Ok(ratio)
    }

    /// Projects `q` onto Φ(c, t) = 0 (Gauss–Newton, minimum scaled
    /// correction; module docs) until ‖R Φ‖∞ ≤ `tol` · L, or until the
    /// residual stops decreasing below 1e-8 L (roundoff: e.g. a correction of
    /// a large angle below its ulp). Returns the iterations used;
    /// [`DynamicsError::NoConvergence`] after `max_iterations`.
    pub fn project_positions(
        &self,
        q: &mut SVector<f64, N>,
        t: f64,
        tol: f64,
        max_iterations: usize,
    ) -> Result<usize> {
        let m = self.equations;
        let l = self.length_scale;
        let mut last = f64::INFINITY;
        for it in 0..=max_iterations {
            let poses = self.poses(q);
            let phi = self.eval_phi(&poses, t).component_mul(&self.row_scale);
            let (worst, res) = (0..m).fold((0, 0.0f64), |(w, r), i| {
                if phi[i].abs() > r {
                    (i, phi[i].abs())
                } else {
                    (w, r)
                }
            });
            if !res.is_finite() {
                return Err(DynamicsError::NonFinite {
                    t_s: t,
                    what: "constraint residual (projection)",
                });
            }
            if res <= tol * l || (it > 0 && res >= 0.5 * last && res <= 1e-8 * l) {
                return Ok(it);
            }
            if it == max_iterations {
                let nj = self
                    .joints()
                    .iter()
                    .rev()
                    .find(|j| j.row <= worst)
                    .unwrap_or(&self.joints()[0]);
                return Err(DynamicsError::NoConvergence {
                    t_s: t,
                    iterations: max_iterations,
                    residual: res,
                    tolerance: tol * l,
                    joint: nj.name.clone(),
                });
            }
            last = res;
            let s = self.assemble_jacobian(&poses, t, true);
            let mu = self.gram_factor(&s, q, t)?.solve(&phi);
            *q -= (s.transpose() * mu).component_mul(&self.col_scale);
        }
        unreachable!("the loop returns")
    }

    /// Projects `qd` onto D ċ = ν (exact, one linear solve; module docs).
    pub fn project_velocities(
        &self,
        q: &SVector<f64, N>,
        qd: &mut SVector<f64, N>,
        t: f64,
    ) -> Result<()> {
        let poses = self.poses(q);
        let s = self.assemble_jacobian(&poses, t, true);
        let d = self.assemble_jacobian(&poses, t, false);
        let vel = (d * *qd - self.eval_nu(t)).component_mul(&self.row_scale);
        let mu = self.gram_factor(&s, q, t)?.solve(&vel);
        *qd -= (s.transpose() * mu).component_mul(&self.col_scale);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::linkage::{CrankSliderLinkage, test_rig};
    use super::super::system::AppliedLoad;
    use super::*;
    use nalgebra::Vector2;

    /// A free crank–slider (no driver) with offset centroids, a torque and gravity
    /// (the test rig of [`test_rig`]).
    fn free_crank_slider() -> MultibodySystem<9> {
        let mut b = test_rig(0.05, 0.16, 0.01, 0.06, 0.0).builder(["O", "A", "B", "slide"]);
        b.add_load(AppliedLoad::Torque {
            body: CrankSliderLinkage::CRANK,
            torque_nm: 2.0,
        })
        .gravity(Vector2::new(0.0, -9.81));
        b.build_with_dof::<9>().expect("valid model")
    }

    /// An assembled state at crank angle 0.7 with crank speed 5 rad/s (from the exact
    /// kinematics of the crank–slider).
    fn state() -> (SVector<f64, 9>, SVector<f64, 9>) {
        let (r, l, l1, e) = (0.05f64, 0.16f64, 0.06f64, 0.01f64);
        let (phi, w) = (0.7f64, 5.0f64);
        let psi = (r / l * phi.sin()).asin();
        let psid = r * phi.cos() * w / (l * psi.cos());
        let (a, ad) = (
            Vector2::new(r * phi.cos(), r * phi.sin()),
            Vector2::new(-r * phi.sin() * w, r * phi.cos() * w),
        );
        let u = Vector2::new(psi.cos(), -psi.sin());
        let ud = Vector2::new(-psi.sin() * psid, -psi.cos() * psid);
        let g = a + u * l1;
        let gd = ad + ud * l1;
        let b = a + u * l;
        let bd = ad + ud * l;
        let q = SVector::<f64, 9>::from_column_slice(&[
            e * phi.cos(),
            e * phi.sin(),
            phi,
            g.x,
            g.y,
            -psi,
            b.x,
            0.0,
            0.0,
        ]);
        let qd = SVector::<f64, 9>::from_column_slice(&[
            -e * phi.sin() * w,
            e * phi.cos() * w,
            w,
            gd.x,
            gd.y,
            -psid,
            bd.x,
            0.0,
            0.0,
        ]);
        (q, qd)
    }

    #[test]
    fn eight_equations_and_kinematic_analysis_refused() {
        let sys = free_crank_slider();
        assert_eq!((sys.equations(), sys.dof()), (8, 1));
        let (q, qd) = state();
        let v = sys.constraint_violation(&q, &qd, 0.0);
        assert!(v.position < 1e-15 && v.velocity < 1e-14, "{v:?}");
        assert!(matches!(
            sys.analyze(0.0, &q),
            Err(DynamicsError::ConstraintCount {
                equations: 8,
                coordinates: 9,
                ..
            })
        ));
        assert!(sys.check_jacobian(&q, 0.0).unwrap() > 1e-3);
    }

    #[test]
    fn forward_dynamics_satisfies_the_block_system_and_power_balance() {
        let sys = free_crank_slider();
        let (q, qd) = state();
        let f = sys.forward_dynamics(&q, &qd, 0.0, None).unwrap();
        let d = sys.jacobian(&q, 0.0);
        let h = sys.applied_forces(&q);
        let res = sys.mass_diagonal().component_mul(&f.qdd) - h - d.transpose() * f.lambda;
        assert!(res.amax() < 1e-11, "{res}");
        assert!((d * f.qdd - sys.gamma(&q, &qd, 0.0)).amax() < 1e-12);
        assert_eq!(f.lambda[8], 0.0);
        // constraint forces do no work: d/dt (T + V) = torque · φ̇
        let power = sys.mass_diagonal().component_mul(&f.qdd).dot(&qd)
            + 9.81 * (8.0 * qd[1] + 3.0 * qd[4] + 5.0 * qd[7]);
        assert!((power - 2.0 * qd[2]).abs() < 1e-11, "{power}");
        // with a consistent state Baumgarte changes nothing
        let b = Baumgarte {
            alpha: 10.0,
            beta: 10.0,
        };
        let fb = sys.forward_dynamics(&q, &qd, 0.0, Some(b)).unwrap();
        assert!((fb.qdd - f.qdd).amax() < 1e-10);
    }

    #[test]
    fn projection_returns_to_the_manifold_and_keeps_consistent_states() {
        let sys = free_crank_slider();
        let (q0, qd0) = state();
        let (mut q, mut qd) = (q0, qd0);
        sys.project_positions(&mut q, 0.0, 1e-14, 10).unwrap();
        sys.project_velocities(&q, &mut qd, 0.0).unwrap();
        assert!((q - q0).amax() < 1e-15 && (qd - qd0).amax() < 1e-13);
        // perturb and project: back on both manifolds, close to where it started
        let mut dq = SVector::<f64, 9>::zeros();
        for i in 0..9 {
            dq[i] = 1e-5 * ((i as f64) * 1.7).sin();
        }
        q = q0 + dq;
        qd = qd0 + dq * 100.0;
        let it = sys.project_positions(&mut q, 0.0, 1e-14, 10).unwrap();
        sys.project_velocities(&q, &mut qd, 0.0).unwrap();
        let v = sys.constraint_violation(&q, &qd, 0.0);
        assert!(
            it <= 4 && v.position < 1e-15 && v.velocity < 1e-13,
            "{it} {v:?}"
        );
        // the nearest point in the scaled metric (angles times L): within 2 |Δc| there
        let l = sys.length_scale();
        let weights = SVector::<f64, 9>::from_fn(|i, _| if i % 3 == 2 { l } else { 1.0 });
        let scaled = (q - q0).component_mul(&weights);
        assert!(
            scaled.norm() < 2.0 * dq.component_mul(&weights).norm(),
            "{}",
            scaled.norm()
        );
    }

    #[test]
    fn singular_configuration_is_named() {
        // l = r: at φ = 90° the rod stands vertical over B = O (toggle)
        let (r, l1) = (0.05, 0.02);
        let b = test_rig(r, r, 0.0, l1, 0.0).builder(["O", "A", "B", "slide"]);
        let sys = b.build_with_dof::<9>().unwrap();
        let half_pi = std::f64::consts::FRAC_PI_2;
        let q = SVector::<f64, 9>::from_column_slice(&[
            0.0,
            0.0,
            half_pi,
            0.0,
            r - l1,
            -half_pi,
            0.0,
            0.0,
            0.0,
        ]);
        let e = sys
            .forward_dynamics(&q, &SVector::zeros(), 0.3, None)
            .unwrap_err();
        assert!(
            matches!(e, DynamicsError::SingularJacobian { t_s, .. } if t_s == 0.3),
            "{e}"
        );
        let mut qp = q;
        assert!(matches!(
            sys.project_positions(&mut qp, 0.3, 1e-14, 5),
            Ok(0) | Err(DynamicsError::SingularJacobian { .. })
        ));
    }
}
