//! The contact compliance S = C K⁻¹ Cᵀ from the trailing block of the Cholesky factor.
//!
//! C weighs the radial displacements of the wall nodes only: (C u)_b = Σ_a D_ba e_a·u_a
//! ([`super::weights`]). In the nodal frame R_a = [e_a, â × e_a, â] (â the cylinder's axis) of
//! every wall node, u_a = R_a v_a, the stiffness becomes K' = Tᵀ K T (T block diagonal, R_a
//! at the wall nodes, the identity elsewhere; the pattern of K is unchanged, its node blocks
//! being full) and C T = C_r reads the first (radial) component of v_a alone. Ordering those m
//! radial equations last (after the nested dissection of the rest), the trailing m × m block
//! L₂₂ of the factor of K' gives (K'⁻¹)₂₂ = L₂₂⁻ᵀ L₂₂⁻¹ ([`CholeskyFactor::trailing_block`]),
//! hence
//!
//! S = C_r L₂₂⁻ᵀ L₂₂⁻¹ C_rᵀ,
//!
//! columns S[:, J] by two dense triangular solves of size m with |J| right-hand sides, instead
//! of one sparse solve of size n per column (the Schur complement on the contact unknowns,
//! e.g. Wriggers, *Computational Contact Mechanics*, 2nd ed., §6.3.4, condensation on the
//! contact DOFs). The displacement solves use the same factor: b' = Tᵀ b, u = T v.
//!
//! A wall node prescribed in its axial component only (the axis along x, y or z: plane strain,
//! a symmetry plane across the axis) keeps the frame exact, the prescribed component being the
//! frame's axial one. Any other prescribed DOF at a wall node (its frame would mix a prescribed
//! and a free component), or a node on two walls, keeps the columns solved one by one with the
//! factor of K ([`Compliance::Solves`]).

use faer::Par;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};

use super::weights::Wall;
use crate::fem::assembly::{DofMap, SparseSym};
use crate::fem::boundary::cross;
use crate::fem::error::{FemError, Result};
use crate::fem::solver::CholeskyFactor;

/// Columns of the contact compliance solved together by [`Compliance::Solves`].
const BLOCK: usize = 32;

/// The nodal frames of the wall nodes, on the equations.
#[derive(Clone, Debug)]
pub struct NodalFrames {
    /// Per equation: (index of its node's frame, Cartesian component) for the wall nodes.
    at: Vec<Option<(usize, usize)>>,
    /// Whether an equation holds a radial component.
    is_radial: Vec<bool>,
    /// Per frame: the equations of the Cartesian components (x, y, z), the equations holding
    /// the frame's components (radial, circumferential, axial), and R (columns e, â × e, â).
    frames: Vec<Frame>,
}

type Frame = ([Option<usize>; 3], [Option<usize>; 3], [[f64; 3]; 3]);

impl NodalFrames {
    /// The frames of the walls' nodes (per row, in row order), or `None` when a wall node lies
    /// on two walls or has a prescribed DOF other than its axial one on an axis along x, y or z
    /// (the plane-strain and symmetry-plane supports keep the frame exact: the prescribed
    /// component is the frame's axial one).
    pub fn new(walls: &[Wall], dofs: &DofMap) -> Option<NodalFrames> {
        let mut at = vec![None; dofs.n_eq()];
        let mut is_radial = vec![false; dofs.n_eq()];
        let mut frames = Vec::new();
        for w in walls {
            for (a, &nd) in w.nodes.iter().enumerate() {
                let cart: [Option<usize>; 3] = std::array::from_fn(|j| dofs.eq(3 * nd + j));
                let (e, t) = (w.e[a], w.axis);
                let slots = match cart.iter().filter(|q| q.is_none()).count() {
                    0 => cart,
                    1 => {
                        let j = cart.iter().position(|q| q.is_none())?;
                        if t[j].abs() < 1.0 - 1e-12 {
                            return None;
                        }
                        let mut free = cart.iter().flatten().copied();
                        [free.next(), free.next(), None]
                    }
                    _ => return None,
                };
                for (j, &q) in cart
                    .iter()
                    .enumerate()
                    .filter_map(|(j, q)| q.as_ref().map(|q| (j, q)))
                {
                    if at[q].is_some() {
                        return None;
                    }
                    at[q] = Some((frames.len(), j));
                }
                is_radial[slots[0]?] = true;
                let s = cross(t, e);
                let r = std::array::from_fn(|i| [e[i], s[i], t[i]]);
                frames.push((cart, slots, r));
            }
        }
        Some(NodalFrames {
            at,
            is_radial,
            frames,
        })
    }

    /// The radial equation of each frame (row order).
    pub fn radial(&self) -> Vec<usize> {
        self.frames
            .iter()
            .map(|f| f.1[0].expect("a radial slot"))
            .collect()
    }

    /// `order` (`order[new] = old`) with the radial equations moved last, in row order.
    pub fn order_last(&self, order: &[usize]) -> Vec<usize> {
        let mut out: Vec<usize> = order
            .iter()
            .copied()
            .filter(|&q| !self.is_radial[q])
            .collect();
        out.extend(self.radial());
        out
    }

    /// K' = Tᵀ K T on the upper triangle; `None` if the pattern lacks an entry of a node block.
    pub fn rotate_matrix(&self, k: &SparseSym) -> Option<SparseSym> {
        let mut values = k.values.clone();
        let touched = |p: usize| self.at[p].is_some();
        for q in 0..k.n {
            let range = k.col_ptr[q]..k.col_ptr[q + 1];
            for (v, &p) in values[range.clone()].iter_mut().zip(&k.row_idx[range]) {
                if touched(p) || touched(q) {
                    *v = 0.0;
                }
            }
        }
        // T's entries of row p (u_p = Σ T_pp' v_p'): (p', T_pp')
        let t_row = |p: usize| -> Vec<(usize, f64)> {
            match self.at[p] {
                Some((f, alpha)) => {
                    let (_, slots, r) = &self.frames[f];
                    (0..3)
                        .filter_map(|beta| slots[beta].map(|q| (q, r[alpha][beta])))
                        .collect()
                }
                None => vec![(p, 1.0)],
            }
        };
        for q in 0..k.n {
            for i in k.col_ptr[q]..k.col_ptr[q + 1] {
                let p = k.row_idx[i];
                if !(touched(p) || touched(q)) {
                    continue;
                }
                let v = k.values[i];
                let orientations: &[(usize, usize)] =
                    if p == q { &[(p, q)] } else { &[(p, q), (q, p)] };
                for &(a, b) in orientations {
                    for (a2, ta) in t_row(a) {
                        for (b2, tb) in t_row(b) {
                            if a2 > b2 || ta == 0.0 || tb == 0.0 {
                                continue;
                            }
                            let col = &k.row_idx[k.col_ptr[b2]..k.col_ptr[b2 + 1]];
                            let pos = col.binary_search(&a2).ok()?;
                            values[k.col_ptr[b2] + pos] += ta * v * tb;
                        }
                    }
                }
            }
        }
        Some(SparseSym {
            n: k.n,
            col_ptr: k.col_ptr.clone(),
            row_idx: k.row_idx.clone(),
            values,
        })
    }

    /// x ↦ Tᵀ x (`to_nodal`) or x ↦ T x, in place, on a vector of equations.
    pub fn rotate(&self, x: &mut [f64], to_nodal: bool) {
        for (cart, slots, r) in &self.frames {
            let (from, to) = if to_nodal {
                (cart, slots)
            } else {
                (slots, cart)
            };
            let u = from.map(|q| q.map_or(0.0, |q| x[q]));
            for i in 0..3 {
                if let Some(q) = to[i] {
                    x[q] = (0..3)
                        .map(|j| if to_nodal { r[j][i] } else { r[i][j] } * u[j])
                        .sum();
                }
            }
        }
    }
}

/// How the columns of S are computed.
pub enum Compliance {
    /// From the trailing block L₂₂ of the factor of K' (radial equations last).
    Trailing {
        /// Per row: (trailing index of node a's radial equation, D_ba) over the row's weights.
        c_r: Vec<Vec<(usize, f64)>>,
        /// L₂₂.
        l22: faer::Mat<f64>,
    },
    /// One solve with the factor of K per column, `BLOCK` at a time.
    Solves {
        /// Equations.
        n_eq: usize,
        /// Per row: (equation, coefficient) of C.
        c: Vec<Vec<(usize, f64)>>,
    },
}

impl Compliance {
    /// From the factor of K' ordered by [`NodalFrames::order_last`] (`radial`: the radial
    /// equation of each frame, in row order).
    pub fn trailing(
        factor: &CholeskyFactor,
        walls: &[Wall],
        radial: &[usize],
    ) -> Result<Compliance> {
        let m = radial.len();
        let (old, l22) = factor.trailing_block(m);
        let mut pos = std::collections::HashMap::with_capacity(m);
        for (i, &q) in old.iter().enumerate() {
            pos.insert(q, i);
        }
        let mut c_r = Vec::with_capacity(m);
        let mut base = 0;
        for w in walls {
            for b in 0..w.len() {
                let row = w.weights[b]
                    .iter()
                    .map(|&(a, d)| {
                        pos.get(&radial[base + a]).map(|&i| (i, d)).ok_or_else(|| {
                            FemError::Solver(
                                "contact: a radial equation is not among the factor's last \
                                     (ordering not kept)"
                                    .into(),
                            )
                        })
                    })
                    .collect::<Result<Vec<_>>>()?;
                c_r.push(row);
            }
            base += w.len();
        }
        Ok(Compliance::Trailing { c_r, l22 })
    }

    /// Columns solved one by one with the factor of K (unrotated); `eqs[w][a]`: the equations
    /// of wall w's node a.
    pub fn solves(n_eq: usize, walls: &[Wall], eqs: &[Vec<[Option<usize>; 3]>]) -> Compliance {
        let c = walls
            .iter()
            .enumerate()
            .flat_map(|(wi, w)| {
                (0..w.len()).map(move |b| {
                    w.weights[b]
                        .iter()
                        .flat_map(|&(a, d)| {
                            (0..3).filter_map(move |j| eqs[wi][a][j].map(|q| (q, d * w.e[a][j])))
                        })
                        .collect()
                })
            })
            .collect();
        Compliance::Solves { n_eq, c }
    }

    /// The columns S[:, j] (each of length m) of the rows `js`; `factor` is K's (used by
    /// [`Compliance::Solves`] only).
    pub fn columns(&self, factor: &CholeskyFactor, js: &[usize]) -> Vec<Vec<f64>> {
        let apply = |c: &[Vec<(usize, f64)>], x: &dyn Fn(usize) -> f64| -> Vec<f64> {
            c.iter()
                .map(|row| row.iter().map(|&(i, d)| d * x(i)).sum())
                .collect()
        };
        match self {
            Compliance::Trailing { c_r, l22 } => {
                let m = c_r.len();
                let mut x = faer::Mat::<f64>::zeros(m, js.len());
                for (col, &j) in js.iter().enumerate() {
                    for &(i, d) in &c_r[j] {
                        x[(i, col)] += d;
                    }
                }
                let par = Par::rayon(0);
                solve_lower_triangular_in_place(l22.as_ref(), x.as_mut(), par);
                solve_upper_triangular_in_place(l22.transpose(), x.as_mut(), par);
                (0..js.len())
                    .map(|col| apply(c_r, &|i| x[(i, col)]))
                    .collect()
            }
            Compliance::Solves { n_eq, c } => {
                let mut out = Vec::with_capacity(js.len());
                for chunk in js.chunks(BLOCK) {
                    let mut rhs = vec![0.0; n_eq * chunk.len()];
                    for (col, &j) in chunk.iter().enumerate() {
                        for &(q, v) in &c[j] {
                            rhs[col * n_eq + q] += v;
                        }
                    }
                    factor.solve_in_place(&mut rhs, chunk.len());
                    for col in 0..chunk.len() {
                        let x = &rhs[col * n_eq..(col + 1) * n_eq];
                        out.push(apply(c, &|q| x[q]));
                    }
                }
                out
            }
        }
    }
}
