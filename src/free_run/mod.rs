//! Stage 2, scene `free`: the free-running crank (thesis ch. 3–4).
//!
//! The mechanism has one degree of freedom, so the cheapest exact model is the reduction
//! method (thesis §3.1): the crank is the reduction member with reduced moment of inertia
//! `I_red(φ)` (eq. 3.17, two-mass rod model eq. 3.11–3.14) and reduced moment `M_red(φ)`
//! (eq. 3.22), giving the equation of motion eq. 3.24 / 4.1. Its energy integral gives an
//! exact reference (`reference`), against which every integrator is measured (`sweep`).
//!
//! The same scene also runs through the planar multibody core of thesis §3.2 as a DAE
//! ([`dae`]: the stabilised index-1 form with RK45, `dae-index1`, and the index-3 form with
//! generalized-α, `dae-genalpha`); both are measured against the same exact reference, and
//! report their constraint drift.
//!
//! Gravity is off in the `free` scene (see [`Loads::gravity`]) and switchable.
//!
//! Tolerance policy: adaptive methods control `atol + rtol·|y_i|` per component; the default
//! and the work–precision sweep are purely absolute (`rtol = 0`, `atol = tol` on φ \[rad\] and
//! φ̇ [rad/s]), because φ grows without bound and `rtol·|φ|` would loosen the control as it
//! grows (shown by the 10 s and 100 s hard cases). Every run reports the energy drift
//! `max |E(t) − E(t0)|`, `E = ½ I_red φ̇² − M φ − F x + V`, and warns when it exceeds
//! [`ENERGY_WARN_REL`] of the kinetic energy.

pub mod dae;
mod energy_projection;
mod loads;
mod mechanism;
mod method;
mod ode;
mod outcome;
mod quadrature;
mod reduced;
mod reference;
mod run;
mod scene;
mod sweep;

pub use energy_projection::EnergyProjection;
pub use loads::{G, GasSpring, Loads};
pub use mechanism::{CrankSliderData, KinematicPoint, Kinematics};
pub use method::{Method, UnknownMethod};
pub use ode::CrankOde;
pub use outcome::{CaseOutcome, run_all};
pub use quadrature::gk15;
pub use reduced::{ModelError, ReducedModel, TwoMassRod};
pub use reference::{
    ExactReference, PANEL_TOL, ReferenceError, exact_reference, exact_reference_with_tol,
};
pub use run::{ENERGY_WARN_REL, FreeRunOptions, FreeRunResult, REFERENCE_WARN_FACTOR, run_free};
pub use scene::FreeScene;
pub use sweep::{SweepConfig, SweepRow, WorkPrecision, work_precision_sweep};

use crate::integrators::SolverError;
use crate::mechanism::DynamicsError;

/// Failure of a free run or sweep.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FreeRunError {
    /// Mechanism data refused at model build.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The integrator stopped (step/evaluation cap, step underflow, blow-up).
    #[error(transparent)]
    Solver(#[from] SolverError),
    /// The exact reference could not be built.
    #[error(transparent)]
    Reference(#[from] ReferenceError),
    /// Inconsistent options.
    #[error("invalid options: {0}")]
    Options(String),
    /// The method does not run on the reduced model.
    #[error("method `{0}` is not available for the reduced model")]
    Unsupported(String),
    /// The multibody model could not be built or stopped (refused data, singular Jacobian).
    #[error(transparent)]
    Multibody(#[from] DynamicsError),
    /// The scene has a feature the method's model does not have.
    #[error("scene not supported by this model: {0}")]
    SceneNotSupported(String),
}
