//! One crank revolution seen from the connecting rod: per instant, the loads
//! and kinematics the quasi-static FEM stage needs (stress with inertia
//! relief), every vector in the rod's own frame.
//!
//! # Rod frame
//! Origin at the crank pin centre A, x̂ = u the unit vector A→B, ẑ the pin axis
//! (the mechanism's out-of-plane axis, global +z), ŷ = ẑ × x̂ = rot90(u). With
//! the global frame of [`crate::mechanism`] (x along the slide from O towards
//! the piston, y up) and ψ of thesis eq. 2.3–2.4 (sin ψ = (r/l) sin φ), the
//! rod angle is θ₃ = −ψ and
//!
//! * x̂ = (cos ψ, −sin ψ), ŷ = (sin ψ, cos ψ) in global components; a global
//!   vector v has rod-frame components (v·x̂, v·ŷ);
//! * at top dead centre (φ = 0, ψ = 0) x̂ is global +x and **ŷ is global +y
//!   (up, against gravity)**, so there g has rod-frame components (0, −g);
//! * the rod centroid is at r_G = (l₁, e) from A, e = [`RodInertia::offset_m`]
//!   (positive to the left of A→B, i.e. along +ŷ), and B is at r_B = (l, 0).
//!
//! # Kinematics (thesis §2.1, see [`closed_form`](super::closed_form))
//! At constant crank speed ω (φ = ω t, φ̈ = 0):
//! a_A = r (−cos φ φ̇² − sin φ φ̈, −sin φ φ̇² + cos φ φ̈) (global, |a_A| = r ω²),
//! ω₃ = θ̇₃ = −ψ̇, α₃ = θ̈₃ = −ψ̈, and any rod point P at rod-frame position r
//! from A accelerates as a planar rigid body ([`acceleration_of`]):
//! a_P = a_A + α₃ ẑ × r − ω₃² r.
//!
//! # Pin forces from the rod's own Newton–Euler equations
//! Unknowns F_A (crank on rod at A) and Q = F_B,rod (piston pin on rod at B),
//! rod frame; m = m₃, I = I_zz about G, a_G = a_P(r_G):
//!
//! * rod, force:   F_A + Q + m g = m a_G;
//! * rod, moment about A (equivalent to the moment about G with I_zz):
//!   r_B × Q + r_G × m g = I α₃ + r_G × m a_G
//!   ⇒ Q_y = [I α₃ + m r_G × (a_G − g)] / l;
//! * piston (mass m₄ at B, slides along global x, thesis eq. 2.27–2.31; the
//!   slide's normal force is along global y and does not act on the rod):
//!   F_B,x(global) = m₄ (ẍ_B − g_x) − F_p, with Q = −F_B; the global x̂ has
//!   rod-frame components (cos ψ, sin ψ), so Q_x cos ψ + Q_y sin ψ = −F_B,x
//!   ⇒ Q_x = (−F_B,x − Q_y sin ψ) / cos ψ (cos ψ > 0 because l > r);
//! * F_A = m (a_G − g) − Q.
//!
//! These are the equations the closed form ([`CrankSlider::closed_form`])
//! solves in the global frame; here they are written in the rod frame with the
//! given [`RodInertia`], so a caller can pass mass properties computed from an
//! FEM mesh and get pin forces consistent with them (the FEM's inertia relief
//! then balances to rounding). Sources: the thesis (Boublíková 2012,
//! `seed/000_2ca998116c89c115.txt`), ch. 2 (kinematics, eq. 2.1–2.31) and
//! §3.2; R. L. Norton, *Design of Machinery*, ch. 13 (dynamic force analysis
//! of the slider-crank: pin forces from the links' Newton–Euler equations).

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};

use super::closed_form::kinematics;
use super::crank_slider::{CrankSlider, MechanismParams, RodInertia};
use super::error::{DynamicsError, Result, positive};
use super::gas::{CYCLE_DEG, GasForce};
use super::motion::MotionSample;
use super::peak::wrap_degrees_to;
use super::scene::MAX_STEPS;

/// One instant, every vector in the rod frame: origin at A (crank pin
/// centre), x̂ along A→B, ẑ the pin axis (the mechanism's out-of-plane axis),
/// ŷ = ẑ × x̂ (global +y at top dead centre). SI units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RodFrameInstant {
    /// φ in [0, 360) degrees (in [0, 720) over the four-stroke cycle), φ = ω t, 0 = (firing) top
    /// dead centre.
    pub crank_angle_deg: f64,
    /// Time t (s).
    pub time_s: f64,
    /// Acceleration of A (the crank pin centre), rod-frame components (m/s²).
    pub a_a_m_s2: [f64; 2],
    /// Rod angular velocity ω₃ = θ̇₃ = −ψ̇ about ẑ (rad/s).
    pub omega3_rad_s: f64,
    /// Rod angular acceleration α₃ = θ̈₃ = −ψ̈ about ẑ (rad/s²).
    pub alpha3_rad_s2: f64,
    /// Gravitational acceleration g (the params' gravity vector, zero if
    /// gravity is off), rod frame (m/s²).
    pub gravity_m_s2: [f64; 2],
    /// Force BY the crank ON the rod at A, rod frame (N).
    pub f_a_on_rod_n: [f64; 2],
    /// Force BY the piston pin ON the rod at B (= −F_B of
    /// [`DrivenResult`](super::scene::DrivenResult), rotated), rod frame (N).
    pub f_b_on_rod_n: [f64; 2],
    /// The gas force on the piston at this instant, N (towards the crank; 0 without a trace).
    #[serde(default)]
    pub gas_force_n: f64,
}

/// Acceleration of the rod point at rod-frame position `r` (m, from A),
/// rod-frame components: a_P = a_A + α₃ ẑ × r − ω₃² r (planar rigid body).
pub fn acceleration_of(inst: &RodFrameInstant, r: [f64; 2]) -> [f64; 2] {
    let (w2, al) = (inst.omega3_rad_s * inst.omega3_rad_s, inst.alpha3_rad_s2);
    [
        inst.a_a_m_s2[0] - al * r[1] - w2 * r[0],
        inst.a_a_m_s2[1] + al * r[0] - w2 * r[1],
    ]
}

/// `instants` equally spaced instants over one revolution at the constant
/// crank speed `omega_rad_s` (> 0, counter-clockwise), the first at φ = 0
/// exactly: t_k = (2π/ω)·k/instants (the grid of
/// [`DrivenScene::time`](super::scene::DrivenScene::time) with duration 2π/ω
/// and `instants` steps), φ_k = ω t_k. See the module documentation for the
/// frame and the equations.
///
/// Errors: invalid mechanism or rod data (as [`CrankSlider::new`]), a speed
/// that is not finite and positive, `instants` = 0 or above
/// [`MAX_STEPS`]; [`DynamicsError::NonFinite`] as a guard.
pub fn rod_frame_cycle(
    params: &MechanismParams,
    rod: &RodInertia,
    omega_rad_s: f64,
    instants: usize,
) -> Result<Vec<RodFrameInstant>> {
    rod_frame_engine_cycle(params, rod, omega_rad_s, instants, None)
}

/// The engine's load cycle in the rod frame: with a gas force ([`GasForce`]) the
/// four-stroke cycle, 2 × `instants_per_revolution` equally spaced instants over 720° (φ_k = ω t_k,
/// t_k = (4π/ω)·k/(2n)), the gas force F_gas(φ_k) acting on the piston along global −x (towards the
/// crank), so that F_B,x(global) = m₄ (ẍ_B − g_x) − F_p + F_gas(φ) as in the closed form
/// ([`CrankSlider::closed_form`]) and crank angles in [0, 720); without one exactly
/// [`rod_frame_cycle`] (one revolution, angles in [0, 360)).
pub fn rod_frame_engine_cycle(
    params: &MechanismParams,
    rod: &RodInertia,
    omega_rad_s: f64,
    instants_per_revolution: usize,
    gas: Option<&GasForce>,
) -> Result<Vec<RodFrameInstant>> {
    let model = CrankSlider::new(params, rod)?;
    let omega = positive("omega_rad_s", omega_rad_s)?;
    if instants_per_revolution == 0 || instants_per_revolution > MAX_STEPS {
        return Err(DynamicsError::InvalidScene(format!(
            "instants per revolution must be between 1 and {MAX_STEPS}, got {instants_per_revolution}"
        )));
    }
    let (revolutions, period_deg) = match gas {
        Some(_) => (2usize, CYCLE_DEG),
        None => (1usize, 360.0),
    };
    let instants = revolutions * instants_per_revolution;
    let p = model.params();
    let (r, l) = (p.crank_radius_m, p.centre_distance_m);
    let (m3, i3, m4) = (rod.mass_kg, rod.i_zz_kgm2, p.piston_mass_kg);
    let r_g = Vector2::new(rod.l1_m, rod.offset_m);
    let g_global = p.gravity_vector();
    let period = revolutions as f64 * std::f64::consts::TAU / omega;
    let mut out = Vec::with_capacity(instants);
    for k in 0..instants {
        let t = period * (k as f64) / (instants as f64);
        let m = MotionSample {
            phi: omega * t,
            omega,
            alpha: 0.0,
        };
        let kin = kinematics(r, l, m);
        let (sp, cp) = (kin.sin_psi, kin.cos_psi);
        // rod-frame components of a global vector: (v·x̂, v·ŷ)
        let to_rod = |v: Vector2<f64>| Vector2::new(cp * v.x - sp * v.y, sp * v.x + cp * v.y);
        let (s, c) = (kin.sin_phi, kin.cos_phi);
        let a_a_global = Vector2::new(
            -c * m.omega * m.omega - s * m.alpha,
            -s * m.omega * m.omega + c * m.alpha,
        ) * r;
        let a_a = to_rod(a_a_global);
        let g = to_rod(g_global);
        let (w3, al3) = (-kin.psi_dot, -kin.psi_ddot);
        let a_g = a_a + Vector2::new(-r_g.y, r_g.x) * al3 - r_g * (w3 * w3);
        let net = (a_g - g) * m3; // F_A + Q
        // moment about A: l Q_y = I α₃ + r_G × m (a_G − g)
        let q_y = (i3 * al3 + r_g.x * net.y - r_g.y * net.x) / l;
        // piston, global x: F_B,x = m₄ (ẍ_B − g_x) − F_p; Q·x̂_global = −F_B,x
        let f_gas = gas.map_or(0.0, |g| g.at(m.phi));
        let f_bx = m4 * (kin.xdd_b - g_global.x) - p.piston_force_n + f_gas;
        let q_x = (-f_bx - q_y * sp) / cp;
        let q = Vector2::new(q_x, q_y);
        let f_a = net - q;
        let inst = RodFrameInstant {
            crank_angle_deg: wrap_degrees_to(m.phi, period_deg),
            time_s: t,
            a_a_m_s2: [a_a.x, a_a.y],
            omega3_rad_s: w3,
            alpha3_rad_s2: al3,
            gravity_m_s2: [g.x, g.y],
            f_a_on_rod_n: [f_a.x, f_a.y],
            f_b_on_rod_n: [q.x, q.y],
            gas_force_n: f_gas,
        };
        let finite = [w3, al3, a_a.x, a_a.y, f_a.x, f_a.y, q.x, q.y]
            .iter()
            .all(|v| v.is_finite());
        if !finite {
            return Err(DynamicsError::NonFinite {
                t_s: t,
                what: "rod-frame loads",
            });
        }
        out.push(inst);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::scene::{DrivenScene, Method, driven_scene, driven_scene_with_gas};
    use super::*;
    use std::sync::Arc;

    const OMEGA: f64 = 40.0 * std::f64::consts::PI;

    /// (params, rod) cases: the thesis rod with the defaults, and a design-like
    /// rod (design 1's mass and I_zz) with an exaggerated offset and a piston force.
    fn cases() -> Vec<(MechanismParams, RodInertia)> {
        vec![
            (MechanismParams::default(), RodInertia::thesis_original()),
            (
                MechanismParams::builder()
                    .piston_force_n(-1500.0)
                    .build()
                    .expect("params"),
                RodInertia::new(3.042003489, 0.07176, 0.0201955829).with_offset(0.004),
            ),
            (
                MechanismParams::default().with_gravity(false),
                RodInertia::new(2.4794512, 0.0656, 0.0188578).with_offset(-0.003),
            ),
        ]
    }

    fn rotate_to_global(psi: f64, v: [f64; 2]) -> Vector2<f64> {
        let (sp, cp) = psi.sin_cos();
        // x̂ = (cos ψ, −sin ψ), ŷ = (sin ψ, cos ψ)
        Vector2::new(cp * v[0] + sp * v[1], -sp * v[0] + cp * v[1])
    }

    fn psi_at(p: &MechanismParams, t: f64) -> f64 {
        kinematics(
            p.crank_radius_m,
            p.centre_distance_m,
            MotionSample {
                phi: OMEGA * t,
                omega: OMEGA,
                alpha: 0.0,
            },
        )
        .psi
    }

    #[test]
    fn pin_forces_agree_with_the_driven_scene() {
        let n = 360;
        for (p, rod) in cases() {
            let cyc = rod_frame_cycle(&p, &rod, OMEGA, n).expect("cycle");
            let scene = DrivenScene {
                omega_rad_s: OMEGA,
                duration_s: std::f64::consts::TAU / OMEGA,
                steps: n,
                phi0_rad: 0.0,
            };
            let d = driven_scene(&p, &rod, &scene, Method::ClosedForm).expect("scene");
            let peak_a = d.fa_abs_n.iter().fold(0.0f64, |a, b| a.max(*b));
            let peak_b = d.fb_abs_n.iter().fold(0.0f64, |a, b| a.max(*b));
            let (mut ea, mut eb) = (0.0f64, 0.0f64);
            for (k, inst) in cyc.iter().enumerate() {
                assert_eq!(inst.time_s, d.t_s[k]);
                let psi = psi_at(&p, inst.time_s);
                let fa = rotate_to_global(psi, inst.f_a_on_rod_n);
                let fb = rotate_to_global(psi, inst.f_b_on_rod_n);
                ea = ea.max((fa - Vector2::new(d.fa_x_n[k], d.fa_y_n[k])).norm() / peak_a);
                eb = eb.max((fb + Vector2::new(d.fb_x_n[k], d.fb_y_n[k])).norm() / peak_b);
            }
            eprintln!("driven_scene agreement: F_A {ea:.2e}, F_B {eb:.2e} (rel. to peak)");
            assert!(ea < 1e-9 && eb < 1e-9, "F_A {ea:e}, F_B {eb:e}");
        }
    }

    /// A trace in miniature: a firing peak of 60 bar 12° after firing top dead centre, a little
    /// pressure elsewhere, on an 82 mm bore.
    fn test_gas() -> GasForce {
        let trace = super::super::gas::PressureTrace::parse(
            "crank_angle_deg,pressure_bar\n0,30\n12,60\n60,8\n180,1\n360,0.2\n540,0.5\n690,12\n720,30\n",
        )
        .expect("trace");
        GasForce::from_trace(&trace, 0.082)
    }

    #[test]
    fn with_a_gas_force_the_cycle_spans_720_degrees_and_agrees_with_the_closed_form() {
        let n = 180;
        let gas = Arc::new(test_gas());
        for (p, rod) in cases() {
            let cyc = rod_frame_engine_cycle(&p, &rod, OMEGA, n, Some(&gas)).expect("cycle");
            assert_eq!(cyc.len(), 2 * n);
            assert_eq!(cyc[0].crank_angle_deg, 0.0);
            assert!((cyc[n].crank_angle_deg - 360.0).abs() < 1e-9);
            assert!(
                cyc.iter()
                    .all(|i| (0.0..720.0).contains(&i.crank_angle_deg))
            );
            let scene = DrivenScene {
                omega_rad_s: OMEGA,
                duration_s: 2.0 * std::f64::consts::TAU / OMEGA,
                steps: 2 * n,
                phi0_rad: 0.0,
            };
            let d =
                driven_scene_with_gas(&p, &rod, Some(Arc::clone(&gas)), &scene, Method::ClosedForm)
                    .expect("scene");
            let peak_a = d.fa_abs_n.iter().fold(0.0f64, |a, b| a.max(*b));
            let peak_b = d.fb_abs_n.iter().fold(0.0f64, |a, b| a.max(*b));
            let (mut ea, mut eb, mut eg) = (0.0f64, 0.0f64, 0.0f64);
            let gas_n = d.gas_force_n.as_ref().expect("gas force samples");
            for (k, inst) in cyc.iter().enumerate() {
                assert!((inst.time_s - d.t_s[k]).abs() <= 1e-15 * d.t_s[k].max(1.0));
                let psi = psi_at(&p, inst.time_s);
                let fa = rotate_to_global(psi, inst.f_a_on_rod_n);
                let fb = rotate_to_global(psi, inst.f_b_on_rod_n);
                ea = ea.max((fa - Vector2::new(d.fa_x_n[k], d.fa_y_n[k])).norm() / peak_a);
                eb = eb.max((fb + Vector2::new(d.fb_x_n[k], d.fb_y_n[k])).norm() / peak_b);
                eg = eg.max((inst.gas_force_n - gas_n[k]).abs() / gas.max_n());
            }
            eprintln!("engine cycle vs closed form: F_A {ea:.2e}, F_B {eb:.2e}, F_gas {eg:.2e}");
            assert!(
                ea < 1e-9 && eb < 1e-9 && eg < 1e-12,
                "F_A {ea:e}, F_B {eb:e}"
            );
            // the gas force matters here: the firing peak is several times the inertia peak
            let no_gas = rod_frame_cycle(&p, &rod, OMEGA, n).expect("cycle");
            let peak = |c: &[RodFrameInstant]| {
                c.iter()
                    .map(|i| i.f_a_on_rod_n[0].hypot(i.f_a_on_rod_n[1]))
                    .fold(0.0f64, f64::max)
            };
            assert!(
                peak(&cyc) > 2.0 * peak(&no_gas),
                "{} vs {}",
                peak(&cyc),
                peak(&no_gas)
            );
        }
        // without a gas force: exactly the one-revolution cycle
        let (p, rod) = &cases()[0];
        assert_eq!(
            rod_frame_engine_cycle(p, rod, OMEGA, 90, None).expect("cycle"),
            rod_frame_cycle(p, rod, OMEGA, 90).expect("cycle")
        );
    }

    #[test]
    fn newton_euler_residuals_vanish() {
        for (p, rod) in cases() {
            let cyc = rod_frame_cycle(&p, &rod, OMEGA, 720).expect("cycle");
            let l = p.centre_distance_m;
            let m = rod.mass_kg;
            let rg = [rod.l1_m, rod.offset_m];
            let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
            let peak = cyc
                .iter()
                .map(|i| i.f_a_on_rod_n[0].hypot(i.f_a_on_rod_n[1]))
                .fold(0.0f64, f64::max);
            let (mut ef, mut ma, mut mg) = (0.0f64, 0.0f64, 0.0f64);
            for inst in &cyc {
                let (fa, fb, g) = (inst.f_a_on_rod_n, inst.f_b_on_rod_n, inst.gravity_m_s2);
                let a_g = acceleration_of(inst, rg);
                let res = [
                    fa[0] + fb[0] + m * g[0] - m * a_g[0],
                    fa[1] + fb[1] + m * g[1] - m * a_g[1],
                ];
                ef = ef.max(res[0].hypot(res[1]) / peak);
                // moment about A: r_B × F_B + r_G × m g − (I α + r_G × m a_G)
                let mom_a = cross([l, 0.0], fb) + cross(rg, [m * g[0], m * g[1]])
                    - rod.i_zz_kgm2 * inst.alpha3_rad_s2
                    - cross(rg, [m * a_g[0], m * a_g[1]]);
                ma = ma.max(mom_a.abs() / (peak * l));
                // moment about G: (r_A − r_G) × F_A + (r_B − r_G) × F_B = I α
                let mom_g = cross([-rg[0], -rg[1]], fa) + cross([l - rg[0], -rg[1]], fb)
                    - rod.i_zz_kgm2 * inst.alpha3_rad_s2;
                mg = mg.max(mom_g.abs() / (peak * l));
            }
            eprintln!("Newton-Euler residuals: force {ef:.2e}, moment A {ma:.2e}, G {mg:.2e}");
            assert!(ef < 1e-9 && ma < 1e-9 && mg < 1e-9, "{ef:e} {ma:e} {mg:e}");
        }
    }

    #[test]
    fn kinematics_match_finite_differences_and_the_crank_pin() {
        let p = MechanismParams::default();
        let cyc = rod_frame_cycle(&p, &RodInertia::thesis_original(), OMEGA, 360).expect("cycle");
        let theta = |t: f64| -psi_at(&p, t);
        let h = 1e-6;
        let w_peak = cyc.iter().map(|i| i.omega3_rad_s.abs()).fold(0.0, f64::max);
        let a_peak = cyc
            .iter()
            .map(|i| i.alpha3_rad_s2.abs())
            .fold(0.0, f64::max);
        let ra = p.crank_radius_m * OMEGA * OMEGA;
        let (mut ew, mut ea, mut emag, mut edir) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for inst in &cyc {
            let t = inst.time_s;
            let (tm, t0, tp) = (theta(t - h), theta(t), theta(t + h));
            ew = ew.max(((tp - tm) / (2.0 * h) - inst.omega3_rad_s).abs() / w_peak);
            ea = ea.max(((tp - 2.0 * t0 + tm) / (h * h) - inst.alpha3_rad_s2).abs() / a_peak);
            let a = inst.a_a_m_s2;
            emag = emag.max((a[0].hypot(a[1]) - ra).abs() / ra);
            // direction: centripetal, −ω² A in the global frame
            let phi = OMEGA * t;
            let want = Vector2::new(phi.cos(), phi.sin()) * (-ra);
            edir = edir.max((rotate_to_global(-t0, a) - want).norm() / ra);
        }
        eprintln!(
            "kinematics: omega3 {ew:.2e}, alpha3 {ea:.2e} (FD, rel. to peak); \
             |a_A| {emag:.2e}, a_A direction {edir:.2e}"
        );
        assert!(ew < 1e-5 && ea < 1e-5, "omega3 {ew:e}, alpha3 {ea:e}");
        assert!(emag < 1e-12, "|a_A| {emag:e}");
        assert!(edir < 1e-12, "a_A direction {edir:e}");
    }

    #[test]
    fn grid_starts_at_top_dead_centre_and_stays_in_range() {
        let p = MechanismParams::default();
        let rod = RodInertia::thesis_original();
        for n in [1usize, 7, 360, 1000] {
            let cyc = rod_frame_cycle(&p, &rod, OMEGA, n).expect("cycle");
            assert_eq!(cyc.len(), n);
            assert_eq!(cyc[0].crank_angle_deg, 0.0);
            assert_eq!(cyc[0].time_s, 0.0);
            for (k, inst) in cyc.iter().enumerate() {
                assert!((0.0..360.0).contains(&inst.crank_angle_deg));
                let want = 360.0 * k as f64 / n as f64;
                assert!((inst.crank_angle_deg - want).abs() < 1e-9, "{k}/{n}");
                let t = k as f64 * std::f64::consts::TAU / (OMEGA * n as f64);
                assert!((inst.time_s - t).abs() < 1e-15);
            }
        }
        // at top dead centre x̂ = global +x, ŷ = global +y: gravity is (0, −g)
        let first = rod_frame_cycle(&p, &rod, OMEGA, 4).expect("cycle")[0];
        assert_eq!(first.gravity_m_s2, [0.0, -9.81]);
        assert_eq!(
            rod_frame_cycle(&p.with_gravity(false), &rod, OMEGA, 4).expect("cycle")[0].gravity_m_s2,
            [0.0, 0.0]
        );
        assert!(rod_frame_cycle(&p, &rod, OMEGA, 0).is_err());
        assert!(rod_frame_cycle(&p, &rod, 0.0, 10).is_err());
        assert!(rod_frame_cycle(&p, &rod, -OMEGA, 10).is_err());
        assert!(rod_frame_cycle(&p, &rod, f64::NAN, 10).is_err());
        assert!(rod_frame_cycle(&p, &RodInertia::new(-1.0, 0.07, 0.02), OMEGA, 10).is_err());
        let json = serde_json::to_string(&first).expect("serialise");
        assert_eq!(
            serde_json::from_str::<RodFrameInstant>(&json).expect("parse"),
            first
        );
    }

    #[test]
    fn rigid_body_acceleration_matches_the_piston_and_the_centroid() {
        for (p, rod) in cases() {
            let cs = CrankSlider::new(&p, &rod).expect("model");
            let l = p.centre_distance_m;
            let scale = p.crank_radius_m * OMEGA * OMEGA;
            let cyc = rod_frame_cycle(&p, &rod, OMEGA, 360).expect("cycle");
            let (mut eb, mut eg) = (0.0f64, 0.0f64);
            for inst in &cyc {
                let m = MotionSample {
                    phi: OMEGA * inst.time_s,
                    omega: OMEGA,
                    alpha: 0.0,
                };
                let kin = cs.closed_form_kinematics(m);
                // B slides along global x: a_B = (ẍ_B, 0) global
                let a_b = rotate_to_global(kin.psi, acceleration_of(inst, [l, 0.0]));
                eb = eb.max((a_b - Vector2::new(kin.xdd_b, 0.0)).norm() / scale);
                // the centroid at (l1, offset) is the crate's G3 (offset sign convention)
                let cm = cs.centroid_motion(&kin);
                let a_g =
                    rotate_to_global(kin.psi, acceleration_of(inst, [rod.l1_m, rod.offset_m]));
                eg = eg.max((a_g - cm.g3[2]).norm() / scale);
            }
            eprintln!("rigid-body acceleration: B {eb:.2e}, G {eg:.2e} (rel. to r w^2)");
            assert!(eb < 1e-9 && eg < 1e-9, "B {eb:e}, G {eg:e}");
        }
    }
}
