//! The gmsh adapter: how a tet10 mesh is made from a rod surface, apart from the FEM mathematics.
//!
//! `pipeline/mesh_rod.py` (gmsh + meshio, in the project's Python environment) runs as a
//! subprocess under a time limit ([`gmsh`]); meshes come back through the `.rodmesh` hand-off file
//! ([`rodmesh`]); adaptive refinement hands gmsh a size map as a binary file ([`size_field`]).
//! Every meshing decision (classification ladder, fallbacks, quality limits, gmsh options, time
//! limit) is [`policy::MeshPolicy`], handed to the script with each call.
//! [`rod_mesher::GmshRodMesher`] puts these together behind [`crate::rod::adapt::Mesher`], the
//! small trait the adaptive loop calls (its meshes made in one gmsh session,
//! [`gmsh_session`], where that works), so that the loop itself can be driven by an in-memory
//! mesher in tests.
//!
//! A user's ready volume mesh is read by [`volume::read_volume_mesh`]: gmsh MSH 4.1 ([`msh`], via
//! the `mshio` crate) and Abaqus/CalculiX `.inp` ([`inp`]) natively, other formats through meshio.

pub mod gmsh;
pub mod gmsh_session;
pub mod inp;
pub mod msh;
pub mod policy;
pub mod raw_volume;
pub mod rod_mesher;
pub mod rodmesh;
pub mod size_field;
pub mod volume;

pub use gmsh::{
    MeshReport, MeshRequest, MeshedRod, StepInRodFrame, convert_mesh, mesh_step_with, mesh_stl,
    mesh_stl_with,
};
pub use policy::MeshPolicy;
pub use rod_mesher::GmshRodMesher;
pub use rodmesh::{read_rodmesh, write_rodmesh};
pub use volume::{
    MESH_READER_VAR, VolumeReader, read_volume_mesh, read_volume_mesh_meshio,
    read_volume_mesh_native, volume_reader,
};

/// The mesher script in `pipeline/`.
pub const MESHER_SCRIPT: &str = "mesh_rod.py";
