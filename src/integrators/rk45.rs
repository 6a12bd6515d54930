//! Dormand–Prince 5(4), the method of MATLAB's ode45.
//!
//! J. R. Dormand, P. J. Prince, "A family of embedded Runge–Kutta formulae", J. Comput. Appl.
//! Math. 6 (1980) 19–26 (coefficients as in Hairer, Nørsett & Wanner, *Solving ODEs I*,
//! Table II.5.2). Seven stages, FSAL, local extrapolation (the 5th-order result is propagated),
//! error estimate `h Σ e_i k_i` with `e = b − b̂` (4th-order), step factor
//! `0.9 err^(-1/5)` in `[0.2, 5]` (no increase right after a rejection).
//! Dense output: the 4th-order continuous extension of MATLAB's `ntrp45`
//! (Shampine 1986; `y(t+θh) = y + h Σ_i k_i Σ_j BI_ij θ^j`).
//!
//! With a post-step projection ([`solve_projected`], Hairer, Lubich & Wanner, *Geometric
//! Numerical Integration*, §IV.4) each accepted step is: the Dormand–Prince step from the
//! projected `y_n` gives `ỹ_{n+1}` (error test on `ỹ_{n+1}`), then `y_{n+1} = P(ỹ_{n+1})`, and
//! the FSAL stage is re-evaluated at `y_{n+1}` (one extra evaluation per step) so that the next
//! step starts consistently. Dense output stays consistent with the projected solution: the
//! step's continuous extension (built from `y_n` and the step's own stages, so it ends at
//! `ỹ_{n+1}`) is evaluated at each interior output time and the sample is projected with the
//! same map `P`; a grid point at `t_{n+1}` takes `y_{n+1}`. The samples therefore lie on the
//! manifold, and differ from the unprojected interpolant by O(local error), which keeps its
//! 4th order. A periodic component ([`OdeSystem::period`](super::OdeSystem::period)) stays
//! whole periods + remainder under a projection: the projection sees the full state, and a
//! change it makes is added to the remainder (the free crank's energy projection changes φ̇
//! only, so φ keeps its exact remainder and compensation).

use super::adaptive::{AdaptiveStepper, Attempt, Step, integrate};
use super::control::Controller;
use super::eval::Evaluator;
use super::norm::{Weights, all_finite};
use super::{OdeSystem, OutputGrid, Solution, SolverError, SolverOptions, StepProjection};
use nalgebra::DVector;

const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// `e = b − b̂` (`b = A[6]`, 5th order; `b̂` the 4th-order weights).
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
/// ntrp45 interpolation matrix: coefficients of θ, θ², θ³, θ⁴ for each stage.
const BI: [[f64; 4]; 7] = [
    [1.0, -183.0 / 64.0, 37.0 / 12.0, -145.0 / 128.0],
    [0.0, 0.0, 0.0, 0.0],
    [0.0, 1500.0 / 371.0, -1000.0 / 159.0, 1000.0 / 371.0],
    [0.0, -125.0 / 32.0, 125.0 / 12.0, -375.0 / 64.0],
    [0.0, 9477.0 / 3392.0, -729.0 / 106.0, 25515.0 / 6784.0],
    [0.0, -11.0 / 7.0, 11.0 / 3.0, -55.0 / 28.0],
    [0.0, 3.0 / 2.0, -4.0, 5.0 / 2.0],
];

/// Integrates with error control `opts.rtol`, `opts.atol`.
pub fn solve<S: OdeSystem + ?Sized>(
    sys: &S,
    y0: &DVector<f64>,
    grid: &OutputGrid,
    opts: &SolverOptions,
) -> Result<Solution, SolverError> {
    integrate::<DormandPrince, _>(sys, y0, grid, opts, None)
}

/// [`solve`] with a projection onto an invariant manifold after every accepted step, applied
/// to `y0` and to every dense-output sample as well (see the module docs). A failed projection
/// stops the run with [`FailureKind::Projection`](super::FailureKind::Projection).
pub fn solve_projected<S: OdeSystem + ?Sized>(
    sys: &S,
    y0: &DVector<f64>,
    grid: &OutputGrid,
    opts: &SolverOptions,
    projection: &mut dyn StepProjection,
) -> Result<Solution, SolverError> {
    integrate::<DormandPrince, _>(sys, y0, grid, opts, Some(projection))
}

/// Stages `k_1 … k_7` (`k_1 = f(t_n, y_n)`, `k_7 = f(t_{n+1}, y_{n+1})`) and scratch.
struct DormandPrince {
    k: [DVector<f64>; 7],
    ys: DVector<f64>,
    err: DVector<f64>,
}

impl AdaptiveStepper for DormandPrince {
    const NAME: &'static str = "rk45";
    const START_ORDER: u32 = 4;
    const CONTROL: Controller = Controller {
        exponent: 5.0,
        safety: 0.9,
        fac_min: 0.2,
    };

    fn new(n: usize, _weights: &Weights) -> Self {
        Self {
            k: std::array::from_fn(|_| DVector::zeros(n)),
            ys: DVector::zeros(n),
            err: DVector::zeros(n),
        }
    }

    fn derivative_mut(&mut self) -> &mut DVector<f64> {
        &mut self.k[0]
    }

    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        ev: &mut Evaluator<'_, S>,
        weights: &Weights,
        step: &Step,
        y: &DVector<f64>,
        y_new: &mut DVector<f64>,
        dy: &mut DVector<f64>,
    ) -> Result<Attempt, SolverError> {
        let Step { t, h, t_new, .. } = *step;
        let Self { k, ys, err } = self;
        let n = y.len();
        for s in 1..7 {
            // component loops: cheaper than vector ops for the small systems of this crate
            for i in 0..n {
                let mut acc = 0.0;
                for (j, kj) in k.iter().enumerate().take(s) {
                    acc += A[s][j] * kj[i];
                }
                // the last stage's increment is the step's (A[6] = b, FSAL)
                dy[i] = h * acc;
                ys[i] = y[i] + dy[i];
            }
            let ts = if s >= 5 { t_new } else { t + C[s] * h };
            ev.rhs(ts, ys, &mut k[s])?;
        }
        // stage 7 was evaluated at y_new = ys (FSAL)
        y_new.copy_from(ys);
        for i in 0..n {
            let mut acc = 0.0;
            for (j, kj) in k.iter().enumerate() {
                acc += E[j] * kj[i];
            }
            err[i] = h * acc;
        }
        let en = weights.norm(err, y, y_new);
        Ok(Attempt::checked(en, all_finite(y_new) && all_finite(&k[6])))
    }

    fn interpolate(
        &self,
        theta: f64,
        h: f64,
        y: &DVector<f64>,
        _y_new: &DVector<f64>,
        out: &mut DVector<f64>,
    ) {
        let (t1, t2, t3, t4) = (theta, theta * theta, theta.powi(3), theta.powi(4));
        out.copy_from(y);
        for (j, kj) in self.k.iter().enumerate() {
            let b = BI[j][0] * t1 + BI[j][1] * t2 + BI[j][2] * t3 + BI[j][3] * t4;
            if b != 0.0 {
                out.axpy(h * b, kj, 1.0);
            }
        }
    }

    fn accept(&mut self) {
        self.k.swap(0, 6);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::FailureKind;
    use crate::integrators::tests_common::{Decay, Oscillator, max_error};

    #[test]
    fn tableau_is_consistent() {
        for s in 1..7 {
            let row: f64 = A[s].iter().sum();
            assert!((row - C[s]).abs() < 1e-14, "row {s}");
        }
        assert!(E.iter().sum::<f64>().abs() < 1e-15);
        // the continuous extension reproduces y_new at θ = 1
        for j in 0..7 {
            let b: f64 = BI[j].iter().sum();
            let bj = if j < 6 { A[6][j] } else { 0.0 };
            assert!((b - bj).abs() < 1e-14, "stage {j}");
        }
    }

    #[test]
    fn decay_within_tolerance() {
        let grid = OutputGrid::new(0.0, 2.0, 0.01).unwrap();
        let y0 = DVector::from_vec(vec![1.0]);
        for tol in [1e-4, 1e-7, 1e-10] {
            let sol = solve(
                &Decay { lambda: 1.0 },
                &y0,
                &grid,
                &SolverOptions::absolute(tol),
            )
            .unwrap();
            let e = max_error(&sol, |t| vec![(-t).exp()]);
            assert!(e < 10.0 * tol, "tol {tol}: error {e}");
        }
    }

    #[test]
    fn oscillator_error_scales_like_tol_to_the_fifth_root() {
        let sys = Oscillator { omega: 2.0 };
        let grid = OutputGrid::new(0.0, 10.0, 0.01).unwrap();
        let y0 = DVector::from_vec(vec![1.0, 0.0]);
        let run = |tol: f64| {
            let sol = solve(&sys, &y0, &grid, &SolverOptions::absolute(tol)).unwrap();
            (
                max_error(&sol, |t| sys.exact(t).to_vec()),
                sol.stats.steps as f64,
            )
        };
        let (e1, n1) = run(1e-6);
        let (e2, n2) = run(1e-9);
        assert!(e2 < e1 && e1 < 1e-4 && e2 < 1e-7, "{e1} {e2}");
        // steps grow like tol^(-1/5): 1000^(1/5) ≈ 4
        let ratio = n2 / n1;
        assert!(ratio > 3.0 && ratio < 5.5, "step ratio {ratio}");
    }

    /// Radial projection onto the oscillator's energy ellipse q² + (q̇/ω)² = 1.
    struct OntoEllipse {
        omega: f64,
        calls: usize,
    }

    impl StepProjection for OntoEllipse {
        fn project(&mut self, _t: f64, y: &mut DVector<f64>) -> Result<(), String> {
            self.calls += 1;
            let r = (y[0] * y[0] + (y[1] / self.omega).powi(2)).sqrt();
            if r == 0.0 {
                return Err("at the origin".into());
            }
            *y /= r;
            Ok(())
        }
    }

    #[test]
    fn projection_keeps_the_invariant_and_the_accuracy() {
        let sys = Oscillator { omega: 2.0 };
        let grid = OutputGrid::new(0.0, 20.0, 0.05).unwrap();
        let y0 = DVector::from_vec(vec![1.0, 0.0]);
        let opts = SolverOptions::absolute(1e-6);
        let invariant = |s: &Solution| {
            (0..s.t.len())
                .map(|k| (s.y_at(k)[0].powi(2) + (s.y_at(k)[1] / 2.0).powi(2) - 1.0).abs())
                .fold(0.0, f64::max)
        };
        let plain = solve(&sys, &y0, &grid, &opts).unwrap();
        let mut p = OntoEllipse {
            omega: 2.0,
            calls: 0,
        };
        let proj = solve_projected(&sys, &y0, &grid, &opts, &mut p).unwrap();
        assert!(invariant(&plain) > 1e-7, "{:e}", invariant(&plain));
        assert!(invariant(&proj) < 1e-15, "{:e}", invariant(&proj));
        // every step and every interior sample was projected; one extra evaluation per step
        assert!(p.calls as u64 >= proj.stats.steps + grid.n as u64 / 2);
        assert!(proj.stats.rhs_evals >= 6 * proj.stats.steps + proj.stats.steps - 1);
        let e_plain = max_error(&plain, |t| sys.exact(t).to_vec());
        let e_proj = max_error(&proj, |t| sys.exact(t).to_vec());
        assert!(
            e_proj < 2.0 * e_plain && e_proj < 1e-5,
            "{e_proj:e} vs {e_plain:e}"
        );
        // a failing projection is a typed error
        let mut bad = OntoEllipse {
            omega: 2.0,
            calls: 0,
        };
        let e = solve_projected(
            &sys,
            &DVector::from_vec(vec![0.0, 0.0]),
            &grid,
            &opts,
            &mut bad,
        )
        .unwrap_err();
        assert!(
            matches!(e.kind, FailureKind::Projection(ref m) if m == "at the origin"),
            "{e}"
        );
    }

    #[test]
    fn dense_output_is_fourth_order() {
        // one long step on y' = -y, interpolant error at θ = 0.5 shrinks like h^5
        let y0 = DVector::from_vec(vec![1.0]);
        let mut errs = vec![];
        for h in [0.2, 0.1] {
            let grid = OutputGrid::new(0.0, h, h / 2.0).unwrap();
            let opts = SolverOptions {
                h: Some(h),
                rtol: 0.5,
                atol: 1.0,
                ..Default::default()
            };
            let sol = solve(&Decay { lambda: 1.0 }, &y0, &grid, &opts).unwrap();
            assert_eq!(sol.stats.steps, 1);
            errs.push((sol.y_at(1)[0] - (-h / 2.0).exp()).abs());
        }
        let p = (errs[0] / errs[1]).log2();
        assert!(p > 4.5, "interpolant local order {p}");
    }
}
