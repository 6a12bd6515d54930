//! Periodic state components carried as whole periods plus a remainder.
//!
//! A component in which `f` is periodic ([`OdeSystem::period`], e.g. a crank angle: the
//! mechanism repeats every turn) is held by the solvers as `y_i = turns_i · P_i + r_i` with
//! the remainder `r_i ∈ [0, P_i)`: the method's stages, the right-hand side and the Jacobian
//! see only `r_i`, whose last place is that of `P_i` (8.9e-16 rad for `2π`), not that of the
//! growing angle (2.9e-11 rad at 1.8e5 rad, the free crank after 100 s). Without it the
//! right-hand side is evaluated at an angle rounded to the ulp of `|y_i|`, and that
//! perturbation, `∂f/∂y_i · ulp(y_i)/2` per stage, accumulates into the solution like a random
//! walk whatever the tolerance. Combined with the compensated update of the remainder
//! ([`super::adaptive`]) the angle is kept to the precision of its increments over any
//! horizon. The full value `turns_i · P_i + r_i` is formed only for the output and for the
//! relative part `rtol·|y_i|` of the error scale, which keeps its meaning.
//!
//! A shift by one period, `r ← r ∓ P`, is exact for `r ∈ [P, 2P)` (Sterbenz's lemma); any
//! rounding of a larger or negative shift is added to the compensation term, so the
//! bookkeeping `y = turns·P + r + c` stays exact with `P` the f64 period (whose own rounding,
//! 2.4e-16 rad for `2π`, moves the evaluation point by that much per turn: 7e-12 rad after the
//! 29 000 turns of the 100 s run).

use super::OdeSystem;
use nalgebra::DVector;

/// The whole periods of the periodic components of a state.
pub(crate) struct Turns {
    period: Vec<Option<f64>>,
    turns: Vec<f64>,
    /// `turns_i · P_i` (0 for non-periodic components).
    offset: DVector<f64>,
}

impl Turns {
    /// The periods of `sys`.
    pub(crate) fn new<S: OdeSystem + ?Sized>(sys: &S, n: usize) -> Self {
        let period = (0..n)
            .map(|i| sys.period(i).filter(|p| p.is_finite() && *p > 0.0))
            .collect();
        Self {
            period,
            turns: vec![0.0; n],
            offset: DVector::zeros(n),
        }
    }

    /// `true` if any component is periodic.
    pub(crate) fn any(&self) -> bool {
        self.period.iter().any(Option::is_some)
    }

    /// `true` if component `i` is carried as whole periods + a remainder.
    pub(crate) fn is_periodic(&self, i: usize) -> bool {
        self.period[i].is_some()
    }

    /// `turns_i · P_i` per component.
    pub(crate) fn offset(&self) -> &DVector<f64> {
        &self.offset
    }

    /// Moves whole periods of `r` (with compensation `comp`) into the turns, so that every
    /// periodic `r_i` is in `[0, P_i)`; returns `true` if anything moved.
    pub(crate) fn wrap(&mut self, r: &mut DVector<f64>, comp: &mut DVector<f64>) -> bool {
        let mut moved = false;
        for (i, p) in self.period.iter().enumerate() {
            let Some(p) = *p else { continue };
            if r[i] >= 0.0 && r[i] < p {
                continue;
            }
            let k = (r[i] / p).floor();
            // r − k·p by two-sum, its rounding error into the compensation
            let (a, b) = (r[i], -k * p);
            let s = a + b;
            let bb = s - a;
            comp[i] += (a - (s - bb)) + (b - bb);
            r[i] = s;
            self.turns[i] += k;
            self.offset[i] = self.turns[i] * p;
            moved = true;
        }
        moved
    }

    /// The full state `offset + r` into `out`.
    pub(crate) fn full(&self, r: &DVector<f64>, out: &mut DVector<f64>) {
        for i in 0..r.len() {
            out[i] = self.offset[i] + r[i];
        }
    }
}
