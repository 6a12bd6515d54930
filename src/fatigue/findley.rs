//! A critical-plane check of a stress history at a point: the Findley criterion.
//!
//! **Criterion** (W. N. Findley, "A theory for the effect of mean stress on fatigue of metals
//! under combined torsion and axial load or bending", J. Eng. Ind. 81 (1959) 301–306; D. F. Socie,
//! G. B. Marquis, *Multiaxial Fatigue*, SAE 2000, §8; as implemented in PragTic and the COMSOL
//! Fatigue Module): on a material plane with unit normal n, the traction σ(t)·n splits into the
//! normal stress σ_n(t) = n·σ(t)·n and the shear vector τ(t) = σ(t)·n − σ_n(t) n, which runs along
//! a closed path in the plane over the cycle. With τ_a the shear amplitude on the plane and
//! σ_n,max the largest normal stress on it over the cycle, the Findley parameter of the history is
//!
//!   f = max over n of (τ_a + k · σ_n,max),
//!
//! the maximising plane the critical plane, and the history is below its fatigue limit when
//! f ≤ f_lim. **Shear amplitude**: the radius of the minimum circumscribed circle of the shear
//! path (Papadopoulos' and Dang Van's choice; Welzl's algorithm, expected linear time). For a
//! proportional history it equals half the longest chord; for the ellipse of out-of-phase loading
//! it is the semi-major axis, as the longest chord is.
//!
//! **Constants from the fatigue limits in fully reversed tension σ_W and torsion τ_W.** On the
//! plane at θ to the axis of a tension σ_a sin ωt: τ_a = (σ_a/2)|sin 2θ|, σ_n,max = (σ_a/2)(1 +
//! cos 2θ), so f = (σ_a/2)(√(1+k²) + k) at tan 2θ = 1/k. In torsion τ_a sin ωt: f = τ_a √(1+k²)
//! at tan 2α = k from the plane of largest shear. Equal f at the two limits with r = τ_W/σ_W:
//!
//!   k = (2r − 1) / (2 √(r (1 − r))),      f_lim = τ_W √(1 + k²)      (½ < r < 1),
//!
//! k = 0 for r ≤ ½ (Tresca). For steel's r = 0.577: k = 0.1559. The **Findley factor**
//! S = f_lim / f is the load factor to the limit: τ_a and σ_n,max are positively homogeneous of
//! degree one in the history, so f is too.
//!
//! **Plane search.** Normals on the upper hemisphere (n and −n are one plane) on a grid of polar
//! angle θ ∈ [0°, 90°] and azimuth φ ∈ [0°, 360°) with step `grid_deg`, then a compass search
//! (step halving to `tolerance_deg`) from the best few grid planes. The cost per node is that of
//! (90/grid)·(360/grid) circles of the history's length: meant for the nodes the FKM assessment
//! ranks worst, not the whole surface.

use serde::{Deserialize, Serialize};

use super::tensor::{dot, quadratic_form, tangent_basis, traction};

/// Constants and search settings of the Findley check.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FindleySettings {
    /// Normal-stress sensitivity k.
    pub k: f64,
    /// Limit f_lim, Pa.
    pub limit_pa: f64,
    /// Step of the coarse grid of plane normals, degrees.
    pub grid_deg: f64,
    /// Angle resolution of the refinement, degrees.
    pub tolerance_deg: f64,
}

impl FindleySettings {
    /// k and f_lim from the fully reversed fatigue limits in tension `sigma_w_pa` and torsion
    /// `tau_w_pa` (see the module documentation); a 5° grid refined to 0.01°.
    pub fn from_fatigue_limits(sigma_w_pa: f64, tau_w_pa: f64) -> Self {
        let r = tau_w_pa / sigma_w_pa;
        let k = if r > 0.5 && r < 1.0 {
            (2.0 * r - 1.0) / (2.0 * (r * (1.0 - r)).sqrt())
        } else {
            0.0
        };
        FindleySettings {
            k,
            limit_pa: tau_w_pa * (1.0 + k * k).sqrt(),
            grid_deg: 5.0,
            tolerance_deg: 0.01,
        }
    }
}

/// The critical plane of a history.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FindleyResult {
    /// Unit normal of the critical plane.
    pub normal: [f64; 3],
    /// Shear amplitude on it, Pa.
    pub shear_amplitude_pa: f64,
    /// Largest normal stress on it over the cycle, Pa.
    pub max_normal_stress_pa: f64,
    /// Findley parameter f = τ_a + k σ_n,max, Pa.
    pub parameter_pa: f64,
    /// S = f_lim / f (∞ when f ≤ 0).
    pub factor: f64,
}

/// The Findley critical plane of `history` (σ(t_i), Pa, `[xx, yy, zz, xy, yz, zx]`).
pub fn findley(history: &[[f64; 6]], settings: &FindleySettings) -> FindleyResult {
    let eval = |theta: f64, phi: f64| plane_parameter(history, normal_of(theta, phi), settings.k);
    let step = settings.grid_deg.to_radians();
    let n_theta = (std::f64::consts::FRAC_PI_2 / step).round().max(1.0) as usize;
    let n_phi = (2.0 * std::f64::consts::PI / step).round().max(4.0) as usize;
    let mut grid: Vec<(f64, f64, f64)> = Vec::with_capacity((n_theta + 1) * n_phi);
    for i in 0..=n_theta {
        let theta = std::f64::consts::FRAC_PI_2 * i as f64 / n_theta as f64;
        let count = if i == 0 { 1 } else { n_phi };
        for j in 0..count {
            let phi = 2.0 * std::f64::consts::PI * j as f64 / n_phi as f64;
            grid.push((eval(theta, phi).2, theta, phi));
        }
    }
    grid.sort_by(|a, b| b.0.total_cmp(&a.0));
    let tol = settings.tolerance_deg.to_radians();
    let mut best = (f64::NEG_INFINITY, 0.0, 0.0);
    for &(f0, t0, p0) in grid.iter().take(6) {
        let (mut f, mut t, mut p) = (f0, t0, p0);
        let mut h = 0.5 * step;
        while h >= tol {
            let mut moved = false;
            for (dt, dp) in [(h, 0.0), (-h, 0.0), (0.0, h), (0.0, -h)] {
                let v = eval(t + dt, p + dp).2;
                if v > f {
                    (f, t, p) = (v, t + dt, p + dp);
                    moved = true;
                }
            }
            if !moved {
                h *= 0.5;
            }
        }
        if f > best.0 {
            best = (f, t, p);
        }
    }
    let n = normal_of(best.1, best.2);
    let (tau_a, sn_max, f) = plane_parameter(history, n, settings.k);
    FindleyResult {
        normal: n,
        shear_amplitude_pa: tau_a,
        max_normal_stress_pa: sn_max,
        parameter_pa: f,
        factor: if f > 0.0 {
            settings.limit_pa / f
        } else {
            f64::INFINITY
        },
    }
}

/// Unit normal at polar angle `theta` and azimuth `phi`.
pub fn normal_of(theta: f64, phi: f64) -> [f64; 3] {
    [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ]
}

/// (τ_a, σ_n,max, τ_a + k σ_n,max) of `history` on the plane with unit normal `n`.
pub fn plane_parameter(history: &[[f64; 6]], n: [f64; 3], k: f64) -> (f64, f64, f64) {
    let (u, v) = tangent_basis(n);
    let mut sn_max = f64::NEG_INFINITY;
    let pts: Vec<[f64; 2]> = history
        .iter()
        .map(|s| {
            let t = traction(s, n);
            sn_max = sn_max.max(quadratic_form(s, n, n));
            [dot(t, u), dot(t, v)]
        })
        .collect();
    let tau_a = min_circle_radius(&pts);
    (tau_a, sn_max, tau_a + k * sn_max)
}

/// Radius of the smallest circle containing `pts` (Welzl's incremental form, in a fixed
/// pseudo-random order so that ordered paths such as ellipses stay linear in expectation).
pub fn min_circle_radius(pts: &[[f64; 2]]) -> f64 {
    if pts.len() < 2 {
        return 0.0;
    }
    let mut p = pts.to_vec();
    // Fisher–Yates with a fixed LCG: deterministic, order-breaking
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    for i in (1..p.len()).rev() {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let j = (state >> 33) as usize % (i + 1);
        p.swap(i, j);
    }
    let inside = |c: &([f64; 2], f64), q: &[f64; 2]| {
        (q[0] - c.0[0]).hypot(q[1] - c.0[1]) <= c.1 * (1.0 + 1e-12) + 1e-300
    };
    let mut c = (p[0], 0.0);
    for i in 1..p.len() {
        if inside(&c, &p[i]) {
            continue;
        }
        c = (p[i], 0.0);
        for j in 0..i {
            if inside(&c, &p[j]) {
                continue;
            }
            c = circle2(p[i], p[j]);
            for l in 0..j {
                if !inside(&c, &p[l]) {
                    c = circle3(p[i], p[j], p[l]);
                }
            }
        }
    }
    c.1
}

fn circle2(a: [f64; 2], b: [f64; 2]) -> ([f64; 2], f64) {
    let m = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    (m, 0.5 * (a[0] - b[0]).hypot(a[1] - b[1]))
}

fn circle3(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> ([f64; 2], f64) {
    let (bx, by) = (b[0] - a[0], b[1] - a[1]);
    let (cx, cy) = (c[0] - a[0], c[1] - a[1]);
    let d = 2.0 * (bx * cy - by * cx);
    if d.abs() <= 1e-300 {
        // collinear: the circle on the farthest pair
        let cands = [circle2(a, b), circle2(b, c), circle2(a, c)];
        return cands
            .into_iter()
            .max_by(|x, y| x.1.total_cmp(&y.1))
            .expect("three");
    }
    let (b2, c2) = (bx * bx + by * by, cx * cx + cy * cy);
    let ux = (cy * b2 - by * c2) / d;
    let uy = (bx * c2 - cx * b2) / d;
    ([a[0] + ux, a[1] + uy], ux.hypot(uy))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn min_circle_of_simple_sets() {
        // a segment: half its length; a square: half the diagonal; an ellipse: the semi-major axis
        assert_eq!(
            min_circle_radius(&[[0.0, 0.0], [2.0, 0.0], [1.0, 0.0]]),
            1.0
        );
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5]];
        assert!((min_circle_radius(&sq) - 0.5 * 2f64.sqrt()).abs() < 1e-12);
        let ell: Vec<[f64; 2]> = (0..360)
            .map(|i| {
                let t = (i as f64).to_radians();
                [3.0 * t.cos(), 1.0 * t.sin()]
            })
            .collect();
        assert!((min_circle_radius(&ell) - 3.0).abs() < 1e-12);
        // an acute triangle: the circumcircle (equilateral side 1: 1/√3)
        let tri = [[0.0, 0.0], [1.0, 0.0], [0.5, 0.5 * 3f64.sqrt()]];
        assert!((min_circle_radius(&tri) - 1.0 / 3f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn constants_of_steel() {
        let s = FindleySettings::from_fatigue_limits(1.0, 0.577);
        let r: f64 = 0.577;
        assert!((s.k - (2.0 * r - 1.0) / (2.0 * (r * (1.0 - r)).sqrt())).abs() < 1e-15);
        assert!((s.k - 0.1559).abs() < 5e-5, "{}", s.k);
        // the two calibration tests give the same f: (σ_W/2)(√(1+k²) + k) = τ_W √(1+k²)
        let f_tension = 0.5 * ((1.0 + s.k * s.k).sqrt() + s.k);
        assert!((f_tension - s.limit_pa).abs() < 1e-14);
        assert_eq!(FindleySettings::from_fatigue_limits(1.0, 0.5).k, 0.0);
    }
}
