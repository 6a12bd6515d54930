//! The crank–slider of the spec (thesis ch. 2–3), built from a rod's mass
//! properties, as data plus a validated model that both solution methods use.
//!
//! Geometry (global frame, thesis Fig. 2.4, SPEC "The mechanism"):
//! * crank (thesis body 2) turns about O = (0, 0); crank pin A = r (cos φ, sin φ);
//! * rod (body 3) from A to the piston pin B; centre distance l;
//! * piston (body 4) slides on the x axis; B = (r cos φ + l cos ψ, 0) with
//!   sin ψ = (r/l) sin φ (thesis eq. 2.3), so the rod angle is φ₃ = −ψ.
//!
//! Mass properties:
//! * crank: mass m₂, I₂ about O, eccentricity e. **Assumption** (the thesis
//!   gives only |e|): the crank centroid G₂ lies on the crank line OA at the
//!   signed distance e from O, towards A for e > 0 (G₂ = e (cos φ, sin φ)); the
//!   centroidal inertia is I_S2 = I₂ − m₂ e² (parallel axes, thesis eq. 3.43),
//!   which must be positive;
//! * rod: [`RodInertia`]: mass m₃, centroid G₃ = A + l₁ u + offset · n with u
//!   the unit vector A→B and n = rot90(u) (the offset is positive to the left of
//!   A→B, in the plane of motion), I_zz about G₃ normal to the plane;
//! * piston: mass m₄, centroid on the pin axis B (the thesis' ξ₄ = η₄ = 0,
//!   eq. 2.27); its rotational inertia never enters (φ₄ ≡ 0).
//!
//! Loads: gravity g along −y (on by default, switchable) on all three bodies,
//! an optional constant piston force along global +x
//! ([`MechanismParams::piston_force_n`], default 0; for the spec's `free` scene),
//! and an optional gas force F_gas(φ) = p(φ)·A_piston along global −x, a
//! periodic function of the crank angle over the four-stroke cycle
//! ([`CrankSlider::with_gas_force`], [`GasForce`]; none by default).

use nalgebra::{SVector, Vector2};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

use super::body::BodyId;
use super::error::{DynamicsError, Result, finite, non_negative, positive};
use super::gas::GasForce;
use super::linkage::CrankSliderLinkage;
use super::motion::CrankMotion;
use super::system::{
    AppliedLoad, KinematicSolution, MultibodyBuilder, MultibodySystem, SolverOptions,
};

/// Mass properties of a connecting rod in the mechanism frame (SI units).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RodInertia {
    /// Rod mass m₃ (kg).
    pub mass_kg: f64,
    /// Distance l₁ from the crank pin A to the centroid along A→B (m).
    pub l1_m: f64,
    /// Transverse centroid offset, perpendicular to A→B in the plane of
    /// motion, positive to the left of A→B (m). Default 0 when deserialised.
    #[serde(default)]
    pub offset_m: f64,
    /// Moment of inertia about the centroid, about the pin axis z (kg·m²).
    pub i_zz_kgm2: f64,
}

impl RodInertia {
    /// A rod without transverse offset.
    pub fn new(mass_kg: f64, l1_m: f64, i_zz_kgm2: f64) -> RodInertia {
        RodInertia {
            mass_kg,
            l1_m,
            offset_m: 0.0,
            i_zz_kgm2,
        }
    }

    /// The original rod of thesis ch. 3 (m₃ = 4.3069062051 kg, l₁ =
    /// 0.07939460165 m, I_S3 = 0.002520181413 kg·m² as printed). With the
    /// ch. 3 data the spec uses l = l₁ + l₂ = 0.17999999995 m
    /// ([`MechanismParams::centre_distance_m`]), 0.18 m elsewhere.
    pub fn thesis_original() -> RodInertia {
        RodInertia::new(4.3069062051, 0.07939460165, 0.002520181413)
    }

    /// Same rod with a transverse offset.
    pub fn with_offset(mut self, offset_m: f64) -> RodInertia {
        self.offset_m = offset_m;
        self
    }

    /// Refuse non-positive mass/inertia and non-finite lengths.
    pub fn validate(&self) -> Result<()> {
        positive("rod.mass_kg", self.mass_kg)?;
        finite("rod.l1_m", self.l1_m)?;
        finite("rod.offset_m", self.offset_m)?;
        positive("rod.i_zz_kgm2", self.i_zz_kgm2)?;
        Ok(())
    }
}

/// Mechanism data besides the rod, with the spec's defaults.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MechanismParams {
    /// Crank radius r (m). Default 0.046.
    pub crank_radius_m: f64,
    /// Centre distance l of the rod (m). Default 0.18.
    pub centre_distance_m: f64,
    /// Crank mass m₂ (kg). Default 8.9459574505.
    pub crank_mass_kg: f64,
    /// Crank inertia I₂ about O (kg·m²). Default 0.016438481547370.
    pub crank_inertia_o_kgm2: f64,
    /// Signed crank eccentricity e: centroid on OA at e from O, towards A
    /// for e > 0 (m). Default 0.005190636979.
    pub crank_eccentricity_m: f64,
    /// Piston mass m₄ (kg). Default 5.2269229374.
    pub piston_mass_kg: f64,
    /// Constant applied piston force along global +x (N). Default 0.
    pub piston_force_n: f64,
    /// Gravity on (g along −y). Default true.
    pub gravity: bool,
    /// Gravitational acceleration g (m/s²). Default 9.81.
    pub g_mps2: f64,
}

impl Default for MechanismParams {
    fn default() -> Self {
        MechanismParams {
            crank_radius_m: 0.046,
            centre_distance_m: 0.18,
            crank_mass_kg: 8.9459574505,
            crank_inertia_o_kgm2: 0.016438481547370,
            crank_eccentricity_m: 0.005190636979,
            piston_mass_kg: 5.2269229374,
            piston_force_n: 0.0,
            gravity: true,
            g_mps2: 9.81,
        }
    }
}

impl MechanismParams {
    /// Builder starting from the spec's defaults.
    pub fn builder() -> MechanismParamsBuilder {
        MechanismParamsBuilder(MechanismParams::default())
    }

    /// The same parameters with gravity switched on or off.
    pub fn with_gravity(mut self, on: bool) -> MechanismParams {
        self.gravity = on;
        self
    }

    /// The gravitational acceleration vector (0, −g), or zero when off.
    pub fn gravity_vector(&self) -> Vector2<f64> {
        if self.gravity {
            Vector2::new(0.0, -self.g_mps2)
        } else {
            Vector2::zeros()
        }
    }

    /// Check every value; l ≤ r gives [`DynamicsError::CrankCannotTurn`].
    pub fn validate(&self) -> Result<()> {
        let r = positive("crank_radius_m", self.crank_radius_m)?;
        let l = positive("centre_distance_m", self.centre_distance_m)?;
        if l <= r {
            return Err(DynamicsError::CrankCannotTurn { l_m: l, r_m: r });
        }
        let m2 = positive("crank_mass_kg", self.crank_mass_kg)?;
        let i2 = positive("crank_inertia_o_kgm2", self.crank_inertia_o_kgm2)?;
        let e = finite("crank_eccentricity_m", self.crank_eccentricity_m)?;
        if i2 - m2 * e * e <= 0.0 {
            return Err(DynamicsError::InvalidParameter {
                name: "crank_inertia_o_kgm2",
                value: i2,
                reason: format!(
                    "must exceed m2 e^2 = {} kg m^2 so that the centroidal inertia I2 - m2 e^2 \
                     (thesis eq. 3.43) is positive",
                    m2 * e * e
                ),
            });
        }
        positive("piston_mass_kg", self.piston_mass_kg)?;
        finite("piston_force_n", self.piston_force_n)?;
        non_negative("g_mps2", self.g_mps2)?;
        Ok(())
    }
}

/// Builder of [`MechanismParams`]; [`build`](Self::build) validates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MechanismParamsBuilder(MechanismParams);

impl MechanismParamsBuilder {
    /// Crank radius r (m).
    pub fn crank_radius_m(mut self, v: f64) -> Self {
        self.0.crank_radius_m = v;
        self
    }
    /// Centre distance l (m).
    pub fn centre_distance_m(mut self, v: f64) -> Self {
        self.0.centre_distance_m = v;
        self
    }
    /// Crank mass m₂ (kg).
    pub fn crank_mass_kg(mut self, v: f64) -> Self {
        self.0.crank_mass_kg = v;
        self
    }
    /// Crank inertia I₂ about O (kg·m²).
    pub fn crank_inertia_o_kgm2(mut self, v: f64) -> Self {
        self.0.crank_inertia_o_kgm2 = v;
        self
    }
    /// Signed crank eccentricity e (m).
    pub fn crank_eccentricity_m(mut self, v: f64) -> Self {
        self.0.crank_eccentricity_m = v;
        self
    }
    /// Piston mass m₄ (kg).
    pub fn piston_mass_kg(mut self, v: f64) -> Self {
        self.0.piston_mass_kg = v;
        self
    }
    /// Constant piston force along +x (N).
    pub fn piston_force_n(mut self, v: f64) -> Self {
        self.0.piston_force_n = v;
        self
    }
    /// Gravity on/off.
    pub fn gravity(mut self, on: bool) -> Self {
        self.0.gravity = on;
        self
    }
    /// g (m/s²).
    pub fn g_mps2(mut self, v: f64) -> Self {
        self.0.g_mps2 = v;
        self
    }
    /// Validate and return the parameters.
    pub fn build(self) -> Result<MechanismParams> {
        self.0.validate()?;
        Ok(self.0)
    }
}

/// Loads of the crank–slider at one instant, identical in meaning for both
/// methods (global frame, N and N·m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PinLoads {
    /// F_A: force exerted BY the crank ON the rod at the crank pin A.
    pub f_a: Vector2<f64>,
    /// F_B: force exerted BY the rod ON the piston at the piston pin B.
    pub f_b: Vector2<f64>,
    /// F_O: force exerted BY the ground (main bearing) ON the crank at O.
    pub f_o: Vector2<f64>,
    /// Normal force of the slide ON the piston (y component, N).
    pub piston_normal_n: f64,
    /// Reaction couple of the slide ON the piston (N·m; zero with the piston
    /// centroid on the pin axis).
    pub slide_moment_nm: f64,
    /// Driving torque the drive applies ON the crank (N·m).
    pub crank_torque_nm: f64,
}

/// Joint indices of the crank–slider multibody model (rows 0–1, 2–3, 4–5, 6–7, 8).
pub mod joints {
    /// Revolute ground–crank at O (λ = force of the ground on the crank).
    pub const O: usize = 0;
    /// Revolute crank–rod at A (λ = force of the crank on the rod).
    pub const A: usize = 1;
    /// Revolute rod–piston at B (λ = force of the rod on the piston).
    pub const B: usize = 2;
    /// Translational ground–piston along x (λ = [couple, normal force] on the piston).
    pub const SLIDE: usize = 3;
    /// Driving constraint φ₂ = φ(t) (λ = driving torque on the crank); absent
    /// from [`CrankSlider::free_multibody`](super::CrankSlider::free_multibody).
    pub const DRIVE: usize = 4;
}

/// A validated crank–slider: [`MechanismParams`] plus a [`RodInertia`], and
/// optionally the gas force on the piston.
#[derive(Clone, Debug, PartialEq)]
pub struct CrankSlider {
    params: MechanismParams,
    rod: RodInertia,
    gas: Option<Arc<GasForce>>,
}

impl CrankSlider {
    /// Validate and build. Refuses l ≤ r ([`DynamicsError::CrankCannotTurn`]),
    /// non-positive masses or inertias and non-finite input.
    pub fn new(params: &MechanismParams, rod: &RodInertia) -> Result<CrankSlider> {
        params.validate()?;
        rod.validate()?;
        Ok(CrankSlider {
            params: *params,
            rod: *rod,
            gas: None,
        })
    }

    /// The same mechanism with the gas force F_gas(φ) on the piston, directed
    /// along global −x (towards the crank; see [`GasForce`]); both methods
    /// evaluate it at the crank angle of each instant.
    pub fn with_gas_force(mut self, gas: Option<Arc<GasForce>>) -> CrankSlider {
        self.gas = gas;
        self
    }

    /// The gas force, if any.
    pub fn gas_force(&self) -> Option<&GasForce> {
        self.gas.as_deref()
    }

    /// F_gas at crank angle φ (N, positive towards the crank); 0 without a gas force.
    pub fn gas_force_at(&self, phi_rad: f64) -> f64 {
        self.gas.as_ref().map_or(0.0, |g| g.at(phi_rad))
    }

    /// The mechanism parameters.
    pub fn params(&self) -> &MechanismParams {
        &self.params
    }

    /// The rod.
    pub fn rod(&self) -> &RodInertia {
        &self.rod
    }

    /// Centroidal crank inertia I_S2 = I₂ − m₂ e² (thesis eq. 3.43).
    pub fn crank_inertia_centroid_kgm2(&self) -> f64 {
        let p = &self.params;
        p.crank_inertia_o_kgm2 - p.crank_mass_kg * p.crank_eccentricity_m * p.crank_eccentricity_m
    }

    /// The general multibody model of thesis §3.2: 3 moving bodies (crank,
    /// rod, piston; 9 coordinates, eq. 2.14), revolute joints O, A, B (eq. 2.20,
    /// 2.23, 2.25), the slide (eq. 2.28–2.31, here with i = ground, j = piston)
    /// and the driving constraint φ₂ = φ(t): 9 equations. Joint order and
    /// multiplier meaning: see [`joints`].
    pub fn multibody(&self, motion: CrankMotion) -> Result<MultibodySystem<9>> {
        self.multibody_with(motion, SolverOptions::default())
    }

    /// [`multibody`](Self::multibody) with explicit solver options.
    pub fn multibody_with(
        &self,
        motion: CrankMotion,
        options: SolverOptions,
    ) -> Result<MultibodySystem<9>> {
        let mut b = self.joints_and_loads(options);
        b.add_driving("crank drive", BodyId::Ground, BodyId::Moving(0), motion);
        b.build::<9>()
    }

    /// The free crank–slider (thesis eq. 3.25–3.26: the same 9 coordinates,
    /// joints O, A, B and the slide, **no driver**: 8 equations, one degree of
    /// freedom) for forward dynamics ([`forward`](super::forward)), loaded by
    /// a constant torque on the crank (N·m, positive counter-clockwise),
    /// besides the piston force and gravity of the parameters.
    pub fn free_multibody(
        &self,
        crank_torque_nm: f64,
        options: SolverOptions,
    ) -> Result<MultibodySystem<9>> {
        let mut b = self.joints_and_loads(options);
        if crank_torque_nm != 0.0 {
            b.add_load(AppliedLoad::Torque {
                body: BodyId::Moving(0),
                torque_nm: crank_torque_nm,
            });
        }
        b.build_with_dof::<9>()
    }

    /// Bodies, joints O, A, B, slide ([`CrankSliderLinkage`]), gravity, the
    /// piston force and the gas force (a function of the crank's angle φ₂).
    fn joints_and_loads(&self, options: SolverOptions) -> MultibodyBuilder {
        let p = &self.params;
        let linkage = CrankSliderLinkage {
            crank_radius_m: p.crank_radius_m,
            centre_distance_m: p.centre_distance_m,
            crank_centroid_m: p.crank_eccentricity_m,
            rod_l1_m: self.rod.l1_m,
            rod_offset_m: self.rod.offset_m,
            slide_y_m: 0.0,
            masses_kg: [p.crank_mass_kg, self.rod.mass_kg, p.piston_mass_kg],
            inertias_kgm2: [self.crank_inertia_centroid_kgm2(), self.rod.i_zz_kgm2, 0.0],
        };
        let mut b = linkage.builder([
            "O (ground-crank)",
            "A (crank-rod)",
            "B (rod-piston)",
            "slide (ground-piston)",
        ]);
        b.gravity(p.gravity_vector()).options(options);
        if p.piston_force_n != 0.0 {
            b.add_load(AppliedLoad::Force {
                body: CrankSliderLinkage::PISTON,
                point: Vector2::zeros(),
                force: Vector2::new(p.piston_force_n, 0.0),
            });
        }
        if let Some(gas) = &self.gas {
            b.add_load(AppliedLoad::GasForce {
                body: CrankSliderLinkage::PISTON,
                point: Vector2::zeros(),
                direction: Vector2::new(-1.0, 0.0),
                angle_of: CrankSliderLinkage::CRANK,
                force: Arc::clone(gas),
            });
        }
        b
    }

    /// A rough assembly guess for the multibody model at crank angle φ₀: the
    /// crank exact, the rod laid along +x, the piston at A + (l, 0). Newton
    /// assembles the mechanism from it (on the branch with B to the right of O).
    pub fn assembly_guess(&self, phi0_rad: f64) -> SVector<f64, 9> {
        let p = &self.params;
        let (s, c) = phi0_rad.sin_cos();
        let a = Vector2::new(p.crank_radius_m * c, p.crank_radius_m * s);
        SVector::<f64, 9>::from_column_slice(&[
            p.crank_eccentricity_m * c,
            p.crank_eccentricity_m * s,
            phi0_rad,
            a.x + self.rod.l1_m,
            a.y + self.rod.offset_m,
            0.0,
            a.x + p.centre_distance_m,
            0.0,
            0.0,
        ])
    }

    /// Read the loads from the multipliers of a multibody solution of
    /// [`multibody`](Self::multibody) (see [`joints`] for their meaning).
    pub fn loads_from_multibody(
        &self,
        sys: &MultibodySystem<9>,
        sol: &KinematicSolution<9>,
    ) -> PinLoads {
        let row = |k: usize| sys.joints()[k].row;
        let v = |k: usize| Vector2::new(sol.lambda[row(k)], sol.lambda[row(k) + 1]);
        let slide = row(joints::SLIDE);
        PinLoads {
            f_a: v(joints::A),
            f_b: v(joints::B),
            f_o: v(joints::O),
            // slide: generalized force on the piston = (n lambda_2, lambda_1) with n = (0, 1)
            piston_normal_n: sol.lambda[slide + 1],
            slide_moment_nm: sol.lambda[slide],
            crank_torque_nm: sol.lambda[row(joints::DRIVE)],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_spec_values() {
        let p = MechanismParams::default();
        assert_eq!(p.crank_radius_m, 0.046);
        assert_eq!(p.centre_distance_m, 0.18);
        assert_eq!(p.crank_mass_kg, 8.9459574505);
        assert_eq!(p.crank_inertia_o_kgm2, 0.016438481547370);
        assert_eq!(p.crank_eccentricity_m, 0.005190636979);
        assert_eq!(p.piston_mass_kg, 5.2269229374);
        assert!(p.gravity);
        assert_eq!(p.g_mps2, 9.81);
        assert_eq!(MechanismParams::builder().build(), Ok(p));
        // thesis eq. 3.43: I_S2 = I2 - m2 e^2 = 0.01619745319 (printed as 0.1619745319)
        let cs = CrankSlider::new(&p, &RodInertia::thesis_original()).expect("valid");
        assert!((cs.crank_inertia_centroid_kgm2() - 0.01619745319).abs() < 1e-10);
    }

    #[test]
    fn builder_refuses_bad_data() {
        let e = MechanismParams::builder()
            .centre_distance_m(0.046)
            .build()
            .unwrap_err();
        assert!(matches!(e, DynamicsError::CrankCannotTurn { .. }));
        assert!(e.to_string().contains("cannot turn"), "{e}");
        assert!(
            MechanismParams::builder()
                .crank_mass_kg(0.0)
                .build()
                .is_err()
        );
        assert!(
            MechanismParams::builder()
                .piston_mass_kg(f64::NAN)
                .build()
                .is_err()
        );
        assert!(
            MechanismParams::builder()
                .crank_inertia_o_kgm2(1e-5)
                .build()
                .is_err()
        );
        assert!(MechanismParams::builder().g_mps2(-1.0).build().is_err());
        let p = MechanismParams::default();
        assert!(CrankSlider::new(&p, &RodInertia::new(3.0, 0.07, 0.0)).is_err());
        assert!(CrankSlider::new(&p, &RodInertia::new(-3.0, 0.07, 0.02)).is_err());
        assert!(CrankSlider::new(&p, &RodInertia::new(3.0, f64::INFINITY, 0.02)).is_err());
    }

    #[test]
    fn multibody_assembles_and_has_nine_equations() {
        let cs = CrankSlider::new(
            &MechanismParams::default(),
            &RodInertia::thesis_original().with_offset(0.002),
        )
        .expect("valid");
        let sys = cs
            .multibody(CrankMotion::constant_speed(40.0 * std::f64::consts::PI))
            .expect("model");
        assert_eq!(sys.joints().len(), 5);
        assert_eq!(sys.joints()[joints::DRIVE].row, 8);
        let sol = sys
            .analyze(0.0, &cs.assembly_guess(0.0))
            .expect("assembles");
        // at phi = 0 the rod lies on the x axis, the piston at r + l
        assert!((sol.q[6] - 0.226).abs() < 1e-12 && sol.q[5].abs() < 1e-12);
    }
}
