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
//! [`DynamicsError::SingularJacobian`] with the time and the joint whose
//! equation is linearly dependent on the preceding ones (Gram–Schmidt over the
//! rows in joint order) — a toggle position or a redundant constraint — before
//! any NaN can arise.
//!
//! Newton–Raphson that does not reach the tolerance (inconsistent constraints,
//! a position beyond a locking point) is [`DynamicsError::NoConvergence`],
//! naming the time and the joint with the largest residual.
//!
//! # Allocation
//! All per-step quantities are fixed-size (`SVector<f64, N>`,
//! `SMatrix<f64, N, N>`, arrays); the joint and body lists are built once; the
//! per-step path allocates nothing (only error messages do).

use nalgebra::{Const, DMatrix, DimMin, SMatrix, SVector, Vector2};

use super::body::{Body, BodyId, Pose, Twist, cross};
use super::constraint::ConstraintEquations;
use super::driving::Driving;
use super::error::{DynamicsError, Result, non_negative, positive};
use super::joint::Joint;
use super::motion::CrankMotion;
use super::revolute::Revolute;
use super::translational::Translational;
use crate::linalg::{Factorization, most_dependent_row};

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

/// Relative pivot of the partial-pivoting LU below which the rank decision is
/// handed to the complete-pivoting LU. Healthy crank–slider Jacobians have
/// ratios of 0.3–1 (0.04 at l/r = 1.001), so the costlier factorisation
/// only runs close to a singular configuration.
pub const RANK_CONFIRM: f64 = 1e-3;

/// A load applied to a moving body (goes into h, thesis eq. 3.31).
#[derive(Clone, Copy, Debug, PartialEq)]
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

/// Builder of a [`MultibodySystem`].
#[derive(Clone, Debug)]
pub struct MultibodyBuilder {
    bodies: Vec<Body>,
    joints: Vec<(String, Joint)>,
    loads: Vec<AppliedLoad>,
    gravity: Vector2<f64>,
    options: SolverOptions,
}

impl Default for MultibodyBuilder {
    fn default() -> Self {
        Self::new()
    }
}

impl MultibodyBuilder {
    /// Empty system, no gravity, default options.
    pub fn new() -> Self {
        MultibodyBuilder {
            bodies: Vec::new(),
            joints: Vec::new(),
            loads: Vec::new(),
            gravity: Vector2::zeros(),
            options: SolverOptions::default(),
        }
    }

    /// Add a moving body whose reference point is its centroid.
    pub fn add_body(&mut self, name: &str, mass_kg: f64, inertia_kgm2: f64) -> BodyId {
        self.bodies.push(Body {
            name: name.to_string(),
            mass_kg,
            inertia_kgm2,
        });
        BodyId::Moving(self.bodies.len() - 1)
    }

    /// Add a revolute joint (see [`Revolute`]).
    pub fn add_revolute(
        &mut self,
        name: &str,
        body_i: BodyId,
        point_i: Vector2<f64>,
        body_j: BodyId,
        point_j: Vector2<f64>,
    ) -> &mut Self {
        self.joints.push((
            name.to_string(),
            Joint::Revolute(Revolute {
                body_i,
                point_i,
                body_j,
                point_j,
            }),
        ));
        self
    }

    /// Add a translational joint (see [`Translational`]); the axis is
    /// normalised (and a zero axis refused) by [`build`](Self::build).
    #[allow(clippy::too_many_arguments)]
    pub fn add_translational(
        &mut self,
        name: &str,
        body_i: BodyId,
        point_i: Vector2<f64>,
        axis_i: Vector2<f64>,
        body_j: BodyId,
        point_j: Vector2<f64>,
        angle0_rad: f64,
    ) -> &mut Self {
        self.joints.push((
            name.to_string(),
            Joint::Translational(Translational {
                body_i,
                point_i,
                axis_i,
                body_j,
                point_j,
                angle0_rad,
            }),
        ));
        self
    }

    /// Add a driving constraint φⱼ − φᵢ = f(t) (see [`Driving`]).
    pub fn add_driving(
        &mut self,
        name: &str,
        body_i: BodyId,
        body_j: BodyId,
        motion: CrankMotion,
    ) -> &mut Self {
        self.joints.push((
            name.to_string(),
            Joint::Driving(Driving {
                body_i,
                body_j,
                motion,
            }),
        ));
        self
    }

    /// Add an applied load.
    pub fn add_load(&mut self, load: AppliedLoad) -> &mut Self {
        self.loads.push(load);
        self
    }

    /// Gravitational acceleration vector (m/s²), e.g. (0, −9.81).
    pub fn gravity(&mut self, g: Vector2<f64>) -> &mut Self {
        self.gravity = g;
        self
    }

    /// Solver settings.
    pub fn options(&mut self, options: SolverOptions) -> &mut Self {
        self.options = options;
        self
    }

    /// Validate and freeze. `N` must be 3 × (number of moving bodies) and the
    /// joints must give exactly `N` equations (zero DOF).
    pub fn build<const N: usize>(&self) -> Result<MultibodySystem<N>> {
        self.build_checked(false)
    }

    /// Validate and freeze a system that keeps degrees of freedom: the joints
    /// give m ≤ `N` equations (rows 0..m of Φ, D, γ; the remaining N − m rows
    /// are identically zero and carry no multiplier). Such a system is for
    /// forward dynamics ([`forward`](super::forward)); its kinematic analysis
    /// ([`MultibodySystem::analyze`]) is refused with
    /// [`DynamicsError::ConstraintCount`].
    pub fn build_with_dof<const N: usize>(&self) -> Result<MultibodySystem<N>> {
        self.build_checked(true)
    }

    fn build_checked<const N: usize>(&self, allow_dof: bool) -> Result<MultibodySystem<N>> {
        let nb = self.bodies.len();
        if nb == 0 || 3 * nb != N {
            return Err(DynamicsError::InvalidModel(format!(
                "{nb} moving bodies have {} body coordinates, but the system is declared with N = {N}",
                3 * nb
            )));
        }
        for b in &self.bodies {
            positive("mass_kg", b.mass_kg).map_err(|e| in_body(e, &b.name))?;
            non_negative("inertia_kgm2", b.inertia_kgm2).map_err(|e| in_body(e, &b.name))?;
        }
        let o = &self.options;
        positive("tolerance", o.tolerance)?;
        positive("pivot_threshold", o.pivot_threshold)?;
        positive("max_angle_step_rad", o.max_angle_step_rad)?;
        if o.max_iterations == 0 || o.max_substeps == 0 {
            return Err(DynamicsError::InvalidModel(
                "max_iterations and max_substeps must be at least 1".into(),
            ));
        }
        let check_body = |id: BodyId, joint: &str| -> Result<()> {
            match id {
                BodyId::Moving(k) if k >= nb => Err(DynamicsError::InvalidModel(format!(
                    "joint '{joint}' refers to body {k}, but only {nb} moving bodies exist"
                ))),
                _ => Ok(()),
            }
        };
        let vec_finite = |v: Vector2<f64>| v.x.is_finite() && v.y.is_finite();
        let mut joints = Vec::with_capacity(self.joints.len());
        let mut row = 0usize;
        let mut length_scale = 0.0f64;
        for (name, joint) in &self.joints {
            let (bi, bj) = joint.bodies();
            check_body(bi, name)?;
            check_body(bj, name)?;
            if bi == bj {
                return Err(DynamicsError::InvalidModel(format!(
                    "joint '{name}' connects {bi:?} with itself"
                )));
            }
            let mut joint = joint.clone();
            let mut points: [Option<(BodyId, Vector2<f64>)>; 2] = [None, None];
            match &mut joint {
                Joint::Revolute(r) => {
                    points = [Some((r.body_i, r.point_i)), Some((r.body_j, r.point_j))]
                }
                Joint::Translational(t) => {
                    let norm = t.axis_i.norm();
                    if !(norm.is_finite() && norm > 0.0 && t.angle0_rad.is_finite()) {
                        return Err(DynamicsError::InvalidModel(format!(
                            "translational joint '{name}' needs a finite, non-zero axis and a finite angle"
                        )));
                    }
                    t.axis_i /= norm;
                    points = [Some((t.body_i, t.point_i)), Some((t.body_j, t.point_j))];
                }
                Joint::Driving(d) => d.motion.validate()?,
            }
            for (body, p) in points.iter().flatten() {
                if !vec_finite(*p) {
                    return Err(DynamicsError::InvalidModel(format!(
                        "joint '{name}' has a non-finite point"
                    )));
                }
                if *body != BodyId::Ground {
                    length_scale = length_scale.max(p.norm());
                }
            }
            let m = joint.equations();
            if row + m > N {
                return Err(DynamicsError::ConstraintCount {
                    equations: self.joints.iter().map(|(_, j)| j.equations()).sum(),
                    coordinates: N,
                    detail: format!(
                        "; joint '{name}' ({} equations from row {row}) exceeds the {N} coordinates: \
                         redundant constraint",
                        m
                    ),
                });
            }
            joints.push(NamedJoint {
                name: name.clone(),
                joint,
                row,
            });
            row += m;
        }
        if row < N && !allow_dof {
            return Err(DynamicsError::ConstraintCount {
                equations: row,
                coordinates: N,
                detail: format!(
                    "; the system keeps {} degree(s) of freedom: add driving constraints",
                    N - row
                ),
            });
        }
        for load in &self.loads {
            let (body, ok) = match *load {
                AppliedLoad::Force { body, point, force } => {
                    (body, vec_finite(point) && vec_finite(force))
                }
                AppliedLoad::Torque { body, torque_nm } => (body, torque_nm.is_finite()),
            };
            match body {
                BodyId::Moving(k) if k < nb && ok => {}
                _ => {
                    return Err(DynamicsError::InvalidModel(format!(
                        "applied load {load:?} must act on an existing moving body with finite values"
                    )));
                }
            }
        }
        if !vec_finite(self.gravity) {
            return Err(DynamicsError::InvalidModel("gravity must be finite".into()));
        }
        let length_scale = if length_scale > 0.0 {
            length_scale
        } else {
            1.0
        };
        let mut row_scale = SVector::<f64, N>::repeat(1.0);
        for nj in &joints {
            for k in 0..nj.joint.equations() {
                if nj.joint.is_angle_row(k) {
                    row_scale[nj.row + k] = length_scale;
                }
            }
        }
        let mut col_scale = SVector::<f64, N>::repeat(1.0);
        let mut mass = SVector::<f64, N>::zeros();
        for (k, b) in self.bodies.iter().enumerate() {
            col_scale[3 * k + 2] = 1.0 / length_scale;
            mass[3 * k] = b.mass_kg;
            mass[3 * k + 1] = b.mass_kg;
            mass[3 * k + 2] = b.inertia_kgm2;
        }
        Ok(MultibodySystem {
            equations: row,
            bodies: self.bodies.clone(),
            joints,
            loads: self.loads.clone(),
            gravity: self.gravity,
            options: self.options,
            length_scale,
            row_scale,
            col_scale,
            mass,
        })
    }
}

fn in_body(e: DynamicsError, body: &str) -> DynamicsError {
    match e {
        DynamicsError::InvalidParameter {
            name,
            value,
            reason,
        } => DynamicsError::InvalidParameter {
            name,
            value,
            reason: format!("{reason} (body '{body}')"),
        },
        other => other,
    }
}

/// Result of the kinematic analysis and inverse dynamics at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KinematicSolution<const N: usize> {
    /// Time (s).
    pub t: f64,
    /// Body coordinates c.
    pub q: SVector<f64, N>,
    /// Velocities ċ.
    pub qd: SVector<f64, N>,
    /// Accelerations c̈.
    pub qdd: SVector<f64, N>,
    /// Lagrange multipliers λ (one per constraint row).
    pub lambda: SVector<f64, N>,
    /// Newton iterations used.
    pub newton_iterations: usize,
    /// Relative pivot of the scaled D at the solution (conditioning indicator).
    pub pivot_ratio: f64,
}

/// Generalized force on one body: force in the global frame and moment about
/// the body's reference point (its centroid; the global origin for the ground).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct GeneralizedForce {
    /// Force, x component (N).
    pub fx_n: f64,
    /// Force, y component (N).
    pub fy_n: f64,
    /// Moment (N·m).
    pub torque_nm: f64,
}

/// Reaction of one joint on each of its two bodies.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct JointReaction {
    /// Joint name.
    pub joint: String,
    /// Generalized force on body i (D_{k,i}ᵀ λ_k).
    pub on_i: GeneralizedForce,
    /// Generalized force on body j (D_{k,j}ᵀ λ_k).
    pub on_j: GeneralizedForce,
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

    pub(super) fn poses(&self, q: &SVector<f64, N>) -> Poses<N> {
        let mut p = [Pose::GROUND; N];
        for (k, slot) in p.iter_mut().take(self.bodies.len()).enumerate() {
            *slot = Pose::new(q[3 * k], q[3 * k + 1], q[3 * k + 2]);
        }
        p
    }

    pub(super) fn twists(&self, qd: &SVector<f64, N>) -> Twists<N> {
        let mut v = [Twist::ZERO; N];
        for (k, slot) in v.iter_mut().take(self.bodies.len()).enumerate() {
            *slot = Twist {
                v: Vector2::new(qd[3 * k], qd[3 * k + 1]),
                w: qd[3 * k + 2],
            };
        }
        v
    }

    pub(super) fn eval_phi(&self, p: &Poses<N>, t: f64) -> SVector<f64, N> {
        let mut out = SVector::<f64, N>::zeros();
        for nj in &self.joints {
            let (bi, bj) = nj.joint.bodies();
            let f = nj.joint.phi(&pose_of(p, bi), &pose_of(p, bj), t);
            for (k, v) in f.iter().take(nj.joint.equations()).enumerate() {
                out[nj.row + k] = *v;
            }
        }
        out
    }

    fn eval_jacobian(&self, p: &Poses<N>, t: f64) -> SMatrix<f64, N, N> {
        self.assemble_jacobian(p, t, false)
    }

    /// D, or the scaled S = R D C when `scaled` (see the module docs).
    pub(super) fn assemble_jacobian(
        &self,
        p: &Poses<N>,
        t: f64,
        scaled: bool,
    ) -> SMatrix<f64, N, N> {
        let mut d = SMatrix::<f64, N, N>::zeros();
        for nj in &self.joints {
            let (bi, bj) = nj.joint.bodies();
            let blocks = nj.joint.jacobian(&pose_of(p, bi), &pose_of(p, bj), t);
            for k in 0..nj.joint.equations() {
                let r = nj.row + k;
                let rs = if scaled { self.row_scale[r] } else { 1.0 };
                for (body, block) in [(bi, &blocks.di[k]), (bj, &blocks.dj[k])] {
                    if let Some(c) = body.offset() {
                        for (m, v) in block.iter().enumerate() {
                            let cs = if scaled { self.col_scale[c + m] } else { 1.0 };
                            d[(r, c + m)] += *v * rs * cs;
                        }
                    }
                }
            }
        }
        d
    }

    pub(super) fn eval_nu(&self, t: f64) -> SVector<f64, N> {
        let mut out = SVector::<f64, N>::zeros();
        for nj in &self.joints {
            let f = nj.joint.nu(t);
            for (k, v) in f.iter().take(nj.joint.equations()).enumerate() {
                out[nj.row + k] = *v;
            }
        }
        out
    }

    pub(super) fn eval_gamma(&self, p: &Poses<N>, v: &Twists<N>, t: f64) -> SVector<f64, N> {
        let mut out = SVector::<f64, N>::zeros();
        for nj in &self.joints {
            let (bi, bj) = nj.joint.bodies();
            let g = nj.joint.gamma(
                &pose_of(p, bi),
                &pose_of(p, bj),
                &twist_of(v, bi),
                &twist_of(v, bj),
                t,
            );
            for (k, x) in g.iter().take(nj.joint.equations()).enumerate() {
                out[nj.row + k] = *x;
            }
        }
        out
    }

    pub(super) fn eval_h(&self, p: &Poses<N>) -> SVector<f64, N> {
        let mut h = SVector::<f64, N>::zeros();
        for (k, b) in self.bodies.iter().enumerate() {
            h[3 * k] = b.mass_kg * self.gravity.x;
            h[3 * k + 1] = b.mass_kg * self.gravity.y;
        }
        for load in &self.loads {
            match *load {
                AppliedLoad::Force {
                    body: BodyId::Moving(k),
                    point,
                    force,
                } => {
                    h[3 * k] += force.x;
                    h[3 * k + 1] += force.y;
                    h[3 * k + 2] += cross(p[k].rotate(point), force);
                }
                AppliedLoad::Torque {
                    body: BodyId::Moving(k),
                    torque_nm,
                } => h[3 * k + 2] += torque_nm,
                _ => {}
            }
        }
        h
    }

    /// Constraint vector Φ(c, t) (thesis eq. 3.25–3.26).
    pub fn constraints(&self, q: &SVector<f64, N>, t: f64) -> SVector<f64, N> {
        self.eval_phi(&self.poses(q), t)
    }

    /// Constraint Jacobian D = ∂Φ/∂c (thesis eq. 3.32–3.33).
    pub fn jacobian(&self, q: &SVector<f64, N>, t: f64) -> SMatrix<f64, N, N> {
        self.eval_jacobian(&self.poses(q), t)
    }

    /// ν = −Φ_t, the right-hand side of D ċ = ν (thesis eq. 3.35).
    pub fn velocity_rhs(&self, t: f64) -> SVector<f64, N> {
        self.eval_nu(t)
    }

    /// γ, the right-hand side of D c̈ = γ (thesis eq. 3.36–3.38).
    pub fn gamma(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>, t: f64) -> SVector<f64, N> {
        self.eval_gamma(&self.poses(q), &self.twists(qd), t)
    }

    /// Applied forces h (gravity and loads, thesis eq. 3.31).
    pub fn applied_forces(&self, q: &SVector<f64, N>) -> SVector<f64, N> {
        self.eval_h(&self.poses(q))
    }

    /// Kinetic energy ½ ċᵀ M ċ (thesis eq. 3.4 per body).
    pub fn kinetic_energy(&self, qd: &SVector<f64, N>) -> f64 {
        0.5 * qd.component_mul(&self.mass).dot(qd)
    }

    /// Potential energy of gravity, −Σ mᵢ g·rᵢ (J).
    pub fn potential_energy(&self, q: &SVector<f64, N>) -> f64 {
        self.bodies
            .iter()
            .enumerate()
            .map(|(k, b)| -b.mass_kg * (self.gravity.x * q[3 * k] + self.gravity.y * q[3 * k + 1]))
            .sum()
    }

    fn joint_of_row(&self, row: usize) -> (&NamedJoint, usize) {
        let mut found = &self.joints[0];
        for nj in &self.joints {
            if nj.row <= row {
                found = nj;
            }
        }
        (found, row - found.row)
    }

    fn singular_error(&self, s: &SMatrix<f64, N, N>, ratio: f64, t: f64) -> DynamicsError {
        let d = DMatrix::from_column_slice(N, N, s.as_slice());
        let (row, _) = most_dependent_row(&d);
        let (nj, eq) = self.joint_of_row(row);
        DynamicsError::SingularJacobian {
            t_s: t,
            joint: nj.name.clone(),
            row,
            equation: eq + 1,
            pivot_ratio: ratio,
            threshold: self.options.pivot_threshold,
        }
    }

    /// Factorise the *scaled* Jacobian `s`, refusing a singular one: partial
    /// pivoting first; when its relative pivot comes within
    /// [`RANK_CONFIRM`] of singular, complete pivoting (rank-revealing) decides
    /// and is used instead.
    fn factor(&self, s: &SMatrix<f64, N, N>, t: f64) -> Result<Factorization<N>> {
        let partial = Factorization::Partial(s.lu());
        if partial.pivot_ratio() >= RANK_CONFIRM.max(self.options.pivot_threshold) {
            return Ok(partial);
        }
        let full = Factorization::Full(s.full_piv_lu());
        let ratio = full.pivot_ratio();
        if ratio < self.options.pivot_threshold {
            return Err(self.singular_error(s, ratio, t));
        }
        Ok(full)
    }

    /// Rank diagnosis of D at a configuration: `Err(SingularJacobian)` naming
    /// the dependent joint, or the relative pivot.
    pub fn check_jacobian(&self, q: &SVector<f64, N>, t: f64) -> Result<f64> {
        if self.equations < N {
            // the padded zero rows would always count as dependent
            return self.check_active_rows(q, t);
        }
        let s = self.assemble_jacobian(&self.poses(q), t, true);
        let ratio = Factorization::Full(s.full_piv_lu()).pivot_ratio();
        if ratio < self.options.pivot_threshold {
            return Err(self.singular_error(&s, ratio, t));
        }
        Ok(ratio)
    }

    /// Newton–Raphson on Φ(c, t) = 0 from `guess`; returns the converged
    /// coordinates, their poses, the LU of D there (checked for rank at every
    /// iterate, see [`factor`](Self::factor)) and the iteration count.
    fn newton(
        &self,
        t: f64,
        guess: &SVector<f64, N>,
    ) -> Result<(SVector<f64, N>, Poses<N>, Factorization<N>, usize)> {
        if self.equations < N {
            return Err(DynamicsError::ConstraintCount {
                equations: self.equations,
                coordinates: N,
                detail: format!(
                    "; this system keeps {} degree(s) of freedom (built for forward dynamics)",
                    N - self.equations
                ),
            });
        }
        let tol = self.options.tolerance * self.length_scale;
        let mut q = *guess;
        let mut res = f64::INFINITY;
        let mut worst_row = 0usize;
        for it in 0..=self.options.max_iterations {
            let poses = self.poses(&q);
            let phi = self.eval_phi(&poses, t);
            res = 0.0;
            for r in 0..N {
                let v = (phi[r] * self.row_scale[r]).abs();
                if !v.is_finite() {
                    return Err(DynamicsError::NonFinite {
                        t_s: t,
                        what: "constraint residual",
                    });
                }
                if v > res {
                    res = v;
                    worst_row = r;
                }
            }
            if res > 1e6 * self.length_scale {
                break; // diverging: report below
            }
            let d = self.assemble_jacobian(&poses, t, true);
            let lu = self.factor(&d, t)?;
            if res <= tol {
                return Ok((q, poses, lu, it));
            }
            if it == self.options.max_iterations {
                break;
            }
            let step = lu.solve(&-phi.component_mul(&self.row_scale));
            q += step.component_mul(&self.col_scale);
        }
        let (nj, _) = self.joint_of_row(worst_row);
        Err(DynamicsError::NoConvergence {
            t_s: t,
            iterations: self.options.max_iterations,
            residual: res,
            tolerance: tol,
            joint: nj.name.clone(),
        })
    }

    /// Position, velocity and acceleration analysis plus Lagrange multipliers
    /// at time `t`, Newton started from `guess`.
    pub fn analyze(&self, t: f64, guess: &SVector<f64, N>) -> Result<KinematicSolution<N>> {
        if !t.is_finite() {
            return Err(DynamicsError::NonFinite {
                t_s: t,
                what: "time",
            });
        }
        let (q, poses, lu, iterations) = self.newton(t, guess)?;
        // velocity: D qd = nu
        let qd = lu
            .solve(&self.eval_nu(t).component_mul(&self.row_scale))
            .component_mul(&self.col_scale);
        let twists = self.twists(&qd);
        // acceleration: D qdd = gamma
        let gamma = self.eval_gamma(&poses, &twists, t);
        let qdd = lu
            .solve(&gamma.component_mul(&self.row_scale))
            .component_mul(&self.col_scale);
        // multipliers: D^T lambda = M qdd - h
        let rhs = self.mass.component_mul(&qdd) - self.eval_h(&poses);
        let lambda = lu
            .solve_transpose(&rhs.component_mul(&self.col_scale))
            .component_mul(&self.row_scale);
        for (v, what) in [
            (&qd, "velocities"),
            (&qdd, "accelerations"),
            (&lambda, "Lagrange multipliers"),
        ] {
            if !v.iter().all(|x| x.is_finite()) {
                return Err(DynamicsError::NonFinite { t_s: t, what });
            }
        }
        Ok(KinematicSolution {
            t,
            q,
            qd,
            qdd,
            lambda,
            newton_iterations: iterations,
            pivot_ratio: lu.pivot_ratio(),
        })
    }

    /// Reaction of joint `index` on its two bodies at a solution.
    pub fn reaction(&self, index: usize, sol: &KinematicSolution<N>) -> Option<JointReaction> {
        let nj = self.joints.get(index)?;
        let poses = self.poses(&sol.q);
        let (bi, bj) = nj.joint.bodies();
        let blocks = nj
            .joint
            .jacobian(&pose_of(&poses, bi), &pose_of(&poses, bj), sol.t);
        let mut on_i = [0.0; 3];
        let mut on_j = [0.0; 3];
        for k in 0..nj.joint.equations() {
            let l = sol.lambda[nj.row + k];
            for m in 0..3 {
                on_i[m] += blocks.di[k][m] * l;
                on_j[m] += blocks.dj[k][m] * l;
            }
        }
        let g = |a: [f64; 3]| GeneralizedForce {
            fx_n: a[0],
            fy_n: a[1],
            torque_nm: a[2],
        };
        Some(JointReaction {
            joint: nj.name.clone(),
            on_i: g(on_i),
            on_j: g(on_j),
        })
    }

    /// Reactions of all joints.
    pub fn reactions(&self, sol: &KinematicSolution<N>) -> Vec<JointReaction> {
        (0..self.joints.len())
            .filter_map(|k| self.reaction(k, sol))
            .collect()
    }

    /// A tracker that follows the motion from an assembly guess.
    pub fn tracker(&self, guess: SVector<f64, N>) -> Tracker<'_, N> {
        Tracker {
            system: self,
            guess,
            last: None,
            before_last: None,
        }
    }
}

/// Follows a zero-DOF system along time, warm-starting Newton–Raphson with a
/// predictor from the previous solutions: the quintic Hermite polynomial
/// through (c, ċ, c̈) at the last two solved times, extrapolated (error
/// O(h⁶), so that one Newton step usually converges), or the Taylor
/// polynomial c + h ċ + ½ h² c̈ after the first solve. Steps whose predicted
/// angle change exceeds [`SolverOptions::max_angle_step_rad`] are subdivided,
/// and a step where Newton fails is retried with 8× finer substeps (up to
/// [`SolverOptions::max_substeps`]).
#[derive(Clone, Debug)]
pub struct Tracker<'a, const N: usize> {
    system: &'a MultibodySystem<N>,
    guess: SVector<f64, N>,
    last: Option<KinematicSolution<N>>,
    before_last: Option<KinematicSolution<N>>,
}

/// Predict c(t) from the solution `cur` and, if available, an earlier one.
fn predict<const N: usize>(
    cur: &KinematicSolution<N>,
    prev: Option<&KinematicSolution<N>>,
    t: f64,
) -> SVector<f64, N> {
    let h = t - cur.t;
    let taylor = cur.q + cur.qd * h + cur.qdd * (0.5 * h * h);
    let Some(p) = prev else {
        return taylor;
    };
    let d = p.t - cur.t;
    // only extrapolate over at most ~2 previous intervals; otherwise Taylor
    if d == 0.0 || !d.is_finite() || (h / d).abs() > 2.0 {
        return taylor;
    }
    // p(s) = q + qd s + qdd s^2/2 + b3 (s/d)^3 + b4 (s/d)^4 + b5 (s/d)^5 matching q, qd, qdd at s = d
    let r0 = p.q - (cur.q + cur.qd * d + cur.qdd * (0.5 * d * d));
    let r1 = (p.qd - (cur.qd + cur.qdd * d)) * d;
    let r2 = (p.qdd - cur.qdd) * (d * d);
    let u = r1 - r0 * 3.0;
    let v = r2 - r0 * 6.0;
    let b5 = (v - u * 6.0) * 0.5;
    let b4 = u - b5 * 2.0;
    let b3 = r0 - b4 - b5;
    let x = h / d;
    taylor + b3 * (x * x * x) + b4 * (x * x * x * x) + b5 * (x * x * x * x * x)
}

impl<const N: usize> Tracker<'_, N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    /// The last solution.
    pub fn last(&self) -> Option<&KinematicSolution<N>> {
        self.last.as_ref()
    }

    /// Solve at time `t` (the first call assembles from the guess).
    pub fn solve_at(&mut self, t: f64) -> Result<&KinematicSolution<N>> {
        match self.last {
            None => {
                let sol = self.system.analyze(t, &self.guess)?;
                Ok(self.last.insert(sol))
            }
            Some(cur) => {
                self.advance(cur, t)?;
                self.last.as_ref().ok_or(DynamicsError::NonFinite {
                    t_s: t,
                    what: "tracker state",
                })
            }
        }
    }

    fn advance(&mut self, cur: KinematicSolution<N>, t: f64) -> Result<()> {
        let sys = self.system;
        let h = t - cur.t;
        if !h.is_finite() {
            return Err(DynamicsError::NonFinite {
                t_s: t,
                what: "time",
            });
        }
        let mut dphi = 0.0f64;
        for k in 0..sys.bodies.len() {
            let i = 3 * k + 2;
            dphi = dphi.max((cur.qd[i] * h).abs() + 0.5 * (cur.qdd[i] * h * h).abs());
        }
        let max_sub = sys.options.max_substeps;
        let mut n = ((dphi / sys.options.max_angle_step_rad).ceil() as usize).clamp(1, max_sub);
        let prev = self.before_last;
        loop {
            match self.substeps(t, n) {
                Ok(()) => return Ok(()),
                Err(DynamicsError::NoConvergence { .. }) if n < max_sub => {
                    // restart the interval with finer substeps
                    self.last = Some(cur);
                    self.before_last = prev;
                    n = (n * 8).min(max_sub);
                }
                Err(e) => return Err(e),
            }
        }
    }

    fn substeps(&mut self, t: f64, n: usize) -> Result<()> {
        let Some(start) = self.last else {
            return Err(DynamicsError::NonFinite {
                t_s: t,
                what: "tracker state",
            });
        };
        let t0 = start.t;
        for k in 1..=n {
            let tk = if k == n {
                t
            } else {
                t0 + (t - t0) * (k as f64) / (n as f64)
            };
            let next = match &self.last {
                Some(cur) => {
                    let guess = predict(cur, self.before_last.as_ref(), tk);
                    self.system.analyze(tk, &guess)?
                }
                None => {
                    return Err(DynamicsError::NonFinite {
                        t_s: tk,
                        what: "tracker state",
                    });
                }
            };
            self.before_last = self.last.replace(next);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SMatrix;

    /// A crank–slider with an offset rod centroid, a crank centroid off O, a
    /// piston force and gravity, built directly on the core.
    fn crank_slider(motion: CrankMotion) -> MultibodySystem<9> {
        let (r, l, l1, off, e) = (0.05, 0.16, 0.06, 0.004, 0.01);
        let mut b = MultibodyBuilder::new();
        let crank = b.add_body("crank", 8.0, 0.015);
        let rod = b.add_body("rod", 3.0, 0.02);
        let piston = b.add_body("piston", 5.0, 0.0);
        b.add_revolute(
            "O",
            BodyId::Ground,
            Vector2::zeros(),
            crank,
            Vector2::new(-e, 0.0),
        )
        .add_revolute(
            "A",
            crank,
            Vector2::new(r - e, 0.0),
            rod,
            Vector2::new(-l1, -off),
        )
        .add_revolute(
            "B",
            rod,
            Vector2::new(l - l1, -off),
            piston,
            Vector2::zeros(),
        )
        .add_translational(
            "slide",
            BodyId::Ground,
            Vector2::zeros(),
            Vector2::new(1.0, 0.0),
            piston,
            Vector2::zeros(),
            0.0,
        )
        .add_driving("drive", BodyId::Ground, crank, motion)
        .add_load(AppliedLoad::Force {
            body: piston,
            point: Vector2::zeros(),
            force: Vector2::new(-150.0, 0.0),
        })
        .add_load(AppliedLoad::Torque {
            body: rod,
            torque_nm: 0.7,
        })
        .gravity(Vector2::new(0.0, -9.81));
        b.build::<9>().expect("valid model")
    }

    fn guess() -> SVector<f64, 9> {
        SVector::<f64, 9>::from_column_slice(&[0.01, 0.0, 0.0, 0.11, 0.004, 0.0, 0.21, 0.0, 0.0])
    }

    #[test]
    fn system_jacobian_matches_finite_differences() {
        let sys = crank_slider(CrankMotion::constant_speed(10.0));
        let q = SVector::<f64, 9>::from_column_slice(&[
            0.01, 0.02, 0.3, 0.1, 0.01, -0.2, 0.2, 0.003, 0.05,
        ]);
        let d = sys.jacobian(&q, 0.1);
        let h = 1e-6;
        for c in 0..9 {
            let mut qp = q;
            let mut qm = q;
            qp[c] += h;
            qm[c] -= h;
            let col = (sys.constraints(&qp, 0.1) - sys.constraints(&qm, 0.1)) / (2.0 * h);
            for r in 0..9 {
                assert!((col[r] - d[(r, c)]).abs() < 1e-8, "D[{r},{c}]");
            }
        }
    }

    #[test]
    fn block_system_of_eq_3_38_is_satisfied() {
        let sys = crank_slider(CrankMotion::Harmonic {
            phi0_rad: 0.4,
            omega_rad_s: 60.0,
            amplitude_rad: 0.2,
            frequency_rad_s: 90.0,
        });
        let sol = sys.analyze(0.0, &guess()).expect("assembles");
        let t = sol.t;
        let d = sys.jacobian(&sol.q, t);
        let h = sys.applied_forces(&sol.q);
        let g = sys.gamma(&sol.q, &sol.qd, t);
        // assemble [M -D^T; D 0] [qdd; lambda] = [h; gamma] and solve it directly
        let mut a = SMatrix::<f64, 18, 18>::zeros();
        let mut rhs = SVector::<f64, 18>::zeros();
        for i in 0..9 {
            a[(i, i)] = sys.mass_diagonal()[i];
            rhs[i] = h[i];
            rhs[9 + i] = g[i];
            for j in 0..9 {
                a[(i, 9 + j)] = -d[(j, i)];
                a[(9 + i, j)] = d[(i, j)];
            }
        }
        let x = a.lu().solve(&rhs).expect("regular block system");
        let scale = sol.lambda.amax();
        for i in 0..9 {
            assert!((x[i] - sol.qdd[i]).abs() < 1e-9 * (1.0 + sol.qdd.amax()));
            assert!((x[9 + i] - sol.lambda[i]).abs() < 1e-9 * scale);
        }
        // and the position / velocity equations hold
        assert!(sys.constraints(&sol.q, t).amax() < 1e-13);
        assert!((d * sol.qd - sys.velocity_rhs(t)).amax() < 1e-10);
    }

    #[test]
    fn power_balance_drive_torque_times_speed_equals_energy_rate() {
        // independent check of the inverse dynamics: P_drive + P_loads = d/dt (T + V),
        // with d/dt by central differences of the *positions/velocities* only
        let motion = CrankMotion::Harmonic {
            phi0_rad: 0.1,
            omega_rad_s: 50.0,
            amplitude_rad: 0.3,
            frequency_rad_s: 70.0,
        };
        let sys = crank_slider(motion);
        let drive = sys.joint_index("drive").expect("drive");
        let row = sys.joints()[drive].row;
        let mut tr = sys.tracker(guess());
        let energy =
            |s: &KinematicSolution<9>| sys.kinetic_energy(&s.qd) + sys.potential_energy(&s.q);
        let dt = 1e-5;
        for k in 0..40 {
            let t = 0.0031 * k as f64 + 0.002;
            let em2 = energy(tr.solve_at(t - 2.0 * dt).expect("solves"));
            let em1 = energy(tr.solve_at(t - dt).expect("solves"));
            let s = *tr.solve_at(t).expect("solves");
            let ep1 = energy(tr.solve_at(t + dt).expect("solves"));
            let ep2 = energy(tr.solve_at(t + 2.0 * dt).expect("solves"));
            let de = (em2 - 8.0 * em1 + 8.0 * ep1 - ep2) / (12.0 * dt);
            let p_drive = s.lambda[row] * motion.sample(t).omega;
            // loads: piston force -150 N along x at piston; torque 0.7 N m on the rod
            let p_loads = -150.0 * s.qd[6] + 0.7 * s.qd[5];
            let scale = p_drive.abs().max(1.0);
            assert!(
                (p_drive + p_loads - de).abs() < 1e-6 * scale,
                "t = {t}: drive {p_drive} loads {p_loads} dE/dt {de}"
            );
        }
    }

    #[test]
    fn reactions_balance_each_body() {
        let sys = crank_slider(CrankMotion::constant_speed(100.0));
        let sol = sys.analyze(0.0, &guess()).expect("assembles");
        let h = sys.applied_forces(&sol.q);
        let mut total = SVector::<f64, 9>::zeros();
        for (k, nj) in sys.joints().iter().enumerate() {
            let r = sys.reaction(k, &sol).expect("joint");
            let (bi, bj) = nj.joint.bodies();
            for (b, f) in [(bi, r.on_i), (bj, r.on_j)] {
                if let Some(o) = b.offset() {
                    total[o] += f.fx_n;
                    total[o + 1] += f.fy_n;
                    total[o + 2] += f.torque_nm;
                }
            }
        }
        // M qdd = h + sum of reactions
        let m = sys.mass_diagonal();
        for i in 0..9 {
            assert!((m[i] * sol.qdd[i] - h[i] - total[i]).abs() < 1e-9 * (1.0 + total.amax()));
        }
        // revolute A: action = -reaction
        let a = sys.reaction(1, &sol).expect("A");
        assert!(
            (a.on_i.fx_n + a.on_j.fx_n).abs() < 1e-12 && (a.on_i.fy_n + a.on_j.fy_n).abs() < 1e-12
        );
    }

    #[test]
    fn count_and_model_errors() {
        let mut b = MultibodyBuilder::new();
        let c = b.add_body("c", 1.0, 0.1);
        b.add_revolute("O", BodyId::Ground, Vector2::zeros(), c, Vector2::zeros());
        let e = b.build::<3>().unwrap_err();
        assert!(
            matches!(
                e,
                DynamicsError::ConstraintCount {
                    equations: 2,
                    coordinates: 3,
                    ..
                }
            ),
            "{e}"
        );
        b.add_driving("drive", BodyId::Ground, c, CrankMotion::constant_speed(1.0));
        assert!(b.build::<3>().is_ok());
        assert!(matches!(
            b.build::<6>(),
            Err(DynamicsError::InvalidModel(_))
        ));
        b.add_revolute(
            "again",
            BodyId::Ground,
            Vector2::zeros(),
            c,
            Vector2::zeros(),
        );
        let e = b.build::<3>().unwrap_err().to_string();
        assert!(e.contains("'again'"), "{e}");
        let mut b = MultibodyBuilder::new();
        let c = b.add_body("c", -1.0, 0.1);
        b.add_revolute("O", BodyId::Ground, Vector2::zeros(), c, Vector2::zeros())
            .add_driving("d", BodyId::Ground, c, CrankMotion::constant_speed(1.0));
        let e = b.build::<3>().unwrap_err().to_string();
        assert!(e.contains("mass_kg") && e.contains("'c'"), "{e}");
        let mut b = MultibodyBuilder::new();
        let c = b.add_body("c", 1.0, 0.1);
        b.add_revolute("self", c, Vector2::zeros(), c, Vector2::zeros())
            .add_driving("d", BodyId::Ground, c, CrankMotion::constant_speed(1.0));
        assert!(matches!(
            b.build::<3>(),
            Err(DynamicsError::InvalidModel(_))
        ));
    }
}
