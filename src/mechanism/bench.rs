//! Timing of the `driven` scene by both methods (for `rodstudy bench
//! dynamics`): median wall time of several full scenes, per scene and per
//! step, their ratio, and the agreement of the two methods — speed next to
//! error, as the spec asks.

use std::hint::black_box;
use std::time::Instant;

use serde::Serialize;

use super::crank_slider::{CrankSlider, MechanismParams, RodInertia};
use super::error::{DynamicsError, Result};
use super::peak::refine_peak;
use super::scene::{DrivenScene, Method, compare_results, driven_scene};

/// Timing report of [`bench_driven`] (seconds).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DynamicsBench {
    /// Repeats per method (median taken).
    pub repeats: usize,
    /// Steps (intervals) of the scene.
    pub steps: usize,
    /// Samples per scene.
    pub samples: usize,
    /// Median wall time of one full scene, closed form (s), including the
    /// peak refinement and the output vectors.
    pub closed_form_scene_s: f64,
    /// Median wall time of one full scene, multibody (s).
    pub multibody_scene_s: f64,
    /// Closed form per sample (s).
    pub closed_form_per_step_s: f64,
    /// Multibody per sample (s).
    pub multibody_per_step_s: f64,
    /// multibody / closed form.
    pub ratio_multibody_over_closed_form: f64,
    /// Median wall time of the refined peak alone (closed form, one
    /// revolution) — what a design study needs per design (s).
    pub peak_only_s: f64,
    /// Max pointwise relative difference of F_A, multibody vs closed form.
    pub max_rel_diff: f64,
    /// Refined peak (N).
    pub peak_pin_force_n: f64,
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Time the full `driven` scene `repeats` times with each method.
pub fn bench_driven(
    params: &MechanismParams,
    rod: &RodInertia,
    scene: &DrivenScene,
    repeats: usize,
) -> Result<DynamicsBench> {
    if repeats == 0 {
        return Err(DynamicsError::InvalidScene(
            "bench needs at least one repeat".into(),
        ));
    }
    // warm-up runs, also used for the agreement figure
    let reference = driven_scene(params, rod, scene, Method::ClosedForm)?;
    let test = driven_scene(params, rod, scene, Method::Multibody)?;
    let agreement = compare_results(&test, &reference)?;
    let time = |method: Method| -> Result<f64> {
        let mut v = Vec::with_capacity(repeats);
        for _ in 0..repeats {
            let start = Instant::now();
            let r = driven_scene(black_box(params), black_box(rod), black_box(scene), method)?;
            v.push(start.elapsed().as_secs_f64());
            black_box(r);
        }
        Ok(median(&mut v))
    };
    let cf = time(Method::ClosedForm)?;
    let mb = time(Method::Multibody)?;
    let model = CrankSlider::new(params, rod)?;
    let mut v = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        let start = Instant::now();
        let p = refine_peak(
            black_box(&model),
            scene.phi0_rad,
            scene.omega_rad_s,
            scene.duration_s,
        )?;
        v.push(start.elapsed().as_secs_f64());
        black_box(p);
    }
    let peak_only = median(&mut v);
    let n = scene.samples() as f64;
    Ok(DynamicsBench {
        repeats,
        steps: scene.steps,
        samples: scene.samples(),
        closed_form_scene_s: cf,
        multibody_scene_s: mb,
        closed_form_per_step_s: cf / n,
        multibody_per_step_s: mb / n,
        ratio_multibody_over_closed_form: mb / cf,
        peak_only_s: peak_only,
        max_rel_diff: agreement.max_rel_diff,
        peak_pin_force_n: reference.peak_pin_force_n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 2.0, 3.0]), 2.5);
    }
}
