//! rodstudy: connecting-rod design studies.
//!
//! The modules follow the pipeline of the study (see `SPEC.md` and the thesis in `shared/seed`):
//!
//! - [`geometry`]: stage 1, reading STL, validating the solid, exact mass properties and the
//!   mapping into the mechanism frame;
//! - [`linalg`]: the crate's one small dense LU ([`linalg::DenseLu`]), shared by the mechanism
//!   core and the implicit integrators;
//! - [`mechanism`]: stage 2, the planar crank–slider: closed-form Newton–Euler and a planar
//!   multibody core (thesis §3.2), the driven scene and its peak pin force;
//! - [`integrators`]: ODE solvers (the thesis' initial-acceleration method, RK45 (optionally
//!   with projection onto an invariant manifold), RK23, BDF, Rosenbrock, TR-BDF2) and
//!   generalized-α for constrained mechanical systems, with dense output, step control,
//!   counters and caps;
//! - [`free_run`]: scene `free` (thesis ch. 4): the reduction-method equation of motion, its exact
//!   energy-integral reference, the multibody DAE forms and the work–precision sweep;
//! - [`fem`]: stage 3, linear elasticity with 10-node tetrahedra (gmsh mesh, faer Cholesky),
//!   von Mises under F_x and F_y;
//! - [`study`]: running the stages over every design of a folder;
//! - [`python_env`]: the project-local Python environment the `pipeline/` scripts run in;
//! - [`bench`]: benchmarks, reported as ratios against a reference run;
//! - [`cli`]: the command-line interface the binary is a thin front over.

pub mod bench;
pub mod cli;
pub mod fem;
pub mod free_run;
pub mod geometry;
pub mod integrators;
pub mod linalg;
pub mod mechanism;
pub mod python_env;
pub mod study;
