//! Stage 2 — dynamics of the crank–slider: kinematic analysis and inverse
//! dynamics of the driven (zero-DOF) mechanism, by a closed-form Newton–Euler
//! solution and by a general planar multibody core, which cross-check each
//! other to ≤ 1e-9 relative.
//!
//! Sources: the thesis (Boublíková 2012, `seed/000_2ca998116c89c115.txt`),
//! ch. 2 (kinematics, constraint equations, eq. 2.1–2.31) and §3.2 (the
//! planar multibody formulation, eq. 3.25–3.38, after Nikravesh); P. E.
//! Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, Prentice Hall
//! 1988 (body coordinates, joint constraints, kinematic and dynamic
//! analysis), and *Planar Multibody Dynamics*, CRC 2008 (cited by the thesis).
//!
//! # Layout
//! | file | contents |
//! |---|---|
//! | `error.rs` | [`DynamicsError`], the typed error (Display names parameter, or time and joint) |
//! | `body.rs` | body coordinates (x, y, φ), [`BodyId`] (ground implicit), poses, planar helpers |
//! | `motion.rs` | prescribed motions φ(t), φ̇, φ̈: [`CrankMotion`] |
//! | `constraint.rs` | the joint interface (Φ, D, ν = −Φ_t, γ): [`constraint::ConstraintEquations`], [`constraint::JacobianBlocks`] |
//! | `revolute.rs` | revolute joint, eq. 2.17–2.19 |
//! | `translational.rs` | translational joint, eq. 2.28–2.29 |
//! | `driving.rs` | driving constraint φⱼ − φᵢ = f(t) |
//! | `joint.rs` | the [`joint::Joint`] enum over the three joint types and its dispatch |
//! | `system/` | [`MultibodySystem`] (one file per idea: builder, assembly, analysis, reactions, tracker): assembly of Φ, D, γ, M, h; Newton–Raphson position analysis, velocity, acceleration, Lagrange multipliers, joint reactions; [`Tracker`] along the motion; `build_with_dof` for systems that keep degrees of freedom; its LU is the crate's one, [`crate::linalg::DenseLu`] |
//! | `forward.rs` | forward dynamics of such systems: the index-1 form [M −Dᵀ; D 0][c̈; λ] = [h; γ̃] (plain or Baumgarte), constraint violation, projection onto Φ = 0, D ċ = ν |
//! | `linkage.rs` | [`CrankSliderLinkage`]: the crank–slider's bodies and joints O, A, B, slide on the core, written out once (for [`CrankSlider`] and the test rigs) |
//! | `crank_slider.rs` | [`RodInertia`], [`MechanismParams`] (spec defaults, builder, validation), [`CrankSlider`] (validated model, its multibody form), [`PinLoads`] |
//! | `gas.rs` | the cylinder pressure trace ([`PressureTrace`]: CSV, checks) and the gas force on the piston over 720° ([`GasForce`], periodic, linear between the rows) |
//! | `closed_form.rs` | closed-form kinematics (eq. 2.1–2.12) and hand-solved Newton–Euler loads: the oracle |
//! | `rod_cycle.rs` | [`rod_frame_cycle`]: one revolution in the rod frame (a_A, ω₃, α₃, g, pin forces from the rod's Newton–Euler) for the FEM stage |
//! | `peak.rs` | the true maximum of \|F_A\| (scan + golden section on the closed form) |
//! | `scene.rs` | scene `driven`: [`DrivenScene`], [`Method`], [`driven_scene`], [`DrivenResult`], [`compare_results`] |
//! | `tdc_peak.rs` | the peak pin force at constant speed: the TDC formula, the refined peak, the l₁ that reproduces a peak ([`L1Fit`]) |
//! | `table_5_1.rs` | the thesis' Table 5.1 and its reproduction ([`table_5_1_check`]) |
//! | `sensitivity.rs` | sensitivity of the peak to m₃, l₁, I_zz ([`peak_sensitivity`]) |
//! | `bench.rs` | [`bench_driven`]: timing of both methods |
//!
//! # Conventions
//! * SI units inside, f64 throughout; global frame x along the slide (from O
//!   towards the piston), y up; gravity g along −y (on by default).
//! * Crank angle φ from +x, counter-clockwise; crank pin A = r (cos φ, sin φ);
//!   top dead centre (piston farthest from O) at φ = 0.
//! * **F_A is the force exerted BY the crank ON the rod at the crank pin A,**
//!   in the global frame (N); the rod exerts −F_A on the crank. F_B is the
//!   force BY the rod ON the piston at B. The crank torque is the torque the
//!   drive applies to the crank (the driving-constraint multiplier).
//! * Multibody sign convention: M c̈ = h + Dᵀλ (thesis eq. 3.27), so a joint's
//!   multipliers give the reaction D_{k,b}ᵀλ_k on each of its bodies; for a
//!   revolute joint between bodies i and j, λ is the force of i on j.
//! * The ground is implicit (no coordinates); the crank–slider has 9 body
//!   coordinates (crank, rod, piston) and 9 constraint equations; without the
//!   driver ([`CrankSlider::free_multibody`], thesis eq. 3.25) 8 equations and
//!   one degree of freedom, for forward dynamics ([`forward`]; the `free`
//!   scene's DAE forms in [`crate::free_run::dae`]).
//! * Default method for the study: [`Method::ClosedForm`] (cheapest exact
//!   model); the multibody core is the cross-check run by the tests over full
//!   scenes. Neither integrates in time: the driven mechanism has zero DOF.
pub mod bench;
pub mod body;
pub mod closed_form;
pub mod constraint;
pub mod crank_slider;
pub mod driving;
pub mod error;
pub mod forward;
pub mod gas;
pub mod joint;
pub mod linkage;
pub mod motion;
pub mod peak;
pub mod revolute;
pub mod rod_cycle;
pub mod scene;
pub mod sensitivity;
pub mod system;
pub mod table_5_1;
pub mod tdc_peak;
pub mod translational;

pub use bench::{DynamicsBench, bench_driven};
pub use body::{Body, BodyId};
pub use closed_form::{CrankSliderKinematics, kinematics, transfer_functions};
pub use crank_slider::{
    CrankSlider, MechanismParams, MechanismParamsBuilder, PinLoads, RodInertia,
};
pub use error::{DynamicsError, Result};
pub use forward::{Baumgarte, ConstraintViolation, ForwardSolution};
pub use gas::{GasForce, PressureTrace, piston_area_m2};
pub use linkage::{CrankSliderLinkage, LinkageJoint};
pub use motion::{CrankMotion, MotionSample};
pub use peak::{PeakRefinement, refine_max_of, refine_peak, wrap_degrees, wrap_degrees_to};
pub use rod_cycle::{RodFrameInstant, acceleration_of, rod_frame_cycle, rod_frame_engine_cycle};
pub use scene::{
    Agreement, AxialPeaks, DrivenResult, DrivenScene, Method, compare_results, driven_scene,
    driven_scene_with_gas,
};
pub use sensitivity::{PeakSensitivity, peak_sensitivity};
pub use system::{
    AppliedLoad, GeneralizedForce, JointReaction, KinematicSolution, MultibodyBuilder,
    MultibodySystem, SolverOptions, Tracker,
};
pub use table_5_1::{
    DESIGN_2_L1_M, TABLE_5_1, THESIS_OMEGA_RAD_S, Table51Check, Table51Row, table_5_1_check,
};
pub use tdc_peak::{L1Fit, l1_for_peak_force, peak_pin_force, tdc_peak_formula};
