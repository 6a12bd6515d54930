//! Solves with, and rank diagnosis of, the fixed-size constraint Jacobian.
//!
//! From nalgebra (stack-allocated for `SMatrix`, no heap): the
//! factorisations [`LU`] (partial row pivoting, P A = L U) and [`FullPivLU`]
//! (complete pivoting, P A Q = L U), their `solve_mut` for A x = b, their
//! factors and permutations, and the triangular solves. Added here, as
//! nalgebra has no such methods: the relative pivot min|u_kk| / max|u_kk|
//! (with complete pivoting a reliable indicator of numerical rank deficiency,
//! Golub & Van Loan, *Matrix Computations*, §3.4.8), the transposed solve
//! Aᵀ x = b from the same factors (Lagrange multipliers, Dᵀλ = M c̈ − h), and
//! the Gram–Schmidt search for the dependent row. nalgebra's LU needs
//! `Const<N>: DimMin<Const<N>>`, i.e. N ≤ 127.

use nalgebra::{Const, DMatrix, DimMin, FullPivLU, LU, SMatrix, SVector};

/// nalgebra's LU of an N×N matrix, partial or complete pivoting.
#[derive(Clone, Debug)]
pub enum Factorization<const N: usize>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    /// Partial pivoting (`SMatrix::lu`, P A = L U); its relative pivot is an
    /// indicator only, rank decisions near singularity use complete pivoting.
    Partial(LU<f64, Const<N>, Const<N>>),
    /// Complete pivoting (`SMatrix::full_piv_lu`, P A Q = L U), rank-revealing.
    Full(FullPivLU<f64, Const<N>, Const<N>>),
}

/// min |u_kk| / max |u_kk| over the diagonal of `u` (only the diagonal is
/// read); 0 when a pivot is zero or not finite.
fn pivot_ratio<const N: usize>(u: &SMatrix<f64, N, N>) -> f64 {
    let d = u.diagonal().abs();
    if d.iter().all(|v| v.is_finite()) && d.min() > 0.0 {
        d.min() / d.max()
    } else {
        0.0
    }
}

impl<const N: usize> Factorization<N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    /// The packed factors (L below, U on and above the diagonal) via
    /// nalgebra's `lu_internal()`, which is public but `#[doc(hidden)]`: the
    /// documented `u()` and `unpack()` copy U, at about half the cost of the
    /// LU itself, once per Newton iterate.
    fn packed(&self) -> &SMatrix<f64, N, N> {
        match self {
            Factorization::Partial(f) => f.lu_internal(),
            Factorization::Full(f) => f.lu_internal(),
        }
    }

    /// min |u_kk| / max |u_kk| of this factorisation's U.
    pub fn pivot_ratio(&self) -> f64 {
        pivot_ratio(self.packed())
    }

    /// Solve A x = b (nalgebra's `solve_mut`); NaN when A is exactly singular.
    pub fn solve(&self, b: &SVector<f64, N>) -> SVector<f64, N> {
        let mut x = *b;
        let ok = match self {
            Factorization::Partial(f) => f.solve_mut(&mut x),
            Factorization::Full(f) => f.solve_mut(&mut x),
        };
        if !ok {
            x.fill(f64::NAN);
        }
        x
    }

    /// Solve Aᵀ x = b, which nalgebra's LU does not offer: with P A Q = L U
    /// (Q = I for partial pivoting), x = Pᵀ L⁻ᵀ U⁻ᵀ Qᵀ b by nalgebra's
    /// transposed triangular solves; NaN when A is exactly singular.
    pub fn solve_transpose(&self, b: &SVector<f64, N>) -> SVector<f64, N> {
        let mut x = *b;
        let (p, l) = match self {
            Factorization::Partial(f) => (f.p(), f.l()),
            Factorization::Full(f) => {
                f.q().permute_rows(&mut x);
                (f.p(), f.l())
            }
        };
        // the packed matrix's upper triangle is U; `l()` has the unit diagonal
        if self.packed().tr_solve_upper_triangular_mut(&mut x)
            && l.tr_solve_lower_triangular_mut(&mut x)
        {
            p.inv_permute_rows(&mut x);
        } else {
            x.fill(f64::NAN);
        }
        x
    }
}

/// Diagnose which row of a (scaled) constraint Jacobian is linearly dependent
/// on the rows *before* it: modified Gram–Schmidt over the rows in order; the
/// row whose remainder is smallest relative to its own norm is returned,
/// together with that relative remainder. Used only on the error path, so it
/// may allocate; works for any number of rows.
pub fn most_dependent_row(rows: &DMatrix<f64>) -> (usize, f64) {
    let (m, n) = rows.shape();
    let mut basis: Vec<nalgebra::DVector<f64>> = Vec::with_capacity(m);
    let (mut worst, mut worst_ratio) = (0usize, f64::INFINITY);
    for k in 0..m {
        let row = rows.row(k).transpose();
        let norm = row.norm();
        let mut v = row.clone_owned();
        for b in &basis {
            let c = v.dot(b);
            v.axpy(-c, b, 1.0);
        }
        let rem = v.norm();
        let ratio = if norm > 0.0 { rem / norm } else { 0.0 };
        if ratio < worst_ratio {
            worst_ratio = ratio;
            worst = k;
        }
        if rem > 1e-13 * norm.max(f64::MIN_POSITIVE) && basis.len() < n {
            basis.push(v / rem);
        }
    }
    (worst, worst_ratio)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix4, Vector4};

    fn sample() -> Matrix4<f64> {
        Matrix4::new(
            2.0, -1.0, 0.0, 3.0, //
            0.5, 4.0, 1.0, 0.0, //
            0.0, 1.0, -3.0, 2.0, //
            1.0, 0.0, 2.0, 1.0,
        )
    }

    #[test]
    fn solves_and_transposed_solves_of_both_pivotings() {
        let (a, b) = (sample(), Vector4::new(1.0, -2.0, 0.5, 3.0));
        for lu in [
            Factorization::Partial(a.lu()),
            Factorization::Full(a.full_piv_lu()),
        ] {
            assert!((a * lu.solve(&b) - b).norm() < 1e-13);
            assert!((a.transpose() * lu.solve_transpose(&b) - b).norm() < 1e-13);
            assert!(lu.pivot_ratio() > 0.01);
        }
    }

    #[test]
    fn singular_matrix_has_tiny_pivot_ratio_and_dependent_row_found() {
        let mut a = sample();
        // row 3 = row 0 + 2 row 1: rank 3
        let r = a.row(0) + a.row(1) * 2.0;
        a.set_row(3, &r);
        assert!(Factorization::Full(a.full_piv_lu()).pivot_ratio() < 1e-14);
        assert!(Factorization::Partial(a.lu()).pivot_ratio() < 1e-14);
        let (row, ratio) = most_dependent_row(&DMatrix::from_column_slice(4, 4, a.as_slice()));
        assert_eq!((row, ratio < 1e-14), (3, true));
        let zero = Matrix4::<f64>::zeros();
        assert_eq!(Factorization::Full(zero.full_piv_lu()).pivot_ratio(), 0.0);
        assert_eq!(Factorization::Partial(zero.lu()).pivot_ratio(), 0.0);
        assert!(Factorization::Full(zero.full_piv_lu()).solve(&Vector4::x())[0].is_nan());
        assert!(Factorization::Partial(zero.lu()).solve_transpose(&Vector4::x())[0].is_nan());
        let mut nan = sample();
        nan[(1, 1)] = f64::NAN;
        assert_eq!(Factorization::Full(nan.full_piv_lu()).pivot_ratio(), 0.0);
        assert_eq!(Factorization::Partial(nan.lu()).pivot_ratio(), 0.0);
    }
}
