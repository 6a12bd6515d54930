//! Generalized-α for constrained mechanical systems in index-3 form, as modern multibody
//! codes use it.
//!
//! Equations of motion with the sign convention of the multibody core (thesis eq. 3.27):
//!
//! `M(q) q̈ = h(t, q, v) + D(q)ᵀ λ`,  `Φ(t, q) = 0`,  `v = q̇`,  `D = ∂Φ/∂q`.
//!
//! Scheme (Chung & Hulbert, *J. Appl. Mech.* 60 (1993) 371–375; for the index-3 DAE
//! M. Arnold & O. Brüls, "Convergence of the generalized-α scheme for constrained mechanical
//! systems", *Multibody Syst. Dyn.* 18 (2007) 185–202, eq. 9–10), with the auxiliary
//! "acceleration-like" variable `a`:
//!
//! - `q_{n+1} = q_n + h v_n + h² (½ − β) a_n + h² β a_{n+1}`
//! - `v_{n+1} = v_n + h (1 − γ) a_n + h γ a_{n+1}`
//! - `(1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) q̈_{n+1} + α_f q̈_n`
//! - `M q̈_{n+1} = h(t_{n+1}, q_{n+1}, v_{n+1}) + Dᵀ(q_{n+1}) λ_{n+1}`,  `Φ(t_{n+1}, q_{n+1}) = 0`
//!
//! with `a_0 = q̈_0` and `λ_0` from the consistent initial accelerations
//! `[M −Dᵀ; D 0][q̈_0; λ_0] = [h; γ]` (`D q̈ = γ`). Parameters from the spectral radius at
//! infinity `ρ∞ ∈ [0, 1]` (Chung & Hulbert): `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`,
//! `α_f = ρ∞/(ρ∞ + 1)`, `γ = ½ + α_f − α_m`, `β = ¼ (γ + ½)²`: second order, unconditionally
//! stable for linear problems, high frequencies damped to `ρ∞` per step (`ρ∞ = 1`: no
//! numerical damping). Arnold & Brüls prove second-order convergence of `q` and `v` for the
//! index-3 form; `λ` and `q̈` carry an O(h) transient from the start that only `ρ∞ < 1`
//! damps, so `ρ∞ = 1` is refused for constrained systems. Close to 1 the damping is weak: on
//! the crank's 10 s run with h = 1e-4 s, ρ∞ = 0.99 stopped with a Newton failure at t = 4.5 s
//! (ρ∞ = 1: 1.5 s) while 0.9 and 0.5 completed.
//! Only `Φ = 0` is enforced: the hidden constraint `D v = −Φ_t` is met to O(h²) (reported by
//! the caller as velocity drift).
//!
//! # Newton iteration and scaling
//! Unknowns `q_{n+1}` and `λ_{n+1}`; through the formulas above `∂q̈_{n+1}/∂q_{n+1} = β' =
//! (1 − α_m)/(h² β (1 − α_f))` and `∂v_{n+1}/∂q_{n+1} = γ' = γ/(h β)`. The residual
//! `r = M q̈ − h − Dᵀλ` and `Φ` give the iteration matrix `[β' M + γ' C + K, −Dᵀ; D, 0]`
//! with `C = ∂r/∂v = −∂h/∂v` and `K = ∂r/∂q` (at fixed `q̈, v, λ`), both by forward
//! differences of the system's functions. Its condition grows like `h⁻²`; the usual scaling
//! (Bottasso, Dopico & Trainelli, *Multibody Syst. Dyn.* 19 (2008) 29–43; Arnold & Brüls §5)
//! divides the dynamic rows by `β'` and solves for `Δλ̃ = Δλ/β'`:
//!
//! `[M + (γ'/β') C + K/β', −Dᵀ; D, 0] [Δq; Δλ̃] = −[r/β'; Φ]`,
//!
//! whose blocks are O(1) for every `h`. Predictor: `q̈_{n+1} = q̈_n`, `λ_{n+1} = λ_n`.
//! The matrix is built and factorised at the predictor of every step and kept for the step's
//! further iterations (rebuilt at the current iterate if an iteration contracts by less than
//! `θ = e_k / e_{k−1} > ½`). With the scaled increment
//! `e_k = max_i |Δq_i| / (newton_tol + 4 ε |q_i|)` (the ε term: the resolution of a large
//! angle) the step has converged when `e_k ≤ 1` and, after the first iteration,
//! `θ/(1 − θ) e_k ≤ 1` (the remaining error of a linearly converging iteration, Hairer &
//! Wanner, *Solving ODEs II*, §IV.8) or `θ ≥ 1` (stagnation below the tolerance: roundoff).
//! Why a fresh matrix every step: `q̈_{n+1}` is updated by `β' Δq` with `β' ~ h⁻²`, so a
//! Newton remainder in `q` far below any position tolerance is an acceleration error that
//! accumulates over the steps. The quadratic first iteration from a fresh matrix leaves a
//! negligible remainder; a matrix kept over many steps (tried: 3–5 evaluations per step
//! instead of 11) converges linearly and spoiled the h² law below h = 1e-4 s on the crank
//! (9.5e-6 rad instead of 2.7e-6 at h = 3e-5 s), while it saved only ~20 % of the time at
//! h = 1e-4 s. The finite-difference columns make the matrix cost `n` residual evaluations.
//!
//! # Steps, output, counters, caps
//! Fixed step `h` (the last step is shortened to end at `t_end`; step `k` starts at
//! `t0 + k h`). Dense output: cubic Hermite interpolation of `q` from `(q, v)` and of `v` from
//! `(v, q̈)` at both ends of the step (O(h⁴), below the scheme's O(h²)). The state recorded on
//! the grid is `y = [q; v]`. Counters: `rhs_evals` = evaluations of the residual (`M`, `h`,
//! `Φ`, `D` at one point; the finite-difference columns count one each), `jac_evals` =
//! iteration matrices, `lu_decompositions`, `newton_iters`. Caps: `max_steps`, `max_evals`
//! and `max_newton_iters` per step, reported as typed [`SolverError`]s, as are a singular
//! iteration matrix and non-finite values.

use super::grid::Recorder;
use super::{FailureKind, OutputGrid, Solution, SolverError, Stats};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

const NAME: &str = "generalized-alpha";

/// A constrained mechanical system `M q̈ = h + Dᵀλ`, `Φ = 0` with `n` coordinates and `m`
/// constraints.
pub trait ConstrainedSystem {
    /// Number of coordinates `n`.
    fn dim(&self) -> usize;
    /// Number of constraint equations `m`.
    fn n_constraints(&self) -> usize;
    /// Mass matrix `M(q)` (n × n).
    fn mass(&self, q: &DVector<f64>, m: &mut DMatrix<f64>);
    /// Applied (and velocity-dependent) forces `h(t, q, v)` (length n).
    fn forces(&self, t: f64, q: &DVector<f64>, v: &DVector<f64>, h: &mut DVector<f64>);
    /// Constraints `Φ(t, q)` (length m).
    fn constraints(&self, t: f64, q: &DVector<f64>, phi: &mut DVector<f64>);
    /// Constraint Jacobian `D = ∂Φ/∂q` (m × n).
    fn constraint_jacobian(&self, t: f64, q: &DVector<f64>, d: &mut DMatrix<f64>);
    /// `γ` of the acceleration constraint `D q̈ = γ` (for the initial accelerations).
    fn gamma(&self, t: f64, q: &DVector<f64>, v: &DVector<f64>, g: &mut DVector<f64>);
    /// `false` if `h` does not depend on `v` (skips the damping matrix `C`).
    fn forces_depend_on_velocity(&self) -> bool {
        true
    }
}

/// Settings of the generalized-α solver.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GenAlphaOptions {
    /// Step size \[s\].
    pub h: f64,
    /// Spectral radius at infinity `ρ∞ ∈ [0, 1]`.
    pub rho_inf: f64,
    /// Absolute tolerance on the Newton increment of `q` (coordinates' units).
    pub newton_tol: f64,
    /// Cap on Newton iterations per step.
    pub max_newton_iters: usize,
    /// Cap on steps.
    pub max_steps: u64,
    /// Cap on residual evaluations (including finite-difference columns).
    pub max_evals: u64,
}

impl Default for GenAlphaOptions {
    fn default() -> Self {
        Self {
            h: 1e-4,
            rho_inf: 0.9,
            newton_tol: 1e-10,
            max_newton_iters: 10,
            max_steps: 1_000_000,
            max_evals: 10_000_000,
        }
    }
}

/// The scheme's parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GenAlphaParams {
    /// `α_m`.
    pub alpha_m: f64,
    /// `α_f`.
    pub alpha_f: f64,
    /// `γ`.
    pub gamma: f64,
    /// `β`.
    pub beta: f64,
}

impl GenAlphaParams {
    /// Chung & Hulbert's optimal parameters for `ρ∞` (module docs).
    pub fn from_rho_inf(rho: f64) -> Self {
        let alpha_m = (2.0 * rho - 1.0) / (rho + 1.0);
        let alpha_f = rho / (rho + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        Self {
            alpha_m,
            alpha_f,
            gamma,
            beta: 0.25 * (gamma + 0.5) * (gamma + 0.5),
        }
    }
}

/// Work counters and caps.
struct Work {
    stats: Stats,
    max_steps: u64,
    max_evals: u64,
    t: f64,
}

impl Work {
    fn fail(&self, kind: FailureKind) -> SolverError {
        SolverError {
            method: NAME,
            kind,
            t: self.t,
            stats: self.stats,
        }
    }

    fn charge(&mut self) -> Result<(), SolverError> {
        if self.stats.rhs_evals >= self.max_evals {
            return Err(self.fail(FailureKind::EvalLimit {
                max_rhs_evals: self.max_evals,
            }));
        }
        self.stats.rhs_evals += 1;
        Ok(())
    }
}

/// Evaluations of the system at one point, with scratch space.
struct Eval<'a, S: ConstrainedSystem + ?Sized> {
    sys: &'a S,
    mass: DMatrix<f64>,
    jac: DMatrix<f64>,
    forces: DVector<f64>,
}

impl<S: ConstrainedSystem + ?Sized> Eval<'_, S> {
    /// `r = M q̈ − h − Dᵀλ` into `r` (leaves `M`, `D`, `h` at this point in the scratch).
    fn residual(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        v: &DVector<f64>,
        qdd: &DVector<f64>,
        lam: &DVector<f64>,
        r: &mut DVector<f64>,
    ) {
        self.sys.mass(q, &mut self.mass);
        self.sys.forces(t, q, v, &mut self.forces);
        self.sys.constraint_jacobian(t, q, &mut self.jac);
        r.copy_from(&(&self.mass * qdd - &self.forces - self.jac.tr_mul(lam)));
    }
}

fn all_finite(v: &DVector<f64>) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Solves the saddle-point system `[a11, −Dᵀ; D, 0] x = b` (LU with partial pivoting);
/// `None` if singular (relative pivot below 1e-14) or not finite.
fn saddle_lu(
    a11: &DMatrix<f64>,
    d: &DMatrix<f64>,
) -> Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>> {
    let (m, n) = d.shape();
    let mut a = DMatrix::<f64>::zeros(n + m, n + m);
    a.view_mut((0, 0), (n, n)).copy_from(a11);
    for r in 0..m {
        for c in 0..n {
            a[(n + r, c)] = d[(r, c)];
            a[(c, n + r)] = -d[(r, c)];
        }
    }
    let lu = a.lu();
    let p = lu.lu_internal().diagonal().abs();
    (p.iter().all(|x| x.is_finite()) && p.min() > 1e-14 * p.max()).then_some(lu)
}

/// Integrates from consistent `q0`, `v0` (`Φ(t0, q0) = 0`, `D v0 = −Φ_t`) over `grid`.
pub fn solve<S: ConstrainedSystem + ?Sized>(
    sys: &S,
    q0: &DVector<f64>,
    v0: &DVector<f64>,
    grid: &OutputGrid,
    opts: &GenAlphaOptions,
) -> Result<Solution, SolverError> {
    let (t0, t_end) = (grid.t0, grid.t_end());
    let (n, m) = (sys.dim(), sys.n_constraints());
    let mut work = Work {
        stats: Stats::default(),
        max_steps: opts.max_steps,
        max_evals: opts.max_evals,
        t: t0,
    };
    let invalid = |msg: String| SolverError {
        method: NAME,
        kind: FailureKind::InvalidInput(msg),
        t: t0,
        stats: Stats::default(),
    };
    if !(opts.h > 0.0 && opts.h.is_finite()) {
        return Err(invalid(format!(
            "step size must be positive and finite, got {}",
            opts.h
        )));
    }
    if !(0.0..=1.0).contains(&opts.rho_inf) || (m > 0 && opts.rho_inf == 1.0) {
        return Err(invalid(format!(
            "ρ∞ must lie in [0, 1), got {} (ρ∞ = 1 leaves the O(h) transient of λ and q̈ of the \
             index-3 form undamped, Arnold & Brüls 2007)",
            opts.rho_inf
        )));
    }
    if opts.newton_tol.is_nan() || opts.newton_tol <= 0.0 || opts.max_newton_iters == 0 {
        return Err(invalid(
            "Newton tolerance and iteration cap must be positive".into(),
        ));
    }
    if opts.max_steps == 0 || opts.max_evals == 0 {
        return Err(invalid("step and evaluation caps must be positive".into()));
    }
    if q0.len() != n || v0.len() != n || !all_finite(q0) || !all_finite(v0) {
        return Err(invalid(format!(
            "initial q, v must be finite vectors of length {n} (got {}, {})",
            q0.len(),
            v0.len()
        )));
    }
    let p = GenAlphaParams::from_rho_inf(opts.rho_inf);
    let mut ev = Eval {
        sys,
        mass: DMatrix::zeros(n, n),
        jac: DMatrix::zeros(m, n),
        forces: DVector::zeros(n),
    };
    // consistent initial accelerations and multipliers
    work.charge()?;
    sys.mass(q0, &mut ev.mass);
    sys.forces(t0, q0, v0, &mut ev.forces);
    sys.constraint_jacobian(t0, q0, &mut ev.jac);
    let mut g = DVector::zeros(m);
    sys.gamma(t0, q0, v0, &mut g);
    let lu = saddle_lu(&ev.mass, &ev.jac).ok_or_else(|| work.fail(FailureKind::SingularMatrix))?;
    work.stats.lu_decompositions += 1;
    let mut b = DVector::zeros(n + m);
    b.rows_mut(0, n).copy_from(&ev.forces);
    b.rows_mut(n, m).copy_from(&g);
    let x = lu
        .solve(&b)
        .filter(all_finite)
        .ok_or_else(|| work.fail(FailureKind::NonFinite))?;
    let (mut q, mut v) = (q0.clone(), v0.clone());
    let mut qdd: DVector<f64> = x.rows(0, n).into_owned();
    let mut lam: DVector<f64> = x.rows(n, m).into_owned();
    let mut a = qdd.clone();

    let mut y0 = DVector::zeros(2 * n);
    y0.rows_mut(0, n).copy_from(&q);
    y0.rows_mut(n, n).copy_from(&v);
    let mut rec = Recorder::new(grid, &y0);
    let mut y_new = y0.clone();
    let n_steps = ((t_end - t0) / opts.h * (1.0 - 1e-12)).ceil().max(1.0) as u64;

    // per-step unknowns and scratch
    let (mut q1, mut v1, mut qdd1, mut lam1, mut a1) =
        (q.clone(), v.clone(), qdd.clone(), lam.clone(), a.clone());
    let mut r = DVector::zeros(n);
    let mut r_fd = DVector::zeros(n);
    let mut phi = DVector::zeros(m);
    let mut rhs = DVector::zeros(n + m);
    let mut a11 = DMatrix::zeros(n, n);
    let mut x_fd = DVector::zeros(n);
    let mut h_fd = DVector::zeros(n);
    let sqrt_eps = f64::EPSILON.sqrt();
    for k in 0..n_steps {
        if work.stats.steps >= work.max_steps {
            return Err(work.fail(FailureKind::StepLimit {
                max_steps: work.max_steps,
            }));
        }
        let t = t0 + k as f64 * opts.h;
        let t1 = if k + 1 == n_steps {
            t_end
        } else {
            t0 + (k + 1) as f64 * opts.h
        };
        let h = t1 - t;
        let beta_p = (1.0 - p.alpha_m) / (h * h * p.beta * (1.0 - p.alpha_f));
        let gamma_p = p.gamma / (h * p.beta);
        let mut lu: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>> = None;
        'newton: {
            // predictor: q̈_{n+1} = q̈_n, λ_{n+1} = λ_n
            qdd1.copy_from(&qdd);
            a1.copy_from(&((&qdd - &a * p.alpha_m) / (1.0 - p.alpha_m)));
            v1.copy_from(&(&v + &a * (h * (1.0 - p.gamma)) + &a1 * (h * p.gamma)));
            q1.copy_from(&(&q + &v * h + &a * (h * h * (0.5 - p.beta)) + &a1 * (h * h * p.beta)));
            lam1.copy_from(&lam);
            let mut rebuilt = false;
            let mut err_prev: Option<f64> = None;
            let mut err = f64::INFINITY;
            for _ in 0..opts.max_newton_iters {
                work.stats.newton_iters += 1;
                work.charge()?;
                ev.residual(t1, &q1, &v1, &qdd1, &lam1, &mut r);
                sys.constraints(t1, &q1, &mut phi);
                if !all_finite(&r) || !all_finite(&phi) {
                    return Err(work.fail(FailureKind::NonFinite));
                }
                if lu.is_none() {
                    // iteration matrix M + (γ'/β') C + K/β' by forward differences
                    work.stats.jac_evals += 1;
                    let jac = ev.jac.clone();
                    a11.copy_from(&ev.mass);
                    for j in 0..n {
                        let delta = sqrt_eps * q1[j].abs().max(1.0);
                        x_fd.copy_from(&q1);
                        x_fd[j] += delta;
                        work.charge()?;
                        ev.residual(t1, &x_fd, &v1, &qdd1, &lam1, &mut r_fd);
                        for i in 0..n {
                            a11[(i, j)] += (r_fd[i] - r[i]) / (delta * beta_p);
                        }
                    }
                    if sys.forces_depend_on_velocity() {
                        sys.forces(t1, &q1, &v1, &mut h_fd);
                        for j in 0..n {
                            let delta = sqrt_eps * v1[j].abs().max(1.0);
                            x_fd.copy_from(&v1);
                            x_fd[j] += delta;
                            work.charge()?;
                            sys.forces(t1, &q1, &x_fd, &mut r_fd);
                            for i in 0..n {
                                a11[(i, j)] -= (r_fd[i] - h_fd[i]) * gamma_p / (delta * beta_p);
                            }
                        }
                    }
                    if !a11.iter().all(|x| x.is_finite()) {
                        return Err(work.fail(FailureKind::NonFinite));
                    }
                    let f = saddle_lu(&a11, &jac)
                        .ok_or_else(|| work.fail(FailureKind::SingularMatrix))?;
                    lu = Some(f);
                    work.stats.lu_decompositions += 1;
                }
                rhs.rows_mut(0, n).copy_from(&(&r * (-1.0 / beta_p)));
                rhs.rows_mut(n, m).copy_from(&(-&phi));
                let Some(x) = lu.as_ref().and_then(|f| f.solve(&rhs)).filter(all_finite) else {
                    return Err(work.fail(FailureKind::NonFinite));
                };
                err = 0.0;
                for i in 0..n {
                    let dq = x[i];
                    q1[i] += dq;
                    v1[i] += gamma_p * dq;
                    qdd1[i] += beta_p * dq;
                    a1[i] += dq / (h * h * p.beta);
                    err = err.max(dq.abs() / (opts.newton_tol + 4.0 * f64::EPSILON * q1[i].abs()));
                }
                for i in 0..m {
                    lam1[i] += beta_p * x[n + i];
                }
                let theta = err_prev.map(|e| err / e);
                let done = err <= 1.0
                    && match theta {
                        None => true,
                        // θ ≥ 1 below the tolerance: stagnation at roundoff
                        Some(th) => th >= 1.0 || err * th <= 1.0 - th,
                    };
                if done {
                    break 'newton;
                }
                if theta.is_some_and(|th| th > 0.5) && !rebuilt {
                    lu = None; // slow contraction: rebuild the matrix at this iterate, once
                    rebuilt = true;
                }
                err_prev = Some(err);
            }
            return Err(work.fail(FailureKind::NoConvergence {
                iterations: opts.max_newton_iters,
                increment: err,
            }));
        }
        y_new.rows_mut(0, n).copy_from(&q1);
        y_new.rows_mut(n, n).copy_from(&v1);
        rec.record(t, t1, &y_new, |theta, out| {
            // cubic Hermite basis on [0, 1]
            let (t2, t3) = (theta * theta, theta * theta * theta);
            let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
            let h10 = t3 - 2.0 * t2 + theta;
            let h01 = -2.0 * t3 + 3.0 * t2;
            let h11 = t3 - t2;
            for i in 0..n {
                out[i] = h00 * q[i] + h10 * h * v[i] + h01 * q1[i] + h11 * h * v1[i];
                out[n + i] = h00 * v[i] + h10 * h * qdd[i] + h01 * v1[i] + h11 * h * qdd1[i];
            }
        });
        work.stats.steps += 1;
        work.t = t1;
        std::mem::swap(&mut q, &mut q1);
        std::mem::swap(&mut v, &mut v1);
        std::mem::swap(&mut qdd, &mut qdd1);
        std::mem::swap(&mut lam, &mut lam1);
        std::mem::swap(&mut a, &mut a1);
    }
    Ok(rec.finish(work.stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::{OdeSystem, SolverOptions, rk45};

    /// Planar pendulum in Cartesian coordinates: unit mass at (x, y), rod length 1,
    /// `Φ = ½ (x² + y² − 1)`, `D = [x, y]`, `γ = −(ẋ² + ẏ²)`, gravity along −y.
    struct Pendulum;

    const G: f64 = 9.81;

    impl ConstrainedSystem for Pendulum {
        fn dim(&self) -> usize {
            2
        }
        fn n_constraints(&self) -> usize {
            1
        }
        fn mass(&self, _q: &DVector<f64>, m: &mut DMatrix<f64>) {
            m.fill_with_identity();
        }
        fn forces(&self, _t: f64, _q: &DVector<f64>, _v: &DVector<f64>, h: &mut DVector<f64>) {
            h[0] = 0.0;
            h[1] = -G;
        }
        fn constraints(&self, _t: f64, q: &DVector<f64>, phi: &mut DVector<f64>) {
            phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - 1.0);
        }
        fn constraint_jacobian(&self, _t: f64, q: &DVector<f64>, d: &mut DMatrix<f64>) {
            d[(0, 0)] = q[0];
            d[(0, 1)] = q[1];
        }
        fn gamma(&self, _t: f64, _q: &DVector<f64>, v: &DVector<f64>, g: &mut DVector<f64>) {
            g[0] = -(v[0] * v[0] + v[1] * v[1]);
        }
        fn forces_depend_on_velocity(&self) -> bool {
            false
        }
    }

    /// The same pendulum in its angle: θ̈ = −g sin θ.
    struct Angle;

    impl OdeSystem for Angle {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&self, _t: f64, y: &DVector<f64>, d: &mut DVector<f64>) {
            d[0] = y[1];
            d[1] = -G * y[0].sin();
        }
    }

    fn run(h: f64, grid: &OutputGrid) -> Result<Solution, SolverError> {
        let th0: f64 = 1.2;
        let q0 = DVector::from_vec(vec![th0.sin(), -th0.cos()]);
        let v0 = DVector::zeros(2);
        solve(
            &Pendulum,
            &q0,
            &v0,
            grid,
            &GenAlphaOptions {
                h,
                ..Default::default()
            },
        )
    }

    #[test]
    fn parameters_of_chung_and_hulbert() {
        let p = GenAlphaParams::from_rho_inf(1.0);
        assert_eq!(
            (p.alpha_m, p.alpha_f, p.gamma, p.beta),
            (0.5, 0.5, 0.5, 0.25)
        );
        let p = GenAlphaParams::from_rho_inf(0.0);
        assert_eq!((p.alpha_m, p.alpha_f, p.gamma), (-1.0, 0.0, 1.5));
        assert_eq!(p.beta, 1.0);
    }

    #[test]
    fn pendulum_converges_at_second_order_on_the_manifold() {
        let grid = OutputGrid::new(0.0, 2.0, 0.01).unwrap();
        let reference = rk45::solve(
            &Angle,
            &DVector::from_vec(vec![1.2, 0.0]),
            &grid,
            &SolverOptions::absolute(1e-13),
        )
        .unwrap();
        let errors: Vec<(f64, f64)> = [4e-3, 2e-3, 1e-3]
            .iter()
            .map(|&h| {
                let s = run(h, &grid).unwrap();
                let (mut eq, mut ev) = (0.0f64, 0.0f64);
                for k in 0..s.t.len() {
                    let y = s.y_at(k);
                    let (th, w) = (reference.y_at(k)[0], reference.y_at(k)[1]);
                    let (x, z) = (th.sin(), -th.cos());
                    eq = eq.max((y[0] - x).abs()).max((y[1] - z).abs());
                    ev = ev
                        .max((y[2] - w * th.cos()).abs())
                        .max((y[3] - w * th.sin()).abs());
                    // positions on the circle to the Newton tolerance
                    // on the circle to the Newton tolerance at the steps (every grid point
                    // for h = 1e-3), to O(h⁴) of the Hermite interpolation between them
                    let c = (y[0] * y[0] + y[1] * y[1] - 1.0).abs();
                    assert!(c < if h == 1e-3 { 1e-12 } else { 1e-8 }, "h {h}: {c:e}");
                }
                (eq, ev)
            })
            .collect();
        for w in errors.windows(2) {
            let (rq, rv) = (w[0].0 / w[1].0, w[0].1 / w[1].1);
            assert!((3.5..4.5).contains(&rq), "q error ratio {rq} ({errors:?})");
            assert!((3.0..5.0).contains(&rv), "v error ratio {rv} ({errors:?})");
        }
        assert!(errors[2].0 < 2e-3, "{errors:?}");
    }

    #[test]
    fn caps_and_bad_input_are_typed_errors() {
        let grid = OutputGrid::new(0.0, 1.0, 0.01).unwrap();
        let e = solve(
            &Pendulum,
            &DVector::from_vec(vec![1.0, 0.0]),
            &DVector::zeros(2),
            &grid,
            &GenAlphaOptions {
                max_steps: 7,
                ..Default::default()
            },
        )
        .unwrap_err();
        assert_eq!(e.kind, FailureKind::StepLimit { max_steps: 7 });
        assert!((e.t - 7e-4).abs() < 1e-15 && e.stats.steps == 7);
        let e = solve(
            &Pendulum,
            &DVector::from_vec(vec![1.0, 0.0]),
            &DVector::zeros(2),
            &grid,
            &GenAlphaOptions {
                max_evals: 50,
                ..Default::default()
            },
        )
        .unwrap_err();
        assert_eq!(e.kind, FailureKind::EvalLimit { max_rhs_evals: 50 });
        let e = solve(
            &Pendulum,
            &DVector::from_vec(vec![1.0, 0.0]),
            &DVector::zeros(2),
            &grid,
            &GenAlphaOptions {
                h: 0.5,
                max_newton_iters: 1,
                ..Default::default()
            },
        )
        .unwrap_err();
        assert!(
            matches!(e.kind, FailureKind::NoConvergence { iterations: 1, .. }),
            "{e}"
        );
        assert!(
            e.to_string().contains("did not converge in 1 iterations"),
            "{e}"
        );
        let e = solve(
            &Pendulum,
            &DVector::from_vec(vec![1.0, 0.0]),
            &DVector::zeros(2),
            &grid,
            &GenAlphaOptions {
                rho_inf: 1.5,
                ..Default::default()
            },
        )
        .unwrap_err();
        assert!(matches!(e.kind, FailureKind::InvalidInput(_)));
        let e = solve(
            &Pendulum,
            &DVector::from_vec(vec![1.0, 0.0]),
            &DVector::zeros(2),
            &grid,
            &GenAlphaOptions {
                rho_inf: 1.0,
                ..Default::default()
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("undamped"), "{e}");
    }
}
