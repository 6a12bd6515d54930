//! The static load cases of the rod problem (SPEC "Stage 3 — FEM", thesis §5.3), as data: in every
//! case bore B is fixed (all DOFs of its nodes) and the pin force acts on bore A, spread as
//! `[fem] bore_load` says ([`super::pin_load`]); the peak is judged away from the fixed bore and the
//! sharp edges ([`super::judged`]). A case is its name, its label, the direction of its pin force
//! in the rod frame and which force it carries:
//!
//! | name | label | direction | force |
//! |---|---|---|---|
//! | `fx` | F_x | along A→B, perpendicular to the pin axis (e_x) | the pin force |
//! | `fy` | F_y | e_y = pin axis × e_x, in the plane of motion | the transverse force |
//!
//! The name keys the case's record in `results.json` (`"fx": {…}`) and prefixes its CSV fields
//! (`fx_von_mises_away_from_fixed_mpa`); the label names it in the reports. All cases share one
//! factorisation of K. Adding a case is an entry in [`STATIC_CASES`] (and a [`CaseDirection`] or
//! [`CaseForce`] if it needs a new one): the solve, the adaptive loop, the criterion, the ranking,
//! the CSV and the field files follow the list.

/// Which way a case's pin force points, in the rod frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CaseDirection {
    /// e_x: along A→B, perpendicular to the pin axis (a push on A towards B compresses the rod).
    AlongRod,
    /// e_y = pin axis × e_x: across the rod, in the plane of motion.
    AcrossRod,
}

/// Which force a case carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CaseForce {
    /// The pin force of the study (the peak crank–rod pin force, or the engine's).
    PinForce,
    /// The largest force across the rod ([`super::solve::RodOptions::fy_force_n`]; the pin force
    /// where it is not given, the thesis' setting).
    TransverseForce,
}

/// One static load case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoadCase {
    /// The key of the case's record and the prefix of its CSV fields.
    pub name: &'static str,
    /// How the reports name it.
    pub label: &'static str,
    /// The direction of its pin force.
    pub direction: CaseDirection,
    /// Its force.
    pub force: CaseForce,
}

/// The static load cases, in the order they are solved and written.
pub const STATIC_CASES: &[LoadCase] = &[
    LoadCase {
        name: "fx",
        label: "F_x",
        direction: CaseDirection::AlongRod,
        force: CaseForce::PinForce,
    },
    LoadCase {
        name: "fy",
        label: "F_y",
        direction: CaseDirection::AcrossRod,
        force: CaseForce::TransverseForce,
    },
];

/// The case named `name`.
pub fn case(name: &str) -> Option<&'static LoadCase> {
    STATIC_CASES.iter().find(|c| c.name == name)
}

/// How the reports name the case `name` (the name itself for a case not in the list).
pub fn label(name: &str) -> &str {
    case(name).map_or(name, |c| c.label)
}

impl LoadCase {
    /// The unit direction of the pin force: `ex` (along A→B, perpendicular to `axis`) or
    /// `axis × ex`.
    pub fn unit_direction(&self, axis: [f64; 3], ex: [f64; 3]) -> [f64; 3] {
        match self.direction {
            CaseDirection::AlongRod => ex,
            CaseDirection::AcrossRod => crate::fem::boundary::cross(axis, ex),
        }
    }

    /// The magnitude of the pin force, N: `pin_force_n`, or `transverse_force_n` where given.
    pub fn force_n(&self, pin_force_n: f64, transverse_force_n: Option<f64>) -> f64 {
        match self.force {
            CaseForce::PinForce => pin_force_n,
            CaseForce::TransverseForce => transverse_force_n.unwrap_or(pin_force_n),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cases are named once each; e_y = axis × e_x is a right-handed frame with the axis.
    #[test]
    fn the_cases_are_distinct_and_their_directions_a_right_handed_frame() {
        for (i, a) in STATIC_CASES.iter().enumerate() {
            assert!(STATIC_CASES[i + 1..].iter().all(|b| b.name != a.name));
            assert_eq!(case(a.name), Some(a));
        }
        let (axis, ex) = ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
        assert_eq!(
            case("fy").unwrap().unit_direction(axis, ex),
            [0.0, 1.0, 0.0]
        );
        assert_eq!(case("fx").unwrap().force_n(10.0, Some(3.0)), 10.0);
        assert_eq!(case("fy").unwrap().force_n(10.0, Some(3.0)), 3.0);
        assert_eq!(case("fy").unwrap().force_n(10.0, None), 10.0);
        assert_eq!(label("fy"), "F_y");
    }
}
