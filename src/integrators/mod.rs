//! Generic initial-value ODE solvers for `y' = f(t, y)`, written for the free-running crank
//! (thesis ch. 4) but independent of it.
//!
//! Every solver
//! - integrates from `grid.t0` to `grid.t_end()` and writes its dense output onto the uniform
//!   output grid (`OutputGrid`), never extrapolating;
//! - counts right-hand-side evaluations, Jacobian evaluations, LU decompositions and steps
//!   (`Stats`);
//! - stops with a typed [`SolverError`] (with `Display`) when it reaches its cap on steps or on
//!   right-hand-side evaluations, when the step size underflows, or when a non-finite value
//!   appears: no NaN ever reaches an output.
//!
//! Error control (adaptive methods): the local error estimate `e` is measured in the weighted
//! RMS norm `sqrt(mean((e_i / (atol + rtol * |y_i|))^2))` (Hairer, Nørsett & Wanner, *Solving
//! ODEs I*, eq. II.4.11) with the user's `rtol` and `atol`; a step is accepted when the norm is
//! at most 1. With `rtol = 0` the control is purely absolute, which is what a growing angle
//! needs (a relative tolerance on φ loosens as φ grows).
//!
//! The adaptive one-step methods ([`rk45`], [`rk23`], [`rosenbrock`], [`trbdf2`]) share one
//! step-size loop (`adaptive.rs`: accept/reject, step-size control, dense output onto the
//! grid, caps, the optional post-step projection); each method's file holds only its tableau,
//! stages, error estimate, controller constants and continuous extension. [`bdf`] keeps its
//! own loop (variable order; its backward differences are rescaled at every step change).
//! Below the methods, and imported by them: `input.rs` (input checks and the
//! [`FailureKind::InvalidInput`] error), `control.rs` (step-size selection), `hermite.rs` (the
//! cubic Hermite dense output of [`rk23`] and [`trbdf2`]); `method.rs` only dispatches
//! ([`OdeMethod`], [`solve`]) and no method imports it.
//! The iteration matrices `I − γhJ` of the implicit methods are factored by the crate's one
//! dense LU, [`crate::linalg::DenseLu`].
//!
//! Methods (one file each):
//! - [`initial_acceleration`]: the thesis' "initial acceleration" method (§4.1.1, eq. 4.5–4.13),
//!   fixed step, for second-order systems in the layout `y = [q; q̇]`;
//! - [`rk45`]: Dormand & Prince (1980) 5(4) with its 4th-order continuous extension (ode45);
//!   [`rk45::solve_projected`] adds a post-step projection onto an invariant manifold
//!   ([`StepProjection`]), used for the stabilised index-1 multibody form;
//! - [`rk23`]: Bogacki & Shampine (1989) 3(2), cubic Hermite dense output (ode23);
//! - [`bdf`]: variable-order (1–5) BDF in backward-difference form with quasi-constant step
//!   (Shampine & Reichelt 1997, ode15s; Byrne & Hindmarsh 1975); the NDF variant of ode15s is
//!   [`OdeMethod::Ndf`];
//! - [`rosenbrock`]: the Shampine & Reichelt (1997) modified Rosenbrock 2(3) W-method (ode23s);
//! - [`trbdf2`]: TR-BDF2 with the Hosea & Shampine (1996) embedded estimate (ode23tb);
//! - [`genalpha`]: generalized-α (Chung & Hulbert 1993) for constrained mechanical systems in
//!   index-3 form (Arnold & Brüls 2007), fixed step, Newton on positions and multipliers; it
//!   integrates a [`genalpha::ConstrainedSystem`], not an [`OdeSystem`].
//!
//! Why hand-written and not `diffsol` 0.18: measured on the 2-state crank problem (same
//! tolerances, same 1e-4 s output grid), diffsol's BDF was as fast as [`bdf`], its TR-BDF2
//! 1.3–1.5× and its TSIT45 about 2× slower than [`trbdf2`] and [`rk45`]; it has no
//! Bogacki–Shampine, Rosenbrock or fixed-step method, and it pulls in `faer` even with
//! `default-features = false` (cold release build of 144 units, 3.5 min on 2 cores).
//! `ode_solvers` 0.6 was avoided for its wrong last dense-output point, `russell_ode` lacks
//! BS23 and Rosenbrock.

mod adaptive;
mod control;
mod error;
mod eval;
mod grid;
mod hermite;
mod input;
mod newton;
mod norm;
mod options;
mod projection;
#[cfg(test)]
mod regression;
mod stats;
mod system;
#[cfg(test)]
mod tests_common;
mod turns;

pub mod bdf;
pub mod genalpha;
pub mod initial_acceleration;
mod method;
pub mod rk23;
pub mod rk45;
pub mod rosenbrock;
pub mod trbdf2;

pub use error::{FailureKind, SolverError};
pub use grid::{OutputGrid, Solution};
pub use method::{OdeMethod, solve};
pub use norm::{TOL_FLOOR_KAPPA, rms_norm_scaled};
pub use options::{JacobianSource, SolverOptions};
pub use projection::StepProjection;
pub use stats::Stats;
pub use system::OdeSystem;
