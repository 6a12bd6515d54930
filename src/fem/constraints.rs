//! Linear constraints on the DOFs — prescribed values, multi-point equations Σ c_k u_k = g, and
//! both in rotated axes — eliminated by master–slave substitution: every DOF is written as
//!
//! u = T q + g,
//!
//! q the independent DOFs (the equations of the reduced system), T sparse. The constrained
//! minimum of ½ uᵀ K u − fᵀ u is then the solution of Tᵀ K T q = Tᵀ (f − K g) (R. D. Cook, D. S.
//! Malkus, M. E. Plesha, R. J. Witt, *Concepts and Applications of FEA*, 4th ed., §9.2
//! "constraints: transformation (master–slave) method"; the CalculiX manual, "*EQUATION": the
//! first DOF of an equation is the dependent one and is eliminated).
//!
//! Constraints are taken one after the other. A constraint is first written in the independent
//! DOFs (the dependent ones substituted); its dependent DOF is its first term's DOF when that is
//! still independent (CalculiX's rule), otherwise the term of largest |coefficient|; earlier
//! expressions that use the new dependent DOF are updated. A constraint that is a combination of
//! earlier ones is dropped when consistent and refused when not. The constrained solution does
//! not depend on which DOF of a constraint is eliminated.

use std::collections::HashMap;

use super::error::{FemError, Result};

/// One linear constraint Σ c_k u_{d_k} = value.
#[derive(Clone, Debug, PartialEq)]
pub struct Constraint {
    /// (DOF, coefficient); the first term's DOF is the preferred dependent one.
    pub terms: Vec<(usize, f64)>,
    /// Right-hand side.
    pub value: f64,
    /// A label for errors (the deck's line, say).
    pub label: String,
}

/// u = T q + g for every DOF.
#[derive(Clone, Debug, PartialEq)]
pub struct Reduction {
    /// Per DOF its row of T: (equation, coefficient).
    rows: Vec<Vec<(usize, f64)>>,
    /// Per DOF g.
    offset: Vec<f64>,
    n_eq: usize,
    /// Per DOF: dependent (constrained).
    dependent: Vec<bool>,
}

/// Coefficients below this (relative to the constraint's largest) are round-off.
const TINY: f64 = 1e-12;

/// Adds v u_d to the linear form `row`.
fn add(row: &mut Vec<(usize, f64)>, d: usize, v: f64) {
    if let Some(t) = row.iter_mut().find(|(e, _)| *e == d) {
        t.1 += v;
    } else {
        row.push((d, v));
    }
}

impl Reduction {
    /// The reduction of `n_dofs` DOFs under `constraints`.
    pub fn new(n_dofs: usize, constraints: &[Constraint]) -> Result<Self> {
        // dependent DOF → (terms in independent DOFs, constant)
        let mut expr: HashMap<usize, (Vec<(usize, f64)>, f64)> = HashMap::new();
        // independent DOF → dependent DOFs whose expression uses it
        let mut users: HashMap<usize, Vec<usize>> = HashMap::new();
        for c in constraints {
            if let Some(&(d, _)) = c.terms.iter().find(|(d, _)| *d >= n_dofs) {
                return Err(FemError::InvalidInput(format!(
                    "{}: DOF {d} out of range ({n_dofs} DOFs)",
                    c.label
                )));
            }
            // the constraint in independent DOFs
            let mut row: Vec<(usize, f64)> = Vec::new();
            let mut rhs = c.value;
            for &(d, coef) in &c.terms {
                if let Some((terms, g)) = expr.get(&d) {
                    for &(e, v) in terms {
                        add(&mut row, e, coef * v);
                    }
                    rhs -= coef * g;
                } else {
                    add(&mut row, d, coef);
                }
            }
            let scale = c
                .terms
                .iter()
                .fold(0.0f64, |m, (_, v)| m.max(v.abs()))
                .max(f64::MIN_POSITIVE);
            row.retain(|(_, v)| v.abs() > TINY * scale);
            if row.is_empty() {
                if rhs.abs() > 1e-9 * (c.value.abs().max(1.0)) {
                    return Err(FemError::InvalidInput(format!(
                        "{}: the constraint contradicts earlier ones (the same DOFs are already \
                         held at other values): remove one of them",
                        c.label
                    )));
                }
                continue;
            }
            let first = c.terms[0].0;
            let pivot = row
                .iter()
                .position(|(d, v)| *d == first && v.abs() > 1e-3 * scale)
                .unwrap_or_else(|| {
                    (0..row.len())
                        .max_by(|&a, &b| row[a].1.abs().total_cmp(&row[b].1.abs()))
                        .expect("non-empty")
                });
            let (dep, cd) = row.swap_remove(pivot);
            let terms: Vec<(usize, f64)> = row.iter().map(|&(d, v)| (d, -v / cd)).collect();
            let g = rhs / cd;
            // substitute the new dependent DOF where earlier expressions use it
            if let Some(list) = users.remove(&dep) {
                for u in list {
                    let (old, og) = expr.remove(&u).expect("a user has an expression");
                    let mut new: Vec<(usize, f64)> = Vec::new();
                    let mut ng = og;
                    for (d, v) in old {
                        if d == dep {
                            for &(e, w) in &terms {
                                add(&mut new, e, v * w);
                            }
                            ng += v * g;
                        } else {
                            add(&mut new, d, v);
                        }
                    }
                    for &(e, _) in &new {
                        let l = users.entry(e).or_default();
                        if !l.contains(&u) {
                            l.push(u);
                        }
                    }
                    expr.insert(u, (new, ng));
                }
            }
            for &(e, _) in &terms {
                users.entry(e).or_default().push(dep);
            }
            expr.insert(dep, (terms, g));
        }
        let mut eq = vec![usize::MAX; n_dofs];
        let mut n_eq = 0;
        let mut dependent = vec![false; n_dofs];
        for (d, slot) in eq.iter_mut().enumerate() {
            if expr.contains_key(&d) {
                dependent[d] = true;
            } else {
                *slot = n_eq;
                n_eq += 1;
            }
        }
        let mut rows = vec![Vec::new(); n_dofs];
        let mut offset = vec![0.0; n_dofs];
        for d in 0..n_dofs {
            match expr.get(&d) {
                None => rows[d].push((eq[d], 1.0)),
                Some((terms, g)) => {
                    rows[d] = terms.iter().map(|&(e, v)| (eq[e], v)).collect();
                    offset[d] = *g;
                }
            }
        }
        Ok(Reduction {
            rows,
            offset,
            n_eq,
            dependent,
        })
    }

    /// Number of independent DOFs (equations).
    pub fn n_eq(&self) -> usize {
        self.n_eq
    }

    /// Number of DOFs.
    pub fn n_dofs(&self) -> usize {
        self.rows.len()
    }

    /// Row `dof` of T.
    pub fn row(&self, dof: usize) -> &[(usize, f64)] {
        &self.rows[dof]
    }

    /// g at `dof`.
    pub fn offset(&self, dof: usize) -> f64 {
        self.offset[dof]
    }

    /// Whether `dof` is constrained (eliminated).
    pub fn is_dependent(&self, dof: usize) -> bool {
        self.dependent[dof]
    }

    /// Whether any g is non-zero.
    pub fn has_offset(&self) -> bool {
        self.offset.iter().any(|v| *v != 0.0)
    }

    /// u = T q + g.
    pub fn expand(&self, q: &[f64]) -> Vec<f64> {
        self.rows
            .iter()
            .zip(&self.offset)
            .map(|(r, g)| g + r.iter().map(|&(e, v)| v * q[e]).sum::<f64>())
            .collect()
    }

    /// Tᵀ f.
    pub fn restrict(&self, f: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.n_eq];
        for (r, fv) in self.rows.iter().zip(f) {
            for &(e, v) in r {
                out[e] += v * fv;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(terms: &[(usize, f64)], value: f64) -> Constraint {
        Constraint {
            terms: terms.to_vec(),
            value,
            label: "test".into(),
        }
    }

    /// u0 = 1; u1 − u2 = 0; u2 − 2 u3 = 0 (u2 dependent after u1 used it): u1 = u2 = 2 u3.
    #[test]
    fn chains_and_prescribed_values() {
        let r = Reduction::new(
            4,
            &[
                c(&[(0, 1.0)], 1.0),
                c(&[(1, 1.0), (2, -1.0)], 0.0),
                c(&[(2, 1.0), (3, -2.0)], 0.0),
            ],
        )
        .unwrap();
        assert_eq!(r.n_eq(), 1);
        let u = r.expand(&[0.5]);
        assert_eq!(u, vec![1.0, 1.0, 1.0, 0.5]);
        // a repeated consistent constraint is dropped, a contradicting one refused
        assert!(Reduction::new(2, &[c(&[(0, 1.0)], 0.0), c(&[(0, 2.0)], 0.0)]).is_ok());
        assert!(Reduction::new(2, &[c(&[(0, 1.0)], 0.0), c(&[(0, 1.0)], 1.0)]).is_err());
    }
}
