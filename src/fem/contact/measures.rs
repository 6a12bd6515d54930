//! What a contact solution says about a bore: the pressure's resultant, peak and arc, and the
//! bore's change of diameter along and across a direction (its ovality).

use super::cylinder::{Cylinder, radial};
use super::problem::CylinderContact;
use super::weights::Wall;
use crate::fem::boundary::{dot, norm};
use crate::fem::error::{FemError, Result};
use crate::fem::mesh::TetMesh;

/// The contact figures of one wall from its pressures `lambda`, nodal gaps `gap` and pin
/// translation `pin`. Angles are measured about the axis from the direction of the contact
/// resultant (from t₁ of the wall's frame when the resultant vanishes, e.g. a pressed pin);
/// the arc is 360° minus the largest angular gap between active nodes (λ > 0), and 360° when
/// that gap is no wider than the wall's own largest gap between nodes.
pub fn summarise(wall: &Wall, lambda: &[f64], gap: &[f64], pin: [f64; 3]) -> CylinderContact {
    let mut res = [0.0; 3];
    let mut total = 0.0;
    for (b, l) in lambda.iter().enumerate() {
        let c = wall.force_per_pressure(b);
        total += l.abs() * norm(c);
        for j in 0..3 {
            res[j] += l * c[j];
        }
    }
    let (t1, t2) = wall.basis;
    let zero = if norm(res) > 1e-9 * total {
        dot(res, t2).atan2(dot(res, t1))
    } else {
        0.0
    };
    let wrap = |a: f64| {
        let d = (a - zero).to_degrees().rem_euclid(360.0);
        if d > 180.0 { d - 360.0 } else { d }
    };
    let angle_deg: Vec<f64> = wall.angle.iter().map(|a| wrap(*a)).collect();
    let smoothed = wall.smoothed(lambda);
    let (mut peak, mut peak_angle) = (0.0, 0.0);
    for (b, l) in smoothed.iter().enumerate() {
        if *l > peak {
            peak = *l;
            peak_angle = angle_deg[b];
        }
    }
    let largest_gap = |angles: &mut Vec<f64>| -> (f64, f64, f64) {
        angles.sort_by(f64::total_cmp);
        angles.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        let mut best = (
            360.0 + angles[0] - angles[angles.len() - 1],
            angles[angles.len() - 1],
            angles[0],
        );
        for w in angles.windows(2) {
            if w[1] - w[0] > best.0 {
                best = (w[1] - w[0], w[0], w[1]);
            }
        }
        best
    };
    let mut all = angle_deg.clone();
    let wall_gap = largest_gap(&mut all).0;
    let mut act: Vec<f64> = (0..lambda.len())
        .filter(|&b| lambda[b] > 0.0)
        .map(|b| angle_deg[b])
        .collect();
    let (arc_deg, arc_ends_deg) = if act.is_empty() {
        (0.0, [0.0, 0.0])
    } else {
        let (g, before, after) = largest_gap(&mut act);
        if g <= wall_gap * (1.0 + 1e-9) {
            (360.0, [-180.0, 180.0])
        } else {
            (360.0 - g, [after, before])
        }
    };
    CylinderContact {
        nodes: wall.nodes.clone(),
        pressure_pa: lambda.to_vec(),
        smoothed_pressure_pa: smoothed,
        gap_m: gap.to_vec(),
        angle_deg,
        pin_displacement_m: pin,
        pin_deflection_m: Vec::new(),
        resultant_n: res,
        peak_pressure_pa: peak,
        peak_nodal_pressure_pa: lambda.iter().fold(0.0, |a, l| a.max(*l)),
        peak_angle_deg: peak_angle,
        arc_deg,
        arc_ends_deg,
        penetration_max_m: gap.iter().fold(0.0, |a, g| a.max(-g)),
        max_tensile_pressure_pa: lambda.iter().fold(0.0, |a, l| a.max(-l)),
    }
}

/// A bore's change of diameter, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiameterChange {
    /// Along the direction given.
    pub along_m: f64,
    /// Across it (perpendicular to it and to the axis).
    pub across_m: f64,
}

/// The change of diameter of the bore wall `cylinder.faces` under the displacements `u`, along
/// `direction` and across it. The radial displacement u_r = e_r · u of the wall nodes is fitted
/// by least squares with a Fourier series in the angle φ from `direction`,
/// u_r ≈ a₀ + Σ_{n=1}^{N} (a_n cos nφ + b_n sin nφ) (N = 8, or fewer on a coarse wall: at
/// most a quarter of the nodes around), averaged along the axis; the diameter change along is
/// u_r(0) + u_r(π) = 2 (a₀ + Σ_{n even} a_n), across u_r(π/2) + u_r(3π/2) = 2 (a₀ + Σ_{n even}
/// (−1)^{n/2} a_n). A rigid translation (n = 1) changes neither.
pub fn diameter_change(
    mesh: &TetMesh,
    cylinder: &Cylinder,
    u: &[f64],
    direction: [f64; 3],
) -> Result<DiameterChange> {
    let a = cylinder.unit_axis(0)?;
    let dp: [f64; 3] = std::array::from_fn(|j| direction[j] - dot(direction, a) * a[j]);
    let l = norm(dp);
    if l.partial_cmp(&(1e-12 * norm(direction).max(1e-300))) != Some(std::cmp::Ordering::Greater) {
        return Err(FemError::InvalidInput(
            "diameter change: the direction is along the axis".into(),
        ));
    }
    let d1 = dp.map(|v| v / l);
    let d2 = crate::fem::boundary::cross(a, d1);
    let mut nodes: Vec<usize> = cylinder.faces.iter().flatten().copied().collect();
    nodes.sort_unstable();
    nodes.dedup();
    let samples: Vec<(f64, f64)> = nodes
        .iter()
        .map(|&nd| {
            let (_, e) = radial(mesh.nodes()[nd], cylinder.axis_point_m, a);
            let ur = (0..3).map(|j| e[j] * u[3 * nd + j]).sum();
            (dot(e, d2).atan2(dot(e, d1)), ur)
        })
        .collect();
    let mut angles: Vec<f64> = samples.iter().map(|s| s.0).collect();
    angles.sort_by(f64::total_cmp);
    angles.dedup_by(|x, y| (*x - *y).abs() < 1e-9);
    let order = (angles.len() / 4).min(8);
    let cols = 1 + 2 * order;
    let basis = |phi: f64| -> Vec<f64> {
        let mut v = vec![1.0];
        for nh in 1..=order {
            v.push((nh as f64 * phi).cos());
            v.push((nh as f64 * phi).sin());
        }
        v
    };
    let mut ata = nalgebra::DMatrix::<f64>::zeros(cols, cols);
    let mut atb = nalgebra::DVector::<f64>::zeros(cols);
    for (phi, ur) in &samples {
        let r = basis(*phi);
        for i in 0..cols {
            atb[i] += r[i] * ur;
            for j in 0..cols {
                ata[(i, j)] += r[i] * r[j];
            }
        }
    }
    let c = ata.cholesky().ok_or_else(|| {
        FemError::InvalidInput("diameter change: too few wall nodes around the axis".into())
    })?;
    let x = c.solve(&atb);
    let at = |phi: f64| -> f64 { basis(phi).iter().zip(x.iter()).map(|(p, q)| p * q).sum() };
    let pi = std::f64::consts::PI;
    Ok(DiameterChange {
        along_m: at(0.0) + at(pi),
        across_m: at(0.5 * pi) + at(1.5 * pi),
    })
}
