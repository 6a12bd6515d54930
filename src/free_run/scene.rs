//! Scene `free` (thesis §4.2) and its hard-case variants.

use super::FreeRunError;
use super::loads::{GasSpring, Loads};
use super::mechanism::CrankSliderData;
use super::reduced::ReducedModel;
use super::reference::{ExactReference, exact_reference};
use crate::integrators::OutputGrid;
use serde::{Deserialize, Serialize};

/// A free-running crank scene: data, loads, interval, initial state, output grid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FreeScene {
    /// Mechanism data.
    pub data: CrankSliderData,
    /// Loads.
    pub loads: Loads,
    /// Start time \[s\].
    pub t0: f64,
    /// End time \[s\].
    pub t_end: f64,
    /// Initial crank angle \[rad\].
    pub phi0: f64,
    /// Initial crank angular velocity [rad/s].
    pub omega0: f64,
    /// Output grid spacing \[s\].
    pub dt_out: f64,
}

/// Most output points a run keeps (φ and φ̇ at each: 160 MB; 1,000 s of the scene's 1e-4 s grid,
/// ten times the 100 s hard case).
pub const MAX_OUTPUT_SAMPLES: usize = 10_000_000;

impl Default for FreeScene {
    fn default() -> Self {
        Self::thesis()
    }
}

impl FreeScene {
    /// Scene `free`: thesis ch. 3 data, `M = 1 N·m`, `F = 15 N` along +x, no gravity,
    /// `t ∈ [0, 1] s`, `φ(0) = 0`, `φ̇(0) = 0` (not stated in the thesis), output every 1e-4 s.
    pub fn thesis() -> Self {
        Self {
            data: CrankSliderData::thesis_ch3(),
            loads: Loads::thesis_ch4(),
            t0: 0.0,
            t_end: 1.0,
            phi0: 0.0,
            omega0: 0.0,
            dt_out: 1e-4,
        }
    }

    /// Hard case: the same rod scaled to `l = ratio · r` (near toggle for `ratio → 1`).
    pub fn near_toggle(ratio: f64) -> Self {
        let mut s = Self::thesis();
        s.data = s.data.with_rod_ratio(ratio);
        s
    }

    /// Hard case: a long run to `t_end` (100 s: φ grows to ≈ 1.8e5 rad), output every `dt_out`.
    pub fn long_run(t_end: f64, dt_out: f64) -> Self {
        Self {
            t_end,
            dt_out,
            ..Self::thesis()
        }
    }

    /// Hard case: a stiff gas spring `k` [N/m] with damping `c` [N·s/m] on the piston, at rest
    /// at mid-stroke (`φ0 = 90°`, `x0 = x(φ0)`); the loads push the crank slightly off and it
    /// creeps to equilibrium. Linearised: fast mode `−c p42²/I_red`, slow mode `−k/c`.
    pub fn stiff_spring(k: f64, c: f64) -> Self {
        let mut s = Self::thesis();
        s.phi0 = std::f64::consts::FRAC_PI_2;
        let kin = super::mechanism::Kinematics {
            r: s.data.r,
            l: s.data.l(),
        };
        s.loads.spring = Some(GasSpring {
            k,
            x0: kin.x(s.phi0),
            c,
        });
        s
    }

    /// The reduced model (validated: refuses `l ≤ r` and `I_red ≤ 0`).
    pub fn model(&self) -> Result<ReducedModel, FreeRunError> {
        Ok(ReducedModel::new(self.data)?)
    }

    /// The output grid: refused when `t_end` is not after `t0`, or when it would hold more than
    /// [`MAX_OUTPUT_SAMPLES`] points (the trajectories are kept in memory, 16 bytes a point).
    pub fn grid(&self) -> Result<OutputGrid, FreeRunError> {
        if self.t_end.is_nan() || self.t_end <= self.t0 {
            return Err(FreeRunError::Options(format!(
                "the end time {} s must be after the start {} s (--t-end > 0)",
                self.t_end, self.t0
            )));
        }
        let samples = (self.t_end - self.t0) / self.dt_out;
        if samples > MAX_OUTPUT_SAMPLES as f64 {
            return Err(FreeRunError::Options(format!(
                "--t-end {} s with an output every {} s is {samples:.2e} points, more than the \
                 {MAX_OUTPUT_SAMPLES:.0e} kept in memory: the longest run is {} s",
                self.t_end,
                self.dt_out,
                self.t0 + MAX_OUTPUT_SAMPLES as f64 * self.dt_out
            )));
        }
        OutputGrid::new(self.t0, self.t_end, self.dt_out).map_err(FreeRunError::Options)
    }

    /// The exact reference on the output grid (conservative loads only).
    pub fn reference(&self) -> Result<ExactReference, FreeRunError> {
        let model = self.model()?;
        Ok(exact_reference(
            &model,
            &self.loads,
            self.phi0,
            self.omega0,
            &self.grid()?,
        )?)
    }
}
