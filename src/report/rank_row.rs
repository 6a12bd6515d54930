//! One design's row of the ranking ([`RankRow`]): its records, its rank and its verdict
//! ([`Status`]), what [`super::ranking`] orders and [`super::columns`] renders.

use crate::geometry::design::DesignMass;
use crate::stages::records::{DesignCycle, DesignDynamics, DesignFem};

/// The verdict of one row.
#[derive(Clone, Debug, PartialEq)]
pub enum Status {
    /// Meets the stress criterion.
    Pass,
    /// Does not.
    Fail,
    /// Stage 3 was left out of the study on purpose.
    NotJudged,
    /// A stage failed; the earlier stages' figures are kept.
    StageFailed { stage: String, error: String },
}

impl Status {
    /// The short word of the status column.
    pub fn word(&self) -> String {
        match self {
            Status::Pass => "pass".into(),
            Status::Fail => "fail".into(),
            Status::NotJudged => "not judged (FEM skipped)".into(),
            Status::StageFailed { stage, .. } => format!("not judged ({stage} failed)"),
        }
    }
    /// A CSS class for the html rendering.
    pub fn class(&self) -> &'static str {
        match self {
            Status::Pass => "pass",
            Status::Fail => "fail",
            Status::NotJudged => "unjudged",
            Status::StageFailed { .. } => "failed",
        }
    }
}

/// One design in the ranking, whatever stages it passed.
#[derive(Clone, Debug)]
pub struct RankRow<'a> {
    /// 1-based; `None` for a design that could not be judged because a stage failed.
    pub rank: Option<usize>,
    pub mass: &'a DesignMass,
    pub dynamics: Option<&'a DesignDynamics>,
    pub fem: Option<&'a DesignFem>,
    pub cycle: Option<&'a DesignCycle>,
    pub status: Status,
    /// On the Pareto front (mass, force, safety factor); see [`super::pareto`].
    pub pareto: bool,
    /// The smallest accepted buckling load factor (`[criterion] buckling_factor`), judged where
    /// the design has one.
    pub buckling_required: f64,
}

impl RankRow<'_> {
    /// The peak crank–rod pin force, N.
    pub fn peak_force_n(&self) -> Option<f64> {
        self.dynamics.map(|d| d.peak_pin_force_n)
    }
    /// Where the linear model is out of its depth (beyond yield, large displacement): the short
    /// names, `; `-joined.
    pub fn model_validity(&self) -> String {
        self.fem
            .map(|f| {
                f.criterion
                    .model_validity
                    .iter()
                    .map(|m| m.split(':').next().unwrap_or_default())
                    .collect::<Vec<_>>()
                    .join("; ")
            })
            .unwrap_or_default()
    }
    /// Why a design fails: `static`, `fatigue`, `buckling` or several, `and`-joined (empty when it
    /// passes or is not judged).
    pub fn failing_on(&self) -> String {
        let Some(f) = self.fem else {
            return String::new();
        };
        let c = &f.criterion;
        let fatigue = c
            .fatigue_safety_factor
            .zip(c.fatigue_required)
            .is_some_and(|(n, r)| n < r);
        let buckling = f
            .buckling_load_factor
            .is_some_and(|l| l < self.buckling_required);
        [
            (c.static_pass, "static"),
            (!fatigue, "fatigue"),
            (!buckling, "buckling"),
        ]
        .into_iter()
        .filter(|(ok, _)| !ok)
        .map(|(_, name)| name)
        .collect::<Vec<_>>()
        .join(" and ")
    }
}

/// A rod body drawn without its cap (a partial pin bore): its mass, peak force and stresses lack
/// the cap's, so it is ranked after the complete rods and its status says so.
pub fn is_rod_body_alone(m: &DesignMass) -> bool {
    m.pins.crank_bore_arc_deg < 360.0 || m.pins.piston_bore_arc_deg < 360.0
}

/// What the status of a rod body without its cap adds.
pub const ROD_BODY_ALONE: &str =
    "rod body alone, without its cap: mass, force and stresses lack the cap's";
