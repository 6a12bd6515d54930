//! Assembly of the system quantities from the joints' and bodies'
//! contributions, thesis §3.2: the constraint vector Φ (eq. 3.25–3.26), its
//! Jacobian D (eq. 3.32–3.33; plain or scaled S = R D C), ν = −Φ_t
//! (eq. 3.35), γ (eq. 3.36–3.38), the applied forces h (eq. 3.31), the mass
//! matrix M (eq. 3.28–3.29) and the kinetic and potential energies.

use nalgebra::{Const, DimMin, SMatrix, SVector, Vector2};

use super::super::body::{BodyId, Pose, Twist, cross};
use super::super::constraint::ConstraintEquations;
use super::{AppliedLoad, MultibodySystem, Poses, Twists, pose_of, twist_of};

impl<const N: usize> MultibodySystem<N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    pub(in crate::mechanism) fn poses(&self, q: &SVector<f64, N>) -> Poses<N> {
        let mut p = [Pose::GROUND; N];
        for (k, slot) in p.iter_mut().take(self.bodies.len()).enumerate() {
            *slot = Pose::new(q[3 * k], q[3 * k + 1], q[3 * k + 2]);
        }
        p
    }

    pub(in crate::mechanism) fn twists(&self, qd: &SVector<f64, N>) -> Twists<N> {
        let mut v = [Twist::ZERO; N];
        for (k, slot) in v.iter_mut().take(self.bodies.len()).enumerate() {
            *slot = Twist {
                v: Vector2::new(qd[3 * k], qd[3 * k + 1]),
                w: qd[3 * k + 2],
            };
        }
        v
    }

    pub(in crate::mechanism) fn eval_phi(&self, p: &Poses<N>, t: f64) -> SVector<f64, N> {
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
    pub(in crate::mechanism) fn assemble_jacobian(
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

    pub(in crate::mechanism) fn eval_nu(&self, t: f64) -> SVector<f64, N> {
        let mut out = SVector::<f64, N>::zeros();
        for nj in &self.joints {
            let f = nj.joint.nu(t);
            for (k, v) in f.iter().take(nj.joint.equations()).enumerate() {
                out[nj.row + k] = *v;
            }
        }
        out
    }

    pub(in crate::mechanism) fn eval_gamma(
        &self,
        p: &Poses<N>,
        v: &Twists<N>,
        t: f64,
    ) -> SVector<f64, N> {
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

    pub(in crate::mechanism) fn eval_h(&self, p: &Poses<N>) -> SVector<f64, N> {
        let mut h = SVector::<f64, N>::zeros();
        for (k, b) in self.bodies.iter().enumerate() {
            h[3 * k] = b.mass_kg * self.gravity.x;
            h[3 * k + 1] = b.mass_kg * self.gravity.y;
        }
        for load in &self.loads {
            match load {
                &AppliedLoad::Force {
                    body: BodyId::Moving(k),
                    point,
                    force,
                } => {
                    h[3 * k] += force.x;
                    h[3 * k + 1] += force.y;
                    h[3 * k + 2] += cross(p[k].rotate(point), force);
                }
                &AppliedLoad::Torque {
                    body: BodyId::Moving(k),
                    torque_nm,
                } => h[3 * k + 2] += torque_nm,
                AppliedLoad::GasForce {
                    body: BodyId::Moving(k),
                    point,
                    direction,
                    angle_of,
                    force,
                } => {
                    let k = *k;
                    let f = direction * force.at(pose_of(p, *angle_of).phi);
                    h[3 * k] += f.x;
                    h[3 * k + 1] += f.y;
                    h[3 * k + 2] += cross(p[k].rotate(*point), f);
                }
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
}
