//! Couplings to a reference node as the discrete system ccx forms them (CalculiX manual, ccx
//! 2.20, "Kinematic and Distributing Coupling"; its `couplings.f`).
//!
//! * `*KINEMATIC`: per surface node i and listed DOF j the linearised rigid-body equation
//!   u_i,j − u_R,j − (θ × (x_i − x_R))_j = 0, θ the three DOFs of the coupling's rotation node
//!   (ccx's rigid-body MPCs, linearised once in a linear step). The surface node's DOF is the
//!   dependent one, as ccx writes it first.
//! * `*DISTRIBUTING`: no equations; the reference node's force F and moment M become point loads
//!   on the surface's nodes (the classic bolt-pattern distribution, ccx's `coeffc` and Abaqus's
//!   "distributing coupling elements" theory manual): with area weights w_i = A_i / A (A_i the
//!   node's share ∫ N_i dA of the faces, on the faces' integration points: 3 for a C3D10 face,
//!   1 for a C3D4 face), the centroid c = Σ w_i x_i, r_i = x_i − c, the weighted polar inertia
//!   T = Σ w_i (|r_i|² I − r_i r_iᵀ) and the moment about the centroid M̂ = M + (x_R − c) × F,
//!
//!   f_i = w_i (F + (T⁻¹ M̂) × r_i),
//!
//!   so that Σ f_i = F and Σ r_i × f_i = M̂. ccx writes T⁻¹ M̂ in T's principal axes (Σ_k M̂_k e_k
//!   / T_kk); the two are the same vector. The reference node itself carries nothing and stays
//!   at zero displacement, as ccx prints it.

use crate::fem::boundary::face_point;
use crate::fem::constraints::Constraint;
use crate::fem::error::{FemError, Result};
use crate::fem::shape::TET10_FACES;

use super::model::{Coupling, CouplingKind, Model};

/// CalculiX's face rule for C3D10 faces (`gauss2d5`): 3 points, weight 1/6.
const FACE_POINTS: [[f64; 2]; 3] = [
    [1.0 / 6.0, 1.0 / 6.0],
    [2.0 / 3.0, 1.0 / 6.0],
    [1.0 / 6.0, 2.0 / 3.0],
];
const FACE_WEIGHT: f64 = 1.0 / 6.0;

/// The rigid-body equations of every kinematic coupling (global DOFs, 3 per node).
pub fn kinematic_constraints(path: &std::path::Path, model: &Model) -> Vec<Constraint> {
    let mut out = Vec::new();
    for c in &model.couplings {
        let CouplingKind::Kinematic {
            dofs,
            rotation_node,
        } = c.kind
        else {
            continue;
        };
        let (r, t) = (c.reference, rotation_node);
        let xr = model.nodes[r];
        for &i in &c.nodes {
            let d: [f64; 3] = std::array::from_fn(|k| model.nodes[i][k] - xr[k]);
            for j in (0..3).filter(|&j| dofs[j]) {
                // (θ × d)_j = θ_{j+1} d_{j+2} − θ_{j+2} d_{j+1} (indices mod 3)
                let (a, b) = ((j + 1) % 3, (j + 2) % 3);
                let mut terms = vec![(3 * i + j, 1.0), (3 * r + j, -1.0)];
                terms.extend(
                    [(3 * t + a, -d[b]), (3 * t + b, d[a])]
                        .into_iter()
                        .filter(|x| x.1 != 0.0),
                );
                out.push(Constraint {
                    terms,
                    value: 0.0,
                    label: format!(
                        "{}:{}: *KINEMATIC coupling of node {} dof {}",
                        path.display(),
                        c.line,
                        model.node_ids[i],
                        j + 1
                    ),
                });
            }
        }
    }
    out
}

/// Per surface node its area weight w_i = A_i / A (in the order of `c.nodes`).
fn area_weights(model: &Model, c: &Coupling) -> Vec<f64> {
    let mut area = vec![0.0; c.nodes.len()];
    let slot = |n: usize| {
        c.nodes
            .iter()
            .position(|&m| m == n)
            .expect("a surface node")
    };
    for &(e, f) in &c.faces {
        let el = &model.elements[e];
        let local = TET10_FACES[f];
        if el.nodes.len() == 10 {
            let nodes: [usize; 6] = std::array::from_fn(|a| el.nodes[local[a]]);
            let x: [[f64; 3]; 6] = std::array::from_fn(|a| model.nodes[nodes[a]]);
            for q in &FACE_POINTS {
                let (_, jac, n) = face_point(&x, *q);
                let da = FACE_WEIGHT * norm(jac);
                for a in 0..6 {
                    area[slot(nodes[a])] += da * n[a];
                }
            }
        } else {
            let nodes: [usize; 3] = std::array::from_fn(|a| el.nodes[local[a]]);
            let x: [[f64; 3]; 3] = std::array::from_fn(|a| model.nodes[nodes[a]]);
            let u: [f64; 3] = std::array::from_fn(|j| x[1][j] - x[0][j]);
            let v: [f64; 3] = std::array::from_fn(|j| x[2][j] - x[0][j]);
            let da = 0.5 * norm(cross(u, v));
            for &n in &nodes {
                area[slot(n)] += da / 3.0;
            }
        }
    }
    let total: f64 = area.iter().sum();
    area.iter().map(|a| a / total).collect()
}

/// Adds the point loads of distributing coupling `c` carrying force `force` and moment `moment`
/// at its reference node to `f` (3 per node).
pub fn distribute(
    model: &Model,
    c: &Coupling,
    force: [f64; 3],
    moment: [f64; 3],
    f: &mut [f64],
) -> Result<()> {
    let w = area_weights(model, c);
    let x = |k: usize| model.nodes[c.nodes[k]];
    let centroid: [f64; 3] =
        std::array::from_fn(|j| (0..w.len()).map(|k| w[k] * x(k)[j]).sum::<f64>());
    let r = |k: usize| -> [f64; 3] { std::array::from_fn(|j| x(k)[j] - centroid[j]) };
    let mut t = [[0.0; 3]; 3];
    for (k, wk) in w.iter().enumerate() {
        let rk = r(k);
        let rr = dot(rk, rk);
        for a in 0..3 {
            for b in 0..3 {
                t[a][b] += wk * (if a == b { rr } else { 0.0 } - rk[a] * rk[b]);
            }
        }
    }
    let arm: [f64; 3] = std::array::from_fn(|j| model.nodes[c.reference][j] - centroid[j]);
    let about_centroid: [f64; 3] = {
        let m = cross(arm, force);
        std::array::from_fn(|j| moment[j] + m[j])
    };
    let spin = if about_centroid.iter().all(|v| *v == 0.0) {
        [0.0; 3]
    } else {
        solve3(t, about_centroid).ok_or_else(|| {
            FemError::InvalidInput(format!(
                "{}:{}: the nodes of surface {} lie on a line: a *DISTRIBUTING coupling cannot \
                 pass a moment to them (its polar inertia is singular)",
                c.file.display(),
                c.line,
                c.surface
            ))
        })?
    };
    for (k, (wk, &n)) in w.iter().zip(&c.nodes).enumerate() {
        let s = cross(spin, r(k));
        for j in 0..3 {
            f[3 * n + j] += wk * (force[j] + s[j]);
        }
    }
    Ok(())
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// x with a x = b (Cramer's rule), `None` when a is singular to round-off.
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| dot(m[0], cross(m[1], m[2]));
    let d = det(a);
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    if d.abs() <= 1e-12 * scale.powi(3) {
        return None;
    }
    // a symmetric: column k replaced by b is row k replaced by b
    Some(std::array::from_fn(|k| {
        let mut m = a;
        m[k] = b;
        det(m) / d
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cramer's rule on a symmetric system with a known solution.
    #[test]
    fn solve3_symmetric() {
        let a = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];
        let x = [1.0, -2.0, 0.5];
        let b: [f64; 3] = std::array::from_fn(|i| dot(a[i], x));
        let y = solve3(a, b).unwrap();
        for k in 0..3 {
            assert!((y[k] - x[k]).abs() < 1e-14);
        }
        assert!(solve3([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]], b).is_none());
    }
}
