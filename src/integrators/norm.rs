//! The weighted error norm of all adaptive methods.

use super::SolverOptions;
use nalgebra::DVector;
use std::cell::Cell;

/// Safety factor `κ` of the tolerance floor: a component's error scale
/// `atol_i + rtol_i·|y_i|` is never below `κ·ε·|y_i|` (`ε` = [`f64::EPSILON`] = 2.2e-16), i.e.
/// about two units in the last place of the state (one ulp of `y` is between `ε|y|/2` and
/// `ε|y|`).
///
/// Why: the right-hand side is evaluated at states rounded to f64, so every stage carries an
/// unavoidable perturbation of half an ulp of `y`; a local error request below that cannot be
/// met and the step control then fights round-off (RK45 at `atol` 1e-12 over 100 s of the
/// free crank, `|φ|` up to 1.8e5 rad where an ulp is 2.9e-11: 78 M steps, 28 M rejected).
/// MATLAB raises `RelTol` below `100·eps` to `100·eps` with a warning (`odeset`/`ode45`
/// documentation, "RelTol must be at least 100*eps"); SUNDIALS CVODE computes
/// `tolsf = U·‖y‖_WRMS` (U the unit round-off) at every step and stops with
/// `CV_TOO_MUCH_ACC` ("too much accuracy requested") when it exceeds 1. Both are relative to
/// the state, which is what this floor is, per component. MATLAB's `100·eps` on `rtol` would
/// forbid the purely absolute control (`rtol = 0`) a growing angle needs, and it is sized for
/// plain summation of the increments, whose round-off accumulates over the steps; the state
/// update here is compensated ([`super::adaptive`]), so only the per-evaluation round-off
/// remains and a small `κ` suffices. Like CVODE the floor is checked at every step against
/// the current `|y_i|` (the larger of the states around the step), so it rises with a growing
/// angle instead of being fixed from `y0`; unlike CVODE the run goes on with the raised scale,
/// and every accepted step on which it was in force is counted
/// ([`Stats::floored_steps`](super::Stats::floored_steps)) for the caller's warning.
pub const TOL_FLOOR_KAPPA: f64 = 2.0;

/// Weighted RMS norm `sqrt(mean((e_i / (atol + rtol * max(|a_i|, |b_i|)))^2))`
/// (Hairer, Nørsett & Wanner, *Solving ODEs I*, eq. II.4.11, with the scale taken from the
/// larger of the two states `a`, `b` around the step). No floor (the solvers' own norms have
/// one, see [`TOL_FLOOR_KAPPA`]).
pub fn rms_norm_scaled(
    e: &DVector<f64>,
    a: &DVector<f64>,
    b: &DVector<f64>,
    rtol: f64,
    atol: f64,
) -> f64 {
    let n = e.len();
    let mut s = 0.0;
    for i in 0..n {
        let q = e[i] / (atol + rtol * a[i].abs().max(b[i].abs()));
        s += q * q;
    }
    (s / n as f64).sqrt()
}

/// Per-component tolerances `rtol_i`, `atol_i` (from the scalars of [`SolverOptions`] or its
/// per-component overrides) and the norms built on them, with the floor
/// [`TOL_FLOOR_KAPPA`]`·ε·|y_i|` on every scale.
pub(crate) struct Weights {
    rtol: DVector<f64>,
    atol: DVector<f64>,
    /// Set when a scale was raised to the floor (read and cleared by [`Self::take_floored`]).
    floored: Cell<bool>,
    /// Whole periods of the periodic components (`turns.rs`): the solver holds the
    /// remainder `y_i`, the relative part of the scale uses the full `|offset_i + y_i|`.
    offset: Vec<Cell<f64>>,
}

impl Weights {
    pub(crate) fn new(opts: &SolverOptions, n: usize) -> Self {
        let pick = |v: &Option<Vec<f64>>, s: f64| match v {
            Some(v) => DVector::from_column_slice(v),
            None => DVector::from_element(n, s),
        };
        Self {
            rtol: pick(&opts.rtol_components, opts.rtol),
            atol: pick(&opts.atol_components, opts.atol),
            floored: Cell::new(false),
            offset: (0..n).map(|_| Cell::new(0.0)).collect(),
        }
    }

    /// Sets the whole-period offsets of the state the solver holds.
    pub(crate) fn set_offset(&self, offset: &DVector<f64>) {
        for (c, &v) in self.offset.iter().zip(offset.iter()) {
            c.set(v);
        }
    }

    /// Scale of component `i` for the held value(s) of magnitude `m = max |y_i|`:
    /// `atol_i + rtol_i·|offset_i + y_i|`, at least `κ·ε·m` ([`TOL_FLOOR_KAPPA`]; the floor
    /// is on the value held, whose ulp is what the evaluations see).
    #[inline]
    fn sc(&self, i: usize, a: f64, b: f64) -> f64 {
        let off = self.offset[i].get();
        let m = a.abs().max(b.abs());
        let full = if off == 0.0 {
            m
        } else {
            (off + a).abs().max((off + b).abs())
        };
        let s = self.atol[i] + self.rtol[i] * full;
        let floor = TOL_FLOOR_KAPPA * f64::EPSILON * m;
        if s < floor {
            self.floored.set(true);
            floor
        } else {
            s
        }
    }

    /// `true` if a scale was raised to the floor since the last call.
    pub(crate) fn take_floored(&self) -> bool {
        self.floored.replace(false)
    }

    /// [`rms_norm_scaled`] with these tolerances.
    pub(crate) fn norm(&self, e: &DVector<f64>, a: &DVector<f64>, b: &DVector<f64>) -> f64 {
        let n = e.len();
        let mut s = 0.0;
        for i in 0..n {
            let q = e[i] / self.sc(i, a[i], b[i]);
            s += q * q;
        }
        (s / n as f64).sqrt()
    }

    /// Writes `atol_i + rtol_i |y_i|` into `scale`.
    pub(crate) fn fill_scale(&self, scale: &mut DVector<f64>, y: &DVector<f64>) {
        for i in 0..y.len() {
            scale[i] = self.sc(i, y[i], y[i]);
        }
    }

    /// Writes `atol_i + rtol_i max(|a_i|, |b_i|)` into `scale`.
    pub(crate) fn fill_scale2(&self, scale: &mut DVector<f64>, a: &DVector<f64>, b: &DVector<f64>) {
        for i in 0..a.len() {
            scale[i] = self.sc(i, a[i], b[i]);
        }
    }

    /// A representative tolerance (largest of all `rtol_i`, `atol_i`), for Newton's κ.
    pub(crate) fn reference_tol(&self) -> f64 {
        self.rtol
            .iter()
            .chain(self.atol.iter())
            .fold(0.0f64, |m, &v| m.max(v))
            .max(1e-16)
    }
}

/// Weighted RMS norm with a precomputed scale vector.
pub(crate) fn rms_norm(e: &DVector<f64>, scale: &DVector<f64>) -> f64 {
    let n = e.len();
    let mut s = 0.0;
    for i in 0..n {
        let q = e[i] / scale[i];
        s += q * q;
    }
    (s / n as f64).sqrt()
}

/// `true` if every entry is finite.
pub(crate) fn all_finite(v: &DVector<f64>) -> bool {
    v.iter().all(|x| x.is_finite())
}
