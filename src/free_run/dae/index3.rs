//! The index-3 form `M c̈ = h + Dᵀλ`, `Φ(c) = 0` (thesis eq. 3.27, 3.25) with generalized-α
//! ([`crate::integrators::genalpha`], Arnold & Brüls 2007; its docs state the scheme, the
//! scaled Newton iteration and the counters).

use super::super::{FreeRunError, FreeRunOptions};
use super::DaeRun;
use super::model::{CRANK_PHI, MultibodyCrank};
use crate::integrators::OutputGrid;
use crate::integrators::genalpha::{self, ConstrainedSystem, GenAlphaOptions};
use crate::mechanism::MultibodySystem;
use nalgebra::{DMatrix, DVector, SVector};
use std::time::Instant;

/// The free multibody system through the [`ConstrainedSystem`] interface: `M` diagonal and
/// constant, `h` constant loads and gravity (independent of `ċ`), the `m = 8` active rows of
/// `Φ`, `D` and `γ`.
pub struct Index3Dae<'a> {
    /// The free multibody system.
    pub system: &'a MultibodySystem<9>,
}

fn coords(q: &DVector<f64>) -> SVector<f64, 9> {
    SVector::<f64, 9>::from_column_slice(q.as_slice())
}

impl ConstrainedSystem for Index3Dae<'_> {
    fn dim(&self) -> usize {
        9
    }

    fn n_constraints(&self) -> usize {
        self.system.equations()
    }

    fn mass(&self, _q: &DVector<f64>, m: &mut DMatrix<f64>) {
        m.set_partial_diagonal(self.system.mass_diagonal().iter().copied());
    }

    fn forces(&self, _t: f64, q: &DVector<f64>, _v: &DVector<f64>, h: &mut DVector<f64>) {
        h.copy_from(&self.system.applied_forces(&coords(q)));
    }

    fn constraints(&self, t: f64, q: &DVector<f64>, phi: &mut DVector<f64>) {
        let all = self.system.constraints(&coords(q), t);
        phi.copy_from(&all.rows(0, phi.len()));
    }

    fn constraint_jacobian(&self, t: f64, q: &DVector<f64>, d: &mut DMatrix<f64>) {
        let all = self.system.jacobian(&coords(q), t);
        d.copy_from(&all.rows(0, d.nrows()));
    }

    fn gamma(&self, t: f64, q: &DVector<f64>, v: &DVector<f64>, g: &mut DVector<f64>) {
        let all = self.system.gamma(&coords(q), &coords(v), t);
        g.copy_from(&all.rows(0, g.len()));
    }

    fn forces_depend_on_velocity(&self) -> bool {
        false
    }
}

/// The generalized-α settings of a run: step `options.fixed_step`, the DAE options' `ρ∞` and
/// Newton settings, the run's caps (`max_rhs_evals` caps residual evaluations).
pub fn genalpha_options(o: &FreeRunOptions) -> GenAlphaOptions {
    GenAlphaOptions {
        h: o.fixed_step,
        rho_inf: o.dae.rho_inf,
        newton_tol: o.dae.newton_tol,
        max_newton_iters: o.dae.max_newton_iters,
        max_steps: o.max_steps,
        max_evals: o.max_rhs_evals,
    }
}

/// Integrates the index-3 form of `mb` over `grid`.
pub(crate) fn run(
    mb: &MultibodyCrank,
    options: &FreeRunOptions,
    grid: &OutputGrid,
) -> Result<DaeRun, FreeRunError> {
    let dae = Index3Dae { system: &mb.system };
    let q0 = DVector::from_column_slice(mb.q0.as_slice());
    let v0 = DVector::from_column_slice(mb.qd0.as_slice());
    let start = Instant::now();
    let sol = genalpha::solve(&dae, &q0, &v0, grid, &genalpha_options(options))?;
    let cpu_s = start.elapsed().as_secs_f64();
    Ok(DaeRun {
        drift: mb.drift(&sol.t, &sol.y),
        phi: sol.component(CRANK_PHI),
        omega: sol.component(9 + CRANK_PHI),
        t: sol.t,
        stats: sol.stats,
        cpu_s,
        model: "multibody DAE (thesis §3.2: 9 body coordinates, 8 constraints), index-3 form, \
                generalized-α",
    })
}
