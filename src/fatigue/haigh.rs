//! The mean stress: FKM's mean-stress sensitivity, its Haigh diagram of the component, the
//! mean-stress factor K_AK of an overload case, and the diagram's data for a report.
//!
//! **Mean-stress sensitivity** (FKM 6th ed. §4.4.2, eq. 4.4.2 with Table 4.6.1 / the group
//! constants of [`super::material`]): M_σ = a_M · 10⁻³ · R_m/MPa + b_M, M_τ = f_W,τ · M_σ.
//!
//! **The Haigh diagram of the component** (FKM §4.4.2, Fig. 4.4.1): in the (σ_m, σ_a) plane, with
//! W = σ_WK and M = M_σ, the amplitude the component bears is the polyline
//!
//! - region I   (R > 1, compressive mean beyond σ_max = 0):  σ_a = W/(1 − M), horizontal;
//! - region II  (−∞ ≤ R ≤ 0):  σ_a = W − M σ_m, from (−W/(1−M), W/(1−M)) through (0, W)
//!   to (W/(1+M), W/(1+M)), the pulsating point R = 0;
//! - region III (0 < R < 0.5): slope −M/3, to the point R = 0.5,
//!   (W(3+M)/(1+M)², W(3+M)/(3(1+M)²));
//! - region IV  (R ≥ 0.5):  σ_a = W(3+M)/(3(1+M)²), horizontal.
//!
//! **Overload case.** How the stress would grow in an overload decides which point of the line
//! is the limit: F1 keeps the mean (the limit straight above the point), F2 keeps the stress ratio
//! R = σ_min/σ_max (the limit on the ray from the origin through the point). A connecting rod's
//! stresses come from the inertia forces (∝ speed²) and the gas force (∝ cylinder pressure), and a
//! linear FE model scales the whole history with them: mean and amplitude grow together, the
//! stress ratio stays. F2 is therefore the case here, as FKM advises when in doubt (FKM §4.4.1;
//! also the FVA workbench documentation of the 2012 guideline). F1 is available for a fixed
//! preload. K_AK = σ_AK / σ_WK, where σ_AK is the amplitude of the limit point. FKM's closed forms
//! under F2 ([`mean_stress_factor_f2`]; FKM Table 4.4.1, McKelvey et al. 2012 eq. 45–48):
//!
//!   I: 1/(1 − M);  II: 1/(1 + M σ_m/σ_a);  III: (3 + M)/((1 + M)(3 + M σ_m/σ_a));
//!   IV: (3 + M)/(3(1 + M)²).
//!
//! The implementation intersects the load line with the polyline ([`HaighLine`]); the closed forms
//! check it. A shear stress has no sign in its mean: its diagram is the same with τ_WK, M_τ and
//! |τ_m| (FKM §4.4.2).

use serde::{Deserialize, Serialize};

use super::material::GroupConstants;

/// The mean-stress sensitivity M_σ = a_M · 10⁻³ · R_m/MPa + b_M of tensile strength `r_m_pa`.
pub fn mean_stress_sensitivity(r_m_pa: f64, c: &GroupConstants) -> f64 {
    c.a_m * 1e-3 * (r_m_pa / 1e6) + c.b_m
}

/// How the stresses grow in an overload (FKM §4.4.1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OverloadCase {
    /// F1: constant mean stress.
    ConstantMean,
    /// F2: constant stress ratio (the default; see the module documentation).
    #[default]
    ConstantRatio,
}

/// The component's Haigh line: fatigue limit `sigma_wk_pa` at σ_m = 0 and sensitivity `m`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HaighLine {
    /// σ_WK (or τ_WK), Pa.
    pub sigma_wk_pa: f64,
    /// M_σ (or M_τ).
    pub m: f64,
}

impl HaighLine {
    /// The four corner points (σ_m, σ_a) of the line, Pa: R = ∞, σ_m = 0, R = 0, R = 0.5.
    pub fn corners(&self) -> [[f64; 2]; 4] {
        let (w, m) = (self.sigma_wk_pa, self.m);
        let a1 = w / (1.0 - m);
        let a0 = w / (1.0 + m);
        let a5 = w * (3.0 + m) / (3.0 * (1.0 + m).powi(2));
        [[-a1, a1], [0.0, w], [a0, a0], [3.0 * a5, a5]]
    }

    /// The amplitude the component bears at mean stress `sm` (the polyline), Pa.
    pub fn amplitude_at(&self, sm: f64) -> f64 {
        let [p1, _, p3, p4] = self.corners();
        let (w, m) = (self.sigma_wk_pa, self.m);
        if sm <= p1[0] {
            p1[1]
        } else if sm <= p3[0] {
            w - m * sm
        } else if sm <= p4[0] {
            p3[1] - m / 3.0 * (sm - p3[0])
        } else {
            p4[1]
        }
    }

    /// The limit point (σ_m, σ_a) of the point (`sm`, `sa`) (σ_a > 0) under `case`, Pa.
    pub fn limit_point(&self, sa: f64, sm: f64, case: OverloadCase) -> [f64; 2] {
        match case {
            OverloadCase::ConstantMean => [sm, self.amplitude_at(sm)],
            OverloadCase::ConstantRatio => {
                // the ray λ (sm, sa), λ > 0, against the polyline: λ sa = amplitude_at(λ sm).
                // g(λ) = λ sa − amplitude_at(λ sm) starts at −σ_WK and, once it grows, keeps
                // growing (it can only fall in region II, where it is still negative, for
                // σ_m/σ_a < −1/M), so it has one root: bisect on it
                let g = |l: f64| l * sa - self.amplitude_at(l * sm);
                let (mut lo, mut hi) = (0.0, 1.0);
                while g(hi) < 0.0 {
                    hi *= 2.0;
                }
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if g(mid) < 0.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                    if hi - lo <= 1e-15 * hi {
                        break;
                    }
                }
                let l = 0.5 * (lo + hi);
                [l * sm, l * sa]
            }
        }
    }

    /// The mean-stress factor K_AK = σ_AK / σ_WK of amplitude `sa` > 0 and mean `sm`.
    pub fn mean_stress_factor(&self, sa: f64, sm: f64, case: OverloadCase) -> f64 {
        self.limit_point(sa, sm, case)[1] / self.sigma_wk_pa
    }
}

/// FKM's closed form of K_AK under F2 (constant stress ratio), regions I–IV by R = σ_min/σ_max.
pub fn mean_stress_factor_f2(m: f64, sa: f64, sm: f64) -> f64 {
    let ratio = sm / sa;
    if ratio < -1.0 {
        // region I: σ_max < 0, R > 1
        1.0 / (1.0 - m)
    } else if ratio <= 1.0 {
        // region II: R ≤ 0 (σ_min ≤ 0)
        1.0 / (1.0 + m * ratio)
    } else if ratio < 3.0 {
        // region III: 0 < R < 0.5 (σ_m/σ_a = (1 + R)/(1 − R) < 3)
        (3.0 + m) / ((1.0 + m) * (3.0 + m * ratio))
    } else {
        (3.0 + m) / (3.0 * (1.0 + m).powi(2))
    }
}

/// One stress component's point in the diagram and its limit point, Pa.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HaighPoint {
    /// What it is ("σ1", "σ2", ...).
    pub label: String,
    /// (σ_m, σ_a) of the cycle.
    pub point_pa: [f64; 2],
    /// (σ_m, σ_AK): where the load line meets the component's line.
    pub limit_pa: [f64; 2],
}

/// The data of a Haigh diagram: the component's line (open at both ends: the first and last
/// vertices sit at the ends of the plotted mean-stress range) and the points, Pa.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HaighDiagram {
    /// Vertices (σ_m, σ_a) of the line, left to right.
    pub line_pa: Vec<[f64; 2]>,
    /// The overload case the limit points follow.
    pub overload: OverloadCase,
    /// The node's points.
    pub points: Vec<HaighPoint>,
}

/// The Haigh diagram of `line` with the points (`label`, σ_a, σ_m) under `case`; the line spans
/// σ_m from −R_p to R_p (`yield_pa`) or wider if a point lies beyond.
pub fn haigh_diagram(
    line: &HaighLine,
    points: &[(&str, f64, f64)],
    case: OverloadCase,
    yield_pa: f64,
) -> HaighDiagram {
    let corners = line.corners();
    let reach = points
        .iter()
        .map(|p| p.2.abs() * 1.1)
        .fold(yield_pa.max(corners[3][0] * 1.2), f64::max);
    let mut line_pa = vec![[-reach, line.amplitude_at(-reach)]];
    line_pa.extend(corners.iter().filter(|c| c[0].abs() < reach));
    line_pa.push([reach, line.amplitude_at(reach)]);
    let points = points
        .iter()
        .map(|&(label, sa, sm)| HaighPoint {
            label: label.to_string(),
            point_pa: [sm, sa],
            limit_pa: if sa > 0.0 {
                line.limit_point(sa, sm, case)
            } else {
                [sm, line.amplitude_at(sm)]
            },
        })
        .collect();
    HaighDiagram {
        line_pa,
        overload: case,
        points,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fatigue::material::MaterialGroup;

    #[test]
    fn sensitivity_of_the_thesis_steel() {
        // 0.35 · 0.470 − 0.1 = 0.0645
        let m = mean_stress_sensitivity(470e6, &MaterialGroup::Steel.constants());
        assert!((m - 0.0645).abs() < 1e-12);
    }

    #[test]
    fn polyline_is_continuous_at_its_corners() {
        let l = HaighLine {
            sigma_wk_pa: 150e6,
            m: 0.2,
        };
        for c in l.corners() {
            for d in [-1e-6, 1e-6] {
                assert!((l.amplitude_at(c[0] + d) - c[1]).abs() < 1e-3, "{c:?}");
            }
        }
        // region II passes through (0, W); R = 0 lies on σ_a = σ_m; R = 0.5 on σ_m = 3 σ_a
        let [p1, p2, p3, p4] = l.corners();
        assert_eq!(p2, [0.0, 150e6]);
        assert!((p1[0] + p1[1]).abs() < 1e-6);
        assert!((p3[0] - p3[1]).abs() < 1e-6);
        assert!((p4[0] - 3.0 * p4[1]).abs() < 1e-6);
    }

    #[test]
    fn intersection_matches_the_closed_forms_in_all_four_regions() {
        for m in [0.0645, 0.2, 0.5] {
            let w = 180e6;
            let l = HaighLine { sigma_wk_pa: w, m };
            // F2: σ_m/σ_a from region I to IV
            for ratio in [
                -4.0, -1.5, -1.0, -0.3, 0.0, 0.7, 1.0, 1.5, 2.9, 3.0, 5.0, 40.0,
            ] {
                let sa = 50e6;
                let sm = ratio * sa;
                let k = l.mean_stress_factor(sa, sm, OverloadCase::ConstantRatio);
                let r = mean_stress_factor_f2(m, sa, sm);
                assert!((k - r).abs() < 1e-9, "M {m} σm/σa {ratio}: {k} vs {r}");
            }
            // F1: the limit amplitude straight above, FKM's region formulas
            let f1 = |sm: f64| {
                if sm < -w / (1.0 - m) {
                    w / (1.0 - m)
                } else if sm <= w / (1.0 + m) {
                    w - m * sm
                } else if sm < w * (3.0 + m) / (1.0 + m).powi(2) {
                    w * (3.0 + m) / (3.0 * (1.0 + m)) - m / 3.0 * sm
                } else {
                    w * (3.0 + m) / (3.0 * (1.0 + m).powi(2))
                }
            };
            for sm in [-400e6, -100e6, 0.0, 120e6, 200e6, 600e6] {
                let k = l.mean_stress_factor(10e6, sm, OverloadCase::ConstantMean);
                assert!((k * w - f1(sm)).abs() < 1e-3, "M {m} σm {sm}");
            }
        }
    }

    #[test]
    fn diagram_data_spans_the_points() {
        let l = HaighLine {
            sigma_wk_pa: 150e6,
            m: 0.1,
        };
        let d = haigh_diagram(
            &l,
            &[("σ1", 80e6, 100e6), ("σ2", 10e6, -700e6)],
            OverloadCase::ConstantRatio,
            355e6,
        );
        assert!(d.line_pa.first().unwrap()[0] <= -770e6);
        assert!(d.line_pa.len() == 6);
        let p = &d.points[0];
        // the limit lies on the ray through the point
        assert!((p.limit_pa[0] / p.limit_pa[1] - 100.0 / 80.0).abs() < 1e-9);
        assert!((l.amplitude_at(p.limit_pa[0]) - p.limit_pa[1]).abs() < 1e-3);
    }
}
