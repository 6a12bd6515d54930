//! Rank-revealing LU factorisation with complete pivoting for the fixed-size
//! constraint Jacobian (no heap allocation).
//!
//! P A Q = L U with L unit lower triangular; complete pivoting makes the
//! pivots |u_kk| non-increasing, so min|u_kk| / max|u_kk| is a cheap, reliable
//! indicator of numerical rank deficiency (Golub & Van Loan, *Matrix
//! Computations*, §3.4.8). The same factorisation serves A x = b (velocity and
//! acceleration equations) and Aᵀ x = b (Lagrange multipliers, Dᵀλ = M c̈ − h).

use nalgebra::{DMatrix, SMatrix, SVector};

/// Complete-pivoting LU of an N×N matrix (stored column-major in a plain
/// array so that the inner loops run over slices without index checks).
#[derive(Clone, Debug)]
pub struct FullPivLu<const N: usize> {
    /// `lu[j][i]` = entry (i, j) of L (below the diagonal) and U (on/above).
    lu: [[f64; N]; N],
    /// Row k of P A is row `rows[k]` of A.
    rows: [usize; N],
    /// Column k of A Q is column `cols[k]` of A.
    cols: [usize; N],
    /// min |u_kk| / max |u_kk| (0 when exactly singular or not finite).
    pivot_ratio: f64,
}

impl<const N: usize> FullPivLu<N> {
    /// Factorise `m`.
    pub fn new(m: SMatrix<f64, N, N>) -> Self {
        let mut a: [[f64; N]; N] = m.data.0;
        let mut rows = [0usize; N];
        let mut cols = [0usize; N];
        for k in 0..N {
            rows[k] = k;
            cols[k] = k;
        }
        let mut max_pivot = 0.0f64;
        let mut min_pivot = f64::INFINITY;
        let finite = a.iter().flatten().all(|v| v.is_finite());
        for k in 0..N {
            if !finite {
                break;
            }
            // complete pivot search in the trailing block
            let (mut p, mut q, mut best) = (k, k, -1.0f64);
            for (j, col) in a.iter().enumerate().skip(k) {
                for (i, v) in col.iter().enumerate().skip(k) {
                    let v = v.abs();
                    if v > best {
                        best = v;
                        p = i;
                        q = j;
                    }
                }
            }
            if q != k {
                a.swap(q, k);
                cols.swap(q, k);
            }
            if p != k {
                for col in a.iter_mut() {
                    col.swap(p, k);
                }
                rows.swap(p, k);
            }
            max_pivot = max_pivot.max(best);
            min_pivot = min_pivot.min(best);
            if best == 0.0 {
                break;
            }
            let (left, right) = a.split_at_mut(k + 1);
            let colk = &mut left[k];
            let inv = 1.0 / colk[k];
            for v in colk[k + 1..].iter_mut() {
                *v *= inv;
            }
            for colj in right.iter_mut() {
                let akj = colj[k];
                if akj != 0.0 {
                    for (x, l) in colj[k + 1..].iter_mut().zip(colk[k + 1..].iter()) {
                        *x -= l * akj;
                    }
                }
            }
        }
        let pivot_ratio = if finite && max_pivot > 0.0 && min_pivot.is_finite() {
            min_pivot / max_pivot
        } else {
            0.0
        };
        FullPivLu {
            lu: a,
            rows,
            cols,
            pivot_ratio,
        }
    }

    /// min |u_kk| / max |u_kk|.
    pub fn pivot_ratio(&self) -> f64 {
        self.pivot_ratio
    }

    /// Solve A x = b (A = Pᵀ L U Qᵀ, so x = Q U⁻¹ L⁻¹ P b).
    pub fn solve(&self, b: &SVector<f64, N>) -> SVector<f64, N> {
        let mut y = [0.0f64; N];
        for (yk, &r) in y.iter_mut().zip(self.rows.iter()) {
            *yk = b[r];
        }
        // L y = P b (unit lower), column oriented
        for j in 0..N {
            let yj = y[j];
            if yj != 0.0 {
                for (yi, l) in y[j + 1..].iter_mut().zip(self.lu[j][j + 1..].iter()) {
                    *yi -= l * yj;
                }
            }
        }
        // U z = y, column oriented
        for j in (0..N).rev() {
            y[j] /= self.lu[j][j];
            let yj = y[j];
            if yj != 0.0 {
                for (yi, u) in y[..j].iter_mut().zip(self.lu[j][..j].iter()) {
                    *yi -= u * yj;
                }
            }
        }
        let mut x = SVector::<f64, N>::zeros();
        for (yk, &c) in y.iter().zip(self.cols.iter()) {
            x[c] = *yk;
        }
        x
    }

    /// Solve Aᵀ x = b (Aᵀ = Q Uᵀ Lᵀ P, so x = Pᵀ L⁻ᵀ U⁻ᵀ Qᵀ b).
    pub fn solve_transpose(&self, b: &SVector<f64, N>) -> SVector<f64, N> {
        let mut y = [0.0f64; N];
        for (yk, &c) in y.iter_mut().zip(self.cols.iter()) {
            *yk = b[c];
        }
        // Uᵀ w = y (lower triangular, forward): row i of Uᵀ is column i of U
        for i in 0..N {
            let col = &self.lu[i];
            let s: f64 = col[..i].iter().zip(y[..i].iter()).map(|(u, w)| u * w).sum();
            y[i] = (y[i] - s) / col[i];
        }
        // Lᵀ z = w (unit upper, backward): row i of Lᵀ is column i of L
        for i in (0..N).rev() {
            let col = &self.lu[i];
            let s: f64 = col[i + 1..]
                .iter()
                .zip(y[i + 1..].iter())
                .map(|(l, z)| l * z)
                .sum();
            y[i] -= s;
        }
        let mut x = SVector::<f64, N>::zeros();
        for (yk, &r) in y.iter().zip(self.rows.iter()) {
            x[r] = *yk;
        }
        x
    }
}

/// LU with partial pivoting, cheaper than complete pivoting. The
/// column-major storage of A is read as the row-major storage of B = Aᵀ and
/// B is factorised with row pivoting, P B = L U (so A = Uᵀ Lᵀ P: column
/// pivoting of A). Row swaps then exchange whole arrays and the elimination
/// runs over contiguous rows. Its pivot ratio is an indicator; rank decisions
/// near singularity use [`FullPivLu`].
#[derive(Clone, Debug)]
pub struct PartialPivLu<const N: usize> {
    /// `lu[i][k]`: entry (i, k) of L (k < i) and U (k ≥ i) of P B = L U.
    lu: [[f64; N]; N],
    /// Row k of P B is row `rows[k]` of B.
    rows: [usize; N],
    pivot_ratio: f64,
}

impl<const N: usize> PartialPivLu<N> {
    /// Factorise `m`. Non-finite entries propagate into the pivots (ratio 0)
    /// or the solutions, which the callers check.
    pub fn new(m: SMatrix<f64, N, N>) -> Self {
        let mut b: [[f64; N]; N] = m.data.0; // b[i] = row i of B = column i of A
        let mut rows = [0usize; N];
        for (k, r) in rows.iter_mut().enumerate() {
            *r = k;
        }
        let mut max_pivot = 0.0f64;
        let mut min_pivot = f64::INFINITY;
        for k in 0..N {
            let (mut p, mut best) = (k, -1.0f64);
            for (i, row) in b.iter().enumerate().skip(k) {
                let v = row[k].abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            if !(best > 0.0 && best.is_finite()) {
                min_pivot = 0.0;
                break;
            }
            if p != k {
                b.swap(p, k);
                rows.swap(p, k);
            }
            max_pivot = max_pivot.max(best);
            min_pivot = min_pivot.min(best);
            let (top, bottom) = b.split_at_mut(k + 1);
            let pivot_row = &top[k];
            let inv = 1.0 / pivot_row[k];
            for row in bottom.iter_mut() {
                if row[k] != 0.0 {
                    let l = row[k] * inv;
                    row[k] = l;
                    for (x, u) in row[k + 1..].iter_mut().zip(pivot_row[k + 1..].iter()) {
                        *x -= l * u;
                    }
                }
            }
        }
        let pivot_ratio = if max_pivot > 0.0 && min_pivot.is_finite() {
            min_pivot / max_pivot
        } else {
            0.0
        };
        PartialPivLu {
            lu: b,
            rows,
            pivot_ratio,
        }
    }

    /// min |u_kk| / max |u_kk| (an indicator only).
    pub fn pivot_ratio(&self) -> f64 {
        self.pivot_ratio
    }

    /// Solve A x = b: Uᵀ y = b, Lᵀ z = y, x = Pᵀ z.
    pub fn solve(&self, rhs: &SVector<f64, N>) -> SVector<f64, N> {
        let lu = &self.lu;
        let mut y: [f64; N] = rhs.data.0[0];
        // U^T y = b: forward; column i of U^T = row i of U, scatter form
        for i in 0..N {
            let yi = y[i] / lu[i][i];
            y[i] = yi;
            if yi != 0.0 {
                for (yk, u) in y[i + 1..].iter_mut().zip(lu[i][i + 1..].iter()) {
                    *yk -= u * yi;
                }
            }
        }
        // L^T z = y: backward; row i of L^T = column i of L, dot form
        for i in (0..N).rev() {
            let mut s = y[i];
            for k in (i + 1)..N {
                s -= lu[k][i] * y[k];
            }
            y[i] = s;
        }
        let mut x = SVector::<f64, N>::zeros();
        for (z, &r) in y.iter().zip(self.rows.iter()) {
            x[r] = *z;
        }
        x
    }

    /// Solve Aᵀ x = b, i.e. B x = b: L w = P b, U x = w.
    pub fn solve_transpose(&self, rhs: &SVector<f64, N>) -> SVector<f64, N> {
        let lu = &self.lu;
        let mut y = [0.0f64; N];
        for (yk, &r) in y.iter_mut().zip(self.rows.iter()) {
            *yk = rhs[r];
        }
        for i in 0..N {
            let s: f64 = lu[i][..i]
                .iter()
                .zip(y[..i].iter())
                .map(|(l, w)| l * w)
                .sum();
            y[i] -= s;
        }
        for i in (0..N).rev() {
            let s: f64 = lu[i][i + 1..]
                .iter()
                .zip(y[i + 1..].iter())
                .map(|(u, x)| u * x)
                .sum();
            y[i] = (y[i] - s) / lu[i][i];
        }
        SVector::<f64, N>::from(y)
    }
}

/// Either factorisation, behind one interface.
#[derive(Clone, Debug)]
pub enum Factorization<const N: usize> {
    /// Partial pivoting.
    Partial(PartialPivLu<N>),
    /// Complete pivoting.
    Full(FullPivLu<N>),
}

impl<const N: usize> Factorization<N> {
    /// Relative pivot.
    pub fn pivot_ratio(&self) -> f64 {
        match self {
            Factorization::Partial(f) => f.pivot_ratio(),
            Factorization::Full(f) => f.pivot_ratio(),
        }
    }
    /// Solve A x = b.
    pub fn solve(&self, b: &SVector<f64, N>) -> SVector<f64, N> {
        match self {
            Factorization::Partial(f) => f.solve(b),
            Factorization::Full(f) => f.solve(b),
        }
    }
    /// Solve Aᵀ x = b.
    pub fn solve_transpose(&self, b: &SVector<f64, N>) -> SVector<f64, N> {
        match self {
            Factorization::Partial(f) => f.solve_transpose(b),
            Factorization::Full(f) => f.solve_transpose(b),
        }
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
    fn solves_and_transposed_solves_match_nalgebra() {
        let a = sample();
        let b = Vector4::new(1.0, -2.0, 0.5, 3.0);
        let lu = FullPivLu::new(a);
        let x = lu.solve(&b);
        let xt = lu.solve_transpose(&b);
        assert!((a * x - b).norm() < 1e-13);
        assert!((a.transpose() * xt - b).norm() < 1e-13);
        let reference = a.lu().solve(&b).expect("regular");
        assert!((x - reference).norm() < 1e-13);
        let partial = PartialPivLu::new(a);
        assert!((partial.solve(&b) - reference).norm() < 1e-13);
        assert!((a.transpose() * partial.solve_transpose(&b) - b).norm() < 1e-13);
        assert!(partial.pivot_ratio() > 0.01);
        assert!(lu.pivot_ratio() > 0.05);
    }

    #[test]
    fn singular_matrix_has_tiny_pivot_ratio_and_dependent_row_found() {
        let mut a = sample();
        // row 3 = row 0 + 2 row 1: rank 3
        let r = a.row(0) + a.row(1) * 2.0;
        a.set_row(3, &r);
        let lu = FullPivLu::new(a);
        assert!(lu.pivot_ratio() < 1e-14, "{}", lu.pivot_ratio());
        let d = DMatrix::from_column_slice(4, 4, a.as_slice());
        let (row, ratio) = most_dependent_row(&d);
        assert_eq!(row, 3);
        assert!(ratio < 1e-14);
        let zero = FullPivLu::new(Matrix4::<f64>::zeros());
        assert_eq!(zero.pivot_ratio(), 0.0);
        let mut nan = sample();
        nan[(1, 1)] = f64::NAN;
        assert_eq!(FullPivLu::new(nan).pivot_ratio(), 0.0);
        assert!(PartialPivLu::new(a).pivot_ratio() < 1e-14);
        assert_eq!(
            PartialPivLu::new(Matrix4::<f64>::zeros()).pivot_ratio(),
            0.0
        );
    }
}
