//! The rigid-body motions the supports leave free, and a statically determinate support that
//! removes them from the stiffness matrix.
//!
//! A body held only by pins is a floating body: K is singular on its rigid motions. With the
//! prescribed DOFs P, the floating motions are the rigid motions r(x) = t + ω × (x − x_c) that
//! vanish on P: the null space of the 6 × 6 Gram matrix Σ_{d∈P} R_d R_dᵀ (R_d the row of the six
//! rigid modes at DOF d). For these k motions the solver adds k prescribed DOFs S chosen by a
//! pivoted Gram–Schmidt on the rows of Φ = R N (the DOF whose row is largest after removing
//! the directions already chosen: the best-conditioned statically determinate support, the
//! classical 3-2-1 support when k = 6). A statically determinate support carries exactly the
//! out-of-balance of the loads on the motions it holds and does not deform the body
//! (Felippa, *Introduction to Finite Element Methods*, ch. 7, on the rigid-body modes and the
//! statically determinate support); the displacement is then u = u_S + Φ α, with u_S the
//! supported solution and α the rigid motion fixed by the contact (see [`super::solve`]).

use crate::fem::error::{FemError, Result};
use crate::fem::mesh::TetMesh;

/// The floating rigid motions of a body and the support that removes them.
#[derive(Clone, Debug)]
pub struct Floating {
    /// Reference point of the rotations, m (a fixed pin's axis point, else the bounding-box
    /// centre).
    pub centre: [f64; 3],
    /// Length that scales the rotations (the bounding-box diagonal), m.
    pub length: f64,
    /// The floating motions as combinations of the six rigid modes (each of length 6).
    pub basis: Vec<[f64; 6]>,
    /// The DOFs of the added support, one per floating motion.
    pub support: Vec<usize>,
}

impl Floating {
    /// Number of floating motions.
    pub fn k(&self) -> usize {
        self.basis.len()
    }

    /// The six rigid modes at a point x: translations e₁, e₂, e₃, then rotations
    /// e_i × (x − x_c) / L.
    pub fn rigid_modes(&self, x: [f64; 3]) -> [[f64; 3]; 6] {
        let d = std::array::from_fn::<f64, 3, _>(|j| (x[j] - self.centre[j]) / self.length);
        [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, -d[2], d[1]],
            [d[2], 0.0, -d[0]],
            [-d[1], d[0], 0.0],
        ]
    }

    /// Floating motion `i` at the point x.
    pub fn mode_at(&self, i: usize, x: [f64; 3]) -> [f64; 3] {
        let r = self.rigid_modes(x);
        std::array::from_fn(|j| (0..6).map(|m| self.basis[i][m] * r[m][j]).sum())
    }

    /// Φ at DOF d (3 · node + component): the k floating motions' components there.
    pub fn row(&self, mesh: &TetMesh, d: usize) -> Vec<f64> {
        let x = mesh.nodes()[d / 3];
        (0..self.k()).map(|i| self.mode_at(i, x)[d % 3]).collect()
    }

    /// The rigid motion Σ αᵢ Φᵢ added to `u` (3 per node).
    pub fn add_motion(&self, mesh: &TetMesh, alpha: &[f64], u: &mut [f64]) {
        for (n, x) in mesh.nodes().iter().enumerate() {
            for (i, a) in alpha.iter().enumerate() {
                let m = self.mode_at(i, *x);
                for j in 0..3 {
                    u[3 * n + j] += a * m[j];
                }
            }
        }
    }
}

/// The floating motions of `mesh` under the prescribed DOFs `prescribed`, and a support for
/// them on DOFs outside `avoid` (the contact walls' DOFs) and `prescribed`. Rotations are taken
/// about `centre` (the bounding-box centre when `None`).
pub fn floating(
    mesh: &TetMesh,
    prescribed: &[usize],
    avoid: &[bool],
    centre: Option<[f64; 3]>,
) -> Result<Floating> {
    let (lo, hi) = mesh.bounding_box();
    let centre = centre.unwrap_or(std::array::from_fn(|j| 0.5 * (lo[j] + hi[j])));
    let length = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2))
        .sqrt()
        .max(f64::MIN_POSITIVE);
    let probe = Floating {
        centre,
        length,
        basis: Vec::new(),
        support: Vec::new(),
    };
    let mut gram = nalgebra::SMatrix::<f64, 6, 6>::zeros();
    for &d in prescribed {
        let r = probe.rigid_modes(mesh.nodes()[d / 3]);
        let row = nalgebra::SVector::<f64, 6>::from_fn(|m, _| r[m][d % 3]);
        gram += row * row.transpose();
    }
    let eig = gram.symmetric_eigen();
    let scale = eig.eigenvalues.max().max(1.0);
    let basis: Vec<[f64; 6]> = (0..6)
        .filter(|&i| eig.eigenvalues[i] <= 1e-10 * scale)
        .map(|i| std::array::from_fn(|m| eig.eigenvectors[(m, i)]))
        .collect();
    let mut fl = Floating { basis, ..probe };
    let k = fl.k();
    if k == 0 {
        return Ok(fl);
    }
    // pivoted Gram–Schmidt over the rows of Φ
    let mut is_p = vec![false; mesh.n_dofs()];
    for &d in prescribed {
        is_p[d] = true;
    }
    let mut rows: Vec<(usize, Vec<f64>)> = (0..mesh.n_dofs())
        .filter(|&d| !is_p[d] && !avoid[d / 3])
        .map(|d| (d, fl.row(mesh, d)))
        .collect();
    for _ in 0..k {
        let best = rows
            .iter()
            .enumerate()
            .map(|(i, (_, r))| (i, r.iter().map(|v| v * v).sum::<f64>()))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((i, n2)) = best.filter(|b| b.1 > 1e-16) else {
            return Err(FemError::InvalidInput(
                "the body floats and has no node away from the contact walls to hold its \
                 rigid motion"
                    .into(),
            ));
        };
        let (d, r) = rows.swap_remove(i);
        fl.support.push(d);
        let q: Vec<f64> = r.iter().map(|v| v / n2.sqrt()).collect();
        for (_, other) in rows.iter_mut() {
            let p: f64 = other.iter().zip(&q).map(|(a, b)| a * b).sum();
            for (o, qv) in other.iter_mut().zip(&q) {
                *o -= p * qv;
            }
        }
    }
    Ok(fl)
}
