//! Locating the true maximum of the pin force |F_A| over the motion.
//!
//! The driven scene samples |F_A| on its time grid. At constant crank speed
//! the force is periodic with the crank period 2π/ω, so its maximum over a
//! scene that covers at least one revolution is the maximum over one
//! revolution. [`refine_peak`] scans one revolution (or the whole scene if
//! shorter) at 360 points (1° apart) with the closed form, then refines the
//! three best local maxima by golden-section search on ±1 scan interval down
//! to a bracket of 1e-10 of the period (the force is flat at its maximum, so
//! its value is then exact to rounding). About 480 closed-form evaluations,
//! a few tens of microseconds. The reported time is the first occurrence in
//! [0, period). [`refine_peak_of`] does the same on any model of the motion
//! (the multibody core, for `--method multibody`).

use super::crank_slider::CrankSlider;
use super::error::{DynamicsError, Result};
use super::motion::CrankMotion;

/// The refined maximum of |F_A|.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct PeakRefinement {
    /// Maximum of |F_A| (N).
    pub force_n: f64,
    /// First time at which it occurs (s), in [0, min(duration, period)].
    pub time_s: f64,
    /// Crank angle there, wrapped to [0, 360) degrees ([0, 720) over the four-stroke cycle).
    pub crank_angle_deg: f64,
    /// Closed-form evaluations spent.
    pub evaluations: usize,
}

/// Angle in degrees wrapped to [0, 360).
pub fn wrap_degrees(phi_rad: f64) -> f64 {
    wrap_degrees_to(phi_rad, 360.0)
}

/// Angle in degrees wrapped to [0, period_deg) (720 for the four-stroke cycle).
pub fn wrap_degrees_to(phi_rad: f64, period_deg: f64) -> f64 {
    let d = phi_rad.to_degrees().rem_euclid(period_deg);
    if d >= period_deg { 0.0 } else { d }
}

/// Golden-section search for the maximum of a unimodal `f` on [a, b]; stops
/// when the bracket is narrower than `tol` (or after 200 iterations). Returns
/// (argmax, max, evaluations).
pub fn golden_section_max<F: FnMut(f64) -> f64>(
    mut f: F,
    a: f64,
    b: f64,
    tol: f64,
) -> (f64, f64, usize) {
    let inv = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (a, b);
    let mut c = b - inv * (b - a);
    let mut d = a + inv * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    let mut evals = 2;
    while (b - a).abs() > tol && evals < 200 {
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - inv * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + inv * (b - a);
            fd = f(d);
        }
        evals += 1;
    }
    if fc > fd {
        (c, fc, evals)
    } else {
        (d, fd, evals)
    }
}

const SCAN: usize = 360;
const CANDIDATES: usize = 3;

/// True maximum of |F_A| for the constant-speed motion φ = φ₀ + ω t over
/// t ∈ [0, duration], by the closed form (see the module documentation).
pub fn refine_peak(
    model: &CrankSlider,
    phi0_rad: f64,
    omega_rad_s: f64,
    duration_s: f64,
) -> Result<PeakRefinement> {
    let motion = CrankMotion::ConstantSpeed {
        phi0_rad,
        omega_rad_s,
    };
    refine_peak_of(
        |t: f64| model.closed_form(motion.sample(t)).f_a.norm(),
        phi0_rad,
        omega_rad_s,
        duration_s,
    )
}

/// [`refine_peak`] for any model of the motion: `f(t)` is |F_A| at time t (NaN for a failure,
/// which makes the result an error). The scan runs forwards in t and the golden-section brackets
/// are narrow, so a model that tracks its solution from the previous time (the multibody core)
/// can be used as it is.
pub fn refine_peak_of(
    f: impl FnMut(f64) -> f64,
    phi0_rad: f64,
    omega_rad_s: f64,
    duration_s: f64,
) -> Result<PeakRefinement> {
    refine_max_of(f, phi0_rad, omega_rad_s, duration_s, std::f64::consts::TAU)
}

/// [`refine_peak_of`] for a function of period `period_rad` of crank angle (2π for the
/// inertia loads, 4π over the four-stroke cycle with a gas force): the scan has 360 points per
/// revolution (1° apart), the reported angle is wrapped to [0, period) in degrees. `f` may be
/// any quantity to maximise (|F_A|, the rod's axial compression, its tension).
pub fn refine_max_of(
    mut f: impl FnMut(f64) -> f64,
    phi0_rad: f64,
    omega_rad_s: f64,
    duration_s: f64,
    period_rad: f64,
) -> Result<PeakRefinement> {
    if !(omega_rad_s.is_finite()
        && omega_rad_s > 0.0
        && duration_s.is_finite()
        && duration_s > 0.0
        && period_rad.is_finite()
        && period_rad > 0.0)
    {
        return Err(DynamicsError::InvalidScene(format!(
            "peak refinement needs omega > 0 and duration > 0 (got {omega_rad_s} rad/s, {duration_s} s)"
        )));
    }
    let revolutions = (period_rad / std::f64::consts::TAU).round().max(1.0);
    let scan = SCAN * revolutions as usize;
    let period = period_rad / omega_rad_s;
    let periodic = duration_s >= period;
    let window = if periodic { period } else { duration_s };
    let dt = window / scan as f64;
    let mut v = vec![0.0f64; scan + 1];
    for (i, slot) in v.iter_mut().enumerate() {
        *slot = f(dt * i as f64);
    }
    let mut evaluations = scan + 1;
    // the best few local maxima (cyclic neighbours when periodic)
    let mut best: [(usize, f64); CANDIDATES] = [(usize::MAX, f64::NEG_INFINITY); CANDIDATES];
    let last = if periodic { scan - 1 } else { scan };
    for i in 0..=last {
        let prev = if i > 0 {
            v[i - 1]
        } else if periodic {
            v[scan - 1]
        } else {
            f64::NEG_INFINITY
        };
        let next = if i < last {
            v[i + 1]
        } else if periodic {
            v[0]
        } else {
            f64::NEG_INFINITY
        };
        if v[i] >= prev
            && v[i] >= next
            && let Some(slot) = best.iter_mut().min_by(|x, y| x.1.total_cmp(&y.1))
            && v[i] > slot.1
        {
            *slot = (i, v[i]);
        }
    }
    let (mut t_best, mut f_best) = (0.0, f64::NEG_INFINITY);
    for &(i, vi) in best.iter().filter(|c| c.0 != usize::MAX) {
        let ti = dt * i as f64;
        let (mut a, mut b) = (ti - dt, ti + dt);
        if !periodic {
            a = a.max(0.0);
            b = b.min(duration_s);
        }
        let (tg, fg, n) = golden_section_max(&mut f, a, b, 1e-10 * window);
        evaluations += n;
        let (tc, fc) = if fg > vi { (tg, fg) } else { (ti, vi) };
        if fc > f_best {
            t_best = tc;
            f_best = fc;
        }
    }
    if !f_best.is_finite() {
        return Err(DynamicsError::NonFinite {
            t_s: t_best,
            what: "peak pin force",
        });
    }
    if periodic {
        t_best = t_best.rem_euclid(period);
    }
    Ok(PeakRefinement {
        force_n: f_best,
        time_s: t_best,
        crank_angle_deg: wrap_degrees_to(phi0_rad + omega_rad_s * t_best, 360.0 * revolutions),
        evaluations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn golden_section_finds_a_parabola_top() {
        let (x, fx, n) = golden_section_max(|x| 3.0 - (x - 0.123).powi(2), 0.0, 1.0, 1e-12);
        // near a smooth maximum f is flat: x is found to ~sqrt(eps), f to eps
        assert!(
            (x - 0.123).abs() < 1e-7 && (fx - 3.0).abs() < 1e-15 && n < 100,
            "{x} {fx} {n}"
        );
    }

    #[test]
    fn wrapping() {
        assert_eq!(wrap_degrees(0.0), 0.0);
        assert!((wrap_degrees(-1e-3) - (360.0 - 1e-3f64.to_degrees())).abs() < 1e-9);
        assert!(wrap_degrees(-1e-18) < 360.0);
        assert!((wrap_degrees(7.0 * std::f64::consts::PI) - 180.0).abs() < 1e-9);
    }
}
