//! The exact reference solution of the free run from the energy integral.
//!
//! For conservative loads the kinetic-energy theorem (thesis eq. 3.7, with eq. 3.1 and 3.20)
//! integrates once:
//!
//! `½ I_red(φ) φ̇² = ½ I_red(φ0) φ̇0² + M (φ − φ0) + F (x(φ) − x(φ0)) − (V(φ) − V(φ0)) =: W(φ)`,
//!
//! so `φ̇(φ) = sqrt(2 W(φ) / I_red(φ))` in closed form and `t(φ) = t0 + ∫_{φ0}^{φ} dφ'/φ̇(φ')`.
//! At the start with `φ̇0 = 0` the integrand has a `1/sqrt(φ − φ0)` singularity; the
//! substitution `φ = φ0 + u²` removes it: `t(u) = t0 + ∫_0^u 2u'/φ̇(φ0 + u'²) du'`, whose
//! integrand tends to `2 sqrt(I_red(φ0) / (2 M_red(φ0)))` as `u → 0`. `W` is evaluated from the
//! increment `Δ = u²` without cancellation (see [`super::mechanism::Kinematics::x_increment`]),
//! so it keeps full relative accuracy at tiny `Δ`.
//!
//! `t(u)` is built panel by panel with Gauss–Kronrod 7–15 (a panel is accepted when
//! `|K15 − G7| ≤ 1e-11 |K15|`, which leaves the K15 value accurate to roundoff); the panel sums
//! are accumulated with Neumaier compensation. Each output time `t_k` is then inverted by
//! safeguarded Newton on `t(u) = t_k` inside its panel (`dt/du = 2u/φ̇`), with `t(u)` from the
//! panel start plus one K15 over the partial panel; `φ_k = φ0 + u_k²`, `φ̇_k = φ̇(φ_k)`.
//! There is no accumulation along the grid: each point's error is roundoff in `t` (~1e-16 s)
//! times `φ̇`, i.e. ~1e-14 rad over the thesis' run.

use super::loads::{G, Loads};
use super::quadrature::gk15;
use super::reduced::ReducedModel;
use crate::integrators::OutputGrid;
use serde::Serialize;

/// Why the energy-integral reference cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReferenceError {
    /// Damping dissipates energy: no energy integral.
    #[error("no energy integral: the loads are not conservative (damping)")]
    NonConservative,
    /// The crank does not move forward from the start.
    #[error(
        "the crank does not start forward (φ̇0 = {omega0}, M_red(φ0) = {m_red0}): the reference needs φ monotone increasing"
    )]
    NotStartingForward {
        /// Initial angular velocity [rad/s].
        omega0: f64,
        /// Reduced moment at the start [N·m].
        m_red0: f64,
    },
    /// The crank stops (φ̇ = 0) before the end time: φ(t) is not monotone.
    #[error(
        "the crank stops at φ = {phi} rad before t_end: the energy-integral reference needs φ̇ > 0"
    )]
    TurningPoint {
        /// Crank angle where `W(φ) ≤ 0` was met \[rad\].
        phi: f64,
    },
    /// Quadrature trouble (non-finite integrand or no convergence).
    #[error("reference quadrature failed: {0}")]
    Quadrature(String),
}

/// The exact solution on the output grid.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExactReference {
    /// Output times \[s\].
    pub t: Vec<f64>,
    /// Crank angle \[rad\].
    pub phi: Vec<f64>,
    /// Crank angular velocity [rad/s].
    pub omega: Vec<f64>,
    /// Number of quadrature panels.
    pub panels: usize,
    /// Integrand evaluations.
    pub integrand_evals: u64,
}

impl ExactReference {
    /// `(max |Δφ|, max |Δω|)` of a trajectory on the same grid.
    pub fn max_errors(&self, phi: &[f64], omega: &[f64]) -> (f64, f64) {
        let ep = self
            .phi
            .iter()
            .zip(phi)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let ew = self
            .omega
            .iter()
            .zip(omega)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let n_ok = phi.len() == self.phi.len() && omega.len() == self.omega.len();
        if n_ok {
            (ep, ew)
        } else {
            (f64::INFINITY, f64::INFINITY)
        }
    }
}

/// `W(Δ)` and `φ̇(Δ)` relative to the start `(φ0, φ̇0)`.
pub(super) struct EnergyIntegral<'a> {
    model: &'a ReducedModel,
    loads: Loads,
    phi0: f64,
    omega0: f64,
    i0: f64,
    x0: f64,
    g_start: f64,
    evals: u64,
}

impl<'a> EnergyIntegral<'a> {
    /// The integral of `loads` (conservative: the caller checks) on `model` from `(φ0, φ̇0)`.
    pub(super) fn new(model: &'a ReducedModel, loads: &Loads, phi0: f64, omega0: f64) -> Self {
        EnergyIntegral {
            model,
            loads: *loads,
            phi0,
            omega0,
            i0: model.i_red(phi0),
            x0: model.kinematics().x(phi0),
            g_start: 0.0,
            evals: 0,
        }
    }

    /// The start angle `φ0` \[rad\].
    pub(super) fn phi0(&self) -> f64 {
        self.phi0
    }

    /// Work of the loads plus initial kinetic energy, `W(φ0 + Δ)` (cancellation-free).
    fn work(&self, delta: f64) -> f64 {
        let kin = self.model.kinematics();
        let dx = kin.x_increment(self.phi0, delta);
        let mut w = 0.5 * self.i0 * self.omega0 * self.omega0
            + self.loads.torque * delta
            + self.loads.piston_force * dx;
        if self.loads.gravity {
            let dsin = 2.0 * (self.phi0 + 0.5 * delta).cos() * (0.5 * delta).sin();
            w -= G * self.model.gravity_lever() * dsin;
        }
        if let Some(s) = self.loads.spring {
            let x = self.x0 + dx;
            w -= 0.5 * s.k * dx * (x + self.x0 - 2.0 * s.x0);
        }
        w
    }

    /// `φ̇(φ0 + Δ)`; `None` if `W ≤ 0` (the crank would have stopped).
    pub(super) fn omega(&self, delta: f64) -> Option<f64> {
        let w = self.work(delta);
        if w.is_nan() || w <= 0.0 {
            return None;
        }
        Some((2.0 * w / self.model.i_red(self.phi0 + delta)).sqrt())
    }

    /// Integrand `dt/du = 2u / φ̇(φ0 + u²)`.
    fn dt_du(&mut self, u: f64) -> Result<f64, ReferenceError> {
        self.evals += 1;
        if u == 0.0 {
            return Ok(self.g_start);
        }
        let delta = u * u;
        match self.omega(delta) {
            Some(w) if w.is_finite() => Ok(2.0 * u / w),
            _ => Err(ReferenceError::TurningPoint {
                phi: self.phi0 + delta,
            }),
        }
    }

    /// K15 of `dt/du` over `[a, b]`, with the G7 difference.
    fn panel(&mut self, a: f64, b: f64) -> Result<(f64, f64), ReferenceError> {
        let mut failure = None;
        let (k, e) = gk15(
            |u| match self.dt_du(u) {
                Ok(v) => v,
                Err(err) => {
                    failure.get_or_insert(err);
                    f64::NAN
                }
            },
            a,
            b,
        );
        if let Some(err) = failure {
            return Err(err);
        }
        if !k.is_finite() {
            return Err(ReferenceError::Quadrature(format!(
                "non-finite integral on u ∈ [{a}, {b}]"
            )));
        }
        Ok((k, e))
    }
}

/// Neumaier-compensated running sum.
#[derive(Default, Clone, Copy)]
struct Sum {
    s: f64,
    c: f64,
}

impl Sum {
    fn add(&mut self, v: f64) {
        let t = self.s + v;
        if self.s.abs() >= v.abs() {
            self.c += (self.s - t) + v;
        } else {
            self.c += (v - t) + self.s;
        }
        self.s = t;
    }
    fn value(&self) -> f64 {
        self.s + self.c
    }
}

/// One quadrature panel `[u0, u1]` starting at time `t0` (relative to the run's start).
struct Panel {
    u0: f64,
    u1: f64,
    t0: f64,
}

/// Default relative acceptance threshold of a panel on `|K15 − G7|`.
pub const PANEL_TOL: f64 = 1e-11;

/// Builds the exact reference on `grid` from the start `(φ0, φ̇0)` at `grid.t0`
/// (panel threshold [`PANEL_TOL`]).
pub fn exact_reference(
    model: &ReducedModel,
    loads: &Loads,
    phi0: f64,
    omega0: f64,
    grid: &OutputGrid,
) -> Result<ExactReference, ReferenceError> {
    exact_reference_with_tol(model, loads, phi0, omega0, grid, PANEL_TOL)
}

/// [`exact_reference`] with a chosen panel threshold `panel_tol` (for convergence checks).
pub fn exact_reference_with_tol(
    model: &ReducedModel,
    loads: &Loads,
    phi0: f64,
    omega0: f64,
    grid: &OutputGrid,
    panel_tol: f64,
) -> Result<ExactReference, ReferenceError> {
    if !loads.is_conservative() {
        return Err(ReferenceError::NonConservative);
    }
    let i0 = model.i_red(phi0);
    let m_red0 = model.m_red(loads, phi0, omega0);
    if omega0 < 0.0 || (omega0 == 0.0 && (m_red0.is_nan() || m_red0 <= 0.0)) {
        return Err(ReferenceError::NotStartingForward { omega0, m_red0 });
    }
    let g_start = if omega0 > 0.0 {
        0.0
    } else {
        2.0 * (i0 / (2.0 * m_red0)).sqrt()
    };
    let mut ei = EnergyIntegral {
        g_start,
        ..EnergyIntegral::new(model, loads, phi0, omega0)
    };
    let span = grid.t_end() - grid.t0;

    // 1. panels of t(u) until they cover the whole time span
    let mut panels: Vec<Panel> = Vec::new();
    let mut total = Sum::default();
    let (mut u, mut h) = (0.0f64, 1e-2f64);
    while total.value() < span {
        if panels.len() > 10_000_000 {
            return Err(ReferenceError::Quadrature("too many panels".into()));
        }
        let (k, e) = ei.panel(u, u + h)?;
        if e > panel_tol * k.abs() {
            h *= 0.5;
            if h < 1e-14 * u.max(1e-3) {
                return Err(ReferenceError::Quadrature(format!(
                    "panel width underflow at u = {u}"
                )));
            }
            continue;
        }
        panels.push(Panel {
            u0: u,
            u1: u + h,
            t0: total.value(),
        });
        total.add(k);
        u += h;
        if e < 1e-3 * panel_tol * k.abs() {
            h *= 2.0;
        } else if e < 0.1 * panel_tol * k.abs() {
            h *= 1.3;
        }
    }

    // 2. invert t(u) = t_k on the grid
    let n = grid.len();
    let (mut t_out, mut phi, mut omega) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    let mut p = 0usize;
    let (mut u_prev, mut tau_prev) = (0.0, 0.0);
    for k in 0..n {
        let tk = grid.t(k);
        let tau = tk - grid.t0;
        let (uk, w) = if k == 0 {
            (0.0, omega0)
        } else {
            while p + 1 < panels.len() && panels[p + 1].t0 <= tau {
                p += 1;
            }
            let pan = &panels[p];
            // first guess: one Newton step from the previous point (dt/du known there)
            let guess = u_prev + (tau - tau_prev) / ei.dt_du(u_prev)?;
            let uk = invert_in_panel(&mut ei, pan, tau, guess)?;
            let w = if uk == 0.0 {
                omega0
            } else {
                ei.omega(uk * uk).ok_or(ReferenceError::TurningPoint {
                    phi: phi0 + uk * uk,
                })?
            };
            (uk, w)
        };
        u_prev = uk;
        tau_prev = tau;
        t_out.push(tk);
        phi.push(phi0 + uk * uk);
        omega.push(w);
    }
    Ok(ExactReference {
        t: t_out,
        phi,
        omega,
        panels: panels.len(),
        integrand_evals: ei.evals,
    })
}

/// Safeguarded Newton for `pan.t0 + ∫_{pan.u0}^{u} dt/du = tau` on `u ∈ [pan.u0, pan.u1]`.
fn invert_in_panel(
    ei: &mut EnergyIntegral<'_>,
    pan: &Panel,
    tau: f64,
    u_guess: f64,
) -> Result<f64, ReferenceError> {
    let (mut lo, mut hi) = (pan.u0, pan.u1);
    let mut u = u_guess.clamp(lo, hi);
    if u == lo && lo == 0.0 {
        u = 0.5 * (lo + hi);
    }
    for _ in 0..200 {
        let (q, _) = if u > pan.u0 {
            ei.panel(pan.u0, u)?
        } else {
            (0.0, 0.0)
        };
        let f = pan.t0 + q - tau;
        if f == 0.0 {
            return Ok(u);
        }
        if f > 0.0 {
            hi = u;
        } else {
            lo = u;
        }
        let g = ei.dt_du(u)?;
        let mut u_new = u - f / g;
        if !(u_new >= lo && u_new <= hi) {
            u_new = 0.5 * (lo + hi);
        }
        let step = (u_new - u).abs();
        u = u_new;
        if step <= 4.0 * f64::EPSILON * u.abs() || hi - lo <= 4.0 * f64::EPSILON * hi.abs() {
            return Ok(u);
        }
    }
    Err(ReferenceError::Quadrature(format!(
        "Newton inversion did not converge at t = {tau}"
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::free_run::mechanism::CrankSliderData;

    /// Crank alone (no rod or piston mass): `I_red = I2`, and with `F = 0` the motion is
    /// uniformly accelerated, `φ = φ0 + ω0 t + ½ (M/I2) t²`.
    fn crank_only() -> ReducedModel {
        let d = CrankSliderData {
            m3: 0.0,
            i_s3: 0.0,
            m4: 0.0,
            ..CrankSliderData::thesis_ch3()
        };
        ReducedModel::new(d).unwrap()
    }

    #[test]
    fn uniform_acceleration_from_rest_and_from_motion() {
        let m = crank_only();
        let loads = Loads {
            piston_force: 0.0,
            ..Loads::thesis_ch4()
        };
        let grid = OutputGrid::new(0.0, 2.0, 1e-3).unwrap();
        let a = 1.0 / m.data.i2;
        for (phi0, w0) in [(0.0, 0.0), (0.3, 5.0)] {
            let r = exact_reference(&m, &loads, phi0, w0, &grid).unwrap();
            for (k, &t) in r.t.iter().enumerate() {
                let phi = phi0 + w0 * t + 0.5 * a * t * t;
                assert!(
                    (r.phi[k] - phi).abs() <= 2e-15 * phi.max(1.0),
                    "t = {t}: {} vs {phi}",
                    r.phi[k]
                );
                assert!((r.omega[k] - (w0 + a * t)).abs() <= 1e-13, "t = {t}");
            }
        }
    }

    #[test]
    fn refuses_what_it_cannot_represent() {
        let m = crank_only();
        let grid = OutputGrid::new(0.0, 1.0, 0.1).unwrap();
        let backwards = Loads {
            torque: -1.0,
            piston_force: 0.0,
            ..Loads::thesis_ch4()
        };
        let e = exact_reference(&m, &backwards, 0.0, 0.0, &grid).unwrap_err();
        assert!(matches!(e, ReferenceError::NotStartingForward { .. }));
        // braked from 1 rad/s: stops at t = I2 (·1 rad/s / 1 N·m) ≈ 0.016 s
        let e = exact_reference(&m, &backwards, 0.0, 1.0, &grid).unwrap_err();
        assert!(matches!(e, ReferenceError::TurningPoint { .. }), "{e}");
        let damped = Loads {
            spring: Some(crate::free_run::loads::GasSpring {
                k: 1.0,
                x0: 0.0,
                c: 1.0,
            }),
            ..Loads::thesis_ch4()
        };
        assert_eq!(
            exact_reference(&m, &damped, 0.0, 0.0, &grid).unwrap_err(),
            ReferenceError::NonConservative
        );
    }
}
