//! Running every method on one scene and collecting outcomes, failures included (for the
//! hard-case tables: long run, stiff spring, near toggle).

use super::FreeRunError;
use super::dae::ConstraintViolation;
use super::method::Method;
use super::run::{FreeRunOptions, run_free};
use serde::Serialize;

/// What one method did on a scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CaseOutcome {
    /// Method.
    pub method: Method,
    /// `true` if the run reached `t_end`.
    pub completed: bool,
    /// Why it stopped, if it did (step/evaluation cap, blow-up, refused data).
    pub failure: Option<String>,
    /// Time reached \[s\].
    pub t_reached: f64,
    /// Crank angle at the end \[rad\] (completed runs).
    pub phi_end_rad: Option<f64>,
    /// Angular velocity at the end [rad/s] (completed runs).
    pub omega_end_rad_s: Option<f64>,
    /// Accepted steps.
    pub steps: u64,
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Jacobian evaluations.
    pub jac_evals: u64,
    /// Elapsed time of the integration \[s\] (completed runs).
    pub cpu_s: Option<f64>,
    /// Energy drift \[J\] (completed runs with conservative loads).
    pub energy_drift_max_j: Option<f64>,
    /// Energy drift relative to the largest kinetic energy.
    pub energy_drift_rel: Option<f64>,
    /// DAE forms: largest constraint violation on the grid (completed runs).
    pub constraint_drift_max: Option<ConstraintViolation>,
    /// Warnings of the completed run.
    pub warnings: Vec<String>,
}

/// Runs each of `methods` with `options`; solver failures and scenes a method's model does
/// not cover ([`FreeRunError::SceneNotSupported`]) become outcomes, other errors (refused
/// data, bad options) are returned.
pub fn run_all(
    methods: &[Method],
    options: &FreeRunOptions,
) -> Result<Vec<CaseOutcome>, FreeRunError> {
    let mut out = Vec::with_capacity(methods.len());
    for &method in methods {
        out.push(match run_free(method, options) {
            Ok(r) => CaseOutcome {
                method,
                completed: true,
                failure: None,
                t_reached: *r.t.last().unwrap_or(&f64::NAN),
                phi_end_rad: Some(r.phi_rad),
                omega_end_rad_s: Some(r.omega_rad_s),
                steps: r.steps,
                rhs_evals: r.rhs_evals,
                jac_evals: r.jac_evals,
                cpu_s: Some(r.cpu_s),
                energy_drift_max_j: r.energy_drift_max_j,
                energy_drift_rel: r.energy_drift_rel,
                constraint_drift_max: r.constraint_drift_max,
                warnings: r.warnings,
            },
            Err(FreeRunError::Solver(e)) => CaseOutcome {
                method,
                completed: false,
                failure: Some(e.to_string()),
                t_reached: e.t,
                phi_end_rad: None,
                omega_end_rad_s: None,
                steps: e.stats.steps,
                rhs_evals: e.stats.rhs_evals,
                jac_evals: e.stats.jac_evals,
                cpu_s: None,
                energy_drift_max_j: None,
                energy_drift_rel: None,
                constraint_drift_max: None,
                warnings: Vec::new(),
            },
            Err(FreeRunError::SceneNotSupported(why)) => CaseOutcome {
                method,
                completed: false,
                failure: Some(format!("scene not supported by this model: {why}")),
                t_reached: options.scene.t0,
                phi_end_rad: None,
                omega_end_rad_s: None,
                steps: 0,
                rhs_evals: 0,
                jac_evals: 0,
                cpu_s: None,
                energy_drift_max_j: None,
                energy_drift_rel: None,
                constraint_drift_max: None,
                warnings: Vec::new(),
            },
            Err(e) => return Err(e),
        });
    }
    Ok(out)
}
