//! The rod problem of stage 3 (SPEC "Stage 3 — FEM", thesis §5.3) on the tet10 kernel of
//! [`crate::fem`]: the pin bores found on the mesh ([`bores`]), the pin loads of the load cases
//! ([`solve`]), the judged region away from the fixed bore and sharp edges, the half model of a
//! mirror-symmetric rod, the geometry check on a smooth surface through an STL's vertices
//! ([`smooth`]), what the facets say ([`facets`], [`small_fillets`], [`segment_grid`]), the adaptive
//! loop ([`adapt`]) and the refinement study ([`refinement`]), the rod's buckling ([`buckling`]),
//! stress over the engine cycle ([`cycle`]) and its fatigue ([`fatigue`]).
//!
//! Nothing here opens a file: meshes come from [`crate::mesher`], files are written by
//! [`crate::report`].

pub mod adapt;
pub mod bores;
pub mod buckling;
pub mod cycle;
pub mod facets;
pub mod fatigue;
pub mod pin_load;
pub mod refinement;
pub mod segment_grid;
pub mod small_fillets;
pub mod smooth;
pub mod solve;

pub use bores::{BoreRole, BoreSpec, BoreSurface};
pub use solve::{FemResult, LoadCaseResult, RodOptions, solve_rod};
