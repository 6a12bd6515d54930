//! Stage 3 of rodstudy: static linear-elastic FEM of a rod with 10-node tetrahedra (SPEC "Stage 3 —
//! FEM", thesis §5.3, which used NX Nastran CTETRA(10) at 5 mm).
//!
//! Pipeline: STL → `pipeline/mesh_rod.py` (gmsh, straight-sided tetra10) → [`TetMesh`] (metres) →
//! boundary faces → bores found on the geometry ([`bores`]) → consistent nodal forces of a uniform
//! bore traction ([`load`]) → parallel assembly ([`assembly`]) → sparse Cholesky (faer, [`solver`],
//! in a nested-dissection order, [`ordering`]), both load cases (F_x, F_y) from one factorisation → stresses at the element nodes, unaveraged and
//! nodally averaged ([`stress`]) → figures ([`rod::FemResult`]) and fields ([`rod::RodSolution`]);
//! the meshes come from [`crate::mesher`], the ParaView files and pictures are written by
//! [`crate::report`]: nothing here opens a file.
//!
//! Cost: the sparse Cholesky factorisation dominates (about half the analysis of a rod; design 1 at
//! 4 mm, 169 kDOF: factor 88 M entries, 2.3 s); the symbolic analysis ([`solver::SymbolicFactor`]) is kept and
//! can be reused for any matrix with the same pattern (same mesh and supports, e.g. another
//! material); load cases share one numeric factorisation. Results are linear in the force.
//!
//! Conventions: SI inside (m, N, Pa); millimetres only at the edges (mesh files, reports). Tetra10
//! node order: VTK's (see [`shape`]). Stress/strain components `[xx, yy, zz, xy, yz, zx]`.
//!
//! References: O. C. Zienkiewicz, R. L. Taylor, J. Z. Zhu, *The Finite Element Method: Its Basis and
//! Fundamentals*, 7th ed. (tetra10 shape functions, consistent loads, patch test); T. J. R. Hughes,
//! *The Finite Element Method* (isoparametric elements, stiffness, quadrature); P. Keast, *Moderate
//! degree tetrahedral quadrature formulas*, CMAME 55 (1986); D. A. Dunavant, IJNME 21 (1985).

pub mod adapt;
pub mod assembly;
pub mod body_force;
pub mod bores;
pub mod boundary;
pub mod buckling;
pub mod contact;
pub mod cycle;
pub mod element;
pub mod error;
pub mod estimate;
pub mod facets;
pub mod fatigue;
pub mod geometric_stiffness;
pub mod load;
pub mod material;
pub mod mesh;
pub mod nodal_stress;
pub mod ordering;
pub mod quadrature;
pub mod recovery;
pub mod refinement;
pub mod rod;
pub mod rod_buckling;
pub mod segment_grid;
pub mod shape;
pub mod small_fillets;
pub mod smooth;
pub mod solver;
pub mod statics;
pub mod stress;

pub use bores::{BoreRole, BoreSpec, BoreSurface};
pub use element::QuadratureChoice;
pub use error::{FemError, Result};
pub use material::Material;
pub use mesh::TetMesh;
pub use rod::{FemResult, LoadCaseResult, RodOptions, solve_rod};
pub use statics::{StaticProblem, StaticSolution, solve_static};
