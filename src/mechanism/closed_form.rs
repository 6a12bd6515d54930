//! Closed-form Newton–Euler solution of the crank–slider — the independent
//! oracle for the multibody core, and the study's default method (the
//! cheapest model that answers the driven scene exactly).
//!
//! # Kinematics (thesis §2.1)
//! With λ = r/l and a prescribed crank motion φ(t), φ̇, φ̈:
//!
//! * sin ψ = λ sin φ (eq. 2.3), ψ = arcsin(λ sin φ) (eq. 2.4),
//!   cos ψ = √(1 − λ² sin² φ) (eq. 2.7);
//! * piston travel x = (r + l) − (r cos φ + l cos ψ) (eq. 2.1, 2.8); the
//!   piston pin is at x_B = r cos φ + l cos ψ;
//! * transfer functions p42 = dx/dφ = r sin φ + r² sin φ cos φ /(l cos ψ)
//!   (eq. 2.11) and p32 = dψ/dφ = r cos φ /(l cos ψ) (eq. 2.12), so
//!   ẋ = p42 φ̇ (eq. 2.9), ψ̇ = p32 φ̇ (eq. 2.10);
//! * differentiating r sin φ = l sin ψ (eq. 2.2) twice:
//!   ψ̈ = [λ (cos φ φ̈ − sin φ φ̇²) + sin ψ ψ̇²] / cos ψ;
//! * ẋ_B = −r sin φ φ̇ − l sin ψ ψ̇,
//!   ẍ_B = −r (cos φ φ̇² + sin φ φ̈) − l (cos ψ ψ̇² + sin ψ ψ̈).
//!
//! The rod angle is θ = −ψ; u = (cos ψ, −sin ψ) is the unit vector A→B and
//! n = rot90(u) = (sin ψ, cos ψ). The rod centroid is G₃ = A + ρ with
//! ρ = l₁ u + e₃ n (e₃ = transverse offset), so
//! a_G3 = a_A + θ̈ rot90(ρ) − θ̇² ρ, a_A = r(−cos φ φ̇² − sin φ φ̈,
//! −sin φ φ̇² + cos φ φ̈).
//!
//! # Free-body equations, solved by hand
//! Unknowns F_A (crank on rod at A), F_B (rod on piston at B), N (slide on
//! piston), T (drive torque on the crank), F_O (ground on crank); g⃗ = (0, −g),
//! F_p the applied piston force along +x: the constant piston force minus the
//! gas force F_gas(φ) = p(φ)·A (which pushes the piston towards the crank,
//! [`GasForce`](super::gas::GasForce)), evaluated at the crank angle φ.
//!
//! * piston, x:  F_Bx + F_p + m₄ g_x = m₄ ẍ_B  ⇒ F_Bx = m₄ (ẍ_B − g_x) − F_p
//! * rod, x:     F_Ax − F_Bx + m₃ g_x = m₃ a_G3,x  ⇒ F_Ax = m₃ (a_G3,x − g_x) + F_Bx
//! * rod, y:     F_Ay − F_By = m₃ (a_G3,y − g_y) =: S
//! * rod, moment about G₃ with p_A = A − G₃ = −ρ, p_B = B − G₃ = l u − ρ:
//!   p_A × F_A − p_B × F_B = I_zz θ̈; inserting F_Ay = S + F_By
//!   (p_A,x − p_B,x = −l cos ψ):
//!   F_By = −(I_zz θ̈ − p_A,x S + p_A,y F_Ax − p_B,y F_Bx) / (l cos ψ), F_Ay = S + F_By
//! * piston, y:  F_By + N + m₄ g_y = 0  ⇒ N = −F_By − m₄ g_y
//! * crank, moment about O (I₂ about O):
//!   T = I₂ φ̈ + A × F_A − G₂ × m₂ g⃗, G₂ = e (cos φ, sin φ)
//! * crank, force: F_O = m₂ a_G2 + F_A − m₂ g⃗.
//!
//! At top dead centre (φ = 0) and constant speed, θ̈ = 0, so the rod inertia
//! drops out and, without gravity and offset,
//! |F_A| = r ω² [m₄ (1 + r/l) + m₃ (1 + (r/l)(l₁/l))]
//! (see [`tdc_peak_formula`](super::study::tdc_peak_formula)).

use nalgebra::Vector2;

use super::body::{cross, rot90};
use super::crank_slider::{CrankSlider, PinLoads};
use super::motion::MotionSample;

/// Closed-form kinematic state of the crank–slider at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrankSliderKinematics {
    /// Crank angle φ, speed φ̇, acceleration φ̈.
    pub crank: MotionSample,
    /// sin φ.
    pub sin_phi: f64,
    /// cos φ.
    pub cos_phi: f64,
    /// ψ (rad), thesis eq. 2.4 (rod angle θ = −ψ).
    pub psi: f64,
    /// sin ψ = (r/l) sin φ (eq. 2.3).
    pub sin_psi: f64,
    /// cos ψ = √(1 − (r/l)² sin² φ) (eq. 2.7), > 0 for l > r.
    pub cos_psi: f64,
    /// ψ̇ (rad/s).
    pub psi_dot: f64,
    /// ψ̈ (rad/s²).
    pub psi_ddot: f64,
    /// Piston travel x from the outer dead centre (eq. 2.1) (m).
    pub travel_m: f64,
    /// Piston pin position x_B = r cos φ + l cos ψ (m).
    pub x_b: f64,
    /// ẋ_B (m/s).
    pub xd_b: f64,
    /// ẍ_B (m/s²).
    pub xdd_b: f64,
    /// p42 = dx/dφ (eq. 2.11) (m/rad).
    pub p42: f64,
    /// p32 = dψ/dφ (eq. 2.12).
    pub p32: f64,
}

/// Transfer functions (p42, p32) of thesis eq. (2.11)–(2.12), as printed.
pub fn transfer_functions(r: f64, l: f64, phi: f64) -> (f64, f64) {
    let (s, c) = phi.sin_cos();
    let root = (1.0 - (r * s / l).powi(2)).sqrt();
    let p42 = r * r * s * c / (l * root) + r * s;
    let p32 = r * c / (l * root);
    (p42, p32)
}

/// Closed-form kinematics for crank radius `r`, centre distance `l > r` and
/// the crank state `m`.
pub fn kinematics(r: f64, l: f64, m: MotionSample) -> CrankSliderKinematics {
    let lam = r / l;
    let (s, c) = m.phi.sin_cos();
    let sp = lam * s;
    let cp = ((1.0 - sp) * (1.0 + sp)).sqrt();
    let psi = sp.asin();
    let p32 = lam * c / cp;
    let p42 = r * s + r * lam * s * c / cp;
    let psi_dot = p32 * m.omega;
    let psi_ddot = (lam * (c * m.alpha - s * m.omega * m.omega) + sp * psi_dot * psi_dot) / cp;
    let x_b = r * c + l * cp;
    let xd_b = -r * s * m.omega - l * sp * psi_dot;
    let xdd_b =
        -r * (c * m.omega * m.omega + s * m.alpha) - l * (cp * psi_dot * psi_dot + sp * psi_ddot);
    CrankSliderKinematics {
        crank: m,
        sin_phi: s,
        cos_phi: c,
        psi,
        sin_psi: sp,
        cos_psi: cp,
        psi_dot,
        psi_ddot,
        travel_m: r + l - x_b,
        x_b,
        xd_b,
        xdd_b,
        p42,
        p32,
    }
}

/// Positions, velocities and accelerations of the three centroids (used by
/// the energy checks and by tests).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CentroidMotion {
    /// Crank centroid G₂, its velocity and acceleration.
    pub g2: [Vector2<f64>; 3],
    /// Rod centroid G₃, its velocity and acceleration.
    pub g3: [Vector2<f64>; 3],
    /// Rod angle θ = −ψ, θ̇, θ̈.
    pub rod_angle: [f64; 3],
    /// Crank pin A, its velocity and acceleration.
    pub a: [Vector2<f64>; 3],
    /// Piston pin B = (x_B, 0), its velocity and acceleration.
    pub b: [Vector2<f64>; 3],
}

impl CrankSlider {
    /// Closed-form kinematics of this mechanism.
    pub fn closed_form_kinematics(&self, m: MotionSample) -> CrankSliderKinematics {
        kinematics(
            self.params().crank_radius_m,
            self.params().centre_distance_m,
            m,
        )
    }

    /// Centroid motion from the closed-form kinematics.
    pub fn centroid_motion(&self, k: &CrankSliderKinematics) -> CentroidMotion {
        let p = self.params();
        let (r, e) = (p.crank_radius_m, p.crank_eccentricity_m);
        let (l1, off) = (self.rod().l1_m, self.rod().offset_m);
        let m = k.crank;
        let (s, c) = (k.sin_phi, k.cos_phi);
        let radial = Vector2::new(c, s);
        let tangential = Vector2::new(-s, c);
        let circle = |rad: f64| {
            [
                radial * rad,
                tangential * (rad * m.omega),
                (tangential * m.alpha - radial * (m.omega * m.omega)) * rad,
            ]
        };
        let a = circle(r);
        let g2 = circle(e);
        let (sp, cp) = (k.sin_psi, k.cos_psi);
        let u = Vector2::new(cp, -sp);
        let rho = u * l1 + rot90(u) * off;
        let (th, thd, thdd) = (-k.psi, -k.psi_dot, -k.psi_ddot);
        let g3 = [
            a[0] + rho,
            a[1] + rot90(rho) * thd,
            a[2] + rot90(rho) * thdd - rho * (thd * thd),
        ];
        let b = [
            Vector2::new(k.x_b, 0.0),
            Vector2::new(k.xd_b, 0.0),
            Vector2::new(k.xdd_b, 0.0),
        ];
        CentroidMotion {
            g2,
            g3,
            rod_angle: [th, thd, thdd],
            a,
            b,
        }
    }

    /// Closed-form Newton–Euler loads at crank state `m` (see the module
    /// documentation for the equations).
    pub fn closed_form(&self, m: MotionSample) -> PinLoads {
        let p = self.params();
        let rod = self.rod();
        let k = self.closed_form_kinematics(m);
        let cm = self.centroid_motion(&k);
        let g = p.gravity_vector();
        let (m2, m3, m4) = (p.crank_mass_kg, rod.mass_kg, p.piston_mass_kg);
        let l = p.centre_distance_m;
        let a_g3 = cm.g3[2];
        let theta_ddot = cm.rod_angle[2];
        let pa = cm.a[0] - cm.g3[0];
        let pb = cm.b[0] - cm.g3[0];
        let mut fbx = m4 * (k.xdd_b - g.x) - p.piston_force_n;
        if let Some(gas) = self.gas_force() {
            // the gas pushes the piston along −x: F_p = piston_force − F_gas(φ)
            fbx += gas.at(m.phi);
        }
        let fax = m3 * (a_g3.x - g.x) + fbx;
        let s = m3 * (a_g3.y - g.y);
        let fby =
            -(rod.i_zz_kgm2 * theta_ddot - pa.x * s + pa.y * fax - pb.y * fbx) / (l * k.cos_psi);
        let fay = s + fby;
        let f_a = Vector2::new(fax, fay);
        let f_b = Vector2::new(fbx, fby);
        let torque =
            p.crank_inertia_o_kgm2 * m.alpha + cross(cm.a[0], f_a) - cross(cm.g2[0], g * m2);
        let f_o = cm.g2[2] * m2 + f_a - g * m2;
        PinLoads {
            f_a,
            f_b,
            f_o,
            piston_normal_n: -fby - m4 * g.y,
            slide_moment_nm: 0.0,
            crank_torque_nm: torque,
        }
    }

    /// Kinetic plus potential energy from the closed-form kinematics (J);
    /// used for the power-balance checks.
    pub fn closed_form_energy(&self, m: MotionSample) -> f64 {
        let p = self.params();
        let k = self.closed_form_kinematics(m);
        let cm = self.centroid_motion(&k);
        let g = p.gravity_vector();
        let rod = self.rod();
        let kinetic = 0.5 * p.crank_inertia_o_kgm2 * m.omega * m.omega
            + 0.5 * rod.mass_kg * cm.g3[1].norm_squared()
            + 0.5 * rod.i_zz_kgm2 * cm.rod_angle[1] * cm.rod_angle[1]
            + 0.5 * p.piston_mass_kg * k.xd_b * k.xd_b;
        let potential = -(p.crank_mass_kg * g.dot(&cm.g2[0]) + rod.mass_kg * g.dot(&cm.g3[0]));
        kinetic + potential
    }
}

#[cfg(test)]
mod tests {
    use super::super::crank_slider::{MechanismParams, RodInertia};
    use super::super::motion::CrankMotion;
    use super::*;

    fn model(offset: f64, gravity: bool) -> CrankSlider {
        let p = MechanismParams::builder()
            .gravity(gravity)
            .piston_force_n(-40.0)
            .build()
            .expect("params");
        CrankSlider::new(
            &p,
            &RodInertia::new(3.0420019180, 0.07176, 0.02).with_offset(offset),
        )
        .expect("model")
    }

    #[test]
    fn transfer_functions_match_derivatives_of_eq_2_8_and_2_4() {
        let (r, l) = (0.046, 0.18);
        let x =
            |phi: f64| (r + l) - (r * phi.cos() + l * (1.0 - (r / l * phi.sin()).powi(2)).sqrt());
        let psi = |phi: f64| (r / l * phi.sin()).asin();
        let h = 1e-6;
        for k in 0..24 {
            let phi = 0.3 + k as f64 * 0.27;
            let (p42, p32) = transfer_functions(r, l, phi);
            assert!(((x(phi + h) - x(phi - h)) / (2.0 * h) - p42).abs() < 1e-9);
            assert!(((psi(phi + h) - psi(phi - h)) / (2.0 * h) - p32).abs() < 1e-9);
            let kin = kinematics(
                r,
                l,
                MotionSample {
                    phi,
                    omega: 2.0,
                    alpha: 0.0,
                },
            );
            assert!((kin.p42 - p42).abs() < 1e-15 && (kin.p32 - p32).abs() < 1e-15);
            assert!((kin.travel_m - x(phi)).abs() < 1e-15);
            assert!(
                (kin.psi_dot - 2.0 * p32).abs() < 1e-14 && (-kin.xd_b - 2.0 * p42).abs() < 1e-14
            );
        }
    }

    #[test]
    fn multibody_velocities_follow_the_transfer_functions() {
        // kinematics of the multibody core against eq. 2.9-2.12: xdot_4 = -p42 phidot, phidot_3 = -p32 phidot
        let cs = model(0.003, true);
        let omega = 40.0 * std::f64::consts::PI;
        let sys = cs
            .multibody(CrankMotion::constant_speed(omega))
            .expect("model");
        let mut tr = sys.tracker(cs.assembly_guess(0.0));
        for k in 0..50 {
            let t = k as f64 * 0.001;
            let sol = *tr.solve_at(t).expect("solves");
            let (p42, p32) = transfer_functions(0.046, 0.18, omega * t);
            assert!((sol.qd[6] + p42 * omega).abs() < 1e-10 * omega);
            assert!((sol.qd[5] + p32 * omega).abs() < 1e-10 * omega);
        }
    }

    #[test]
    fn power_balance_of_the_closed_form() {
        // T phidot + F_p xdot_B = d/dt (kinetic + potential energy): an independent check of the
        // hand-solved force equations (the energy uses only kinematics and mass data)
        for (offset, gravity) in [(0.0, false), (0.004, true), (-0.002, true)] {
            let cs = model(offset, gravity);
            let motion = CrankMotion::Harmonic {
                phi0_rad: 0.2,
                omega_rad_s: 80.0,
                amplitude_rad: 0.25,
                frequency_rad_s: 130.0,
            };
            let e = |t: f64| cs.closed_form_energy(motion.sample(t));
            let dt = 1e-5;
            for k in 0..60 {
                let t = 0.0017 * k as f64;
                let de = (e(t - 2.0 * dt) - 8.0 * e(t - dt) + 8.0 * e(t + dt) - e(t + 2.0 * dt))
                    / (12.0 * dt);
                let m = motion.sample(t);
                let loads = cs.closed_form(m);
                let kin = cs.closed_form_kinematics(m);
                let p = loads.crank_torque_nm * m.omega + cs.params().piston_force_n * kin.xd_b;
                assert!(
                    (p - de).abs() < 1e-6 * (1.0 + p.abs()),
                    "t {t}: {p} vs {de}"
                );
            }
        }
    }

    #[test]
    fn tdc_force_is_the_textbook_formula_without_gravity() {
        let p = MechanismParams::default().with_gravity(false);
        let rod = RodInertia::new(3.0420019180, 0.07176, 0.02);
        let cs = CrankSlider::new(&p, &rod).expect("model");
        let w = 40.0 * std::f64::consts::PI;
        let f = cs.closed_form(MotionSample {
            phi: 0.0,
            omega: w,
            alpha: 0.0,
        });
        let lam = 0.046 / 0.18;
        let formula = 0.046
            * w
            * w
            * (5.2269229374 * (1.0 + lam) + 3.0420019180 * (1.0 + lam * 0.07176 / 0.18));
        assert!((f.f_a.norm() - formula).abs() < 1e-9 * formula);
        assert!(f.f_a.y.abs() < 1e-9);
    }
}
