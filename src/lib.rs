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
//! - [`fem`]: the mathematics of stage 3 and the cycle: linear elasticity with 10-node tetrahedra
//!   (faer Cholesky), von Mises under F_x and F_y, recovery, error estimates, the adaptive loop,
//!   inertia-relief unit cases; it returns fields and opens no file;
//! - [`fatigue`]: FKM local fatigue strength and the Findley critical plane per surface node;
//! - [`stages`]: the spine of a design study, one function per stage from a loaded design and
//!   settings to a typed record (mass, dynamics, fem, cycle), writing nothing;
//! - [`study`]: running the stages over every design of a folder (cache, shards, merge, baseline);
//! - [`report`]: everything that writes: tables, ranking, Pareto front, index page, plots, VTU
//!   field files, stress pictures;
//! - [`deck`]: `rodstudy solve`: linear static analysis of a CalculiX/Abaqus input deck (the
//!   subset a tet model needs), for the field's benchmarks (NAFEMS LE10) and users' models;
//! - [`mesher`]: the gmsh adapter (the Python mesher as a subprocess, the hand-off files), behind
//!   the small trait the adaptive loop calls;
//! - [`config`]: the study's settings (`rodstudy.toml`);
//! - [`python_env`]: the project-local Python environment the `pipeline/` scripts run in;
//! - [`bench`]: benchmarks, reported as ratios against a reference run;
//! - [`cli`]: the command-line interface the binary is a thin front over.

pub mod bench;
pub mod cli;
pub mod config;
pub mod deck;
pub mod fatigue;
pub mod fem;
pub mod free_run;
pub mod geometry;
pub mod integrators;
pub mod linalg;
pub mod mechanism;
pub mod mesher;
pub mod python_env;
pub mod report;
pub mod rod;
pub mod stages;
pub mod study;
