//! Cubic Hermite dense output on one step `[t, t + h]` through `(y_n, f_n)` and
//! `(y_{n+1}, f_{n+1})`: third order, the continuous extension of ode23 ([`super::rk23`]) and
//! ode23tb ([`super::trbdf2`]) (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.6, "Hermite
//! interpolation").

use nalgebra::DVector;

/// Cubic Hermite interpolation on `[t, t + h]` at `θ`: writes into `out`.
pub(crate) fn hermite(
    theta: f64,
    h: f64,
    y0: &DVector<f64>,
    f0: &DVector<f64>,
    y1: &DVector<f64>,
    f1: &DVector<f64>,
    out: &mut DVector<f64>,
) {
    let t2 = theta * theta;
    let t3 = t2 * theta;
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = t3 - 2.0 * t2 + theta;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = t3 - t2;
    for i in 0..out.len() {
        out[i] = h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i];
    }
}
