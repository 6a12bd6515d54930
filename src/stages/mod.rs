//! The stages of a design study, each a function from a loaded design (read and validated once,
//! [`mass::load`]) and settings to a typed record ([`records`]), writing no report file:
//!
//! 1. [`mass`]: mass properties from the geometry, the bore check, the mechanism frame;
//! 2. [`dynamics`]: the driven crank–slider, the peak crank–rod pin force;
//! 3. [`fem`]: tet10 FEM under F_x and F_y of the peak force, one fixed mesh, adaptive refinement
//!    or the user's mesh, and the stress [`criterion`];
//! 4. [`cycle`]: stress over one revolution with inertia relief, and the fatigue factor.
//!
//! The study ([`crate::study`]) and the CLI commands `mass`, `dynamics`, `fem` and `cycle` call
//! the same functions; [`crate::report`] writes what they return.

pub mod criterion;
pub mod cycle;
pub mod dynamics;
pub mod fem;
pub mod mass;
pub mod records;
pub mod rod_surface;
