//! Local fatigue strength of a component after the FKM guideline's local-stress procedure, and a
//! critical-plane check, at the surface nodes of a tet10 model.
//!
//! FKM guideline "Analytical Strength Assessment of Components in Mechanical Engineering"
//! (Forschungskuratorium Maschinenbau, 6th ed. 2012; 7th ed. 2020), chapter 4 (local stresses).
//! The chain at one surface point, one concept per file:
//!
//! - [`material`]: the material group and its constants, R_m, R_p, σ_W,zd = f_W,σ · R_m;
//! - [`gradient`]: the related stress gradient χ* from the FEM field (sampled along the inward
//!   normal, fitted by a quadratic);
//! - [`factors`]: support factor n(χ*), roughness K_R, size K_d,m, surface treatment K_V, the
//!   design factor K_WK and the component fatigue limit σ_WK;
//! - [`haigh`]: mean-stress sensitivity M_σ, the component's Haigh diagram, K_AK under the
//!   overload case (F2, constant stress ratio, by default), the diagram's data;
//! - [`assessment`]: a node's history → amplitude and mean of the surface components → degrees of
//!   utilisation, their combination, the safety factor j_D / a_BK;
//! - [`findley`]: the Findley critical plane of a stress-tensor history;
//! - [`tensor`]: small tensor helpers.
//!
//! Units: SI inside (Pa, m, 1/m for χ*); FKM's formulas in MPa and mm are converted where they are
//! evaluated. Stress components `[xx, yy, zz, xy, yz, zx]` as in [`crate::fem`]. Nothing here
//! opens a file or knows a rod: the cycle calls [`assessment::assess_node`] per surface node with
//! that node's stress history and depth-gradient history (from [`gradient::depth_gradients`] of the
//! unit load cases, combined like the stresses).

pub mod assessment;
pub mod factors;
pub mod findley;
pub mod gradient;
pub mod haigh;
pub mod material;
pub mod tensor;

pub use assessment::{
    ComponentAssessment, LocalAssessment, LocalSettings, NodeHistory, SafetyFactors, assess_node,
};
pub use factors::{LocalStrength, SizeEffect, SurfaceFactors, SurfaceTreatment, local_strength};
pub use findley::{FindleyResult, FindleySettings, findley};
pub use gradient::{
    DepthGradient, GradientOptions, PointGradients, SampleDepth, SurfacePoint, depth_gradients,
    surface_points,
};
pub use haigh::{HaighDiagram, HaighLine, OverloadCase, haigh_diagram};
pub use material::{FatigueMaterial, MaterialGroup};
