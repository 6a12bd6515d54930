//! Superconvergent patch recovery (SPR) of the stress field of a tetra10 solution: a continuous,
//! more accurate stress σ* to measure the error of the finite-element stress σ_h against.
//!
//! Zienkiewicz & Zhu, "The superconvergent patch recovery and a posteriori error estimates",
//! IJNME 33 (1992), Part 1 (recovery) and Part 2 (estimates); Zienkiewicz, Taylor & Zhu, *The
//! Finite Element Method: Its Basis and Fundamentals*, 7th ed., §13.4–13.6. For each corner
//! (vertex) node n, the patch is the set of elements that contain it; σ_h is sampled at the
//! 4-point degree-2 Gauss points of the patch elements (the optimal sampling points of quadratic
//! tetrahedra, where the stress of a P2 solution is most accurate) and each of the six components
//! is fitted in the least-squares sense by a complete quadratic polynomial (10 terms, the degree
//! of the displacement field, as ZZ prescribe for a degree-p element: σ* of degree p)
//!
//!   σ*_c(x) = a_c · P((x − x_n) / h_n),  P = [1, ξ, η, ζ, ξ², η², ζ², ξη, ηζ, ζξ],
//!
//! with local coordinates scaled by the patch radius h_n so the normal matrix is well
//! conditioned. σ*(x_n) = a_c,0. A patch with fewer than [`MIN_POINTS_QUADRATIC`] sampling
//! points (a corner of the surface with one or two elements) is enlarged by the elements that
//! share a corner with it; a fit whose normal matrix is numerically singular falls back to a
//! linear polynomial (4 terms). The midside node of edge (a, b) gets the mean of the polynomials
//! of patches a and b evaluated there. σ* is then interpolated inside each element with the
//! element's own quadratic shape functions.
//!
//! Boundary nodes are fitted by their one-sided patch, extrapolating the polynomial to the
//! surface: that is where stresses usually peak, and the quadratic fit is what makes the recovered
//! surface stress better than the nodal average of σ_h (which is a weighted mean of values
//! inside the elements and so lags behind a steep gradient).

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

use super::element::{ElementCoords, shape_gradients, strain};
use super::error::Result;
use super::material::Material;
use super::mesh::TetMesh;
use super::quadrature::TET4;
use super::shape::{TET10_EDGES, tet10_shape};

/// Terms of the complete quadratic polynomial in three variables.
pub const QUADRATIC_TERMS: usize = 10;
/// A patch is enlarged until it has at least this many sampling points for a quadratic fit.
pub const MIN_POINTS_QUADRATIC: usize = 3 * QUADRATIC_TERMS;

/// The recovered stress: σ* at every mesh node (corners and midsides), Pa, `[xx, yy, zz, xy, yz, zx]`.
#[derive(Clone, Debug)]
pub struct RecoveredStress {
    /// σ* per node.
    pub nodal: Vec<[f64; 6]>,
    /// Corner nodes whose patch had to be enlarged.
    pub enlarged_patches: usize,
    /// Corner nodes fitted with the linear fallback.
    pub linear_fits: usize,
}

impl RecoveredStress {
    /// σ* at natural coordinates `xi` of element `e` (quadratic interpolation of the nodal values).
    pub fn at(&self, mesh: &TetMesh, e: usize, xi: [f64; 3]) -> [f64; 6] {
        let n = tet10_shape(xi);
        let el = &mesh.elements()[e];
        let mut s = [0.0; 6];
        for a in 0..10 {
            for (c, v) in s.iter_mut().enumerate() {
                *v += n[a] * self.nodal[el[a]][c];
            }
        }
        s
    }
}

/// σ_h of each load case at the four Gauss points of every element, with the points'
/// coordinates (the shape gradients formed once for all cases).
struct Samples {
    points: Vec<[[f64; 3]; 4]>,
    /// Per case, per element.
    stress: Vec<Vec<[[f64; 6]; 4]>>,
}

/// The four Gauss points of one element and σ_h there, per case.
type ElementSamples = ([[f64; 3]; 4], Vec<[[f64; 6]; 4]>);

fn gauss_samples(mesh: &TetMesh, material: &Material, us: &[&[f64]]) -> Result<Samples> {
    let per: Vec<ElementSamples> = (0..mesh.n_elements())
        .into_par_iter()
        .map(|e| {
            let x: ElementCoords = mesh.element_coords(e);
            let ues: Vec<_> = us
                .iter()
                .map(|u| mesh.element_displacements(e, u))
                .collect();
            let mut pts = [[0.0; 3]; 4];
            let mut sig = vec![[[0.0; 6]; 4]; us.len()];
            for (g, xi) in TET4.points.iter().enumerate() {
                let n = tet10_shape(*xi);
                for a in 0..10 {
                    for j in 0..3 {
                        pts[g][j] += n[a] * x[a][j];
                    }
                }
                let (grad, _) = shape_gradients(&x, *xi, e, "quadrature point")?;
                for (c, ue) in ues.iter().enumerate() {
                    sig[c][g] = material.stress(&strain(&grad, ue));
                }
            }
            Ok((pts, sig))
        })
        .collect::<Result<_>>()?;
    let mut stress = vec![Vec::with_capacity(per.len()); us.len()];
    let mut points = Vec::with_capacity(per.len());
    for (p, sig) in per {
        points.push(p);
        for (c, s) in sig.into_iter().enumerate() {
            stress[c].push(s);
        }
    }
    Ok(Samples { points, stress })
}

/// Elements containing each node (corner or midside).
pub fn node_elements(mesh: &TetMesh) -> Vec<Vec<u32>> {
    let mut out = vec![Vec::new(); mesh.n_nodes()];
    for (e, el) in mesh.elements().iter().enumerate() {
        for &n in el {
            out[n].push(e as u32);
        }
    }
    out
}

fn basis(d: [f64; 3]) -> SVector<f64, QUADRATIC_TERMS> {
    let [x, y, z] = d;
    SVector::from([1.0, x, y, z, x * x, y * y, z * z, x * y, y * z, z * x])
}

/// A fitted patch polynomial: centre, scale and coefficients (one column per stress component).
struct PatchFit {
    centre: [f64; 3],
    scale: f64,
    /// `terms × 6`; rows beyond the fitted degree are zero.
    coefficients: SMatrix<f64, QUADRATIC_TERMS, 6>,
}

impl PatchFit {
    fn eval(&self, p: [f64; 3]) -> [f64; 6] {
        let d = std::array::from_fn(|j| (p[j] - self.centre[j]) / self.scale);
        let b = basis(d);
        let v = self.coefficients.transpose() * b;
        std::array::from_fn(|c| v[c])
    }
}

/// The least-squares fits of the first `$t` basis functions to the samples at `points`, one per
/// case (`values[c][i]`: case c at point i), on stack matrices (one normal matrix per corner node,
/// factorised once for all cases: no allocation); `None` when it is near singular.
/// A macro, not a const generic: nalgebra's eigenvalues and Cholesky of an `SMatrix<f64, T, T>`
/// carry dimension bounds that a generic `T` cannot meet on stable Rust.
macro_rules! fit_terms {
    ($name:ident, $t:expr) => {
        fn $name(
            centre: [f64; 3],
            scale: f64,
            points: &[[f64; 3]],
            values: &[Vec<[f64; 6]>],
        ) -> Option<Vec<SMatrix<f64, QUADRATIC_TERMS, 6>>> {
            let bases: Vec<SVector<f64, QUADRATIC_TERMS>> = points
                .iter()
                .map(|p| basis(std::array::from_fn(|j| (p[j] - centre[j]) / scale)))
                .collect();
            let mut a = SMatrix::<f64, $t, $t>::zeros();
            for b in &bases {
                for i in 0..$t {
                    for j in 0..$t {
                        a[(i, j)] += b[i] * b[j];
                    }
                }
            }
            // reject near-singular normal matrices (points nearly coplanar for the quadratic
            // terms)
            let eig = a.symmetric_eigenvalues();
            let (lo, hi) = eig.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
            if lo.is_nan() || lo <= 1e-10 * hi {
                return None;
            }
            let chol = a.cholesky()?;
            Some(
                values
                    .iter()
                    .map(|v| {
                        let mut rhs = SMatrix::<f64, $t, 6>::zeros();
                        for (b, s) in bases.iter().zip(v) {
                            for i in 0..$t {
                                for c in 0..6 {
                                    rhs[(i, c)] += b[i] * s[c];
                                }
                            }
                        }
                        let x = chol.solve(&rhs);
                        let mut out = SMatrix::<f64, QUADRATIC_TERMS, 6>::zeros();
                        for i in 0..$t {
                            for c in 0..6 {
                                out[(i, c)] = x[(i, c)];
                            }
                        }
                        out
                    })
                    .collect(),
            )
        }
    };
}
fit_terms!(fit_quadratic_terms, 10);
fit_terms!(fit_linear_terms, 4);

/// Recovers σ* from the displacements `u` (3 per node, m); see the module documentation.
pub fn recover_stress(mesh: &TetMesh, material: &Material, u: &[f64]) -> Result<RecoveredStress> {
    Ok(recover_stress_cases(mesh, material, &[u])?
        .pop()
        .expect("one case"))
}

/// [`recover_stress`] of several load cases on one mesh: the Gauss points' shape gradients and
/// each patch's normal matrix are formed and factorised once for all cases (the same numbers, to
/// the bit, as a case recovered alone).
pub fn recover_stress_cases(
    mesh: &TetMesh,
    material: &Material,
    us: &[&[f64]],
) -> Result<Vec<RecoveredStress>> {
    let samples = gauss_samples(mesh, material, us)?;
    let cases = us.len();
    let elems_of = node_elements(mesh);
    let nodes = mesh.nodes();
    // corner nodes and, for each, its patch fits
    let mut is_corner = vec![false; mesh.n_nodes()];
    for el in mesh.elements() {
        for &n in &el[..4] {
            is_corner[n] = true;
        }
    }
    let corners: Vec<usize> = (0..mesh.n_nodes()).filter(|&n| is_corner[n]).collect();
    let fits: Vec<(Vec<PatchFit>, bool, bool)> = corners
        .par_iter()
        .map(|&n| {
            let mut patch: Vec<u32> = elems_of[n].clone();
            let mut enlarged = false;
            if 4 * patch.len() < MIN_POINTS_QUADRATIC {
                enlarged = true;
                let mut more: Vec<u32> = patch
                    .iter()
                    .flat_map(|&e| mesh.elements()[e as usize][..4].iter())
                    .flat_map(|&m| elems_of[m].iter().copied())
                    .collect();
                more.sort_unstable();
                more.dedup();
                patch = more;
            }
            let at = || {
                patch
                    .iter()
                    .flat_map(|&e| (0..4).map(move |g| (e as usize, g)))
            };
            let pts: Vec<[f64; 3]> = at().map(|(e, g)| samples.points[e][g]).collect();
            let values: Vec<Vec<[f64; 6]>> = (0..cases)
                .map(|c| at().map(|(e, g)| samples.stress[c][e][g]).collect())
                .collect();
            let centre = nodes[n];
            let scale = pts
                .iter()
                .map(|p| super::mesh::dist(*p, centre))
                .fold(0.0, f64::max)
                .max(f64::MIN_POSITIVE);
            let (coefficients, linear) = match (pts.len() >= MIN_POINTS_QUADRATIC)
                .then(|| fit_quadratic_terms(centre, scale, &pts, &values))
                .flatten()
            {
                Some(c) => (c, false),
                None => {
                    let c = fit_linear_terms(centre, scale, &pts, &values).unwrap_or_else(|| {
                        // a degenerate patch (cannot happen for valid tetrahedra): the mean
                        values
                            .iter()
                            .map(|v| {
                                let mut c = SMatrix::<f64, QUADRATIC_TERMS, 6>::zeros();
                                for s in v {
                                    for k in 0..6 {
                                        c[(0, k)] += s[k] / v.len() as f64;
                                    }
                                }
                                c
                            })
                            .collect()
                    });
                    (c, true)
                }
            };
            let fits = coefficients
                .into_iter()
                .map(|coefficients| PatchFit {
                    centre,
                    scale,
                    coefficients,
                })
                .collect();
            (fits, enlarged, linear)
        })
        .collect();
    let mut fit_of = vec![usize::MAX; mesh.n_nodes()];
    for (i, &n) in corners.iter().enumerate() {
        fit_of[n] = i;
    }
    let enlarged_patches = fits.iter().filter(|f| f.1).count();
    let linear_fits = fits.iter().filter(|f| f.2).count();
    Ok((0..cases)
        .map(|c| {
            let mut nodal = vec![[0.0; 6]; mesh.n_nodes()];
            let mut done = vec![false; mesh.n_nodes()];
            for &n in &corners {
                let f = &fits[fit_of[n]].0[c];
                nodal[n] = std::array::from_fn(|k| f.coefficients[(0, k)]);
                done[n] = true;
            }
            for el in mesh.elements() {
                for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
                    let m = el[4 + k];
                    if done[m] {
                        continue;
                    }
                    let p = nodes[m];
                    let sa = fits[fit_of[el[*a]]].0[c].eval(p);
                    let sb = fits[fit_of[el[*b]]].0[c].eval(p);
                    nodal[m] = std::array::from_fn(|j| 0.5 * (sa[j] + sb[j]));
                    done[m] = true;
                }
            }
            RecoveredStress {
                nodal,
                enlarged_patches,
                linear_fits,
            }
        })
        .collect())
}

/// Least-squares helper exposed for tests: fits a quadratic to values at points.
#[cfg(test)]
pub(crate) fn fit_quadratic(points: &[[f64; 3]], values: &[f64]) -> Option<Vec<f64>> {
    // one case, the values in its first stress component
    let values = vec![
        values
            .iter()
            .map(|v| [*v, 0.0, 0.0, 0.0, 0.0, 0.0])
            .collect(),
    ];
    let c = fit_quadratic_terms([0.0; 3], 1.0, points, &values)?.pop()?;
    Some((0..QUADRATIC_TERMS).map(|i| c[(i, 0)]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::mesh::structured::box_tet10;

    /// Consistency (ZZ 1992): when σ_h is exact (u quadratic, in the P2 space, so σ linear), the
    /// patch fit reproduces it at every node, corner and midside, boundary and interior.
    #[test]
    fn recovers_an_exact_linear_stress_exactly() {
        let mesh = box_tet10(0.04, 0.03, 0.02, 4, 3, 2).unwrap();
        let m = Material::STEEL;
        // u quadratic → σ linear: the FE solution space contains u, so σ_h is exact and so is σ*
        let f = |p: [f64; 3]| {
            let [x, y, z] = p;
            [
                1e-3 * (x * x + 2.0 * y * z) + 1e-4 * y,
                1e-3 * (y * y - x * z),
                1e-3 * (z * x + 0.5 * y * y),
            ]
        };
        let u: Vec<f64> = mesh.nodes().iter().flat_map(|p| f(*p)).collect();
        let rec = recover_stress(&mesh, &m, &u).unwrap();
        assert_eq!(rec.linear_fits, 0);
        // exact stress at each node from the analytic gradient
        for (n, p) in mesh.nodes().iter().enumerate() {
            let [x, y, z] = *p;
            let h = [
                [2e-3 * x, 2e-3 * z + 1e-4, 2e-3 * y],
                [-1e-3 * z, 2e-3 * y, -1e-3 * x],
                [1e-3 * z, 1e-3 * y, 1e-3 * x],
            ];
            let e = [
                h[0][0],
                h[1][1],
                h[2][2],
                0.5 * (h[0][1] + h[1][0]),
                0.5 * (h[1][2] + h[2][1]),
                0.5 * (h[2][0] + h[0][2]),
            ];
            let s = m.stress(&e);
            let scale = s.iter().map(|v| v.abs()).fold(1e6, f64::max);
            for (c, (got, want)) in rec.nodal[n].iter().zip(&s).enumerate() {
                assert!(
                    (got - want).abs() < 1e-9 * scale,
                    "node {n} comp {c}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn quadratic_fit_reproduces_a_quadratic() {
        let pts: Vec<[f64; 3]> = (0..40)
            .map(|i| {
                let t = i as f64;
                [(t * 0.37).sin(), (t * 0.73).cos(), (t * 1.31).sin() * 0.5]
            })
            .collect();
        let g = |p: [f64; 3]| 1.0 + 2.0 * p[0] - p[1] + 0.5 * p[2] * p[2] + 3.0 * p[0] * p[1];
        let v: Vec<f64> = pts.iter().map(|p| g(*p)).collect();
        let c = fit_quadratic(&pts, &v).unwrap();
        let want = [1.0, 2.0, -1.0, 0.0, 0.0, 0.0, 0.5, 3.0, 0.0, 0.0];
        for (a, b) in c.iter().zip(want) {
            assert!((a - b).abs() < 1e-10, "{c:?}");
        }
    }

    /// Two load cases recovered together give each case's recovery alone, to the bit (the
    /// shared normal matrices are the same numbers).
    #[test]
    fn cases_recovered_together_are_each_recovered_alone() {
        let mesh = box_tet10(0.04, 0.03, 0.02, 4, 3, 2).unwrap();
        let m = Material::STEEL;
        let fields = [
            |p: [f64; 3]| [1e-3 * p[0] * p[1], 2e-4 * p[2] * p[2], -1e-3 * p[0] * p[2]],
            |p: [f64; 3]| [3e-4 * p[1].sin(), 1e-3 * p[0] * p[0] * p[1], 5e-4 * p[2]],
        ];
        let us: Vec<Vec<f64>> = fields
            .iter()
            .map(|f| mesh.nodes().iter().flat_map(|p| f(*p)).collect())
            .collect();
        let together =
            recover_stress_cases(&mesh, &m, &[us[0].as_slice(), us[1].as_slice()]).unwrap();
        for (u, t) in us.iter().zip(&together) {
            let alone = recover_stress(&mesh, &m, u).unwrap();
            let bits = |r: &RecoveredStress| -> Vec<u64> {
                r.nodal.iter().flatten().map(|v| v.to_bits()).collect()
            };
            assert_eq!(bits(&alone), bits(t));
            assert_eq!(alone.linear_fits, t.linear_fits);
        }
        assert_ne!(together[0].nodal, together[1].nodal);
    }
}
