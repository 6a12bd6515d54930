//! The uniform output grid and the recorded solution.

use super::Stats;
use nalgebra::DVector;
use serde::Serialize;

/// Uniform output grid `t_k = t0 + k·dt`, `k = 0..=n`; the last point is exactly `t_end`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OutputGrid {
    /// First point \[s\].
    pub t0: f64,
    /// Spacing \[s\].
    pub dt: f64,
    /// Number of intervals (the grid has `n + 1` points).
    pub n: usize,
    t_end: f64,
}

impl OutputGrid {
    /// Grid on `[t0, t_end]` with spacing `dt`; `(t_end - t0)/dt` is rounded to the nearest
    /// integer and the last point set to `t_end` exactly.
    pub fn new(t0: f64, t_end: f64, dt: f64) -> Result<Self, String> {
        let ok = t0.is_finite() && t_end.is_finite() && dt.is_finite() && t_end > t0 && dt > 0.0;
        if !ok {
            return Err(format!(
                "bad output grid t0 = {t0}, t_end = {t_end}, dt = {dt}"
            ));
        }
        let n = ((t_end - t0) / dt).round().max(1.0) as usize;
        Ok(Self { t0, dt, n, t_end })
    }

    /// End of the interval.
    pub fn t_end(&self) -> f64 {
        self.t_end
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.n + 1
    }

    /// Always false (a grid has at least two points).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Point `k`.
    pub fn t(&self, k: usize) -> f64 {
        if k >= self.n {
            self.t_end
        } else {
            self.t0 + k as f64 * self.dt
        }
    }
}

/// Solution on the output grid.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Solution {
    /// Output times.
    pub t: Vec<f64>,
    /// States, row-major: point `k`, component `i` at `y[k * dim + i]`.
    pub y: Vec<f64>,
    /// State dimension.
    pub dim: usize,
    /// Work counters.
    pub stats: Stats,
}

impl Solution {
    /// State at output point `k`.
    pub fn y_at(&self, k: usize) -> &[f64] {
        &self.y[k * self.dim..(k + 1) * self.dim]
    }

    /// Component `i` over the whole grid.
    pub fn component(&self, i: usize) -> Vec<f64> {
        self.y.iter().skip(i).step_by(self.dim).copied().collect()
    }

    /// Last state.
    pub fn last(&self) -> &[f64] {
        self.y_at(self.t.len() - 1)
    }
}

/// Writes dense output onto the grid as steps are accepted.
pub(crate) struct Recorder<'g> {
    grid: &'g OutputGrid,
    next: usize,
    sol: Solution,
    buf: DVector<f64>,
}

impl<'g> Recorder<'g> {
    /// Starts the record with the initial state at `grid.t0`.
    pub(crate) fn new(grid: &'g OutputGrid, y0: &DVector<f64>) -> Self {
        let dim = y0.len();
        let mut y = Vec::with_capacity(grid.len() * dim);
        y.extend_from_slice(y0.as_slice());
        let mut t = Vec::with_capacity(grid.len());
        t.push(grid.t0);
        Self {
            grid,
            next: 1,
            sol: Solution {
                t,
                y,
                dim,
                stats: Stats::default(),
            },
            buf: DVector::zeros(dim),
        }
    }

    /// Records every grid point in `(t_old, t_new]` of an accepted step. `interp(theta, out)`
    /// evaluates the step's continuous extension at `t_old + theta (t_new - t_old)`; a grid point
    /// equal to `t_new` takes `y_new` itself.
    pub(crate) fn record<F>(&mut self, t_old: f64, t_new: f64, y_new: &DVector<f64>, mut interp: F)
    where
        F: FnMut(f64, &mut DVector<f64>),
    {
        let h = t_new - t_old;
        while self.next <= self.grid.n {
            let tk = self.grid.t(self.next);
            if tk > t_new {
                break;
            }
            if tk == t_new {
                self.sol.y.extend_from_slice(y_new.as_slice());
            } else {
                interp((tk - t_old) / h, &mut self.buf);
                self.sol.y.extend_from_slice(self.buf.as_slice());
            }
            self.sol.t.push(tk);
            self.next += 1;
        }
    }

    /// Finishes the record.
    pub(crate) fn finish(mut self, stats: Stats) -> Solution {
        self.sol.stats = stats;
        self.sol
    }
}
