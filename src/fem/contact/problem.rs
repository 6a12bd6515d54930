//! What a contact solve takes and what it gives back.

pub use super::acceptance::{ContactCheck, ContactTolerances};
use super::cylinder::Cylinder;
use crate::fem::element::QuadratureChoice;
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;

/// A linear-elastic body on rigid cylinders, with optional prescribed DOFs and nodal loads.
#[derive(Clone, Debug)]
pub struct ContactProblem<'a> {
    /// The body's mesh (m).
    pub mesh: &'a TetMesh,
    /// Its material.
    pub material: Material,
    /// Element quadrature.
    pub quadrature: QuadratureChoice,
    /// Prescribed displacements (DOF = 3 · node + component, m), e.g. a symmetry plane; may be
    /// empty (a body held by its pins only).
    pub prescribed: Vec<(usize, f64)>,
    /// Nodal loads besides the pins (3 per node, N), e.g. inertia; empty for none.
    pub loads: Vec<f64>,
    /// The pins.
    pub cylinders: Vec<Cylinder>,
    /// Acceptance limits of the solution.
    pub tolerances: ContactTolerances,
}

/// The contact on one cylinder.
#[derive(Clone, Debug)]
pub struct CylinderContact {
    /// Wall nodes (global indices).
    pub nodes: Vec<usize>,
    /// Contact pressure at each wall node, Pa (the nodal values of the pressure field).
    pub pressure_pa: Vec<f64>,
    /// The pressure smoothed over the faces: at each wall node the area-weighted mean, over the
    /// faces around it, of each face's mean pressure ∫p dA / A, Pa. The nodal values of a
    /// piecewise-linear multiplier alternate slightly between corner and midside nodes (±1 %
    /// on a uniform pressure with 0.4 mm elements on a 10 mm bore); the face means do not.
    pub smoothed_pressure_pa: Vec<f64>,
    /// Gap at each wall node, m (negative: penetration).
    pub gap_m: Vec<f64>,
    /// Angle of each wall node about the axis from the contact resultant's direction, degrees
    /// in (−180, 180].
    pub angle_deg: Vec<f64>,
    /// The pin's translation, m (zero for a fixed pin).
    pub pin_displacement_m: [f64; 3],
    /// An elastic pin's surface displacement towards its axis at each wall node, m (empty for a
    /// rigid pin); `gap_m` includes it.
    pub pin_deflection_m: Vec<f64>,
    /// Resultant of the contact forces on the body, N.
    pub resultant_n: [f64; 3],
    /// Largest smoothed contact pressure, Pa.
    pub peak_pressure_pa: f64,
    /// Largest nodal contact pressure (the multiplier's nodal value), Pa.
    pub peak_nodal_pressure_pa: f64,
    /// Angle of the peak from the resultant's direction, degrees.
    pub peak_angle_deg: f64,
    /// The active zone's angular extent, degrees (360 for contact all round).
    pub arc_deg: f64,
    /// Its ends from the resultant's direction, degrees (negative side, positive side).
    pub arc_ends_deg: [f64; 2],
    /// Largest penetration (max −gap over the wall nodes, 0 if none), m.
    pub penetration_max_m: f64,
    /// Largest tensile contact pressure (max −pressure, 0 if none), Pa.
    pub max_tensile_pressure_pa: f64,
}

/// The reaction of the support that holds the motions contact leaves free.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Restraint {
    /// The DOFs of the support (one per motion held; none when the prescribed DOFs hold the
    /// body).
    pub dofs: Vec<usize>,
    /// The motions that no pin holds (held by this support alone): the rotation about a lone
    /// fixed pin with the force-driven pins following it, the sliding along the pins.
    pub free_motions: usize,
    /// Force, N.
    pub force_n: [f64; 3],
    /// Moment about `point_m`, N·m.
    pub moment_nm: [f64; 3],
    /// Where the moment is taken (the body's bounding-box centre), m.
    pub point_m: [f64; 3],
    /// max(|force| / load scale, |moment| / (load scale × body size)).
    pub reaction_rel: f64,
}

/// Wall-clock times, seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactTimings {
    /// Assembly of K.
    pub assembly_s: f64,
    /// Ordering, symbolic and numeric Cholesky.
    pub factorisation_s: f64,
    /// Columns of the contact compliance ([`super::compliance`]).
    pub columns_s: f64,
    /// Active-set iterations (dense).
    pub active_set_s: f64,
    /// Everything else (the final solve, outputs, checks).
    pub rest_s: f64,
}

/// The solution of a [`ContactProblem`].
#[derive(Clone, Debug)]
pub struct ContactSolution {
    /// Displacements, 3 per node (m): for [`crate::fem::stress::stress_field`].
    pub displacements: Vec<f64>,
    /// The contact forces of each cylinder on the body, 3 per node (N; zero off its wall), in
    /// the problem's order: the consistent nodal forces of its pressures.
    pub contact_forces: Vec<Vec<f64>>,
    /// Reactions K u − f − f_c at the prescribed DOFs and the free-motion support's DOFs, 3 per
    /// node (N; zero elsewhere), as [`crate::fem::statics::StaticSolution::reactions`].
    pub reactions: Vec<f64>,
    /// Per cylinder, in the problem's order.
    pub cylinders: Vec<CylinderContact>,
    /// The support of the free motions.
    pub restraint: Restraint,
    /// What was checked, with the numbers.
    pub check: ContactCheck,
    /// Active-set iterations.
    pub iterations: usize,
    /// Contact rows (pressure nodes) and the columns of their compliance computed.
    pub rows: usize,
    /// Columns computed.
    pub columns: usize,
    /// Equations of K.
    pub equations: usize,
    /// Times.
    pub timings: ContactTimings,
}
