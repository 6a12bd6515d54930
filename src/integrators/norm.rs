//! The weighted error norm of all adaptive methods.

use super::SolverOptions;
use nalgebra::DVector;

/// Weighted RMS norm `sqrt(mean((e_i / (atol + rtol * max(|a_i|, |b_i|)))^2))`
/// (Hairer, Nørsett & Wanner, *Solving ODEs I*, eq. II.4.11, with the scale taken from the
/// larger of the two states `a`, `b` around the step).
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
/// per-component overrides) and the norms built on them.
pub(crate) struct Weights {
    rtol: DVector<f64>,
    atol: DVector<f64>,
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
        }
    }

    /// Scale of component `i` for state magnitude `m`.
    #[inline]
    fn sc(&self, i: usize, m: f64) -> f64 {
        self.atol[i] + self.rtol[i] * m
    }

    /// [`rms_norm_scaled`] with these tolerances.
    pub(crate) fn norm(&self, e: &DVector<f64>, a: &DVector<f64>, b: &DVector<f64>) -> f64 {
        let n = e.len();
        let mut s = 0.0;
        for i in 0..n {
            let q = e[i] / self.sc(i, a[i].abs().max(b[i].abs()));
            s += q * q;
        }
        (s / n as f64).sqrt()
    }

    /// Writes `atol_i + rtol_i |y_i|` into `scale`.
    pub(crate) fn fill_scale(&self, scale: &mut DVector<f64>, y: &DVector<f64>) {
        for i in 0..y.len() {
            scale[i] = self.sc(i, y[i].abs());
        }
    }

    /// Writes `atol_i + rtol_i max(|a_i|, |b_i|)` into `scale`.
    pub(crate) fn fill_scale2(&self, scale: &mut DVector<f64>, a: &DVector<f64>, b: &DVector<f64>) {
        for i in 0..a.len() {
            scale[i] = self.sc(i, a[i].abs().max(b[i].abs()));
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
