//! The free crank–slider as a multibody system, built from the `free` scene's data.

use super::super::FreeRunError;
use super::super::loads::G;
use super::super::scene::FreeScene;
use super::ConstraintViolation;
use crate::mechanism::{
    CrankMotion, CrankSlider, MechanismParams, MultibodySystem, RodInertia, SolverOptions,
};
use nalgebra::SVector;

/// Index of the crank angle φ in the body coordinates (crank = body 0, coordinates x, y, φ).
pub const CRANK_PHI: usize = 2;

/// The free crank–slider of a scene: its multibody system (8 constraints, 1 DOF) and a
/// consistent initial state.
#[derive(Debug, Clone)]
pub struct MultibodyCrank {
    /// The system (thesis eq. 3.25–3.31 with `M` on the crank and `F` on the piston).
    pub system: MultibodySystem<9>,
    /// Body coordinates at `t0`, on `Φ = 0` with `φ₂ = φ0`.
    pub q0: SVector<f64, 9>,
    /// Body velocities at `t0`, on `D ċ = 0` with `φ̇₂ = ω0`.
    pub qd0: SVector<f64, 9>,
}

impl MultibodyCrank {
    /// Builds the model of `scene` (module docs of [`super`]); the scene's gas spring is not
    /// part of the multibody model and is refused. The initial state comes from the kinematic
    /// analysis of the same mechanism driven at `φ = φ0 + ω0 t` (position by Newton–Raphson,
    /// velocities from `D ċ = ν`), so it is consistent to the core's tolerance (1e-12 L).
    pub fn new(scene: &FreeScene) -> Result<Self, FreeRunError> {
        if scene.loads.spring.is_some() {
            return Err(FreeRunError::SceneNotSupported(
                "the gas spring is not part of the multibody DAE model".into(),
            ));
        }
        let d = &scene.data;
        let params = MechanismParams {
            crank_radius_m: d.r,
            centre_distance_m: d.l(),
            crank_mass_kg: d.m2,
            crank_inertia_o_kgm2: d.i2,
            crank_eccentricity_m: d.crank_ecc,
            piston_mass_kg: d.m4,
            // F along increasing travel x = (r + l) − x_B, i.e. along global −x
            piston_force_n: -scene.loads.piston_force,
            gravity: scene.loads.gravity,
            g_mps2: G,
        };
        let cs = CrankSlider::new(&params, &RodInertia::new(d.m3, d.l1, d.i_s3))?;
        let system = cs.free_multibody(scene.loads.torque, SolverOptions::default())?;
        let driven = cs.multibody(CrankMotion::ConstantSpeed {
            phi0_rad: scene.phi0,
            omega_rad_s: scene.omega0,
        })?;
        let start = driven.analyze(0.0, &cs.assembly_guess(scene.phi0))?;
        Ok(Self {
            system,
            q0: start.q,
            qd0: start.qd,
        })
    }

    /// The largest constraint violation over states `y = [c; ċ]` stored row-major (as
    /// [`crate::integrators::Solution::y`] stores them).
    pub fn drift(&self, t: &[f64], y: &[f64]) -> ConstraintViolation {
        t.iter()
            .zip(y.chunks_exact(18))
            .map(|(&t, y)| {
                let q = SVector::<f64, 9>::from_column_slice(&y[..9]);
                let qd = SVector::<f64, 9>::from_column_slice(&y[9..]);
                self.system.constraint_violation(&q, &qd, t)
            })
            .fold(ConstraintViolation::default(), ConstraintViolation::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::free_run::{Loads, ReducedModel};

    /// The multibody and the reduced model agree on the crank's acceleration at any
    /// consistent state (same mechanics, two formulations): M c̈ = h + Dᵀλ against eq. 4.1.
    #[test]
    fn forward_dynamics_matches_the_reduced_equation_of_motion() {
        for gravity in [false, true] {
            for (phi0, omega0) in [(0.0, 0.0), (0.9, 12.0), (2.5, -7.0), (4.4, 40.0)] {
                let mut scene = FreeScene::thesis();
                scene.loads.gravity = gravity;
                scene.phi0 = phi0;
                scene.omega0 = omega0;
                let mb = MultibodyCrank::new(&scene).unwrap();
                let v = mb.system.constraint_violation(&mb.q0, &mb.qd0, 0.0);
                // Newton–Raphson of the driven analysis stops at 1e-12 L (L ≈ 0.1 m)
                assert!(v.position < 1e-13 && v.velocity < 1e-13, "{v:?}");
                assert!((mb.q0[CRANK_PHI] - phi0).abs() < 1e-15);
                assert!((mb.qd0[CRANK_PHI] - omega0).abs() < 1e-13);
                let f = mb
                    .system
                    .forward_dynamics(&mb.q0, &mb.qd0, 0.0, None)
                    .unwrap();
                let reduced = ReducedModel::new(scene.data).unwrap();
                let loads = Loads {
                    gravity,
                    ..scene.loads
                };
                let want = reduced.acceleration(&loads, phi0, omega0);
                assert!(
                    (f.qdd[CRANK_PHI] - want).abs() < 1e-11 * (1.0 + want.abs()),
                    "φ0 = {phi0}, ω0 = {omega0}, gravity {gravity}: {} vs {want}",
                    f.qdd[CRANK_PHI]
                );
            }
        }
    }

    #[test]
    fn spring_and_bad_data_are_refused() {
        let e = MultibodyCrank::new(&FreeScene::stiff_spring(1e8, 1e7)).unwrap_err();
        assert!(e.to_string().contains("gas spring"), "{e}");
        let e = MultibodyCrank::new(&FreeScene::near_toggle(1.0)).unwrap_err();
        assert!(e.to_string().contains("cannot turn"), "{e}");
    }
}
