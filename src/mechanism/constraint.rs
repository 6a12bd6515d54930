//! The common interface of kinematic constraints (joints).
//!
//! A joint k between bodies i and j contributes `equations()` rows to
//!
//! * Φ(c, t) = 0 — the constraint vector (thesis eq. 2.15, 3.25–3.26),
//! * D = ∂Φ/∂c — the Jacobian (thesis eq. 3.32–3.33),
//! * ν = −∂Φ/∂t — right-hand side of the velocity equation D ċ = ν
//!   (thesis eq. 3.35 for time-independent joints, ν = 0),
//! * γ = −(D ċ)_c ċ − 2 D_t ċ − Φ_tt — right-hand side of the acceleration
//!   equation D c̈ = γ (thesis eq. 3.36–3.38, γ = −Ḋ ċ; Nikravesh 1988,
//!   kinematic analysis),
//!
//! and, through the Lagrange multipliers λ_k of its rows, the generalized
//! reaction D_{k,i}ᵀ λ_k on body i and D_{k,j}ᵀ λ_k on body j (thesis eq. 3.27,
//! M c̈ = h + Dᵀλ).
//!
//! Each joint type lives in its own file, implements [`ConstraintEquations`]
//! there and states its equations: [`Revolute`](super::revolute::Revolute),
//! [`Translational`](super::translational::Translational),
//! [`Driving`](super::driving::Driving); the enum that dispatches over them is
//! [`Joint`](super::joint::Joint). This file imports none of them.

use super::body::{BodyId, Pose, Twist};

/// Jacobian rows of one joint, split into the 3 columns (x, y, φ) of each of
/// its two bodies. Only the first `equations()` rows are meaningful.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JacobianBlocks {
    /// ∂Φ_k/∂(x_i, y_i, φ_i).
    pub di: [[f64; 3]; 2],
    /// ∂Φ_k/∂(x_j, y_j, φ_j).
    pub dj: [[f64; 3]; 2],
}

/// Equations of one joint between body i and body j (at most two rows).
pub trait ConstraintEquations {
    /// Number of scalar equations (1 or 2).
    fn equations(&self) -> usize;
    /// The two bodies (i, j).
    fn bodies(&self) -> (BodyId, BodyId);
    /// Whether row `k` is an angle equation (measured in rad, not m); used to
    /// scale residuals and the Jacobian to common length units.
    fn is_angle_row(&self, k: usize) -> bool;
    /// Φ rows.
    fn phi(&self, pi: &Pose, pj: &Pose, t: f64) -> [f64; 2];
    /// D rows.
    fn jacobian(&self, pi: &Pose, pj: &Pose, t: f64) -> JacobianBlocks;
    /// ν = −Φ_t rows.
    fn nu(&self, t: f64) -> [f64; 2];
    /// γ rows.
    fn gamma(&self, pi: &Pose, pj: &Pose, vi: &Twist, vj: &Twist, t: f64) -> [f64; 2];
}

/// Test helpers shared by the joint files: finite-difference checks of D
/// against Φ and of γ against −Ḋ ċ.
#[cfg(test)]
pub(crate) mod testing {
    use super::*;
    use nalgebra::Vector2;

    /// Pose from an (x, y, φ) triple.
    pub fn pose(c: [f64; 3]) -> Pose {
        Pose::new(c[0], c[1], c[2])
    }

    /// Check D against central differences of Φ, and γ against
    /// −(D(c + h ċ) − D(c − h ċ))/(2h) ċ (time-independent joints), at an
    /// arbitrary, not necessarily assembled, configuration.
    pub fn check_joint<J: ConstraintEquations>(
        j: &J,
        ci: [f64; 3],
        cj: [f64; 3],
        vi: [f64; 3],
        vj: [f64; 3],
    ) {
        let t = 0.3;
        let (pi, pj) = (pose(ci), pose(cj));
        let d = j.jacobian(&pi, &pj, t);
        let h = 1e-6;
        let ground_i = j.bodies().0 == BodyId::Ground;
        let ground_j = j.bodies().1 == BodyId::Ground;
        for col in 0..3 {
            let mut cp = ci;
            let mut cm = ci;
            cp[col] += h;
            cm[col] -= h;
            let fp = j.phi(&pose(cp), &pj, t);
            let fm = j.phi(&pose(cm), &pj, t);
            for row in 0..j.equations() {
                let fd = (fp[row] - fm[row]) / (2.0 * h);
                if !ground_i {
                    let an = d.di[row][col];
                    assert!(
                        (fd - an).abs() < 1e-8,
                        "di row {row} col {col}: fd {fd} vs {an}"
                    );
                }
            }
            let mut cp = cj;
            let mut cm = cj;
            cp[col] += h;
            cm[col] -= h;
            let fp = j.phi(&pi, &pose(cp), t);
            let fm = j.phi(&pi, &pose(cm), t);
            for row in 0..j.equations() {
                let fd = (fp[row] - fm[row]) / (2.0 * h);
                if !ground_j {
                    let an = d.dj[row][col];
                    assert!(
                        (fd - an).abs() < 1e-8,
                        "dj row {row} col {col}: fd {fd} vs {an}"
                    );
                }
            }
        }
        // gamma = -Ddot cdot, Ddot by central differences along the velocity
        let vi = if ground_i { [0.0; 3] } else { vi };
        let vj = if ground_j { [0.0; 3] } else { vj };
        let step =
            |c: [f64; 3], v: [f64; 3], s: f64| [c[0] + s * v[0], c[1] + s * v[1], c[2] + s * v[2]];
        let dp = j.jacobian(&pose(step(ci, vi, h)), &pose(step(cj, vj, h)), t);
        let dm = j.jacobian(&pose(step(ci, vi, -h)), &pose(step(cj, vj, -h)), t);
        let twist = |v: [f64; 3]| Twist {
            v: Vector2::new(v[0], v[1]),
            w: v[2],
        };
        let g = j.gamma(&pi, &pj, &twist(vi), &twist(vj), t);
        for (row, gr) in g.iter().enumerate().take(j.equations()) {
            let mut ddot_cdot = 0.0;
            for col in 0..3 {
                ddot_cdot += (dp.di[row][col] - dm.di[row][col]) / (2.0 * h) * vi[col];
                ddot_cdot += (dp.dj[row][col] - dm.dj[row][col]) / (2.0 * h) * vj[col];
            }
            assert!(
                (gr + ddot_cdot).abs() < 1e-6 * (1.0 + gr.abs()),
                "gamma row {row}: {gr} vs {}",
                -ddot_cdot
            );
        }
    }
}
