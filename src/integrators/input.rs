//! Input checks shared by every method before its first evaluation: state length, per-component
//! tolerances, finite initial state and the options' own validation; and the
//! [`FailureKind::InvalidInput`] error they report.

use super::{FailureKind, OdeSystem, SolverError, SolverOptions};
use nalgebra::DVector;

/// Common input checks; `Err` carries the message for [`FailureKind::InvalidInput`].
pub(crate) fn check_input<S: OdeSystem + ?Sized>(
    sys: &S,
    y0: &DVector<f64>,
    opts: &SolverOptions,
) -> Result<(), String> {
    opts.validate()?;
    if y0.len() != sys.dim() {
        return Err(format!(
            "y0 has length {}, system dimension is {}",
            y0.len(),
            sys.dim()
        ));
    }
    for v in [&opts.rtol_components, &opts.atol_components]
        .into_iter()
        .flatten()
    {
        if v.len() != y0.len() {
            return Err(format!(
                "per-component tolerance has length {}, state has {}",
                v.len(),
                y0.len()
            ));
        }
    }
    if !y0.iter().all(|v| v.is_finite()) {
        return Err("initial state is not finite".into());
    }
    Ok(())
}

/// Builds the [`SolverError`] for invalid input before any evaluation.
pub(crate) fn invalid(method: &'static str, t0: f64, msg: String) -> SolverError {
    SolverError {
        method,
        kind: FailureKind::InvalidInput(msg),
        t: t0,
        stats: Default::default(),
    }
}
