//! Joint reactions from the Lagrange multipliers: the generalized force of
//! joint k on body b is D_{k,b}ᵀ λ_k (thesis eq. 3.27, M c̈ = h + Dᵀλ), a
//! force in the global frame and a moment about the body's reference point.

use nalgebra::{Const, DimMin};

use super::super::constraint::ConstraintEquations;
use super::{KinematicSolution, MultibodySystem, pose_of};

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

impl<const N: usize> MultibodySystem<N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
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
}
