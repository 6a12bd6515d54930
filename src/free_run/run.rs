//! One run of one method on a free scene.

use super::FreeRunError;
use super::dae::{self, ConstraintViolation, DaeOptions};
use super::energy_projection::EnergyProjection;
use super::method::Method;
use super::ode::CrankOde;
use super::reference::ExactReference;
use super::scene::FreeScene;
use crate::integrators::{JacobianSource, SolverOptions, TOL_FLOOR_KAPPA, rk45, solve};
use nalgebra::DVector;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Settings of a free run.
///
/// Tolerance policy: the error norm uses `atol + rtol·|y_i|` per component (φ in rad, φ̇ in
/// rad/s). The default and the work–precision sweep use purely absolute control
/// (`rtol = 0`): φ grows without bound, and a relative tolerance on φ would loosen the error
/// control as it grows. For long runs, where φ̇ reaches thousands of rad/s, the φ̇ component
/// can be given its own tolerances (`omega_rtol`, `omega_atol`), e.g. relative on φ̇ while φ
/// stays absolute.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FreeRunOptions {
    /// The scene.
    pub scene: FreeScene,
    /// Relative tolerance (adaptive methods).
    pub rtol: f64,
    /// Absolute tolerance (adaptive methods) [rad, rad/s].
    pub atol: f64,
    /// Relative tolerance of the φ̇ component, if different from `rtol`.
    pub omega_rtol: Option<f64>,
    /// Absolute tolerance of the φ̇ component [rad/s], if different from `atol`.
    pub omega_atol: Option<f64>,
    /// Step of the fixed-step methods (initial-acceleration, dae-genalpha) \[s\].
    pub fixed_step: f64,
    /// Cap on steps.
    pub max_steps: u64,
    /// Cap on right-hand-side evaluations.
    pub max_rhs_evals: u64,
    /// Jacobian source of the implicit methods.
    pub jacobian: JacobianSource,
    /// Settings of the multibody DAE forms (stabilisation, ρ∞, Newton).
    #[serde(default)]
    pub dae: DaeOptions,
    /// RK45 on the reduced model only: after every step φ̇ is put back onto the energy
    /// integral at the step's φ ([`EnergyProjection`]; conservative loads).
    #[serde(default)]
    pub project_energy: bool,
}

impl Default for FreeRunOptions {
    fn default() -> Self {
        Self {
            scene: FreeScene::thesis(),
            rtol: 0.0,
            atol: 1e-8,
            omega_rtol: None,
            omega_atol: None,
            fixed_step: 1e-5,
            max_steps: 1_000_000,
            max_rhs_evals: 10_000_000,
            jacobian: JacobianSource::Auto,
            dae: DaeOptions::default(),
            project_energy: false,
        }
    }
}

/// Default cap on steps per second of simulated time (the thesis' 1 s scene: a million).
pub const STEPS_PER_SIMULATED_SECOND: u64 = 1_000_000;
/// Default cap on right-hand-side evaluations per second of simulated time.
pub const EVALS_PER_SIMULATED_SECOND: u64 = 10_000_000;

impl FreeRunOptions {
    /// The default caps scaled with the scene's duration: [`STEPS_PER_SIMULATED_SECOND`] and
    /// [`EVALS_PER_SIMULATED_SECOND`] per second (at least one second's worth). A 100 s run at
    /// tolerance 1e-12 (9.1 million RK45 steps at rtol = atol = 1e-12, 41 million at rtol 0)
    /// then finishes, while a method that crawls (the
    /// stiff gas spring under an explicit method, a million steps in its first second) is still
    /// stopped with the step-limit error.
    pub fn with_caps_for_duration(mut self) -> Self {
        let seconds = self.scene.t_end.max(1.0);
        self.max_steps = (STEPS_PER_SIMULATED_SECOND as f64 * seconds).ceil() as u64;
        self.max_rhs_evals = (EVALS_PER_SIMULATED_SECOND as f64 * seconds).ceil() as u64;
        self
    }

    /// The generic solver settings these options imply for `method`.
    pub fn solver_options(&self, method: Method) -> SolverOptions {
        let split = self.omega_rtol.is_some() || self.omega_atol.is_some();
        SolverOptions {
            rtol: self.rtol,
            atol: self.atol,
            rtol_components: split.then(|| vec![self.rtol, self.omega_rtol.unwrap_or(self.rtol)]),
            atol_components: split.then(|| vec![self.atol, self.omega_atol.unwrap_or(self.atol)]),
            h: method.is_fixed_step().then_some(self.fixed_step),
            h_max: None,
            max_steps: self.max_steps,
            max_rhs_evals: self.max_rhs_evals,
            jacobian: self.jacobian,
        }
    }
}

/// Result of a free run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FreeRunResult {
    /// Method.
    pub method: Method,
    /// Model used (the cheapest that answers the scene exactly).
    pub model: &'static str,
    /// Projections onto the energy integral made (`project_energy`; else 0).
    pub energy_projections: u64,
    /// The largest change of φ̇ one of them made [rad/s].
    pub energy_projection_max_change_rad_s: f64,
    /// Crank angle at `t_end` \[rad\].
    pub phi_rad: f64,
    /// Crank angular velocity at `t_end` [rad/s].
    pub omega_rad_s: f64,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected step attempts.
    pub rejected_steps: u64,
    /// Right-hand-side evaluations (including finite-difference Jacobians).
    pub rhs_evals: u64,
    /// Jacobian evaluations.
    pub jac_evals: u64,
    /// LU decompositions.
    pub lu_decompositions: u64,
    /// Elapsed time of the integration alone (single thread, monotonic clock) \[s\].
    pub cpu_s: f64,
    /// `max_t |E(t) − E(t0)|` of the energy invariant on the output grid \[J\]; `None` when the
    /// loads are not conservative.
    pub energy_drift_max_j: Option<f64>,
    /// The drift relative to the largest kinetic energy `½ I_red φ̇²` on the grid.
    pub energy_drift_rel: Option<f64>,
    /// DAE forms: the largest constraint violation `max |Φ_i|`, `max |(D ċ)_i|` over the
    /// output grid (rows in m, the slide's angle row in rad); `None` for the reduced model.
    pub constraint_drift_max: Option<ConstraintViolation>,
    /// Flags raised on an otherwise completed run (e.g. a fixed-step result whose energy
    /// drift exceeds [`ENERGY_WARN_REL`] of the kinetic energy: not trustworthy).
    pub warnings: Vec<String>,
    /// Output times \[s\].
    pub t: Vec<f64>,
    /// Crank angle on the grid \[rad\].
    pub phi: Vec<f64>,
    /// Crank angular velocity on the grid [rad/s].
    pub omega: Vec<f64>,
}

/// Relative energy drift above which a completed run gets a warning.
pub const ENERGY_WARN_REL: f64 = 1e-3;

/// Energy drift [J] below which no warning is given whatever its ratio to the kinetic energy
/// (a run of a picosecond from rest has 1e-23 J of both).
pub const ENERGY_WARN_FLOOR_J: f64 = 1e-9;

/// A run whose error against the exact reference exceeds this multiple of its tolerance gets
/// a warning ([`FreeRunResult::check_against_reference`]).
pub const REFERENCE_WARN_FACTOR: f64 = 10.0;

/// Constraint drift (m or rad, m/s or rad/s) above which a DAE run gets a warning.
pub const CONSTRAINT_WARN: f64 = 1e-6;

/// The warning of a run on which the tolerance floor was in force (see
/// [`TOL_FLOOR_KAPPA`]): which floor, on how many steps, and its size at the end of the run.
fn floor_warning(
    method: Method,
    stats: &crate::integrators::Stats,
    phi: &[f64],
    omega: &[f64],
) -> String {
    let max_abs = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let floor = |m: f64| TOL_FLOOR_KAPPA * f64::EPSILON * m;
    let phi_note = if method.ode_method().is_some() {
        // the reduced model's φ is held as whole turns + a remainder in [0, 2π)
        format!(
            "φ is held as whole turns + a remainder in [0, 2π): floor {:.1e} rad",
            floor(std::f64::consts::TAU)
        )
    } else {
        format!(
            "at |φ| = {:.3e} rad: floor {:.1e} rad",
            max_abs(phi),
            floor(max_abs(phi))
        )
    };
    format!(
        "tolerance below the f64 resolution of the state on {} of {} steps: \
         atol + rtol·|y_i| < κ·ε·|y_i| (κ = {TOL_FLOOR_KAPPA}, ε = {:.1e}) was raised to that \
         floor ({phi_note}; at |φ̇| = {:.3e} rad/s: floor {:.1e} rad/s); a tighter tolerance \
         buys nothing there",
        stats.floored_steps,
        stats.steps,
        f64::EPSILON,
        max_abs(omega),
        floor(max_abs(omega)),
    )
}

impl FreeRunResult {
    /// `max |φ − φ_ref|`, `max |φ̇ − φ̇_ref|` over the output grid against the exact
    /// reference of the scene; a run of an adaptive method whose φ error exceeds
    /// [`REFERENCE_WARN_FACTOR`] × its tolerance on φ (`atol + rtol·max|φ|`) gets a warning:
    /// the tolerance bounds the local error of a step, and over a long run the global error
    /// can grow far beyond it. (φ only: φ̇ ≈ 40–4000 rad/s here, and its error, φ's error
    /// times dφ̇/dφ, is 15–60× the same tolerance even where φ meets it.)
    pub fn check_against_reference(
        &mut self,
        reference: &ExactReference,
        options: &FreeRunOptions,
    ) -> (f64, f64) {
        let (ep, ew) = reference.max_errors(&self.phi, &self.omega);
        if self.method.is_fixed_step() {
            return (ep, ew);
        }
        let max_phi = self.phi.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let tol_phi = options.atol + options.rtol * max_phi;
        let f = REFERENCE_WARN_FACTOR;
        if ep > f * tol_phi || ep.is_nan() {
            self.warnings.push(format!(
                "error against the exact reference max |Δφ| = {ep:.2e} rad is {:.1e}× the \
                 tolerance on φ ({tol_phi:.1e} rad), more than {f}× (max |Δφ̇| = {ew:.2e} \
                 rad/s; the tolerance bounds each step's local error, not the global error \
                 over the run)",
                ep / tol_phi,
            ));
        }
        (ep, ew)
    }
}

/// Runs `method` on `options.scene`: builds and checks the model (refusing `l ≤ r` and
/// `I_red ≤ 0` before integrating), integrates the reduced equation of motion (eq. 3.24 / 4.1)
/// or, for [`Method::DAE`], the multibody DAE ([`dae`]), and evaluates the energy drift (with
/// the reduced model's energy of the crank's φ, φ̇, for every method) and, for the DAE forms,
/// the constraint drift. Warnings: energy drift, constraint drift, and the tolerance floor
/// (a tolerance below the f64 resolution of the state, raised at every step it binds). The
/// comparison with the exact reference is [`FreeRunResult::check_against_reference`] (the
/// reference is built once per scene by the caller).
pub fn run_free(method: Method, options: &FreeRunOptions) -> Result<FreeRunResult, FreeRunError> {
    let scene = &options.scene;
    let model = scene.model()?;
    let grid = scene.grid()?;
    if options.project_energy && method != Method::Rk45 {
        return Err(FreeRunError::Options(format!(
            "the energy projection runs with rk45 only, not with {method}: use --method rk45 \
             with --project-energy, or drop --project-energy"
        )));
    }
    let mut projection = if options.project_energy {
        let p = EnergyProjection::new(&model, &scene.loads, scene.phi0, scene.omega0).ok_or_else(
            || {
                FreeRunError::Options(
                    "the energy projection needs conservative loads (no damping): there is no \
                     energy integral to project on; drop --project-energy for a damped scene"
                        .into(),
                )
            },
        )?;
        Some(p)
    } else {
        None
    };
    let run = match method.ode_method() {
        Some(ode_method) => {
            let sys = CrankOde {
                model: &model,
                loads: scene.loads,
            };
            let y0 = DVector::from_vec(vec![scene.phi0, scene.omega0]);
            let opts = options.solver_options(method);
            let start = Instant::now();
            let sol = match projection.as_mut() {
                Some(p) => rk45::solve_projected(&sys, &y0, &grid, &opts, p)?,
                None => solve(ode_method, &sys, &y0, &grid, &opts)?,
            };
            let cpu_s = start.elapsed().as_secs_f64();
            dae::DaeRun {
                phi: sol.component(0),
                omega: sol.component(1),
                t: sol.t,
                stats: sol.stats,
                cpu_s,
                drift: ConstraintViolation::default(),
                model: "reduced (thesis eq. 3.24, two-mass rod)",
            }
        }
        None => dae::run(method, options, &grid)?,
    };
    let constraint_drift_max = method.is_dae().then_some(run.drift);
    let (phi, omega) = (run.phi, run.omega);
    let (energy_drift_max_j, energy_drift_rel) = if scene.loads.is_conservative() {
        let e0 = model.energy(&scene.loads, phi[0], omega[0]);
        let (mut drift, mut ke_max) = (0.0f64, 0.0f64);
        for (&p, &w) in phi.iter().zip(&omega) {
            drift = drift.max((model.energy(&scene.loads, p, w) - e0).abs());
            ke_max = ke_max.max(0.5 * model.i_red(p) * w * w);
        }
        (Some(drift), (ke_max > 0.0).then(|| drift / ke_max))
    } else {
        (None, None)
    };
    let mut warnings = Vec::new();
    if energy_drift_max_j.is_some_and(|d| !d.is_finite())
        || !phi.iter().chain(&omega).all(|v| v.is_finite())
    {
        warnings.push(format!(
            "the solution is not finite (it blew up){}",
            if method.is_fixed_step() {
                ": the fixed step is too large"
            } else {
                ": the tolerance is too loose (--atol, --rtol)"
            }
        ));
    } else if let Some(rel) = energy_drift_rel
        && rel > ENERGY_WARN_REL
        && energy_drift_max_j.is_some_and(|d| d > ENERGY_WARN_FLOOR_J)
    {
        warnings.push(format!(
            "energy drift {:.3e} J is {:.1e} of the kinetic energy (> {ENERGY_WARN_REL:e}): the result is not accurate{}",
            energy_drift_max_j.unwrap_or(f64::NAN),
            rel,
            if method.is_fixed_step() { " (fixed step too large)" } else { " (tolerance too loose)" }
        ));
    }
    if run.stats.floored_steps > 0 {
        warnings.push(floor_warning(method, &run.stats, &phi, &omega));
    }
    if let Some(d) = constraint_drift_max
        && (d.position > CONSTRAINT_WARN || d.velocity > CONSTRAINT_WARN)
    {
        warnings.push(format!(
            "constraint drift max |Φ| = {:.3e}, max |D ċ| = {:.3e} (> {CONSTRAINT_WARN:e}): the \
             mechanism has come apart by that much",
            d.position, d.velocity
        ));
    }
    Ok(FreeRunResult {
        method,
        model: run.model,
        energy_projections: projection.as_ref().map_or(0, |p| p.projections),
        energy_projection_max_change_rad_s: projection.as_ref().map_or(0.0, |p| p.max_change_rad_s),
        phi_rad: *phi.last().unwrap_or(&f64::NAN),
        omega_rad_s: *omega.last().unwrap_or(&f64::NAN),
        steps: run.stats.steps,
        rejected_steps: run.stats.rejected_steps,
        rhs_evals: run.stats.rhs_evals,
        jac_evals: run.stats.jac_evals,
        lu_decompositions: run.stats.lu_decompositions,
        cpu_s: run.cpu_s,
        energy_drift_max_j,
        energy_drift_rel,
        constraint_drift_max,
        warnings,
        t: run.t,
        phi,
        omega,
    })
}
