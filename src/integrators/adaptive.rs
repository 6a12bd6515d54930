//! The adaptive step-size loop shared by the one-step methods ([`rk45`](super::rk45),
//! [`rk23`](super::rk23), [`rosenbrock`](super::rosenbrock), [`trbdf2`](super::trbdf2)).
//!
//! A method implements [`AdaptiveStepper`]: its tableau and stages ([`AdaptiveStepper::attempt`],
//! which also returns the scaled norm of its error estimate), its continuous extension
//! ([`AdaptiveStepper::interpolate`]) and its step-size controller
//! ([`AdaptiveStepper::CONTROL`]). [`integrate`] does the rest, the same for every method:
//!
//! - input checks, `f(t0, y0)` and the starting step ([`initial_step`]);
//! - per accepted step: the step cap, then attempts until one passes. Each attempt checks for
//!   step-size underflow and clamps the step to the end of the interval ([`clamp_to_end`]);
//!   an attempt whose stages fail (singular iteration matrix, Newton failure:
//!   [`Attempt::Failed`]) is rejected with the method's own remedy; a non-finite error norm
//!   rejects with `h ← 0.2 h`; a norm above 1 rejects with the controller's factor, at most 1;
//! - on acceptance: dense output onto the grid ([`Recorder`]), the optional post-step
//!   projection ([`StepProjection`], see [`rk45`](super::rk45) for how it meets the dense
//!   output), the counters, and the next step `h · factor(err)` with the factor at most
//!   [`FAC_MAX`] (at most 1 right after a rejection) and the step at most `h_max`.

use super::control::{Controller, check_underflow, clamp_to_end, initial_step, max_step};
use super::eval::Evaluator;
use super::grid::Recorder;
use super::input::{check_input, invalid};
use super::norm::Weights;
use super::{
    FailureKind, OdeSystem, OutputGrid, Solution, SolverError, SolverOptions, StepProjection,
};
use nalgebra::DVector;

/// Largest step growth after an accepted step (1 right after a rejection).
pub(crate) const FAC_MAX: f64 = 5.0;

/// Step reduction after an attempt with a non-finite error estimate.
const NON_FINITE_SHRINK: f64 = 0.2;

/// One attempted step from `t` to `t_new = t + h` (`h` already clamped to the interval's end).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Step {
    pub(crate) t: f64,
    pub(crate) h: f64,
    pub(crate) t_new: f64,
}

/// What an attempted step produced.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Attempt {
    /// The stages were computed; the scaled norm of the local error estimate (accepted when
    /// at most 1). Not finite when anything in the step was not finite (see [`Self::checked`]).
    Estimated(f64),
    /// The stages could not be computed (singular iteration matrix, Newton failure): the
    /// attempt is rejected and retried with `h ← shrink · h` (`None`: with the same `h`, e.g.
    /// after refreshing the Jacobian); `cap_growth` limits the next accepted step's growth
    /// to 1, as after a failed error test.
    Failed {
        shrink: Option<f64>,
        cap_growth: bool,
    },
}

impl Attempt {
    /// [`Self::Estimated`] with `err`, or with `∞` unless `finite` (the new state and the
    /// stages the method reuses are all finite).
    pub(crate) fn checked(err: f64, finite: bool) -> Self {
        Self::Estimated(if finite { err } else { f64::INFINITY })
    }
}

/// What a one-step method supplies to [`integrate`]: everything but the loop.
///
/// The stepper owns `f_n = f(t_n, y_n)` at the start of the current step
/// ([`Self::derivative_mut`]); the loop evaluates it once at `t0` (and again after a projection),
/// the method's FSAL stage provides it afterwards ([`Self::accept`]).
pub(crate) trait AdaptiveStepper: Sized {
    /// Method name in reports.
    const NAME: &'static str;
    /// Order `p` of the starting-step heuristic (local error `O(h^(p+1))`, [`initial_step`]).
    const START_ORDER: u32;
    /// Step-size controller of the error estimate.
    const CONTROL: Controller;

    /// Work storage for a system of dimension `n` with tolerances `weights`.
    fn new(n: usize, weights: &Weights) -> Self;

    /// `f(t_n, y_n)` at the start of the current step (the loop writes it at `t0` and after
    /// a projection).
    fn derivative_mut(&mut self) -> &mut DVector<f64>;

    /// Once, after the starting step is chosen (e.g. the first Jacobian).
    fn start<S: OdeSystem + ?Sized>(
        &mut self,
        _ev: &mut Evaluator<'_, S>,
        _t0: f64,
        _y0: &DVector<f64>,
    ) -> Result<(), SolverError> {
        Ok(())
    }

    /// Once per step, before its first attempt (e.g. a Jacobian at `(t, y)`).
    fn begin_step<S: OdeSystem + ?Sized>(
        &mut self,
        _ev: &mut Evaluator<'_, S>,
        _t: f64,
        _y: &DVector<f64>,
    ) -> Result<(), SolverError> {
        Ok(())
    }

    /// Computes the stages of `step` from `y`, writes the propagated result into `y_new` and
    /// returns the scaled error norm (or a failure of the stages).
    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        ev: &mut Evaluator<'_, S>,
        weights: &Weights,
        step: &Step,
        y: &DVector<f64>,
        y_new: &mut DVector<f64>,
    ) -> Result<Attempt, SolverError>;

    /// Continuous extension of the accepted step from `y` to `y_new` (length `h`) at
    /// `t + θh`, into `out`.
    fn interpolate(
        &self,
        theta: f64,
        h: f64,
        y: &DVector<f64>,
        y_new: &DVector<f64>,
        out: &mut DVector<f64>,
    );

    /// The accepted step becomes the past: the derivative at `y_new` becomes
    /// [`Self::derivative_mut`] (FSAL).
    fn accept(&mut self);

    /// Step factor after an accepted step with error norm `err` (`fac_max` is [`FAC_MAX`], or
    /// 1 after a rejection).
    fn accept_factor(&self, err: f64, fac_max: f64) -> f64 {
        Self::CONTROL.factor(err, fac_max)
    }
}

/// Integrates `sys` with method `M` from `grid.t0` to `grid.t_end()`, writing the dense output
/// onto the grid; with `proj`, every accepted step, `y0` and every dense-output sample are
/// projected (a failed projection stops the run with [`FailureKind::Projection`]).
pub(crate) fn integrate<M: AdaptiveStepper, S: OdeSystem + ?Sized>(
    sys: &S,
    y0: &DVector<f64>,
    grid: &OutputGrid,
    opts: &SolverOptions,
    mut proj: Option<&mut dyn StepProjection>,
) -> Result<Solution, SolverError> {
    let (t0, t_end) = (grid.t0, grid.t_end());
    check_input(sys, y0, opts).map_err(|m| invalid(M::NAME, t0, m))?;
    let n = y0.len();
    let weights = Weights::new(opts, n);
    let mut ev = Evaluator::new(sys, M::NAME, opts, t0);
    let mut y = y0.clone();
    if let Some(p) = proj.as_deref_mut() {
        p.project(t0, &mut y)
            .map_err(|m| ev.fail(FailureKind::Projection(m)))?;
    }
    let mut rec = Recorder::new(grid, &y);
    let h_max = max_step(opts, t_end - t0);
    let mut stepper = M::new(n, &weights);
    let mut y_new = DVector::zeros(n);
    let mut y_proj = DVector::zeros(n);
    let mut proj_failure = None;
    let f0 = stepper.derivative_mut();
    ev.rhs_finite(t0, &y, f0)?;
    let mut h = initial_step(&mut ev, t0, &y, f0, M::START_ORDER, t_end - t0, opts)?;
    stepper.start(&mut ev, t0, &y)?;
    let mut t = t0;
    loop {
        ev.check_step_budget()?;
        stepper.begin_step(&mut ev, t, &y)?;
        let mut rejected = false;
        let (step, last, err) = loop {
            check_underflow(&ev, t, h)?;
            let (h_step, t_new, last) = clamp_to_end(t, h, t_end);
            let step = Step {
                t,
                h: h_step,
                t_new,
            };
            match stepper.attempt(&mut ev, &weights, &step, &y, &mut y_new)? {
                Attempt::Failed { shrink, cap_growth } => {
                    ev.reject_step();
                    if let Some(f) = shrink {
                        h = f * h_step;
                    }
                    rejected |= cap_growth;
                }
                Attempt::Estimated(err) if !err.is_finite() => {
                    ev.reject_step();
                    h = NON_FINITE_SHRINK * h_step;
                    rejected = true;
                }
                Attempt::Estimated(err) if err > 1.0 => {
                    ev.reject_step();
                    h = h_step * M::CONTROL.factor(err, 1.0);
                    rejected = true;
                }
                Attempt::Estimated(err) => break (step, last, err),
            }
        };
        let Step {
            h: h_step, t_new, ..
        } = step;
        if let Some(p) = proj.as_deref_mut() {
            y_proj.copy_from(&y_new);
            p.project(t_new, &mut y_proj)
                .map_err(|m| ev.fail(FailureKind::Projection(m)))?;
        }
        let y_out = if proj.is_some() { &y_proj } else { &y_new };
        rec.record(t, t_new, y_out, |theta, out| {
            stepper.interpolate(theta, h_step, &y, &y_new, out);
            if let Some(p) = proj.as_deref_mut()
                && let Err(m) = p.project(t + theta * h_step, out)
            {
                proj_failure.get_or_insert(m);
            }
        });
        if let Some(m) = proj_failure.take() {
            return Err(ev.fail(FailureKind::Projection(m)));
        }
        ev.accept_step(t_new);
        if last {
            break;
        }
        let fac_max = if rejected { 1.0 } else { FAC_MAX };
        h = (h_step * stepper.accept_factor(err, fac_max)).min(h_max);
        t = t_new;
        std::mem::swap(&mut y, &mut y_new);
        stepper.accept();
        if proj.is_some() {
            // the FSAL stage belongs to the unprojected ỹ_{n+1}: re-evaluate at y_{n+1}
            y.copy_from(&y_proj);
            ev.rhs_finite(t, &y, stepper.derivative_mut())?;
        }
    }
    Ok(rec.finish(ev.stats))
}
