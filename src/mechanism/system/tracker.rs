//! [`Tracker`]: follows a zero-DOF system along time, warm-starting the
//! Newton–Raphson position analysis with a quintic Hermite predictor through
//! the last two solutions, subdividing large steps and retrying failed ones.

use nalgebra::{Const, DimMin, SVector};

use super::super::error::{DynamicsError, Result};
use super::{KinematicSolution, MultibodySystem};

impl<const N: usize> MultibodySystem<N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    /// A tracker that follows the motion from an assembly guess.
    pub fn tracker(&self, guess: SVector<f64, N>) -> Tracker<'_, N> {
        Tracker {
            system: self,
            guess,
            last: None,
            before_last: None,
        }
    }
}

/// Follows a zero-DOF system along time, warm-starting Newton–Raphson with a
/// predictor from the previous solutions: the quintic Hermite polynomial
/// through (c, ċ, c̈) at the last two solved times, extrapolated (error
/// O(h⁶), so that one Newton step usually converges), or the Taylor
/// polynomial c + h ċ + ½ h² c̈ after the first solve. Steps whose predicted
/// angle change exceeds [`SolverOptions::max_angle_step_rad`](super::SolverOptions::max_angle_step_rad) are subdivided,
/// and a step where Newton fails is retried with 8× finer substeps (up to
/// [`SolverOptions::max_substeps`](super::SolverOptions::max_substeps)).
#[derive(Clone, Debug)]
pub struct Tracker<'a, const N: usize> {
    system: &'a MultibodySystem<N>,
    guess: SVector<f64, N>,
    last: Option<KinematicSolution<N>>,
    before_last: Option<KinematicSolution<N>>,
}

/// Predict c(t) from the solution `cur` and, if available, an earlier one.
fn predict<const N: usize>(
    cur: &KinematicSolution<N>,
    prev: Option<&KinematicSolution<N>>,
    t: f64,
) -> SVector<f64, N> {
    let h = t - cur.t;
    let taylor = cur.q + cur.qd * h + cur.qdd * (0.5 * h * h);
    let Some(p) = prev else {
        return taylor;
    };
    let d = p.t - cur.t;
    // only extrapolate over at most ~2 previous intervals; otherwise Taylor
    if d == 0.0 || !d.is_finite() || (h / d).abs() > 2.0 {
        return taylor;
    }
    // p(s) = q + qd s + qdd s^2/2 + b3 (s/d)^3 + b4 (s/d)^4 + b5 (s/d)^5 matching q, qd, qdd at s = d
    let r0 = p.q - (cur.q + cur.qd * d + cur.qdd * (0.5 * d * d));
    let r1 = (p.qd - (cur.qd + cur.qdd * d)) * d;
    let r2 = (p.qdd - cur.qdd) * (d * d);
    let u = r1 - r0 * 3.0;
    let v = r2 - r0 * 6.0;
    let b5 = (v - u * 6.0) * 0.5;
    let b4 = u - b5 * 2.0;
    let b3 = r0 - b4 - b5;
    let x = h / d;
    taylor + b3 * (x * x * x) + b4 * (x * x * x * x) + b5 * (x * x * x * x * x)
}

impl<const N: usize> Tracker<'_, N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    /// The last solution.
    pub fn last(&self) -> Option<&KinematicSolution<N>> {
        self.last.as_ref()
    }

    /// Solve at time `t` (the first call assembles from the guess).
    pub fn solve_at(&mut self, t: f64) -> Result<&KinematicSolution<N>> {
        match self.last {
            None => {
                let sol = self.system.analyze(t, &self.guess)?;
                Ok(self.last.insert(sol))
            }
            Some(cur) => {
                self.advance(cur, t)?;
                self.last.as_ref().ok_or(DynamicsError::NonFinite {
                    t_s: t,
                    what: "tracker state",
                })
            }
        }
    }

    fn advance(&mut self, cur: KinematicSolution<N>, t: f64) -> Result<()> {
        let sys = self.system;
        let h = t - cur.t;
        if !h.is_finite() {
            return Err(DynamicsError::NonFinite {
                t_s: t,
                what: "time",
            });
        }
        let mut dphi = 0.0f64;
        for k in 0..sys.bodies.len() {
            let i = 3 * k + 2;
            dphi = dphi.max((cur.qd[i] * h).abs() + 0.5 * (cur.qdd[i] * h * h).abs());
        }
        let max_sub = sys.options.max_substeps;
        let mut n = ((dphi / sys.options.max_angle_step_rad).ceil() as usize).clamp(1, max_sub);
        let prev = self.before_last;
        loop {
            match self.substeps(t, n) {
                Ok(()) => return Ok(()),
                Err(DynamicsError::NoConvergence { .. }) if n < max_sub => {
                    // restart the interval with finer substeps
                    self.last = Some(cur);
                    self.before_last = prev;
                    n = (n * 8).min(max_sub);
                }
                Err(e) => return Err(e),
            }
        }
    }

    fn substeps(&mut self, t: f64, n: usize) -> Result<()> {
        let Some(start) = self.last else {
            return Err(DynamicsError::NonFinite {
                t_s: t,
                what: "tracker state",
            });
        };
        let t0 = start.t;
        for k in 1..=n {
            let tk = if k == n {
                t
            } else {
                t0 + (t - t0) * (k as f64) / (n as f64)
            };
            let next = match &self.last {
                Some(cur) => {
                    let guess = predict(cur, self.before_last.as_ref(), tk);
                    self.system.analyze(tk, &guess)?
                }
                None => {
                    return Err(DynamicsError::NonFinite {
                        t_s: tk,
                        what: "tracker state",
                    });
                }
            };
            self.before_last = self.last.replace(next);
        }
        Ok(())
    }
}
