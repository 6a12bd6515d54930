//! [`MultibodyBuilder`]: collects bodies, joints (revolute, translational,
//! driving) and applied loads, validates them (positive masses, existing
//! bodies, finite points, the constraint count of a zero-DOF system or of one
//! with degrees of freedom) and freezes a [`MultibodySystem`] with its row
//! and column scaling R, C (see the module docs of [`super`], "Scaling").

use nalgebra::{SVector, Vector2};

use super::super::body::{Body, BodyId};
use super::super::constraint::ConstraintEquations;
use super::super::driving::Driving;
use super::super::error::{DynamicsError, Result, non_negative, positive};
use super::super::joint::Joint;
use super::super::motion::CrankMotion;
use super::super::revolute::Revolute;
use super::super::translational::Translational;
use super::{AppliedLoad, MultibodySystem, NamedJoint, SolverOptions};

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
    /// forward dynamics ([`forward`](super::super::forward)); its kinematic analysis
    /// ([`MultibodySystem::analyze`]) is refused with
    /// [`DynamicsError::ConstraintCount`](super::super::error::DynamicsError::ConstraintCount).
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
            let (body, ok) = match load {
                &AppliedLoad::Force { body, point, force } => {
                    (body, vec_finite(point) && vec_finite(force))
                }
                &AppliedLoad::Torque { body, torque_nm } => (body, torque_nm.is_finite()),
                AppliedLoad::GasForce {
                    body,
                    point,
                    direction,
                    angle_of,
                    ..
                } => (
                    *body,
                    vec_finite(*point)
                        && vec_finite(*direction)
                        && match *angle_of {
                            BodyId::Ground => true,
                            BodyId::Moving(j) => j < nb,
                        },
                ),
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
