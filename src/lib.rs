//! rodstudy: connecting-rod design studies.
//!
//! The modules follow the pipeline of the study (see `SPEC.md` and the thesis in `shared/seed`):
//!
//! - [`geometry`]: stage 1, reading STL, validating the solid, exact mass properties and the
//!   mapping into the mechanism frame;
//! - [`mechanism`]: stage 2, the planar crank–slider: closed-form Newton–Euler and a planar
//!   multibody core (thesis §3.2), the driven scene and its peak pin force;
//! - [`study`]: running the stages over every design of a folder;
//! - [`python_env`]: the project-local Python environment the `pipeline/` scripts run in;
//! - [`bench`]: benchmarks, reported as ratios against a reference run;
//! - [`cli`]: the command-line interface the binary is a thin front over.

pub mod bench;
pub mod cli;
pub mod geometry;
pub mod mechanism;
pub mod python_env;
pub mod study;
