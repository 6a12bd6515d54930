//! Dense linear algebra shared by the mechanism core ([`crate::mechanism`]) and the implicit
//! integrators ([`crate::integrators`]); it sits below both and imports neither.
//!
//! | file | contents |
//! |---|---|
//! | `dense_lu.rs` | [`DenseLu`]: nalgebra's LU (partial) and `FullPivLU` (rank-revealing) behind one interface, plus what nalgebra lacks: relative pivot, transposed solve, dependent-row diagnosis ([`most_dependent_row`]) |

pub mod dense_lu;

pub use dense_lu::{DenseLu, Factorization, most_dependent_row};
