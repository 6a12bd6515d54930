//! Method selection and the single entry point [`solve`].

use super::{OdeSystem, OutputGrid, Solution, SolverError, SolverOptions};
use super::{bdf, initial_acceleration, rk23, rk45, rosenbrock, trbdf2};
use nalgebra::DVector;
use serde::{Deserialize, Serialize};

/// The generic ODE methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum OdeMethod {
    /// Thesis §4.1.1, fixed step `SolverOptions::h` (required); second-order layout `[q; q̇]`.
    InitialAcceleration,
    /// Dormand–Prince 5(4) (ode45).
    Rk45,
    /// Bogacki–Shampine 3(2) (ode23).
    Rk23,
    /// Variable-order BDF 1–5 (ode15s with pure BDF coefficients).
    Bdf,
    /// Variable-order NDF 1–5 (ode15s default formulas, Klopfenstein–Shampine).
    Ndf,
    /// Modified Rosenbrock 2(3) (ode23s).
    Rosenbrock,
    /// TR-BDF2 (ode23tb).
    TrBdf2,
}

impl OdeMethod {
    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            Self::InitialAcceleration => "initial-acceleration",
            Self::Rk45 => "rk45",
            Self::Rk23 => "rk23",
            Self::Bdf => "bdf",
            Self::Ndf => "ndf",
            Self::Rosenbrock => "rosenbrock",
            Self::TrBdf2 => "trbdf2",
        }
    }

    /// `true` for methods without error control.
    pub fn is_fixed_step(self) -> bool {
        matches!(self, Self::InitialAcceleration)
    }

    /// `true` for implicit / linearly implicit methods (stiff solvers).
    pub fn is_implicit(self) -> bool {
        matches!(
            self,
            Self::Bdf | Self::Ndf | Self::Rosenbrock | Self::TrBdf2
        )
    }
}

/// Integrates `sys` from `grid.t0` (state `y0`) to `grid.t_end()` with `method`, writing the
/// solution on the output grid.
pub fn solve<S: OdeSystem + ?Sized>(
    method: OdeMethod,
    sys: &S,
    y0: &DVector<f64>,
    grid: &OutputGrid,
    opts: &SolverOptions,
) -> Result<Solution, SolverError> {
    match method {
        OdeMethod::InitialAcceleration => initial_acceleration::solve(sys, y0, grid, opts),
        OdeMethod::Rk45 => rk45::solve(sys, y0, grid, opts),
        OdeMethod::Rk23 => rk23::solve(sys, y0, grid, opts),
        OdeMethod::Bdf => bdf::solve(sys, y0, grid, opts, bdf::Formula::Bdf),
        OdeMethod::Ndf => bdf::solve(sys, y0, grid, opts, bdf::Formula::Ndf),
        OdeMethod::Rosenbrock => rosenbrock::solve(sys, y0, grid, opts),
        OdeMethod::TrBdf2 => trbdf2::solve(sys, y0, grid, opts),
    }
}
