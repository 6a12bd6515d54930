//! The crate's one small dense LU: solves with, and rank diagnosis of, the fixed-size
//! constraint Jacobian of the multibody core (`crate::mechanism`, [`Factorization`]) and the
//! iteration matrices `I − c J` of the implicit integrators (`crate::integrators`, dynamic
//! size: [`DenseLu<Dyn>`](DenseLu)).
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

use nalgebra::allocator::Allocator;
use nalgebra::{Const, DMatrix, DefaultAllocator, DimMin, FullPivLU, LU, OMatrix, OVector};

/// nalgebra's LU of a square matrix of dimension `D` (`Const<N>` or `Dyn`), partial or
/// complete pivoting.
#[derive(Clone, Debug)]
pub enum DenseLu<D>
where
    D: DimMin<D, Output = D>,
    DefaultAllocator: Allocator<D, D> + Allocator<D>,
{
    /// Partial pivoting (`lu()`, P A = L U); its relative pivot is an
    /// indicator only, rank decisions near singularity use complete pivoting.
    Partial(LU<f64, D, D>),
    /// Complete pivoting (`full_piv_lu()`, P A Q = L U), rank-revealing.
    Full(FullPivLU<f64, D, D>),
}

/// The LU of the N×N constraint Jacobian (stack-allocated).
pub type Factorization<const N: usize> = DenseLu<Const<N>>;

/// min |u_kk| / max |u_kk| over the diagonal of `u` (only the diagonal is
/// read); 0 when a pivot is zero or not finite.
fn pivot_ratio<D>(u: &OMatrix<f64, D, D>) -> f64
where
    D: DimMin<D, Output = D>,
    DefaultAllocator: Allocator<D, D> + Allocator<D>,
{
    let d = u.diagonal().abs();
    if d.iter().all(|v| v.is_finite()) && d.min() > 0.0 {
        d.min() / d.max()
    } else {
        0.0
    }
}

impl<D> DenseLu<D>
where
    D: DimMin<D, Output = D>,
    DefaultAllocator: Allocator<D, D> + Allocator<D>,
{
    /// The packed factors (L below, U on and above the diagonal) via
    /// nalgebra's `lu_internal()`, which is public but `#[doc(hidden)]`: the
    /// documented `u()` and `unpack()` copy U, at about half the cost of the
    /// LU itself, once per Newton iterate.
    fn packed(&self) -> &OMatrix<f64, D, D> {
        match self {
            DenseLu::Partial(f) => f.lu_internal(),
            DenseLu::Full(f) => f.lu_internal(),
        }
    }

    /// min |u_kk| / max |u_kk| of this factorisation's U.
    pub fn pivot_ratio(&self) -> f64 {
        pivot_ratio(self.packed())
    }

    /// nalgebra's `is_invertible`: no pivot is exactly zero.
    pub fn is_invertible(&self) -> bool {
        match self {
            DenseLu::Partial(f) => f.is_invertible(),
            DenseLu::Full(f) => f.is_invertible(),
        }
    }

    /// nalgebra's `solve_mut`: `false` (and `x` garbage) when A is exactly singular.
    fn solve_in_place(&self, x: &mut OVector<f64, D>) -> bool {
        match self {
            DenseLu::Partial(f) => f.solve_mut(x),
            DenseLu::Full(f) => f.solve_mut(x),
        }
    }

    /// Solve A x = b in place (nalgebra's `solve_mut`); `false` when A is exactly singular
    /// or the result is not finite.
    pub fn solve_mut(&self, b: &mut OVector<f64, D>) -> bool {
        self.solve_in_place(b) && b.iter().all(|v| v.is_finite())
    }

    /// Solve A x = b (nalgebra's `solve_mut`); NaN when A is exactly singular.
    pub fn solve(&self, b: &OVector<f64, D>) -> OVector<f64, D> {
        let mut x = b.clone();
        if !self.solve_in_place(&mut x) {
            x.fill(f64::NAN);
        }
        x
    }

    /// Solve Aᵀ x = b, which nalgebra's LU does not offer: with P A Q = L U
    /// (Q = I for partial pivoting), x = Pᵀ L⁻ᵀ U⁻ᵀ Qᵀ b by nalgebra's
    /// transposed triangular solves; NaN when A is exactly singular.
    pub fn solve_transpose(&self, b: &OVector<f64, D>) -> OVector<f64, D> {
        let mut x = b.clone();
        let (p, l) = match self {
            DenseLu::Partial(f) => (f.p(), f.l()),
            DenseLu::Full(f) => {
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
    use nalgebra::{DVector, Matrix4, Vector4};

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

    #[test]
    fn dynamic_size_solves_and_reports_singular_or_non_finite() {
        let a = DMatrix::from_column_slice(4, 4, sample().as_slice());
        let b = DVector::from_vec(vec![1.0, -2.0, 0.5, 3.0]);
        let lu = DenseLu::Partial(a.clone().lu());
        let mut x = b.clone();
        assert!(lu.is_invertible() && lu.solve_mut(&mut x));
        assert!((&a * &x - &b).norm() < 1e-13);
        assert!((a.transpose() * lu.solve_transpose(&b) - &b).norm() < 1e-13);
        let zero = DenseLu::Partial(DMatrix::<f64>::zeros(3, 3).lu());
        assert!(!zero.is_invertible());
        assert!(!zero.solve_mut(&mut DVector::from_element(3, 1.0)));
        // invertible, but the solution overflows
        let tiny = DenseLu::Partial(DMatrix::from_diagonal_element(2, 2, 1e-300).lu());
        assert!(tiny.is_invertible());
        assert!(!tiny.solve_mut(&mut DVector::from_element(2, 1e300)));
    }
}
