//! Stage 1: mass properties of a rod from its STL (SPEC "Stage 1").
//!
//! The pipeline of this stage, one file per step:
//! - [`stl_file`]: bytes → triangle soup (binary or ASCII, refusing what is not an STL);
//! - [`weld`]: soup → indexed mesh, equal vertices merged by value;
//! - [`gaps`]: the holes of an open surface measured (a crack of rounding or a missing face);
//! - [`self_crossing`]: facets that cross or overlap (a surface intersecting itself);
//! - [`validate`]: closed, manifold, consistently outward (several bodies: one bonded body, with a
//!   warning), or a precise error;
//! - [`mass_properties`]: exact polyhedral integration (volume, centroid, inertia, principal axes);
//! - [`sidecar`]: the optional `NAME.toml` beside a design (units, density, pins, name);
//! - [`mechanism_frame`]: the rod's properties in the crank–slider frame (l1, offset, I_zz, I_xx);
//! - [`bore_finder`]: the pin bores found from the surface (cylinder fits), when no sidecar gives them;
//! - [`bore_check`]: ray casts proving each pin centre sits in a bore;
//! - `pin_bores`: the bore check of each pin, and a sidecar's pins against the bores there;
//! - [`design`]: the whole stage for one design file, and its report record;
//! - [`primitives`]: closed meshes with known properties, for tests and benchmarks;
//! - [`error`]: the defects a file can have.

pub mod bore_check;
pub mod bore_finder;
pub mod design;
pub mod error;
pub mod gaps;
pub mod half_solid;
pub mod mass_properties;
pub mod mechanism_frame;
pub mod mirror_symmetry;
mod pin_bores;
pub mod primitives;
pub mod self_crossing;
pub mod sidecar;
pub mod simplify;
pub mod step;
pub mod stl_file;
pub mod validate;
pub mod weld;

pub use design::{DesignMass, load_design, mass_of_design};
pub use error::MeshError;
pub use mass_properties::MassProperties;
pub use weld::IndexedMesh;
