//! The stress criterion of a design (SPEC "Outputs": yield with a safety factor, judged on the
//! convergent measure, optionally plus its estimated error), where the linear small-displacement
//! model is out of its depth, and the fatigue factor of the cycle and the buckling load factor
//! (when computed) added to the verdict.

use super::records::{DesignCycle, StressVerdict};
use crate::config::StudyConfig;
use crate::rod::FemResult;

/// Adds the cycle's fatigue safety factor to the verdict when the configuration judges fatigue:
/// the design passes when it passed so far (statically, and on buckling when judged) and its
/// local (FKM) fatigue factor is at least `criterion.fatigue_safety_factor`. The local factor is
/// the component's: the notch's support, the surface and the mean stress at every surface node;
/// the Goodman factor, a von Mises cycle against one specimen endurance limit, is judged only
/// where no local factor was formed (a record from before it existed).
pub fn judge_fatigue(verdict: &mut StressVerdict, cycle: &DesignCycle, config: &StudyConfig) {
    if !config.criterion.fatigue {
        return;
    }
    let required = config.criterion.fatigue_safety_factor;
    let judged = cycle
        .local_fatigue_safety_factor
        .unwrap_or(cycle.fatigue_safety_factor);
    verdict.fatigue_safety_factor = Some(judged);
    verdict.fatigue_required = Some(required);
    verdict.pass = verdict.pass && judged >= required;
}

/// Adds the linear buckling load factor λ₁ to the verdict: the design passes when it passed so
/// far and λ₁ ≥ `criterion.buckling_factor` (default 3).
pub fn judge_buckling(verdict: &mut StressVerdict, load_factor: f64, config: &StudyConfig) {
    verdict.pass = verdict.pass && load_factor >= config.criterion.buckling_factor;
}

/// Displacements above this fraction of the centre distance are beyond small-displacement
/// theory (1 %: the rotation of the shank then changes the load path by more than the target
/// accuracy of the stress, 3 %, for a lever of about a third of the rod).
pub const LARGE_DISPLACEMENT_FRACTION: f64 = 0.01;

/// Judges the stress criterion on the convergent measure (plus its estimated error when the
/// configuration asks for it), and says where the linear, small-displacement model is out of its
/// depth: a peak above yield, a displacement above [`LARGE_DISPLACEMENT_FRACTION`] of the centre
/// distance `centre_distance_mm`.
pub fn verdict(fem: &FemResult, config: &StudyConfig, centre_distance_mm: f64) -> StressVerdict {
    let allowed = config.criterion.yield_mpa / config.criterion.safety_factor;
    let with_error = config.criterion.with_error;
    let judged = |c: &crate::rod::LoadCaseResult| {
        c.max_von_mises_away_from_fixed_mpa
            * if with_error {
                1.0 + c.estimated_error_rel
            } else {
                1.0
            }
    };
    let governing_case = fem.cases.governing_by(judged);
    let (governing, case, err) = (
        judged(governing_case),
        governing_case.name.as_str(),
        governing_case.estimated_error_rel,
    );
    let peak = fem.cases.max_of(|c| c.max_von_mises_away_from_fixed_mpa);
    let displacement = fem.cases.max_of(|c| c.max_displacement_mm);
    let mut model_validity = Vec::new();
    if peak > config.criterion.yield_mpa {
        model_validity.push(format!(
            "beyond yield: the peak, {peak:.0} MPa, exceeds the yield stress ({:.0} MPa); a linear-elastic model does not describe this load (the part would yield first)",
            config.criterion.yield_mpa
        ));
    }
    if displacement > LARGE_DISPLACEMENT_FRACTION * centre_distance_mm {
        model_validity.push(format!(
            "large displacement: {displacement:.2} mm is {:.2} % of the centre distance (above {:.0} %), beyond small-displacement theory",
            100.0 * displacement / centre_distance_mm,
            100.0 * LARGE_DISPLACEMENT_FRACTION
        ));
    }
    StressVerdict {
        model_validity,
        allowed_mpa: allowed,
        governing_mpa: governing,
        governing_case: case.into(),
        governing_error_rel: err,
        with_error,
        raw_peak_mpa: fem.cases.max_of(|c| c.max_von_mises_unaveraged_mpa),
        safety_factor: config.criterion.yield_mpa / governing,
        pass: governing <= allowed,
        static_pass: governing <= allowed,
        fatigue_safety_factor: None,
        fatigue_required: None,
    }
}
