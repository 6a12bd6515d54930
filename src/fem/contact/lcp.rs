//! The contact problem condensed on the contact rows: a mixed linear complementarity problem
//! solved by the primal–dual active-set method.
//!
//! With the compliance S = C K⁻¹ Cᵀ of the contact rows (m × m, symmetric positive definite),
//! the free gaps h, the free unknowns η (rigid motions and pin translations) entering the gaps
//! through E (m × n_e) and their equilibrium right-hand side q, the discrete contact problem is
//!
//! G = S λ + E η + h ≥ 0,  λ ≥ 0,  λ_j G_j = 0 (every j),  Eᵀ λ = q,
//!
//! the optimality system of the strictly convex quadratic programme min ½ λᵀSλ + hᵀλ subject to
//! λ ≥ 0, Eᵀλ = q (the dual of the contact problem; Kikuchi & Oden, *Contact Problems in
//! Elasticity*, SIAM 1988, ch. 6), which has one solution when E has full column rank on the
//! active rows. The primal–dual active-set method (M. Hintermüller, K. Ito, K. Kunisch, SIAM J.
//! Optim. 13 (2002) 865–888: a semi-smooth Newton method on λ − max(0, λ − cG) = 0; S. Hüeber,
//! B. I. Wohlmuth, CMAME 194 (2005) for contact) guesses the active set A, solves
//!
//! S_AA λ_A + E_A η = −h_A,  E_Aᵀ λ_A = q,  λ_I = 0,
//!
//! and updates A = {j ∈ A : λ_j > 0} ∪ {j ∉ A : G_j < −ε}; it stops when A repeats — then
//! λ ≥ 0 and G_I ≥ −ε hold by construction and G_A = 0 to round-off. The saddle-point system is
//! solved through the Cholesky factor of S_AA and the small Schur complement
//! H = E_Aᵀ S_AA⁻¹ E_A. A revisited active set (a cycle), an iteration limit, a non-positive S_AA
//! or a near-singular H (the active contact cannot carry the load or hold the body) is an error.
//!
//! Only the columns of S on rows that are ever active are computed, through the callback
//! `columns` ([`super::compliance`]).

use std::collections::HashSet;

use nalgebra::{DMatrix, DVector};

use crate::fem::error::{FemError, Result};

/// The condensed problem.
#[derive(Clone, Debug)]
pub struct MixedLcp {
    /// Free gaps h (the weighted gaps with λ = 0, η = 0), m³.
    pub h: Vec<f64>,
    /// E, row by row (each of length n_e).
    pub e: Vec<Vec<f64>>,
    /// Right-hand side of Eᵀλ = q.
    pub q: Vec<f64>,
    /// The first guess of the active set.
    pub initial: Vec<bool>,
    /// ε of the update: an inactive row joins when its weighted gap is below −ε.
    pub gap_tol: f64,
    /// Iteration limit.
    pub max_iterations: usize,
}

/// The solution of [`MixedLcp`].
#[derive(Clone, Debug)]
pub struct LcpSolution {
    /// λ (Pa), zero off the active set.
    pub lambda: Vec<f64>,
    /// η.
    pub eta: Vec<f64>,
    /// Weighted gaps G at the solution.
    pub g: Vec<f64>,
    /// Active set.
    pub active: Vec<bool>,
    /// Active-set iterations.
    pub iterations: usize,
    /// Columns of S computed.
    pub columns: usize,
}

/// The callback that returns the columns S[:, j] of the rows `js`.
pub type Columns<'a> = dyn FnMut(&[usize]) -> Result<Vec<Vec<f64>>> + 'a;

/// Solves `p`; `columns(js)` returns the columns S[:, j] (each of length m) of the rows `js`.
///
/// The primal–dual step changes every violated row at once; it can revisit an active set (a
/// cycle: on a few percent of rods, at instants whose force is nearly tangent to the pressed
/// arc). From the first active set seen twice the iteration changes one row per step instead,
/// the violated row of least index (Murty's least-index rule, K. G. Murty, *Linear
/// Complementarity, Linear and Nonlinear Programming*, 1988, §2.2 and §4.2: finite for the
/// positive definite S), within [`single_row_budget`] steps.
pub fn solve(p: &MixedLcp, columns: &mut Columns<'_>) -> Result<LcpSolution> {
    let m = p.h.len();
    let mut cache: Vec<Option<Vec<f64>>> = vec![None; m];
    let mut n_cols = 0;
    let mut active = p.initial.clone();
    let mut seen: HashSet<Vec<usize>> = HashSet::new();
    let mut one_row_from: Option<usize> = None;
    let limit = p.max_iterations + single_row_budget(m);
    for it in 1..=limit {
        let act: Vec<usize> = (0..m).filter(|&j| active[j]).collect();
        if one_row_from.is_none() && !seen.insert(act.clone()) {
            one_row_from = Some(it);
        }
        if one_row_from.is_none() && it > p.max_iterations {
            break;
        }
        let missing: Vec<usize> = act
            .iter()
            .copied()
            .filter(|&j| cache[j].is_none())
            .collect();
        if !missing.is_empty() {
            for (j, col) in missing.iter().zip(columns(&missing)?) {
                cache[*j] = Some(col);
            }
            n_cols += missing.len();
        }
        let (lambda_a, eta) = solve_active(p, &act, &cache)?;
        let mut g = p.h.clone();
        for (k, &j) in act.iter().enumerate() {
            let col = cache[j].as_ref().expect("column computed");
            for (gi, c) in g.iter_mut().zip(col) {
                *gi += c * lambda_a[k];
            }
        }
        for (gi, row) in g.iter_mut().zip(&p.e) {
            *gi += row.iter().zip(&eta).map(|(a, b)| a * b).sum::<f64>();
        }
        let mut lambda = vec![0.0; m];
        for (k, &j) in act.iter().enumerate() {
            lambda[j] = lambda_a[k];
        }
        // a row is violated when active without pressure or inactive and penetrating
        let violated = |j: usize| {
            if active[j] {
                lambda[j] <= 0.0
            } else {
                g[j] < -p.gap_tol
            }
        };
        let flip: Vec<usize> = match one_row_from {
            None => (0..m).filter(|&j| violated(j)).collect(),
            Some(_) => (0..m).find(|&j| violated(j)).into_iter().collect(),
        };
        if flip.is_empty() {
            return Ok(LcpSolution {
                lambda,
                eta,
                g,
                active,
                iterations: it,
                columns: n_cols,
            });
        }
        for j in flip {
            active[j] = !active[j];
        }
    }
    Err(FemError::Solver(match one_row_from {
        Some(k) => format!(
            "contact: no converged active set after {limit} iterations (the primal–dual steps \
             cycled at iteration {k}, then one row per step)"
        ),
        None => format!(
            "contact: no converged active set after {} iterations",
            p.max_iterations
        ),
    }))
}

/// The steps of one row each allowed after a cycle, for m contact rows: 4 m + 200.
pub fn single_row_budget(m: usize) -> usize {
    4 * m + 200
}

/// Solves the saddle-point system of the active rows `act`: (λ_A, η).
fn solve_active(
    p: &MixedLcp,
    act: &[usize],
    cache: &[Option<Vec<f64>>],
) -> Result<(Vec<f64>, Vec<f64>)> {
    let na = act.len();
    let ne = p.q.len();
    if na == 0 {
        if p.q.iter().any(|v| *v != 0.0) {
            return Err(FemError::Solver(
                "contact: no contact row is active, so the pins carry no force and hold \
                 nothing; the load or the support cannot be carried"
                    .into(),
            ));
        }
        return Ok((Vec::new(), vec![0.0; ne]));
    }
    let s = DMatrix::from_fn(na, na, |r, c| {
        cache[act[c]].as_ref().expect("column computed")[act[r]]
    });
    let chol = s.cholesky().ok_or_else(|| {
        FemError::Solver(
            "contact: the compliance of the active contact rows is not positive definite \
             (coincident or dependent contact nodes)"
                .into(),
        )
    })?;
    let h_a = DVector::from_fn(na, |r, _| -p.h[act[r]]);
    let y0 = chol.solve(&h_a);
    if ne == 0 {
        return Ok((y0.iter().copied().collect(), Vec::new()));
    }
    let e_a = DMatrix::from_fn(na, ne, |r, c| p.e[act[r]][c]);
    let x = chol.solve(&e_a);
    let h = e_a.transpose() * &x;
    let eig = h.clone().symmetric_eigen();
    let (lo, hi) = (eig.eigenvalues.min(), eig.eigenvalues.max());
    if lo.partial_cmp(&(1e-12 * hi)) != Some(std::cmp::Ordering::Greater) {
        return Err(FemError::Solver(format!(
            "contact: near-singular — the {na} active contact rows cannot carry the pin forces \
             or hold the body's rigid motion (Schur complement eigenvalues {lo:.3e} … {hi:.3e}); \
             a pin pressing where there is no wall, or a body held by nothing"
        )));
    }
    let rhs = e_a.transpose() * &y0 - DVector::from_column_slice(&p.q);
    let eta = h
        .cholesky()
        .expect("positive definite, checked")
        .solve(&rhs);
    let lambda = y0 - x * &eta;
    Ok((
        lambda.iter().copied().collect(),
        eta.iter().copied().collect(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two springs in series pressed on two obstacles: the closed form is checked by hand.
    #[test]
    fn a_small_problem_gives_the_hand_solution_and_rejects_a_load_nothing_carries() {
        // S = [[2, 1], [1, 2]], h = [-1, 1]: row 0 penetrates, row 1 is open. With λ₁ = 0,
        // G₀ = 2λ₀ − 1 = 0 → λ₀ = 1/2, G₁ = 1/2 + 1 > 0.
        let s = [[2.0, 1.0], [1.0, 2.0]];
        let p = MixedLcp {
            h: vec![-1.0, 1.0],
            e: vec![vec![], vec![]],
            q: vec![],
            initial: vec![false, true],
            gap_tol: 1e-14,
            max_iterations: 10,
        };
        let mut cols = |js: &[usize]| Ok(js.iter().map(|&j| vec![s[0][j], s[1][j]]).collect());
        let sol = solve(&p, &mut cols).unwrap();
        assert_eq!(sol.active, vec![true, false]);
        assert!((sol.lambda[0] - 0.5).abs() < 1e-15 && sol.lambda[1] == 0.0);
        assert!((sol.g[1] - 1.5).abs() < 1e-15);
        // with the equality λ₀ + λ₁ = 1 and a free η (G = Sλ + η + h): both rows active give
        // λ₀ − λ₁ = 2, so λ₁ = −1/2 < 0 and row 1 opens; then λ₀ = 1, 2λ₀ + η = 1 → η = −1,
        // and G₁ = λ₀ + η + 1 = 1 ≥ 0
        let p2 = MixedLcp {
            h: vec![-1.0, 1.0],
            e: vec![vec![1.0], vec![1.0]],
            q: vec![1.0],
            initial: vec![true, true],
            gap_tol: 1e-14,
            max_iterations: 10,
        };
        let sol = solve(&p2, &mut cols).unwrap();
        assert_eq!(sol.active, vec![true, false]);
        assert!((sol.lambda[0] - 1.0).abs() < 1e-15);
        assert!((sol.eta[0] + 1.0).abs() < 1e-15);
        assert!((sol.g[1] - 1.0).abs() < 1e-15);
        // the same equality with no row active: refused
        let p3 = MixedLcp {
            initial: vec![false, false],
            h: vec![1.0, 1.0],
            ..p2
        };
        assert!(solve(&p3, &mut cols).is_err());
    }

    /// A 4 × 4 problem (S positive definite, found by a random search) on which the primal–dual
    /// step revisits an active set after 5 iterations from {1}: the solver goes on one row at a
    /// time and ends on the solution that enumerating all 16 active sets finds.
    #[test]
    fn a_cycling_active_set_goes_on_one_row_at_a_time_to_the_enumerated_solution() {
        let s = [
            [
                2.1206879260352607,
                2.5238103469631925,
                0.9634510555535551,
                -1.4234791134503073,
            ],
            [
                2.5238103469631925,
                10.186666440829669,
                -3.537028467508728,
                -5.693043391026131,
            ],
            [
                0.9634510555535551,
                -3.537028467508728,
                5.344608830857218,
                2.8140602277952165,
            ],
            [
                -1.4234791134503073,
                -5.693043391026131,
                2.8140602277952165,
                3.663641169282786,
            ],
        ];
        let h = vec![
            -3.0279976101113615,
            0.3138043698218066,
            -1.8419315660222617,
            0.19337881476054206,
        ];
        let p = MixedLcp {
            h: h.clone(),
            e: vec![vec![]; 4],
            q: vec![],
            initial: vec![false, true, false, false],
            gap_tol: 1e-14,
            max_iterations: 60,
        };
        let mut cols = |js: &[usize]| {
            Ok(js
                .iter()
                .map(|&j| (0..4).map(|i| s[i][j]).collect())
                .collect())
        };
        // the reference: the one active set whose λ ≥ 0 and G ≥ 0
        let mut reference = None;
        for mask in 0u32..16 {
            let a: Vec<usize> = (0..4).filter(|j| mask & (1 << j) != 0).collect();
            let mut lam = [0.0; 4];
            if a.is_empty() {
                if h.iter().all(|v| *v >= 0.0) {
                    reference = Some(lam);
                }
                continue;
            }
            let sa = DMatrix::from_fn(a.len(), a.len(), |r, c| s[a[r]][a[c]]);
            let la = sa
                .lu()
                .solve(&DVector::from_fn(a.len(), |r, _| -h[a[r]]))
                .unwrap();
            for (k, &j) in a.iter().enumerate() {
                lam[j] = la[k];
            }
            let g: Vec<f64> = (0..4)
                .map(|i| h[i] + (0..4).map(|j| s[i][j] * lam[j]).sum::<f64>())
                .collect();
            if lam.iter().all(|l| *l >= 0.0) && g.iter().all(|v| *v >= -1e-12) {
                reference = Some(lam);
            }
        }
        let reference = reference.expect("a solution");
        let sol = solve(&p, &mut cols).unwrap();
        assert!(sol.iterations > 5, "{}", sol.iterations);
        for j in 0..4 {
            assert!(
                (sol.lambda[j] - reference[j]).abs() < 1e-12,
                "{:?} {reference:?}",
                sol.lambda
            );
            assert!(sol.g[j] >= -1e-12 && sol.lambda[j] * sol.g[j].abs() < 1e-12);
        }
    }
}
