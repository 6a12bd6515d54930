//! Step-size selection shared by the adaptive methods.

use super::eval::Evaluator;
use super::norm::Weights;
use super::{FailureKind, OdeSystem, SolverError, SolverOptions};
use nalgebra::DVector;

/// Starting step by the algorithm of Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4
/// ("Starting step size"), for a method whose local error is `O(h^(order+1))`:
/// `h0 = 0.01 ‖y0‖/‖f0‖`, one explicit Euler step to estimate `‖y''‖`, then
/// `h1 = (0.01 / max(‖f0‖, ‖y''‖))^(1/(order+1))`, `h = min(100 h0, h1)`.
/// Uses one right-hand-side evaluation. `f0 = f(t0, y0)`.
pub(crate) fn initial_step<S: OdeSystem + ?Sized>(
    ev: &mut Evaluator<'_, S>,
    t0: f64,
    y0: &DVector<f64>,
    f0: &DVector<f64>,
    order: u32,
    span: f64,
    opts: &SolverOptions,
) -> Result<f64, SolverError> {
    let h_max = max_step(opts, span);
    if let Some(h) = opts.h {
        return Ok(h.min(h_max));
    }
    let w = Weights::new(opts, y0.len());
    let d0 = w.norm(y0, y0, y0);
    let d1 = w.norm(f0, y0, y0);
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    let h0 = h0.min(h_max);
    let y1 = y0 + f0 * h0;
    let mut f1 = DVector::zeros(y0.len());
    ev.rhs_finite(t0 + h0, &y1, &mut f1)?;
    let d2 = w.norm(&(&f1 - f0), y0, y0) / h0;
    let dm = d1.max(d2);
    let h1 = if dm <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / dm).powf(1.0 / (order as f64 + 1.0))
    };
    // floor: absurd tolerances must not produce a zero step (the controller shrinks it anyway)
    Ok((100.0 * h0).min(h1).min(h_max).max(1e-12 * span))
}

/// Largest allowed step: `h_max` or the whole interval.
pub(crate) fn max_step(opts: &SolverOptions, span: f64) -> f64 {
    opts.h_max.unwrap_or(span).min(span)
}

/// Smallest step that still advances `t` meaningfully (16 ulp of `t`).
pub(crate) fn min_step(t: f64) -> f64 {
    16.0 * f64::EPSILON * t.abs().max(f64::MIN_POSITIVE.sqrt())
}

/// Fails with [`FailureKind::StepSizeUnderflow`] if `h` is below [`min_step`].
pub(crate) fn check_underflow<S: OdeSystem + ?Sized>(
    ev: &Evaluator<'_, S>,
    t: f64,
    h: f64,
) -> Result<(), SolverError> {
    if h < min_step(t) || !h.is_finite() {
        return Err(ev.fail(FailureKind::StepSizeUnderflow { h }));
    }
    Ok(())
}

/// Clamps a step so that it ends exactly at `t_end`; returns `(h, t_new, last)`. A step
/// that would leave a remainder shorter than 1 % of itself is stretched to the end. The step
/// returned is `t_new − t` (exact by Sterbenz's lemma), not the `h` asked for, so that the
/// stages and the recorded times agree to the last bit (SciPy's `solve_ivp` does the same);
/// with `fl(t + h) ≠ t + h` the time would otherwise drift from `Σ h` by up to half an ulp of
/// `t` per step.
pub(crate) fn clamp_to_end(t: f64, h: f64, t_end: f64) -> (f64, f64, bool) {
    if t + 1.01 * h >= t_end {
        (t_end - t, t_end, true)
    } else {
        let t_new = t + h;
        (t_new - t, t_new, false)
    }
}

/// Step-size factor of an elementary controller, `safety · err^(-1/q)` limited to
/// `[fac_min, fac_max]` (Hairer, Nørsett & Wanner, eq. II.4.13); `err` is the scaled norm.
pub(crate) fn factor(err: f64, q: f64, safety: f64, fac_min: f64, fac_max: f64) -> f64 {
    if err == 0.0 {
        return fac_max;
    }
    (safety * err.powf(-1.0 / q)).clamp(fac_min, fac_max)
}

/// An elementary step-size controller: [`factor`] with the method's error exponent, safety
/// factor and smallest factor (the largest is set by the loop, see
/// [`super::adaptive::FAC_MAX`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Controller {
    /// `q` of `err^(-1/q)`: the order of the error estimate plus one.
    pub(crate) exponent: f64,
    /// Safety factor.
    pub(crate) safety: f64,
    /// Smallest factor.
    pub(crate) fac_min: f64,
}

impl Controller {
    /// [`factor`] of this controller, at most `fac_max`.
    pub(crate) fn factor(&self, err: f64, fac_max: f64) -> f64 {
        factor(err, self.exponent, self.safety, self.fac_min, fac_max)
    }
}
