//! The index-1 form with RK45: `y = [c; ċ]`, `y' = [ċ; c̈(c, ċ)]`, `c̈` from
//! `[M −Dᵀ; D 0][c̈; λ] = [h; γ̃]` at every evaluation (thesis eq. 3.38; [`Stabilization`]
//! chooses `γ̃`: `γ`, or Baumgarte's `γ − 2α D ċ − β² Φ`), integrated by
//! [`rk45::solve`], or with projection after every step by [`rk45::solve_projected`] (its
//! docs say how the dense output stays on the manifold).

use super::super::{FreeRunError, FreeRunOptions};
use super::model::{CRANK_PHI, MultibodyCrank};
use super::{Baumgarte, DaeOptions, DaeRun, Stabilization};
use crate::integrators::{FailureKind, OdeSystem, OutputGrid, SolverOptions, StepProjection, rk45};
use crate::mechanism::{DynamicsError, MultibodySystem};
use nalgebra::{DVector, SVector};
use std::cell::{Cell, RefCell};
use std::time::Instant;

/// The index-1 form as a first-order ODE of dimension 18.
pub struct Index1Ode<'a> {
    /// The free multibody system.
    pub system: &'a MultibodySystem<9>,
    /// Baumgarte's feedback, if any.
    pub baumgarte: Option<Baumgarte>,
    /// The first failure of the forward dynamics (the right-hand side then returns NaN,
    /// which makes the solver reject the step; if the solver gives up, this is the cause).
    pub failure: RefCell<Option<DynamicsError>>,
    /// LU factorisations of the block system made (one per evaluation of the right-hand side).
    pub lu_decompositions: Cell<u64>,
}

fn split(y: &DVector<f64>) -> (SVector<f64, 9>, SVector<f64, 9>) {
    (
        SVector::<f64, 9>::from_column_slice(&y.as_slice()[..9]),
        SVector::<f64, 9>::from_column_slice(&y.as_slice()[9..]),
    )
}

impl OdeSystem for Index1Ode<'_> {
    fn dim(&self) -> usize {
        18
    }

    fn rhs(&self, t: f64, y: &DVector<f64>, dydt: &mut DVector<f64>) {
        let (q, qd) = split(y);
        self.lu_decompositions.set(self.lu_decompositions.get() + 1);
        match self.system.forward_dynamics(&q, &qd, t, self.baumgarte) {
            Ok(f) => {
                dydt.rows_mut(0, 9).copy_from(&qd);
                dydt.rows_mut(9, 9).copy_from(&f.qdd);
            }
            Err(e) => {
                self.failure.borrow_mut().get_or_insert(e);
                dydt.fill(f64::NAN);
            }
        }
    }

    fn is_autonomous(&self) -> bool {
        true
    }
}

/// Projection of `[c; ċ]` onto `Φ = 0`, then `D ċ = 0` (see [`crate::mechanism::forward`]).
pub struct Projector<'a> {
    /// The free multibody system.
    pub system: &'a MultibodySystem<9>,
    /// Tolerance `‖R Φ‖∞ ≤ tol · L`.
    pub tol: f64,
    /// Newton iterations per projection.
    pub max_iterations: usize,
    /// Projections done.
    pub count: u64,
}

impl StepProjection for Projector<'_> {
    fn project(&mut self, t: f64, y: &mut DVector<f64>) -> Result<(), String> {
        self.count += 1;
        let (mut q, mut qd) = split(y);
        self.system
            .project_positions(&mut q, t, self.tol, self.max_iterations)
            .map_err(|e| e.to_string())?;
        self.system
            .project_velocities(&q, &mut qd, t)
            .map_err(|e| e.to_string())?;
        y.rows_mut(0, 9).copy_from(&q);
        y.rows_mut(9, 9).copy_from(&qd);
        Ok(())
    }
}

/// RK45 settings for the 18 states: the run's `rtol`/`atol` on the 9 coordinates (m, rad), its
/// φ̇ tolerances (if split) on the 9 velocities (m/s, rad/s).
pub fn solver_options(o: &FreeRunOptions) -> SolverOptions {
    let split = o.omega_rtol.is_some() || o.omega_atol.is_some();
    let both = |a: f64, b: f64| [vec![a; 9], vec![b; 9]].concat();
    SolverOptions {
        rtol: o.rtol,
        atol: o.atol,
        rtol_components: split.then(|| both(o.rtol, o.omega_rtol.unwrap_or(o.rtol))),
        atol_components: split.then(|| both(o.atol, o.omega_atol.unwrap_or(o.atol))),
        h: None,
        h_max: None,
        max_steps: o.max_steps,
        max_rhs_evals: o.max_rhs_evals,
        jacobian: o.jacobian,
    }
}

/// Integrates the index-1 form of `mb` over `grid`.
pub(crate) fn run(
    mb: &MultibodyCrank,
    options: &FreeRunOptions,
    grid: &OutputGrid,
) -> Result<DaeRun, FreeRunError> {
    let dae: &DaeOptions = &options.dae;
    let (baumgarte, model) = match dae.stabilization {
        Stabilization::Projection => (
            None,
            "multibody DAE (thesis §3.2: 9 body coordinates, 8 constraints), index-1 form, \
             RK45 + projection onto Φ = 0, D ċ = 0",
        ),
        Stabilization::Baumgarte { alpha, beta } => {
            if !(alpha >= 0.0 && beta >= 0.0 && alpha.is_finite() && beta.is_finite()) {
                return Err(FreeRunError::Options(format!(
                    "Baumgarte α = {alpha}, β = {beta} must be finite and ≥ 0"
                )));
            }
            (
                Some(Baumgarte { alpha, beta }),
                "multibody DAE (thesis §3.2: 9 body coordinates, 8 constraints), index-1 form \
                 with Baumgarte stabilisation, RK45",
            )
        }
        Stabilization::Off => (
            None,
            "multibody DAE (thesis §3.2: 9 body coordinates, 8 constraints), index-1 form \
             without stabilisation, RK45",
        ),
    };
    let ode = Index1Ode {
        system: &mb.system,
        baumgarte,
        failure: RefCell::new(None),
        lu_decompositions: Cell::new(0),
    };
    let mut y0 = DVector::zeros(18);
    y0.rows_mut(0, 9).copy_from(&mb.q0);
    y0.rows_mut(9, 9).copy_from(&mb.qd0);
    let opts = solver_options(options);
    let start = Instant::now();
    let sol = if dae.stabilization == Stabilization::Projection {
        let mut p = Projector {
            system: &mb.system,
            tol: dae.projection_tol,
            max_iterations: dae.projection_max_iters,
            count: 0,
        };
        rk45::solve_projected(&ode, &y0, grid, &opts, &mut p)
    } else {
        rk45::solve(&ode, &y0, grid, &opts)
    };
    let cpu_s = start.elapsed().as_secs_f64();
    let sol = match sol {
        Ok(mut s) => {
            s.stats.lu_decompositions += ode.lu_decompositions.get();
            s
        }
        Err(e) => {
            // a step-size collapse caused by failing forward dynamics: report the cause
            let gave_up = matches!(
                e.kind,
                FailureKind::StepSizeUnderflow { .. } | FailureKind::NonFinite
            );
            return Err(match ode.failure.into_inner() {
                Some(d) if gave_up => FreeRunError::Multibody(d),
                _ => FreeRunError::Solver(e),
            });
        }
    };
    Ok(DaeRun {
        drift: mb.drift(&sol.t, &sol.y),
        phi: sol.component(CRANK_PHI),
        omega: sol.component(9 + CRANK_PHI),
        t: sol.t,
        stats: sol.stats,
        cpu_s,
        model,
    })
}
