//! The FKM local-stress assessment of one surface node over a load cycle: amplitude and mean of
//! the surface stress components, their component fatigue limits, mean-stress factors, degrees of
//! utilisation, their combination and the safety factor.
//!
//! **The cycle's stress components** (FKM guideline, 6th ed. 2012, §4.1: the local stresses are
//! the surface stresses σ_1, σ_2, τ in a fixed coordinate system of the surface plane). The
//! history σ(t_i) is projected onto the tangent plane of the node (normal n); the two instants
//! (t_a, t_b) farthest apart in the plane-stress von Mises norm of the difference are the cycle's
//! turning points (the longest chord of the path; for a proportional history, as an elastic rod
//! under one cyclic load, exact: σ(t) = σ_0 + λ(t) Δ). The amplitude tensor A = (S_b − S_a)/2 and
//! the mean M = (S_b + S_a)/2; the surface axes e_1, e_2 are A's principal axes, |σ_1,a| ≥ |σ_2,a|,
//! so the shear amplitude vanishes in them and the amplitudes keep their relative sign (in phase:
//! same sign). Means σ_1,m = e_1·M·e_1, σ_2,m, and τ_m. A non-proportional history (the principal
//! directions turn over the cycle) is not reduced faithfully by any fixed axes: the critical-plane
//! check of [`super::findley`] is the one to read there.
//!
//! **Per component** (FKM §4.3–4.5): χ*_i from the depth gradient of the amplitude,
//! χ*_i = −(e_i·G_A·e_i)/σ_i,a, G_A = (G_b − G_a)/2; σ_WK,i from [`super::factors::local_strength`];
//! K_AK,i from the component's Haigh line ([`super::haigh`]); σ_AK,i = K_AK,i · σ_WK,i (the variable
//! amplitude factor K_BK = 1: constant amplitude at the fatigue limit); the degree of utilisation
//! (FKM eq. 4.6.1)
//!
//!   a_BK,σi = σ_i,a / (σ_AK,i / j_D),
//!
//! signed with the sign of σ_i,a for the combination.
//!
//! **Combination** (FKM §4.6.2, eq. 4.6.3–4.6.6, synchronous proportional stresses):
//!
//!   a_NH = ½ (|a_1 + a_2| + √((a_1 − a_2)² + 4 a_τ²))     (normal-stress hypothesis),
//!   a_GH = √(a_1² + a_2² − a_1 a_2 + a_τ²)                  (von Mises' hypothesis),
//!   a_BK,sv = q · a_NH + (1 − q) · a_GH,   q = (√3 − 1/f_W,τ)/(√3 − 1) ∈ [0, 1].
//!
//! For steel and wrought aluminium f_W,τ = 0.577 ≈ 1/√3, q = 0: von Mises on the utilisations (the
//! ductile case); grey cast iron f_W,τ = 0.85, q ≈ 0.76. In the axes chosen here a_τ = 0.
//!
//! **Safety** (FKM §4.5, Table 4.5.1): j_D = j_S · j_F · j_G; j_F = 1.5 for steel without regular
//! inspection and severe consequences of failure (the default), 1.35 with regular inspection, 1.3
//! and 1.2 for moderate consequences; j_S = 1 for loads known exactly (the rod's inertia and gas
//! forces are computed); j_G = 1 except castings. The assessment passes for a_BK,sv ≤ 1. Under
//! overload case F2 (constant stress ratio) the utilisation is linear in the load, so the factor by
//! which the whole load history could grow until the component fatigue limit is reached is
//!
//!   S = j_D / a_BK,sv,
//!
//! the number comparable with a Goodman safety factor ([`LocalAssessment::safety_factor`]).

use serde::{Deserialize, Serialize};

use super::factors::{LocalStrength, SurfaceFactors, local_strength};
use super::haigh::{HaighDiagram, HaighLine, OverloadCase, haigh_diagram, mean_stress_sensitivity};
use super::material::FatigueMaterial;
use super::tensor::{in_plane, quadratic_form, tangent_basis, unit, von_mises_plane};

/// The FKM safety factors.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SafetyFactors {
    /// j_S, on the loads.
    pub load: f64,
    /// j_F, on the fatigue strength.
    pub material: f64,
    /// j_G, for castings.
    pub casting: f64,
}

impl Default for SafetyFactors {
    /// j_S = 1, j_F = 1.5 (no regular inspection, severe consequences), j_G = 1.
    fn default() -> Self {
        SafetyFactors::fkm(false, true)
    }
}

impl SafetyFactors {
    /// FKM Table 4.5.1's j_F for steel and wrought aluminium, with j_S = j_G = 1.
    pub fn fkm(regular_inspection: bool, severe_consequences: bool) -> Self {
        let material = match (regular_inspection, severe_consequences) {
            (false, true) => 1.5,
            (false, false) => 1.3,
            (true, true) => 1.35,
            (true, false) => 1.2,
        };
        SafetyFactors {
            load: 1.0,
            material,
            casting: 1.0,
        }
    }

    /// j_D = j_S · j_F · j_G.
    pub fn total(&self) -> f64 {
        self.load * self.material * self.casting
    }
}

/// Everything the local assessment needs besides the stresses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LocalSettings {
    /// Material strengths and group.
    pub material: FatigueMaterial,
    /// Surface and part factors.
    pub surface: SurfaceFactors,
    /// Overload case (default F2).
    pub overload: OverloadCase,
    /// Safety factors.
    pub safety: SafetyFactors,
}

/// One node's stress history over a cycle.
#[derive(Clone, Copy, Debug)]
pub struct NodeHistory<'a> {
    /// σ(t_i), Pa, `[xx, yy, zz, xy, yz, zx]`.
    pub stress: &'a [[f64; 6]],
    /// dσ/dd(t_i) under the surface, Pa/m (d the depth), same instants; `None`: no gradient
    /// known, no support credited.
    pub depth_gradient: Option<&'a [[f64; 6]]>,
    /// Outward unit normal of the surface.
    pub outward_normal: [f64; 3],
}

/// One surface stress component's assessment, SI.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ComponentAssessment {
    /// Its direction in the surface.
    pub direction: [f64; 3],
    /// Amplitude, signed relative to σ_1's (σ_1,a ≥ 0), Pa.
    pub amplitude_pa: f64,
    /// Mean, Pa.
    pub mean_pa: f64,
    /// The chain from σ_W,zd to σ_WK.
    pub strength: LocalStrength,
    /// Mean-stress sensitivity M_σ.
    pub mean_stress_sensitivity: f64,
    /// Mean-stress factor K_AK.
    pub k_ak: f64,
    /// Component amplitude strength σ_AK, Pa.
    pub sigma_ak_pa: f64,
    /// Degree of utilisation a_BK,σ = |σ_a| j_D / σ_AK (≥ 0).
    pub utilisation: f64,
}

impl ComponentAssessment {
    /// The component's Haigh diagram with its point (`label`), lines spanning ±R_p at least.
    pub fn haigh(&self, label: &str, overload: OverloadCase, yield_pa: f64) -> HaighDiagram {
        let line = HaighLine {
            sigma_wk_pa: self.strength.sigma_wk_pa,
            m: self.mean_stress_sensitivity,
        };
        haigh_diagram(
            &line,
            &[(label, self.amplitude_pa.abs(), self.mean_pa)],
            overload,
            yield_pa,
        )
    }
}

/// The local assessment of one node.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LocalAssessment {
    /// The two instants of the history taken as the cycle's turning points.
    pub turning_points: [usize; 2],
    /// The larger surface component (σ_1,a ≥ |σ_2,a|).
    pub sigma1: ComponentAssessment,
    /// The other one.
    pub sigma2: ComponentAssessment,
    /// Mean shear stress in the (e_1, e_2) axes, Pa (its amplitude is zero by the choice of axes).
    pub shear_mean_pa: f64,
    /// Weight q of the normal-stress hypothesis.
    pub q: f64,
    /// a_NH.
    pub utilisation_normal_stress: f64,
    /// a_GH.
    pub utilisation_von_mises: f64,
    /// a_BK,sv = q a_NH + (1 − q) a_GH: passes for ≤ 1.
    pub utilisation: f64,
    /// j_D used.
    pub j_d: f64,
    /// S = j_D / a_BK,sv: the load factor to the component fatigue limit (∞ without amplitude).
    pub safety_factor: f64,
}

/// The FKM local assessment of `history` with `settings` (see the module documentation). The
/// history needs at least one instant; a constant one has no amplitude and S = ∞.
pub fn assess_node(settings: &LocalSettings, history: &NodeHistory) -> LocalAssessment {
    let n = unit(history.outward_normal);
    let (t1, t2) = tangent_basis(n);
    let plane: Vec<[f64; 3]> = history.stress.iter().map(|s| in_plane(s, t1, t2)).collect();
    let (mut ia, mut ib) = longest_chord(&plane);
    let a: [f64; 3] = std::array::from_fn(|c| 0.5 * (plane[ib][c] - plane[ia][c]));
    let m: [f64; 3] = std::array::from_fn(|c| 0.5 * (plane[ib][c] + plane[ia][c]));
    // principal axes of the amplitude: angle φ from t1
    let phi = 0.5 * (2.0 * a[2]).atan2(a[0] - a[1]);
    let (c, s) = (phi.cos(), phi.sin());
    let mut e1: [f64; 3] = std::array::from_fn(|j| c * t1[j] + s * t2[j]);
    let mut e2: [f64; 3] = std::array::from_fn(|j| -s * t1[j] + c * t2[j]);
    let along = |p: [f64; 3], u: f64, v: f64| p[0] * u * u + p[1] * v * v + 2.0 * p[2] * u * v;
    let mut amp = [along(a, c, s), along(a, -s, c)];
    if amp[1].abs() > amp[0].abs() {
        std::mem::swap(&mut e1, &mut e2);
        amp.swap(0, 1);
    }
    let flip = if amp[0] < 0.0 { -1.0 } else { 1.0 };
    if flip < 0.0 {
        std::mem::swap(&mut ia, &mut ib);
    }
    let amp = amp.map(|v| v * flip);
    let mean_in = |e: [f64; 3]| {
        let (u, v) = (dot3(e, t1), dot3(e, t2));
        along(m, u, v)
    };
    let mean = [mean_in(e1), mean_in(e2)];
    let shear_mean = {
        let (u1, v1, u2, v2) = (dot3(e1, t1), dot3(e1, t2), dot3(e2, t1), dot3(e2, t2));
        m[0] * u1 * u2 + m[1] * v1 * v2 + m[2] * (u1 * v2 + v1 * u2)
    };
    let j_d = settings.safety.total();
    let component = |e: [f64; 3], sa: f64, sm: f64| {
        let chi = match history.depth_gradient {
            Some(g) if sa != 0.0 => {
                let ga: [f64; 6] = std::array::from_fn(|k| 0.5 * (g[ib][k] - g[ia][k]));
                (-quadratic_form(&ga, e, e) / sa).max(0.0)
            }
            _ => 0.0,
        };
        let strength = local_strength(&settings.material, &settings.surface, chi, 0.0);
        let msens = mean_stress_sensitivity(strength.r_m_pa, &settings.material.constants());
        let line = HaighLine {
            sigma_wk_pa: strength.sigma_wk_pa,
            m: msens,
        };
        let (k_ak, utilisation) = if sa != 0.0 {
            let k = line.mean_stress_factor(sa.abs(), sm, settings.overload);
            (k, sa.abs() * j_d / (k * strength.sigma_wk_pa))
        } else {
            (line.amplitude_at(sm) / strength.sigma_wk_pa, 0.0)
        };
        ComponentAssessment {
            direction: e,
            amplitude_pa: sa,
            mean_pa: sm,
            strength,
            mean_stress_sensitivity: msens,
            k_ak,
            sigma_ak_pa: k_ak * strength.sigma_wk_pa,
            utilisation,
        }
    };
    let sigma1 = component(e1, amp[0], mean[0]);
    let sigma2 = component(e2, amp[1], mean[1]);
    let (a1, a2) = (sigma1.utilisation, sigma2.utilisation * amp[1].signum());
    let a_nh = 0.5 * ((a1 + a2).abs() + (a1 - a2).abs());
    let a_gh = (a1 * a1 + a2 * a2 - a1 * a2).max(0.0).sqrt();
    let q = combination_weight(settings.material.constants().f_w_tau);
    let utilisation = q * a_nh + (1.0 - q) * a_gh;
    LocalAssessment {
        turning_points: [ia, ib],
        sigma1,
        sigma2,
        shear_mean_pa: shear_mean,
        q,
        utilisation_normal_stress: a_nh,
        utilisation_von_mises: a_gh,
        utilisation,
        j_d,
        safety_factor: if utilisation > 0.0 {
            j_d / utilisation
        } else {
            f64::INFINITY
        },
    }
}

/// The pair (i, j), i < j, of the in-plane path `plane` (`[σ_11, σ_22, τ_12]` per instant)
/// farthest apart in the plane-stress von Mises norm of the difference; the first such pair in the
/// order (i, then j) on ties, as the plain double loop finds it.
///
/// The norm is Euclidean in u = (σ_11 − σ_22/2, (√3/2) σ_22, √3 τ_12) (σ_vM² = σ_11² + σ_22² −
/// σ_11 σ_22 + 3 τ_12²), so |u_i − u_j| ≤ |u_i − c| + R with c the centroid and R the largest
/// |u_j − c|. A first estimate d* (the farthest point from the farthest point from instant 0: a
/// lower bound of the diameter) lets the loop skip every i with |u_i − c| + R < d*: none of its
/// chords can reach d*. The result is the double loop's, at a fraction of its cost for the
/// elongated paths of a rod's cycle.
pub fn longest_chord(plane: &[[f64; 3]]) -> (usize, usize) {
    let r3 = 3f64.sqrt();
    let u: Vec<[f64; 3]> = plane
        .iter()
        .map(|p| [p[0] - 0.5 * p[1], 0.5 * r3 * p[1], r3 * p[2]])
        .collect();
    let dist = |a: &[f64; 3], b: &[f64; 3]| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    let n = u.len();
    if n < 2 {
        return (0, 0);
    }
    let farthest = |from: usize| {
        (0..n).fold((from, 0.0), |b, j| {
            let d = dist(&u[from], &u[j]);
            if d > b.1 { (j, d) } else { b }
        })
    };
    let (a, _) = farthest(0);
    let (_, estimate) = farthest(a);
    let c: [f64; 3] = std::array::from_fn(|k| u.iter().map(|p| p[k]).sum::<f64>() / n as f64);
    let radius: Vec<f64> = u.iter().map(|p| dist(p, &c)).collect();
    let r_max = radius.iter().copied().fold(0.0, f64::max);
    // a margin for round-off: a skipped i is strictly short of the longest chord
    let cut = estimate * (1.0 - 1e-9);
    let (mut ia, mut ib, mut best) = (0, 0, -1.0);
    for i in 0..n {
        if radius[i] + r_max < cut {
            continue;
        }
        for j in i + 1..n {
            let d = von_mises_plane(std::array::from_fn(|k| plane[j][k] - plane[i][k]));
            if d > best {
                (ia, ib, best) = (i, j, d);
            }
        }
    }
    (ia, ib)
}

/// q = (√3 − 1/f_W,τ)/(√3 − 1), clamped to [0, 1].
pub fn combination_weight(f_w_tau: f64) -> f64 {
    let r3 = 3f64.sqrt();
    ((r3 - 1.0 / f_w_tau) / (r3 - 1.0)).clamp(0.0, 1.0)
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uniaxial(sa: f64, sm: f64, steps: usize) -> Vec<[f64; 6]> {
        (0..steps)
            .map(|i| {
                let t = 2.0 * std::f64::consts::PI * i as f64 / steps as f64;
                [sm + sa * t.sin(), 0.0, 0.0, 0.0, 0.0, 0.0]
            })
            .collect()
    }

    #[test]
    fn fully_reversed_uniaxial_at_the_component_limit_has_utilisation_one() {
        let settings = LocalSettings {
            safety: SafetyFactors {
                load: 1.0,
                material: 1.0,
                casting: 1.0,
            },
            ..LocalSettings::default()
        };
        let strength = local_strength(&settings.material, &settings.surface, 0.0, 0.0);
        // 36 steps: sin reaches ±1 at steps 9 and 27
        let h = uniaxial(strength.sigma_wk_pa, 0.0, 36);
        let r = assess_node(
            &settings,
            &NodeHistory {
                stress: &h,
                depth_gradient: None,
                outward_normal: [0.0, 0.0, 1.0],
            },
        );
        assert!((r.utilisation - 1.0).abs() < 1e-12, "{}", r.utilisation);
        assert!((r.safety_factor - 1.0).abs() < 1e-12);
        assert!(r.sigma1.direction[0].abs() > 1.0 - 1e-12);
        assert_eq!(r.sigma2.utilisation, 0.0);
        assert_eq!(r.q, 0.0);
    }

    #[test]
    fn compressive_tensile_and_turned_histories() {
        let settings = LocalSettings::default();
        let run = |h: &[[f64; 6]]| {
            assess_node(
                &settings,
                &NodeHistory {
                    stress: h,
                    depth_gradient: None,
                    outward_normal: [0.0, 0.0, 1.0],
                },
            )
        };
        let base = run(&uniaxial(80e6, 0.0, 24));
        let tens = run(&uniaxial(80e6, 60e6, 24));
        let comp = run(&uniaxial(80e6, -60e6, 24));
        // a tensile mean costs, a compressive one helps (M > 0)
        assert!(tens.utilisation > base.utilisation && comp.utilisation < base.utilisation);
        assert!((tens.sigma1.mean_pa - 60e6).abs() < 1e-6);
        // the same history turned in the surface by 30°: the same numbers
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let turned: Vec<[f64; 6]> = uniaxial(80e6, 60e6, 24)
            .iter()
            .map(|v| [v[0] * c * c, v[0] * s * s, 0.0, v[0] * c * s, 0.0, 0.0])
            .collect();
        let t = run(&turned);
        assert!((t.utilisation - tens.utilisation).abs() < 1e-12 * tens.utilisation);
        assert!((t.sigma1.direction[0].abs() - c).abs() < 1e-12);
    }

    #[test]
    fn longest_chord_is_the_double_loops() {
        // a non-proportional path (an ellipse turned in the plane, with a mean and a wobble)
        let plane: Vec<[f64; 3]> = (0..300)
            .map(|i| {
                let t = i as f64 * 0.021;
                [
                    40.0 + 90.0 * t.cos() + 7.0 * (5.0 * t).sin(),
                    -10.0 + 30.0 * t.sin(),
                    25.0 * (t + 0.4).cos(),
                ]
            })
            .collect();
        let (mut bi, mut bj, mut best) = (0, 0, -1.0);
        for i in 0..plane.len() {
            for j in i + 1..plane.len() {
                let d = von_mises_plane(std::array::from_fn(|c| plane[j][c] - plane[i][c]));
                if d > best {
                    (bi, bj, best) = (i, j, d);
                }
            }
        }
        assert_eq!(longest_chord(&plane), (bi, bj));
        assert_eq!(longest_chord(&plane[..1]), (0, 0));
    }

    #[test]
    fn combination_weight_of_the_groups() {
        assert_eq!(combination_weight(0.577), 0.0);
        assert!(combination_weight(1.0 / 3f64.sqrt()) < 1e-15);
        let q = combination_weight(0.85);
        assert!((q - (3f64.sqrt() - 1.0 / 0.85) / (3f64.sqrt() - 1.0)).abs() < 1e-15);
        assert!(q > 0.75 && q < 0.77);
    }
}
