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
//!
//! **Compensated state update.** The method returns its increment `Δ = y_{n+1} − y_n` (formed
//! from the stages, exact to the rounding of `Δ` itself), and the loop adds it to the state
//! by compensated summation (Kahan 1965, "Further remarks on reducing truncation errors",
//! Comm. ACM 8(1):40; in the branch-free two-sum form of Knuth, TAOCP vol. 2, §4.2.2, as in
//! Neumaier 1974, "Rundungsfehleranalyse einiger Verfahren zur Summation endlicher Summen",
//! ZAMM 54:39–51): `y_{n+1} + c_{n+1} = y_n + (Δ + c_n)` exactly, the rounding error `c` of
//! each addition carried into the next one. A plain `y_n + Δ` loses up to half an ulp of `y`
//! per step, and over millions of steps of a growing angle that drift, not the truncation
//! error, sets the accuracy (the free crank over 100 s, |φ| → 1.8e5 rad: 5e-4 rad at `atol`
//! 1e-10 with plain sums). The stages are evaluated at the rounded `y_n`; the derivative the
//! method carries to the next step (FSAL) belongs to its own uncompensated `y_n + Δ`, at most
//! one ulp away: the size of the rounding of any stage state. A projection resets `c`.
//! Components in which `f` is periodic ([`OdeSystem::period`]) are held as whole periods plus
//! a remainder (`turns.rs`), so that the stages are evaluated at a state with the precision
//! of the remainder; the output adds the periods back.
//! The step is `h = fl(t + h) − t` ([`clamp_to_end`]), so the stages, the dense output and
//! the recorded times agree to the last bit (as SciPy's `solve_ivp` does); otherwise `t`
//! drifts from `Σ h` by up to half an ulp of `t` per step.

use super::control::{Controller, check_underflow, clamp_to_end, initial_step, max_step};
use super::eval::Evaluator;
use super::grid::Recorder;
use super::input::{check_input, invalid};
use super::norm::Weights;
use super::turns::Turns;
use super::{
    FailureKind, OdeSystem, OutputGrid, Solution, SolverError, SolverOptions, StepProjection,
};
use nalgebra::DVector;

/// Largest step growth after an accepted step (1 right after a rejection).
pub(crate) const FAC_MAX: f64 = 5.0;

/// Step reduction after an attempt with a non-finite error estimate.
const NON_FINITE_SHRINK: f64 = 0.2;

/// One attempted step from `t` to `t_new = t + h` (`h` already clamped to the interval's end,
/// and exactly `t_new − t`, see [`clamp_to_end`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Step {
    pub(crate) t: f64,
    pub(crate) h: f64,
    pub(crate) t_new: f64,
    /// The step the controller asked for (`h` up to the rounding of `t + h`; the clamped
    /// step on the last one): the step-size control continues from it, and a method that
    /// reuses a factorisation while the step is unchanged compares it.
    pub(crate) h_req: f64,
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
    /// its increment `y_new − y`, formed from the stages before the addition to `y` (not as
    /// the difference), into `dy`, and returns the scaled error norm (or a failure of the
    /// stages).
    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        ev: &mut Evaluator<'_, S>,
        weights: &Weights,
        step: &Step,
        y: &DVector<f64>,
        y_new: &mut DVector<f64>,
        dy: &mut DVector<f64>,
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
    // periodic components as whole periods + remainder (turns.rs); a projection sees the full
    // state and its change is added to the remainder ([`write_back_projection`])
    let mut turns = Turns::new(sys, n);
    let mut comp = DVector::zeros(n);
    let mut y_full = DVector::zeros(n);
    if turns.wrap(&mut y, &mut comp) {
        weights.set_offset(turns.offset());
    }
    let h_max = max_step(opts, t_end - t0);
    let mut stepper = M::new(n, &weights);
    let mut y_new = DVector::zeros(n);
    // the step's increment; the exact (remainder of the) state is y + comp
    let mut dy = DVector::zeros(n);
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
            let (h_exact, t_new, last) = clamp_to_end(t, h, t_end);
            let h_step = if last { h_exact } else { h };
            let step = Step {
                t,
                h: h_exact,
                t_new,
                h_req: h_step,
            };
            match stepper.attempt(&mut ev, &weights, &step, &y, &mut y_new, &mut dy)? {
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
            h: h_exact,
            t_new,
            h_req: h_step,
            ..
        } = step;
        if weights.take_floored() {
            ev.stats.floored_steps += 1;
        }
        compensated_add(&y, &dy, &mut comp, &mut y_new);
        if turns.any() {
            turns.full(&y_new, &mut y_full);
        }
        if let Some(p) = proj.as_deref_mut() {
            y_proj.copy_from(if turns.any() { &y_full } else { &y_new });
            p.project(t_new, &mut y_proj)
                .map_err(|m| ev.fail(FailureKind::Projection(m)))?;
        }
        let y_out = if proj.is_some() {
            &y_proj
        } else if turns.any() {
            &y_full
        } else {
            &y_new
        };
        rec.record(t, t_new, y_out, |theta, out| {
            stepper.interpolate(theta, h_exact, &y, &y_new, out);
            if turns.any() {
                *out += turns.offset();
            }
            if let Some(p) = proj.as_deref_mut()
                && let Err(m) = p.project(t + theta * h_exact, out)
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
        if proj.is_some() {
            write_back_projection(&turns, &y_proj, &y_full, &mut y_new, &mut comp);
        }
        let fac_max = if rejected { 1.0 } else { FAC_MAX };
        h = (h_step * stepper.accept_factor(err, fac_max)).min(h_max);
        t = t_new;
        std::mem::swap(&mut y, &mut y_new);
        if turns.wrap(&mut y, &mut comp) {
            weights.set_offset(turns.offset());
        }
        stepper.accept();
        if proj.is_some() {
            // the FSAL stage belongs to the unprojected ỹ_{n+1}: re-evaluate at y_{n+1}
            ev.rhs_finite(t, &y, stepper.derivative_mut())?;
        }
    }
    Ok(rec.finish(ev.stats))
}

/// The projected state `y_proj` of a step into the solver's own state `y_new` (with its
/// compensation `comp`). Without periodic components `y_new` becomes `y_proj` and the
/// compensation is dropped (the projection's value is the state). With them, `y_proj` was
/// projected from the full state `y_full` (whole periods + remainder, rounded to the ulp of the
/// full value): a periodic component the projection left unchanged keeps its exact remainder
/// and compensation, a changed one gets the change added to its remainder; a non-periodic
/// component takes the projected value.
fn write_back_projection(
    turns: &Turns,
    y_proj: &DVector<f64>,
    y_full: &DVector<f64>,
    y_new: &mut DVector<f64>,
    comp: &mut DVector<f64>,
) {
    if !turns.any() {
        y_new.copy_from(y_proj);
        comp.fill(0.0);
        return;
    }
    for i in 0..y_new.len() {
        if y_proj[i] == y_full[i] {
            continue;
        }
        if turns.is_periodic(i) {
            y_new[i] += y_proj[i] - y_full[i];
        } else {
            y_new[i] = y_proj[i];
        }
        comp[i] = 0.0;
    }
}

/// `y_new + comp ← y + (dy + comp)` componentwise by Knuth's two-sum (exact: `y_new` is the
/// rounded sum, the new `comp` its rounding error); see the module docs.
pub(crate) fn compensated_add(
    y: &DVector<f64>,
    dy: &DVector<f64>,
    comp: &mut DVector<f64>,
    y_new: &mut DVector<f64>,
) {
    for i in 0..y.len() {
        let (a, b) = (y[i], dy[i] + comp[i]);
        let s = a + b;
        let bb = s - a;
        comp[i] = (a - (s - bb)) + (b - bb);
        y_new[i] = s;
    }
}
