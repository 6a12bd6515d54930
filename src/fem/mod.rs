//! The tet10 kernel: static linear elasticity with 10-node tetrahedra, knowing nothing of what the
//! body is (the rod problem on it is [`crate::rod`]).
//!
//! Pipeline: [`TetMesh`] (metres) → boundary faces ([`boundary`]) → consistent nodal forces of
//! surface tractions and body forces ([`load`], [`body_force`]) → parallel assembly ([`assembly`])
//! → sparse Cholesky (faer, [`solver`], in a nested-dissection order, [`ordering`]), several load
//! cases from one factorisation ([`statics`]) → stresses at the element nodes, unaveraged and
//! nodally averaged ([`stress`], [`nodal_stress`]) → superconvergent recovery ([`recovery`]) and
//! the error estimates ([`estimate`]); linear buckling on the geometric stiffness ([`buckling`],
//! [`geometric_stiffness`]). Nothing here opens a file.
//!
//! Cost: the sparse Cholesky factorisation dominates (about half the analysis of a rod; design 1 at
//! 4 mm, 169 kDOF: factor 88 M entries, 2.3 s); the symbolic analysis ([`solver::SymbolicFactor`])
//! is kept and can be reused for any matrix with the same pattern (same mesh and supports, e.g.
//! another material); load cases share one numeric factorisation. Results are linear in the force.
//!
//! Conventions: SI inside (m, N, Pa). Tetra10 node order: VTK's (see [`shape`]). Stress/strain
//! components `[xx, yy, zz, xy, yz, zx]`.
//!
//! References: O. C. Zienkiewicz, R. L. Taylor, J. Z. Zhu, *The Finite Element Method: Its Basis and
//! Fundamentals*, 7th ed. (tetra10 shape functions, consistent loads, patch test); T. J. R. Hughes,
//! *The Finite Element Method* (isoparametric elements, stiffness, quadrature); P. Keast, *Moderate
//! degree tetrahedral quadrature formulas*, CMAME 55 (1986); D. A. Dunavant, IJNME 21 (1985).

pub mod assembly;
pub mod body_force;
pub mod boundary;
pub mod buckling;
pub mod constraints;
pub mod contact;
pub mod element;
pub mod error;
pub mod estimate;
pub mod geometric_stiffness;
pub mod load;
pub mod material;
pub mod mesh;
pub mod nodal_stress;
pub mod ordering;
pub mod quadrature;
pub mod recovery;
pub mod reduced_system;
pub mod shape;
pub mod solid_element;
pub mod solver;
pub mod statics;
pub mod stress;
pub mod subspace;

pub use element::QuadratureChoice;
pub use error::{FemError, Result};
pub use material::Material;
pub use mesh::TetMesh;
pub use statics::{StaticProblem, StaticSolution, solve_static};
