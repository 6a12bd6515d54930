//! The `free` scene through the planar multibody core as a DAE (thesis §3.2, eq. 3.25–3.38).
//!
//! The model ([`model`]): the crank–slider of [`CrankSlider::free_multibody`](crate::mechanism::CrankSlider::free_multibody) — crank, rod and
//! piston with their 9 body coordinates `c` (eq. 2.14), revolute joints O, A, B and the slide
//! (eq. 3.25–3.26, 8 equations `Φ(c) = 0`, one degree of freedom), the crank torque `M` and
//! the piston force `F` in `h` (eq. 3.31), gravity switchable as in [`Loads`](super::Loads). The rod is the
//! rigid body itself (mass `m3`, centroid at `l1` from A, `I_S3` about the centroid), the crank
//! has its centroid at `e` from O along OA and `I_S2 = I2 − m2 e²` (eq. 3.43). The two-mass
//! rod of the reduced model preserves mass, centroid and centroidal inertia, so both models
//! have the same kinetic and potential energy and the same `φ(t)`; the tests hold them to it.
//! Sign of the piston force: `F` acts "in the direction of increasing x", the piston travel
//! `x = (r + l) − x_B` (eq. 2.8), so in the global frame it is `−F` along x.
//!
//! Equations of motion: `M c̈ = h + Dᵀλ`, `Φ(c) = 0` (eq. 3.27, 3.25) — an index-3 DAE.
//! Two forms are integrated:
//!
//! - [`Method::DaeIndex1`](super::Method::DaeIndex1) ([`index1`]): the index-1 form
//!   `[M −Dᵀ; D 0][c̈; λ] = [h; γ]` (eq. 3.38) solved for `c̈` at each evaluation, state
//!   `y = [c; ċ]` (18 components), RK45 (Dormand–Prince) with the run's absolute tolerance
//!   on every component. Its invariants `Φ = 0`, `D ċ = 0` drift; [`Stabilization`] chooses
//!   what keeps them: coordinate projection after every step (default), Baumgarte's
//!   feedback, or nothing (to show the drift).
//! - [`Method::DaeGenAlpha`](super::Method::DaeGenAlpha) ([`index3`]): the index-3 form
//!   itself with generalized-α ([`crate::integrators::genalpha`], Arnold & Brüls 2007), fixed
//!   step [`FreeRunOptions::fixed_step`](super::FreeRunOptions::fixed_step), spectral radius
//!   [`DaeOptions::rho_inf`]. `Φ = 0` holds to the Newton tolerance at every step; `D ċ = 0`
//!   is not enforced and drifts by O(h²).
//!
//! Both report φ(t) and ω(t) of the crank (its body angle `c[2]` and `ċ[2]`) on the output
//! grid and the constraint drift `max |Φ_i|`, `max |(D ċ)_i|` over the grid
//! ([`ConstraintViolation`]; rows in m, the slide's angle row in rad).

pub mod index1;
pub mod index3;
pub mod model;

use serde::{Deserialize, Serialize};

pub use crate::mechanism::{Baumgarte, ConstraintViolation};
pub use model::MultibodyCrank;

/// How the index-1 form keeps its invariants `Φ = 0`, `D ċ = 0`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Stabilization {
    /// Coordinate projection onto `Φ = 0` and `D ċ = 0` after every accepted step and of
    /// every output sample ([`crate::mechanism::forward`], [`crate::integrators::rk45`]).
    #[default]
    Projection,
    /// Baumgarte: `D c̈ = γ − 2α D ċ − β² Φ`.
    Baumgarte {
        /// α (1/s).
        alpha: f64,
        /// β (1/s).
        beta: f64,
    },
    /// None: `D c̈ = γ` only; the constraints drift.
    Off,
}

/// Settings of the DAE forms.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct DaeOptions {
    /// Stabilisation of the index-1 form.
    pub stabilization: Stabilization,
    /// Projection tolerance: `‖R Φ‖∞ ≤ projection_tol · L` (see [`crate::mechanism::forward`]).
    pub projection_tol: f64,
    /// Newton iterations of one projection.
    pub projection_max_iters: usize,
    /// Spectral radius at infinity of generalized-α.
    pub rho_inf: f64,
    /// Newton tolerance of generalized-α on the position increments (m, rad).
    pub newton_tol: f64,
    /// Newton iterations per generalized-α step.
    pub max_newton_iters: usize,
}

impl Default for DaeOptions {
    fn default() -> Self {
        Self {
            stabilization: Stabilization::Projection,
            projection_tol: 1e-13,
            projection_max_iters: 10,
            rho_inf: 0.9,
            newton_tol: 1e-10,
            max_newton_iters: 10,
        }
    }
}

/// A completed DAE run, as [`super::run_free`] needs it.
#[derive(Debug, Clone)]
pub(crate) struct DaeRun {
    /// Output times \[s\].
    pub t: Vec<f64>,
    /// Crank angle on the grid \[rad\].
    pub phi: Vec<f64>,
    /// Crank angular velocity on the grid [rad/s].
    pub omega: Vec<f64>,
    /// Work counters.
    pub stats: crate::integrators::Stats,
    /// Elapsed time of the integration \[s\].
    pub cpu_s: f64,
    /// Largest constraint violation on the grid.
    pub drift: ConstraintViolation,
    /// What was integrated.
    pub model: &'static str,
}

/// Runs a DAE method on `options.scene` (the model is built here; the time covers the
/// integration only).
pub(crate) fn run(
    method: super::Method,
    options: &super::FreeRunOptions,
    grid: &crate::integrators::OutputGrid,
) -> Result<DaeRun, super::FreeRunError> {
    let mb = MultibodyCrank::new(&options.scene)?;
    match method {
        super::Method::DaeIndex1 => index1::run(&mb, options, grid),
        super::Method::DaeGenAlpha => index3::run(&mb, options, grid),
        other => Err(super::FreeRunError::Unsupported(other.to_string())),
    }
}
