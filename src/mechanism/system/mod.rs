//! The planar multibody core in body coordinates — thesis §3.2 (after
//! Nikravesh): assembly of Φ, D, ν, γ, h and M, and kinematic analysis plus
//! inverse dynamics of a zero-DOF (fully driven) system.
//!
//! For a system of n_b moving bodies, c = [c₂ᵀ, c₃ᵀ, …]ᵀ with cᵢ = [xᵢ, yᵢ, φᵢ]ᵀ
//! (thesis eq. 2.14, 2.16) has N = 3 n_b entries; the joints contribute the
//! constraint vector Φ(c, t) (eq. 2.15, 3.25–3.26). When the joints give exactly
//! N independent equations the system has zero degrees of freedom and the
//! motion follows from the constraints alone (Nikravesh 1988, kinematic
//! analysis):
//!
//! * position: Φ(c, t) = 0 by Newton–Raphson, D Δc = −Φ, converged to
//!   ‖Φ‖ ≤ 1e-12 L; warm-started along the motion by [`Tracker`] (Hermite
//!   predictor from the previous two solutions, so one Newton step usually
//!   suffices);
//! * velocity: D ċ = ν = −Φ_t (eq. 3.35 plus the driver term);
//! * acceleration: D c̈ = γ (eq. 3.36–3.38, γ = −Ḋ ċ for the joints);
//! * multipliers from the equations of motion M c̈ = h + Dᵀλ (eq. 3.27), i.e.
//!   the block system [M −Dᵀ; D 0][c̈; λ] = [h; γ] (eq. 3.38). With D square
//!   and regular the block system decouples exactly into D c̈ = γ and
//!   Dᵀλ = M c̈ − h, which is how it is solved here (one LU of D serves all
//!   three linear solves; a unit test checks the result against the assembled
//!   block system);
//! * joint reactions: the generalized force of joint k on body b is
//!   D_{k,b}ᵀ λ_k (force in the global frame and moment about the body's
//!   reference point).
//!
//! # Scaling and singularity
//! Rows of Φ are lengths (m) except angle rows (rad); columns of D are
//! dimensionless for x, y and lengths for φ. All linear algebra is done on
//! S = R D C with R = diag(1 or L) (angle rows times the characteristic length
//! L) and C = diag(1, 1, 1/L, …), so that entries are O(1) and the relative
//! pivot min|u_kk|/max|u_kk| of an LU is a meaningful rank test. Every
//! factorisation (each Newton iterate and the converged position) is
//! nalgebra's partial-pivoting LU; when its relative pivot falls below
//! [`RANK_CONFIRM`] (1e-3; healthy crank–slider Jacobians show 0.3–1) the
//! rank-revealing complete-pivoting LU (nalgebra's `FullPivLU`) decides and is
//! used instead (see [`crate::linalg`]). A relative pivot of the
//! latter below [`SolverOptions::pivot_threshold`] (1e-8) is reported as
//! [`DynamicsError::SingularJacobian`](super::error::DynamicsError::SingularJacobian) with the time and the joint whose
//! equation is linearly dependent on the preceding ones (Gram–Schmidt over the
//! rows in joint order) — a toggle position or a redundant constraint — before
//! any NaN can arise.
//!
//! Newton–Raphson that does not reach the tolerance (inconsistent constraints,
//! a position beyond a locking point) is [`DynamicsError::NoConvergence`](super::error::DynamicsError::NoConvergence),
//! naming the time and the joint with the largest residual.
//!
//! # Allocation
//! All per-step quantities are fixed-size (`SVector<f64, N>`,
//! `SMatrix<f64, N, N>`, arrays); the joint and body lists are built once; the
//! per-step path allocates nothing (only error messages do).
//!
//! # Files
//! | file | contents |
//! |---|---|
//! | `mod.rs` | [`MultibodySystem`] (bodies, joints, loads, scaling), [`SolverOptions`], [`AppliedLoad`], [`NamedJoint`] |
//! | `builder.rs` | [`MultibodyBuilder`]: bodies, joints, loads, validation, row/column scaling |
//! | `assembly.rs` | Φ, D (plain or scaled), ν, γ, h, M and the energies (thesis eq. 3.25–3.38) |
//! | `analysis.rs` | Newton–Raphson position analysis, velocity, acceleration and multipliers ([`KinematicSolution`]), rank diagnosis |
//! | `reactions.rs` | joint reactions D_{k,b}ᵀ λ_k ([`JointReaction`], [`GeneralizedForce`]) |
//! | `tracker.rs` | [`Tracker`]: warm-started analysis along the motion |

mod analysis;
mod assembly;
mod builder;
mod reactions;
mod tracker;

#[cfg(test)]
mod tests;

use nalgebra::{Const, DimMin, SVector, Vector2};

use super::body::{Body, BodyId, Pose, Twist};
use super::gas::GasForce;
use super::joint::Joint;

pub use analysis::{KinematicSolution, RANK_CONFIRM};
pub use builder::MultibodyBuilder;
pub use reactions::{GeneralizedForce, JointReaction};
pub use tracker::Tracker;

/// Numerical settings of the kinematic analysis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverOptions {
    /// Newton–Raphson stops when the scaled residual ‖R Φ‖∞ ≤ tolerance × L
    /// (relative to the characteristic length L). Default 1e-12.
    pub tolerance: f64,
    /// Newton iterations per solve. Default 25.
    pub max_iterations: usize,
    /// Relative pivot below which D counts as singular. Default 1e-8
    /// (≈ √ε: below it the position solution has lost half its digits).
    pub pivot_threshold: f64,
    /// The tracker subdivides a step so that no body angle is predicted to
    /// change by more than this (rad). Default 0.25.
    pub max_angle_step_rad: f64,
    /// Upper bound on substeps per requested step (no solver crawls). Default 4096.
    pub max_substeps: usize,
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            tolerance: 1e-12,
            max_iterations: 25,
            pivot_threshold: 1e-8,
            max_angle_step_rad: 0.25,
            max_substeps: 4096,
        }
    }
}

/// A load applied to a moving body (goes into h, thesis eq. 3.31).
#[derive(Clone, Debug, PartialEq)]
pub enum AppliedLoad {
    /// Constant force (global frame, N) acting at a body-fixed point (body frame, m).
    Force {
        /// Loaded body.
        body: BodyId,
        /// Point of application s'ᴾ in the body frame.
        point: Vector2<f64>,
        /// Force in the global frame.
        force: Vector2<f64>,
    },
    /// Constant torque (N·m).
    Torque {
        /// Loaded body.
        body: BodyId,
        /// Torque about the plane normal.
        torque_nm: f64,
    },
    /// A force of fixed global direction whose magnitude is a periodic function of another
    /// body's angle: F = direction · F_gas(φ_angle_of) at a body-fixed point — the cylinder
    /// pressure on the piston as a function of the crank angle ([`GasForce`]).
    GasForce {
        /// Loaded body.
        body: BodyId,
        /// Point of application s'ᴾ in the body frame.
        point: Vector2<f64>,
        /// Direction of a positive magnitude (global frame, unit vector).
        direction: Vector2<f64>,
        /// The body whose angle φ is the argument (the crank).
        angle_of: BodyId,
        /// The magnitude F_gas(φ) (N).
        force: std::sync::Arc<GasForce>,
    },
}

/// A joint with its name and the index of its first row in Φ.
#[derive(Clone, Debug)]
pub struct NamedJoint {
    /// Name used in messages.
    pub name: String,
    /// The joint.
    pub joint: Joint,
    /// Row of its first equation in Φ, D, γ and λ.
    pub row: usize,
}

/// A built, validated planar multibody system with `N` body coordinates.
#[derive(Clone, Debug)]
pub struct MultibodySystem<const N: usize> {
    /// Number m of constraint equations (rows 0..m); `N` for a zero-DOF system.
    pub(super) equations: usize,
    bodies: Vec<Body>,
    joints: Vec<NamedJoint>,
    loads: Vec<AppliedLoad>,
    gravity: Vector2<f64>,
    options: SolverOptions,
    pub(super) length_scale: f64,
    /// R: 1 for length rows, L for angle rows (module docs, "Scaling").
    pub(super) row_scale: SVector<f64, N>,
    /// C: 1 for x, y columns, 1/L for φ columns.
    pub(super) col_scale: SVector<f64, N>,
    pub(super) mass: SVector<f64, N>,
}

type Poses<const N: usize> = [Pose; N];
type Twists<const N: usize> = [Twist; N];

#[inline]
fn pose_of<const N: usize>(p: &Poses<N>, id: BodyId) -> Pose {
    match id {
        BodyId::Ground => Pose::GROUND,
        BodyId::Moving(k) => p[k],
    }
}

#[inline]
fn twist_of<const N: usize>(v: &Twists<N>, id: BodyId) -> Twist {
    match id {
        BodyId::Ground => Twist::ZERO,
        BodyId::Moving(k) => v[k],
    }
}

impl<const N: usize> MultibodySystem<N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    /// The bodies.
    pub fn bodies(&self) -> &[Body] {
        &self.bodies
    }

    /// The joints, in row order.
    pub fn joints(&self) -> &[NamedJoint] {
        &self.joints
    }

    /// Index of the joint with this name.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Number m of constraint equations (rows 0..m of Φ, D, γ, λ).
    pub fn equations(&self) -> usize {
        self.equations
    }

    /// Degrees of freedom N − m (0 for a fully driven system).
    pub fn dof(&self) -> usize {
        N - self.equations
    }

    /// The characteristic length L used for scaling (m).
    pub fn length_scale(&self) -> f64 {
        self.length_scale
    }

    /// Solver settings.
    pub fn options(&self) -> &SolverOptions {
        &self.options
    }

    /// Diagonal of the mass matrix M (thesis eq. 3.28–3.29).
    pub fn mass_diagonal(&self) -> SVector<f64, N> {
        self.mass
    }
}
