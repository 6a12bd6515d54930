//! The rod problem of stage 3 (SPEC "Stage 3 — FEM", thesis §5.3) on the tet10 kernel of
//! [`crate::fem`]: the pin bores found on the mesh ([`bores`]), the load cases as data ([`cases`])
//! and how a pin's force enters its bore ([`pin_load`]) through rigid or elastic pins ([`pin_model`]), their solve ([`solve`]) and records
//! ([`records`]), the judged region away from the fixed bore and sharp edges ([`judged`]), the half
//! model of a mirror-symmetric rod ([`half_model`]), the geometry check on a smooth surface through an STL's vertices
//! ([`smooth`]), what the facets say ([`facets`], [`small_fillets`], [`segment_grid`]), the adaptive
//! loop ([`adapt`]) and the refinement study ([`refinement`]), the rod's buckling ([`buckling`]),
//! stress over the engine cycle ([`cycle`]) and its fatigue ([`fatigue`]).
//!
//! Nothing here opens a file: meshes come from [`crate::mesher`], files are written by
//! [`crate::report`].

pub mod adapt;
pub mod bores;
pub mod buckling;
pub mod cases;
pub mod contact_cases;
pub mod contact_load;
pub mod cycle;
pub mod facets;
pub mod fatigue;
pub mod half_model;
pub mod judged;
pub mod load_models;
pub mod pin_load;
pub mod pin_model;
pub mod records;
pub mod refinement;
pub mod segment_grid;
pub mod small_fillets;
pub mod smooth;
pub mod solve;

pub use bores::{BoreRole, BoreSpec, BoreSurface};
pub use records::{FemResult, LoadCaseResult, LoadCases};
pub use solve::{RodOptions, RodSolution, solve_rod};
