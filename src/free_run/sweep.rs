//! Work–precision sweep of the `free` scene against the exact reference.

use super::FreeRunError;
use super::dae::{ConstraintViolation, DaeOptions};
use super::method::Method;
use super::run::{FreeRunOptions, run_free};
use super::scene::FreeScene;
use crate::integrators::JacobianSource;
use serde::{Deserialize, Serialize};
use std::fmt::Write;
use std::time::Instant;

/// What to sweep.
///
/// Adaptive methods run with purely absolute error control, `rtol = 0`, `atol = tol` on both
/// components (φ \[rad\], φ̇ [rad/s]; dae-index1: on all 18 coordinates and velocities); the
/// initial-acceleration method runs with each step in `fixed_steps`, dae-genalpha with each
/// step in `genalpha_steps`. CPU time is the median of `repeats` runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepConfig {
    /// Methods, in table order.
    pub methods: Vec<Method>,
    /// Absolute tolerances for the adaptive methods, loosest first.
    pub tolerances: Vec<f64>,
    /// Steps \[s\] for the initial-acceleration method, largest first.
    pub fixed_steps: Vec<f64>,
    /// Steps \[s\] for dae-genalpha, largest first.
    #[serde(default = "default_genalpha_steps")]
    pub genalpha_steps: Vec<f64>,
    /// Settings of the DAE forms.
    #[serde(default)]
    pub dae: DaeOptions,
    /// Repeats per point (CPU time is their median).
    pub repeats: usize,
    /// Cap on steps per run.
    pub max_steps: u64,
    /// Cap on right-hand-side evaluations per run.
    pub max_rhs_evals: u64,
    /// Jacobian source of the implicit methods.
    pub jacobian: JacobianSource,
    /// Methods run a second time with the energy projection (`--project-energy`, conservative
    /// scenes, RK45 only), after the plain ones; empty by default.
    #[serde(default)]
    pub projected_methods: Vec<Method>,
}

impl Default for SweepConfig {
    fn default() -> Self {
        Self {
            methods: Method::ALL.to_vec(),
            tolerances: vec![1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12],
            fixed_steps: vec![1e-3, 1e-4, 1e-5, 1e-6],
            genalpha_steps: default_genalpha_steps(),
            dae: DaeOptions::default(),
            repeats: 5,
            max_steps: 1_000_000,
            max_rhs_evals: 10_000_000,
            jacobian: JacobianSource::Auto,
            projected_methods: Vec::new(),
        }
    }
}

fn default_genalpha_steps() -> Vec<f64> {
    vec![1e-3, 3e-4, 1e-4, 3e-5, 1e-5]
}

/// One point of the work–precision table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepRow {
    /// Method.
    pub method: Method,
    /// Run with the energy projection (`dynamics free --project-energy`).
    pub project_energy: bool,
    /// `"atol"` (adaptive, `rtol = 0`) or `"step"` (fixed step \[s\]).
    pub setting: &'static str,
    /// The tolerance or step.
    pub value: f64,
    /// Failure message if the run stopped early.
    pub failure: Option<String>,
    /// `max_k |φ_k − φ_ref(t_k)|` over the output grid \[rad\].
    pub max_err_phi_rad: Option<f64>,
    /// `max_k |φ̇_k − φ̇_ref(t_k)|` over the output grid [rad/s].
    pub max_err_omega_rad_s: Option<f64>,
    /// Accepted steps.
    pub steps: u64,
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Jacobian evaluations.
    pub jac_evals: u64,
    /// LU decompositions.
    pub lu_decompositions: u64,
    /// Median elapsed time of the integration \[s\].
    pub cpu_s: f64,
    /// Energy drift `max |E − E0|` \[J\].
    pub energy_drift_max_j: Option<f64>,
    /// DAE forms: largest constraint violation on the grid.
    pub constraint_drift_max: Option<ConstraintViolation>,
    /// Warnings of the run (tolerance floor, error above 10× the tolerance, energy drift).
    pub warnings: Vec<String>,
}

/// The sweep's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WorkPrecision {
    /// The scene.
    pub scene: FreeScene,
    /// How the tolerance is applied.
    pub tolerance_policy: &'static str,
    /// Quadrature panels of the reference.
    pub reference_panels: usize,
    /// Time to build the reference \[s\].
    pub reference_cpu_s: f64,
    /// All rows, method by method, loosest setting first.
    pub rows: Vec<SweepRow>,
}

impl WorkPrecision {
    /// The rows of one method run plainly.
    pub fn rows_of(&self, method: Method) -> Vec<&SweepRow> {
        self.rows_of_variant(method, false)
    }

    /// The rows of one method, run plainly (`projected` false) or with the energy projection.
    pub fn rows_of_variant(&self, method: Method, projected: bool) -> Vec<&SweepRow> {
        self.rows
            .iter()
            .filter(|r| r.method == method && r.project_energy == projected)
            .collect()
    }

    /// `true` if the method's successful plain runs have non-increasing φ and φ̇ errors as the
    /// tolerance (or step) decreases.
    pub fn is_monotone(&self, method: Method) -> bool {
        self.is_monotone_variant(method, false)
    }

    /// [`Self::is_monotone`] for the plain (`projected` false) or the projected runs.
    pub fn is_monotone_variant(&self, method: Method, projected: bool) -> bool {
        let ok: Vec<_> = self
            .rows_of_variant(method, projected)
            .into_iter()
            .filter(|r| r.failure.is_none())
            .collect();
        ok.windows(2).all(|w| {
            w[1].max_err_phi_rad <= w[0].max_err_phi_rad
                && w[1].max_err_omega_rad_s <= w[0].max_err_omega_rad_s
        })
    }

    /// Smallest `max |Δφ|` of any run.
    pub fn best_phi_error(&self) -> f64 {
        self.rows
            .iter()
            .filter_map(|r| r.max_err_phi_rad)
            .fold(f64::INFINITY, f64::min)
    }

    /// The table in Markdown.
    pub fn to_markdown(&self) -> String {
        let mut s = String::from(
            "| method | setting | max abs err φ [rad] | max abs err ω [rad/s] | steps | RHS evals | Jacobians | CPU [ms] |\n\
             |---|---|---|---|---|---|---|---|\n",
        );
        for r in &self.rows {
            let fmt = |v: Option<f64>| v.map_or("–".to_string(), |x| format!("{x:.2e}"));
            let _ = writeln!(
                s,
                "| {}{} | {} = {:.0e} | {} | {} | {} | {} | {} | {}{} |",
                r.method,
                if r.project_energy {
                    " + energy projection"
                } else {
                    ""
                },
                r.setting,
                r.value,
                fmt(r.max_err_phi_rad),
                fmt(r.max_err_omega_rad_s),
                r.steps,
                r.rhs_evals,
                r.jac_evals,
                if r.cpu_s.is_nan() {
                    "–".to_string()
                } else {
                    format!("{:.3}", r.cpu_s * 1e3)
                },
                r.failure
                    .as_ref()
                    .map_or(String::new(), |f| format!(" (failed: {f})")),
            );
        }
        s
    }
}

/// Runs every method of `cfg` over its tolerances (or steps) on `scene` and measures the
/// error against the exact reference on the output grid. Once a method has reached its step
/// or evaluation cap, its tighter settings (which would need more work) are not run: their
/// rows carry the failure "not run: …" with zero work.
pub fn work_precision_sweep(
    scene: &FreeScene,
    cfg: &SweepConfig,
) -> Result<WorkPrecision, FreeRunError> {
    let start = Instant::now();
    let reference = scene.reference()?;
    let reference_cpu_s = start.elapsed().as_secs_f64();
    let mut rows = Vec::new();
    let variants = cfg
        .methods
        .iter()
        .map(|&m| (m, false))
        .chain(cfg.projected_methods.iter().map(|&m| (m, true)));
    for (method, project_energy) in variants {
        let (setting, values) = if method == Method::DaeGenAlpha {
            ("step", &cfg.genalpha_steps)
        } else if method.is_fixed_step() {
            ("step", &cfg.fixed_steps)
        } else {
            ("atol", &cfg.tolerances)
        };
        let mut capped: Option<f64> = None;
        for &value in values {
            if let Some(at) = capped {
                rows.push(SweepRow {
                    method,
                    project_energy,
                    setting,
                    value,
                    failure: Some(format!(
                        "not run: the cap was already reached at {setting} = {at:e}"
                    )),
                    max_err_phi_rad: None,
                    max_err_omega_rad_s: None,
                    steps: 0,
                    rhs_evals: 0,
                    jac_evals: 0,
                    lu_decompositions: 0,
                    cpu_s: f64::NAN,
                    energy_drift_max_j: None,
                    constraint_drift_max: None,
                    warnings: Vec::new(),
                });
                continue;
            }
            let opts = FreeRunOptions {
                scene: *scene,
                rtol: 0.0,
                atol: value,
                omega_rtol: None,
                omega_atol: None,
                fixed_step: value,
                max_steps: cfg.max_steps,
                max_rhs_evals: cfg.max_rhs_evals,
                jacobian: cfg.jacobian,
                dae: cfg.dae,
                project_energy,
            };
            let mut times = Vec::with_capacity(cfg.repeats.max(1));
            let mut last = None;
            for _ in 0..cfg.repeats.max(1) {
                match run_free(method, &opts) {
                    Ok(r) => {
                        times.push(r.cpu_s);
                        last = Some(Ok(r));
                    }
                    Err(FreeRunError::Solver(e)) => {
                        last = Some(Err(e));
                        break;
                    }
                    Err(e) => return Err(e),
                }
            }
            times.sort_by(f64::total_cmp);
            let cpu_s = times.get(times.len() / 2).copied().unwrap_or(f64::NAN);
            rows.push(match last {
                Some(Ok(mut r)) => {
                    let (ep, ew) = r.check_against_reference(&reference, &opts);
                    SweepRow {
                        method,
                        project_energy,
                        setting,
                        value,
                        failure: None,
                        max_err_phi_rad: Some(ep),
                        max_err_omega_rad_s: Some(ew),
                        steps: r.steps,
                        rhs_evals: r.rhs_evals,
                        jac_evals: r.jac_evals,
                        lu_decompositions: r.lu_decompositions,
                        cpu_s,
                        energy_drift_max_j: r.energy_drift_max_j,
                        constraint_drift_max: r.constraint_drift_max,
                        warnings: r.warnings,
                    }
                }
                Some(Err(e)) => {
                    if e.is_limit() {
                        capped = Some(value);
                    }
                    SweepRow {
                        method,
                        project_energy,
                        setting,
                        value,
                        failure: Some(e.to_string()),
                        max_err_phi_rad: None,
                        max_err_omega_rad_s: None,
                        steps: e.stats.steps,
                        rhs_evals: e.stats.rhs_evals,
                        jac_evals: e.stats.jac_evals,
                        lu_decompositions: e.stats.lu_decompositions,
                        cpu_s,
                        energy_drift_max_j: None,
                        constraint_drift_max: None,
                        warnings: Vec::new(),
                    }
                }
                None => unreachable!("at least one repeat"),
            });
        }
    }
    Ok(WorkPrecision {
        scene: *scene,
        tolerance_policy: "adaptive methods: rtol = 0, atol = tol on φ [rad] and φ̇ [rad/s] \
                           (weighted RMS norm; dae-index1: on all 9 coordinates and 9 \
                           velocities); initial-acceleration and dae-genalpha: fixed step",
        reference_panels: reference.panels,
        reference_cpu_s,
        rows,
    })
}
