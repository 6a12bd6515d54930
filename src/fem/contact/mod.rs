//! Frictionless unilateral contact between a linear-elastic tet10 body and rigid cylinders
//! (pins in bores), small displacements. The kernel knows bodies, walls and cylinders only.
//!
//! Each cylinder (axis, radius ρ) presses on a given set of the body's boundary faces; it is
//! either fixed (it holds the body) or carries a given force (its translation is unknown). The
//! gap g = r₀ − ρ + e_r·(u − w) ([`cylinder`]) and the pressure p live at the faces' nodes with
//! the mortar weights of a piecewise-linear pressure on the four sub-triangles of each 6-node
//! face ([`weights`]); the conditions λ_b ≥ 0, G_b ≥ 0, λ_b G_b = 0 hold node by node on the
//! weighted gaps. The rigid motions of a floating body are held by a statically determinate
//! support ([`modes`]) whose reaction is reported and must vanish where contact cannot carry
//! load ([`check`]). K is factorised once per body, supports and pins ([`system`], reused for
//! other loads); the contact is condensed on the wall nodes and solved by the primal–dual
//! active-set method ([`lcp`], [`solve`]). Every solution is checked before
//! it is returned: equilibrium, the pin forces' resultants, complementarity, penetration, no
//! tensile pressure ([`check`]). Pressure, gap, arc, peak and the bore's ovality: [`measures`].
//!
//! A pin may be elastic instead of rigid: its own compliance, from a mesh extruded from the wall,
//! adds to the body's ([`elastic_pin`]).
//!
//! See `docs/contact.md` for the formulation, the verification and the cost.

pub mod acceptance;
pub mod check;
pub mod compliance;
pub mod cylinder;
pub mod elastic_pin;
pub mod factorised;
pub mod lcp;
pub mod measures;
pub mod modes;
pub mod node_to_surface;
pub mod problem;
pub mod solve;
pub mod system;
pub mod weights;

pub use acceptance::ContactCheck;
pub use check::check;
pub use cylinder::{Cylinder, PinElasticity, PinHold, PinMotion};
pub use measures::{DiameterChange, diameter_change};
pub use problem::{
    ContactProblem, ContactSolution, ContactTimings, ContactTolerances, CylinderContact, Restraint,
};
pub use solve::solve_contact;
pub use system::ContactSystem;
