//! Body forces for quasi-static analysis with inertia relief: consistent nodal loads of four unit
//! body-force shapes, and the mass properties of the meshed solid.
//!
//! **Consistent load vector.** A body force ρ b(x) per unit volume (b per unit mass, N/kg = m/s²)
//! gives the nodal forces f_a = ∫_Ω N_a ρ b dV, three per node (Zienkiewicz, Taylor & Zhu, *The
//! Finite Element Method: Its Basis and Fundamentals*, 7th ed., ch. 2 and ch. 6: the body-force
//! term of the element force vector, integrated over the isoparametric element with det J). Here
//! the integral is taken with the 14-point degree-5 tetrahedron rule ([`TET14`]) on every element.
//! On a straight-sided tetra10 (det J constant, x linear in ξ) the integrand N_a b is of degree 3
//! for the linear fields below, and the second moments of [`mesh_mass_properties`] are of degree 2,
//! so both are exact. On curved elements they are not exact, but loads and mass properties use the
//! *same* points and weights, and Σ_a N_a = 1 and Σ_a N_a x_a = x hold at every point, so the
//! resultants and moments of the loads equal the quantities of [`mesh_mass_properties`] to
//! round-off on any mesh (e.g. Σ f of [`BodyShape::Centrifugal`] = m (x_G, y_G, 0) exactly in the
//! discrete sense).
//!
//! **d'Alembert (inertia relief).** For a rigid planar motion of the body about the z axis with the
//! origin A of the mesh coordinates accelerated by a_A, angular velocity ω and angular acceleration
//! α, a point at in-plane position r = (x, y) from A has a_P = a_A + α ẑ × r − ω² r. In the body's
//! frame the loads are the gravity and the inertia forces, the body force ρ (g − a_P) per unit
//! volume, i.e. by superposition of the unit shapes:
//!
//! ```text
//! f = (g − a_A)_x · f[UniformX] + (g − a_A)_y · f[UniformY]
//!     + ω² · f[Centrifugal] − α · f[AngularAccel]
//! ```
//!
//! (each f[·] from [`body_force_load`] with the material density). The resultant of these loads is
//! m (g − a_A) + m ω² r_G − m α ẑ × r_G and their moment about the z axis through A is
//! m (x_G (g − a_A)_y − y_G (g − a_A)_x) − α I_zz,A, with the mass properties of
//! [`mesh_mass_properties`]; the external (pin) forces must balance exactly these.
//!
//! Out-of-plane components (g_z, a_A,z) are not needed by a planar mechanism and have no shape
//! here.

use rayon::prelude::*;

use super::element::ElementCoords;
use super::mesh::TetMesh;
use super::quadrature::TET14;
use super::shape::{tet10_grad, tet10_shape};

/// A unit body-force field b(x) per unit density [N/kg = m/s²]; r = (x, y) is the in-plane position
/// from the origin of the mesh coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyShape {
    /// b = e_x.
    UniformX,
    /// b = e_y.
    UniformY,
    /// b = (x, y, 0) (times ω² gives the centrifugal field ω² r).
    Centrifugal,
    /// b = ẑ × r = (−y, x, 0) (times α gives α ẑ × r; the d'Alembert load is −α times it).
    AngularAccel,
}

impl BodyShape {
    /// The four shapes.
    pub const ALL: [BodyShape; 4] = [
        BodyShape::UniformX,
        BodyShape::UniformY,
        BodyShape::Centrifugal,
        BodyShape::AngularAccel,
    ];

    /// The field b at the point `p` (m), m/s².
    pub fn field(self, p: [f64; 3]) -> [f64; 3] {
        match self {
            BodyShape::UniformX => [1.0, 0.0, 0.0],
            BodyShape::UniformY => [0.0, 1.0, 0.0],
            BodyShape::Centrifugal => [p[0], p[1], 0.0],
            BodyShape::AngularAccel => [-p[1], p[0], 0.0],
        }
    }
}

/// det J (J_ij = ∂x_i/∂ξ_j) and the position x = Σ N_a x_a at natural coordinates `xi`, with the
/// shape functions there. det J is not checked (the assembly of the stiffness checks it).
fn point(x: &ElementCoords, xi: [f64; 3]) -> ([f64; 10], [f64; 3], f64) {
    let n = tet10_shape(xi);
    let dn = tet10_grad(xi);
    let mut j = [[0.0; 3]; 3];
    let mut p = [0.0; 3];
    for a in 0..10 {
        for r in 0..3 {
            p[r] += n[a] * x[a][r];
            for c in 0..3 {
                j[r][c] += x[a][r] * dn[a][c];
            }
        }
    }
    let det = j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
        - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
        + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
    (n, p, det)
}

/// Consistent nodal forces f_a = ∫ N_a ρ b dV of the body force ρ b (`density_kg_m3` times the unit
/// field `shape`), 3 per node (N), global DOF order; with the 14-point degree-5 rule on every
/// element (exact on straight-sided tetra10, see the module notes). Element contributions are
/// computed in parallel and added in element order (deterministic).
pub fn body_force_load(mesh: &TetMesh, density_kg_m3: f64, shape: BodyShape) -> Vec<f64> {
    let per_element: Vec<[f64; 30]> = (0..mesh.n_elements())
        .into_par_iter()
        .map(|e| {
            let x = mesh.element_coords(e);
            let mut fe = [0.0; 30];
            for (xi, w) in TET14.points.iter().zip(TET14.weights) {
                let (n, p, det) = point(&x, *xi);
                let b = shape.field(p);
                let s = density_kg_m3 * w * det;
                for a in 0..10 {
                    for j in 0..3 {
                        fe[3 * a + j] += s * n[a] * b[j];
                    }
                }
            }
            fe
        })
        .collect();
    let mut f = vec![0.0; mesh.n_dofs()];
    for (el, fe) in mesh.elements().iter().zip(&per_element) {
        for a in 0..10 {
            for j in 0..3 {
                f[3 * el[a] + j] += fe[3 * a + j];
            }
        }
    }
    f
}

/// Mass properties of the meshed solid (uniform density), integrated with the same rule as
/// [`body_force_load`] (exact for straight-sided elements).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshMassProperties {
    /// Volume ∫ dV, m³.
    pub volume_m3: f64,
    /// Mass ρ V, kg.
    pub mass_kg: f64,
    /// Centroid (= centre of mass) ∫ x dV / V, m.
    pub centroid_m: [f64; 3],
    /// ∫ ρ (x² + y²) dV: second moment about the z axis through the origin, kg·m².
    pub i_zz_origin_kgm2: f64,
    /// ∫ ρ ((x − x_G)² + (y − y_G)²) dV: about the parallel axis through the centroid, kg·m²
    /// (integrated directly, not by the parallel-axis theorem, to avoid cancellation).
    pub i_zz_centroid_kgm2: f64,
}

/// Per element, with `f(p)` the integrand: Σ_q w_q det J_q f(x_q), in parallel, summed in element
/// order.
fn integrate<const K: usize>(mesh: &TetMesh, f: impl Fn([f64; 3]) -> [f64; K] + Sync) -> [f64; K] {
    let per_element: Vec<[f64; K]> = (0..mesh.n_elements())
        .into_par_iter()
        .map(|e| {
            let x = mesh.element_coords(e);
            let mut s = [0.0; K];
            for (xi, w) in TET14.points.iter().zip(TET14.weights) {
                let (_, p, det) = point(&x, *xi);
                let v = f(p);
                for k in 0..K {
                    s[k] += w * det * v[k];
                }
            }
            s
        })
        .collect();
    let mut total = [0.0; K];
    for s in &per_element {
        for k in 0..K {
            total[k] += s[k];
        }
    }
    total
}

/// Volume, mass, centroid and the z second moments (about the origin and about the centroid) of the
/// meshed solid with density `density_kg_m3`.
pub fn mesh_mass_properties(mesh: &TetMesh, density_kg_m3: f64) -> MeshMassProperties {
    let [v, sx, sy, sz, szz] =
        integrate(mesh, |p| [1.0, p[0], p[1], p[2], p[0] * p[0] + p[1] * p[1]]);
    let centroid_m = [sx / v, sy / v, sz / v];
    let [szz_g] = integrate(mesh, |p| {
        let (dx, dy) = (p[0] - centroid_m[0], p[1] - centroid_m[1]);
        [dx * dx + dy * dy]
    });
    MeshMassProperties {
        volume_m3: v,
        mass_kg: density_kg_m3 * v,
        centroid_m,
        i_zz_origin_kgm2: density_kg_m3 * szz,
        i_zz_centroid_kgm2: density_kg_m3 * szz_g,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::QuadratureChoice;
    use crate::fem::element::corner_volume;
    use crate::fem::material::Material;
    use crate::fem::mesh::structured::{TwoEyePlate, box_tet10, tet4_to_tet10, two_eye_plate};
    use crate::fem::shape::TET10_EDGES;
    use crate::fem::statics::{StaticProblem, solve_static};
    use crate::fem::stress::stress_field;

    const RHO: f64 = 7850.0;

    /// Σ f (N) and the moment about the z axis through the origin Σ (x f_y − y f_x) (N·m).
    fn resultant_and_moment(mesh: &TetMesh, f: &[f64]) -> ([f64; 3], f64) {
        let mut s = [0.0; 3];
        let mut mz = 0.0;
        for (p, fi) in mesh.nodes().iter().zip(f.chunks_exact(3)) {
            for j in 0..3 {
                s[j] += fi[j];
            }
            mz += p[0] * fi[1] - p[1] * fi[0];
        }
        (s, mz)
    }

    fn rel(a: f64, b: f64, scale: f64) -> f64 {
        (a - b).abs() / scale
    }

    /// The box [0.1, 0.3] × [0.05, 0.1] × [0, 0.03] m (off the origin) and its closed forms: (mesh,
    /// a, b, c, centroid).
    fn off_origin_box() -> (TetMesh, f64, f64, f64, [f64; 3]) {
        let (a, b, c) = (0.2, 0.05, 0.03);
        let mesh = box_tet10(a, b, c, 5, 3, 2)
            .unwrap()
            .map_nodes(|_, p| [p[0] + 0.1, p[1] + 0.05, p[2]])
            .unwrap();
        (mesh, a, b, c, [0.1 + a / 2.0, 0.05 + b / 2.0, c / 2.0])
    }

    /// The element load of a linear field against the closed forms of the volume-coordinate
    /// integrals ∫ L₁^a L₂^b L₃^c L₄^d dV = 3! a! b! c! d! V / (a + b + c + d + 3)! (Zienkiewicz,
    /// Taylor & Zhu): with b = Σ_k b_k L_k, a corner node i gets ρ Σ_{k≠i} (−V/60) b_k (its own
    /// corner value has weight 0), the midside node of edge ij gets
    /// ρ (V/15 (b_i + b_j) + V/30 (b_k + b_l)). A degree-2 rule (tet4) fails this (the integrand is
    /// cubic; checked by swapping the rule). Measured: largest error / (ρ V max|b_k|) 2.3e-16.
    #[test]
    fn element_load_of_linear_field_matches_closed_form() {
        let corners = vec![
            [0.11, 0.02, -0.01],
            [0.17, 0.05, 0.004],
            [0.125, 0.09, 0.01],
            [0.13, 0.04, 0.06],
        ];
        let mesh = tet4_to_tet10(corners, &[[0, 1, 2, 3]]).unwrap();
        let x = mesh.element_coords(0);
        let el = mesh.elements()[0];
        let v = corner_volume(&x);
        assert!(v > 0.0);
        for shape in [BodyShape::Centrifugal, BodyShape::AngularAccel] {
            let f = body_force_load(&mesh, RHO, shape);
            let b: [[f64; 3]; 4] = std::array::from_fn(|k| shape.field(x[k]));
            let bmax = b.iter().flatten().fold(0.0_f64, |m, v| m.max(v.abs()));
            let mut worst: f64 = 0.0;
            for j in 0..3 {
                for i in 0..4 {
                    let exact: f64 = RHO
                        * (0..4)
                            .filter(|&k| k != i)
                            .map(|k| -v / 60.0 * b[k][j])
                            .sum::<f64>();
                    worst = worst.max((f[3 * el[i] + j] - exact).abs() / (RHO * v * bmax));
                }
                for (k, [p, q]) in TET10_EDGES.iter().enumerate() {
                    let others: f64 = (0..4).filter(|c| c != p && c != q).map(|c| b[c][j]).sum();
                    let exact = RHO * (v / 15.0 * (b[*p][j] + b[*q][j]) + v / 30.0 * others);
                    worst = worst.max((f[3 * el[4 + k] + j] - exact).abs() / (RHO * v * bmax));
                }
            }
            eprintln!("element load {shape:?}: worst relative error {worst:.2e}");
            assert!(worst < 1e-13, "{shape:?}: {worst:e}");
        }
    }

    /// Test 1. Resultants and z moments of the four shapes against the closed forms of the box.
    /// Measured (release build): largest relative error 1.2e-15 (scale m, m·|r_G| or I_zz).
    #[test]
    fn resultants_match_closed_forms_of_a_box() {
        let (mesh, a, b, c, g) = off_origin_box();
        let m = RHO * a * b * c;
        let i_origin = m * ((a * a + b * b) / 12.0 + g[0] * g[0] + g[1] * g[1]);
        let rg = (g[0] * g[0] + g[1] * g[1]).sqrt();
        let mut worst: f64 = 0.0;
        for shape in BodyShape::ALL {
            let f = body_force_load(&mesh, RHO, shape);
            let (s, mz) = resultant_and_moment(&mesh, &f);
            let (expected, scale, mz_expected, mz_scale) = match shape {
                BodyShape::UniformX => ([m, 0.0, 0.0], m, -g[1] * m, m * rg),
                BodyShape::UniformY => ([0.0, m, 0.0], m, g[0] * m, m * rg),
                BodyShape::Centrifugal => ([m * g[0], m * g[1], 0.0], m * rg, 0.0, i_origin),
                BodyShape::AngularAccel => ([-m * g[1], m * g[0], 0.0], m * rg, i_origin, i_origin),
            };
            for j in 0..3 {
                let e = rel(s[j], expected[j], scale);
                assert!(
                    e < 1e-12,
                    "{shape:?} component {j}: {} vs {}",
                    s[j],
                    expected[j]
                );
                worst = worst.max(e);
            }
            let e = rel(mz, mz_expected, mz_scale);
            assert!(e < 1e-12, "{shape:?} moment: {mz} vs {mz_expected}");
            worst = worst.max(e);
        }
        eprintln!("resultants: worst relative error {worst:.2e}");
    }

    /// Test 2. Mass properties of the off-origin box against the closed forms. Measured: largest
    /// relative error 1.3e-15.
    #[test]
    fn mass_properties_of_a_box() {
        let (mesh, a, b, c, g) = off_origin_box();
        let mp = mesh_mass_properties(&mesh, RHO);
        let v = a * b * c;
        let m = RHO * v;
        let i_g = m * (a * a + b * b) / 12.0;
        let i_o = i_g + m * (g[0] * g[0] + g[1] * g[1]);
        let errs = [
            rel(mp.volume_m3, v, v),
            rel(mp.mass_kg, m, m),
            rel(mp.centroid_m[0], g[0], g[0]),
            rel(mp.centroid_m[1], g[1], g[0]),
            rel(mp.centroid_m[2], g[2], g[0]),
            rel(mp.i_zz_origin_kgm2, i_o, i_o),
            rel(mp.i_zz_centroid_kgm2, i_g, i_g),
        ];
        let worst = errs.iter().cloned().fold(0.0, f64::max);
        eprintln!("mass properties: {mp:?}, worst relative error {worst:.2e}");
        assert!(worst < 1e-12, "{mp:?}: errors {errs:?}");
    }

    /// On a curved mesh (midside nodes on the bore cylinders) the quadrature is not exact, but
    /// loads and mass properties share it: resultants and moments still equal the mass properties
    /// to round-off. Measured: 6.4e-15.
    #[test]
    fn loads_balance_mass_properties_on_curved_mesh() {
        let mesh = two_eye_plate(&TwoEyePlate {
            curved: true,
            ..TwoEyePlate::default()
        })
        .unwrap();
        assert!(mesh.curved_elements() > 0);
        let mp = mesh_mass_properties(&mesh, RHO);
        let (m, g) = (mp.mass_kg, mp.centroid_m);
        let scale = m * 0.1;
        let (s, _) =
            resultant_and_moment(&mesh, &body_force_load(&mesh, RHO, BodyShape::Centrifugal));
        let mut worst = rel(s[0], m * g[0], scale).max(rel(s[1], m * g[1], scale));
        let (s, mz) =
            resultant_and_moment(&mesh, &body_force_load(&mesh, RHO, BodyShape::AngularAccel));
        worst = worst
            .max(rel(s[0], -m * g[1], scale))
            .max(rel(s[1], m * g[0], scale))
            .max(rel(mz, mp.i_zz_origin_kgm2, mp.i_zz_origin_kgm2));
        // parallel-axis theorem between the two directly integrated moments
        let pa = mp.i_zz_centroid_kgm2 + m * (g[0] * g[0] + g[1] * g[1]);
        worst = worst.max(rel(pa, mp.i_zz_origin_kgm2, mp.i_zz_origin_kgm2));
        eprintln!("curved mesh: worst relative error {worst:.2e}");
        assert!(worst < 1e-12, "{worst:e}");
    }

    /// Nodes with coordinate `j` equal to `v` (to 1e-9 m).
    fn nodes_at(mesh: &TetMesh, j: usize, v: f64) -> Vec<usize> {
        (0..mesh.n_nodes())
            .filter(|&n| (mesh.nodes()[n][j] - v).abs() < 1e-9)
            .collect()
    }

    /// Tests 3 and 5. A bar 0 ≤ x ≤ L, 0 ≤ y ≤ b, 0 ≤ z ≤ c towed by its end x = 0 with the
    /// acceleration a towards −x (a_P = −a e_x): the d'Alembert body force −ρ a_P = +ρ a e_x, and
    /// the equilibrium of the part beyond a cut at x gives σ_xx = ρ a (L − x) (tension), all other
    /// components zero (e.g. Timoshenko & Goodier, *Theory of Elasticity*, body forces; any
    /// strength-of-materials text). The displacements of that state are u_x = (ρa/E)(L x − x²/2) −
    /// ν ρa (y² + z²)/(2E), u_y = −ν y σ_xx/E, u_z = −ν z σ_xx/E: quadratic, so in the tetra10
    /// space. Note the cross-section warping −ν ρa (y² + z²)/(2E): with ν ≠ 0, u_x = 0 on the whole
    /// face x = 0 constrains it and is *not* compatible with the uniaxial state (measured with
    /// steel, u_x = 0 there and 20×2×2 cells: averaged σ_xx off by 3.2 % of ρaL near the support,
    /// the other components up to 1.3 %, decaying to 1.0e-4 beyond x = L/4, as Saint-Venant's
    /// principle says). So two cases, both exact:
    /// * ν = 0 with the plain supports u_x = 0 on x = 0, u_y = 0 on y = 0, u_z = 0 on z = 0;
    /// * steel (ν = 0.3) with u_x on x = 0 prescribed as the exact warping, same u_y, u_z supports.
    ///
    /// Measured (20×2×2 cells): averaged σ vs exact, largest error over all nodes and components /
    /// ρaL: 5.2e-14 (ν = 0) and 6.5e-14 (ν = 0.3); displacements / max u_x: 4.6e-14 and 5.7e-14.
    /// Test 5, reactions: |Σ R + Σ f| / |Σ f| = 2.6e-14 and 5.4e-14.
    #[test]
    fn bar_under_uniform_axial_acceleration_is_exact() {
        let (l, b, c) = (0.2, 0.02, 0.02);
        let acc = 1000.0; // m/s²
        let mesh = box_tet10(l, b, c, 20, 2, 2).unwrap();
        let f: Vec<f64> = body_force_load(&mesh, RHO, BodyShape::UniformX)
            .iter()
            .map(|v| acc * v)
            .collect();
        let sigma_max = RHO * acc * l;
        for nu in [0.0, 0.3] {
            let material = Material {
                poisson_ratio: nu,
                ..Material::STEEL
            };
            let e_mod = material.youngs_modulus_pa;
            let k = RHO * acc / e_mod;
            let exact_u = |p: [f64; 3]| {
                let s = l - p[0];
                [
                    k * (l * p[0] - 0.5 * p[0] * p[0]) - 0.5 * nu * k * (p[1] * p[1] + p[2] * p[2]),
                    -nu * k * s * p[1],
                    -nu * k * s * p[2],
                ]
            };
            let mut prescribed = Vec::new();
            for n in nodes_at(&mesh, 0, 0.0) {
                prescribed.push((3 * n, exact_u(mesh.nodes()[n])[0]));
            }
            for n in nodes_at(&mesh, 1, 0.0) {
                prescribed.push((3 * n + 1, 0.0));
            }
            for n in nodes_at(&mesh, 2, 0.0) {
                prescribed.push((3 * n + 2, 0.0));
            }
            let problem = StaticProblem {
                mesh: &mesh,
                material,
                prescribed,
                loads: vec![f.clone()],
                quadrature: QuadratureChoice::Auto,
            };
            let sol = solve_static(&problem).unwrap();
            let u = &sol.displacements[0];
            let field = stress_field(&mesh, &material, u).unwrap();
            let mut err_s: f64 = 0.0;
            let mut err_u: f64 = 0.0;
            let u_max = k * l * l / 2.0;
            for (n, p) in mesh.nodes().iter().enumerate() {
                let s = field.averaged[n];
                let exact = RHO * acc * (l - p[0]);
                err_s = err_s.max((s[0] - exact).abs() / sigma_max);
                for v in &s[1..] {
                    err_s = err_s.max(v.abs() / sigma_max);
                }
                let ue = exact_u(*p);
                for j in 0..3 {
                    err_u = err_u.max((u[3 * n + j] - ue[j]).abs() / u_max);
                }
            }
            // test 5: reactions balance the applied body force
            let (sf, _) = resultant_and_moment(&mesh, &f);
            let (sr, _) = resultant_and_moment(&mesh, &sol.reactions[0]);
            let fmag = (sf[0] * sf[0] + sf[1] * sf[1] + sf[2] * sf[2]).sqrt();
            let err_r = (0..3).map(|j| (sr[j] + sf[j]).powi(2)).sum::<f64>().sqrt() / fmag;
            eprintln!(
                "bar, ν = {nu}: stress error {err_s:.2e}, displacement error {err_u:.2e}, \
                 reaction balance {err_r:.2e}, residual {:.2e}",
                sol.residual_rel[0]
            );
            assert!(err_s < 1e-8, "ν = {nu}: stress error {err_s:e}");
            assert!(err_u < 1e-8, "ν = {nu}: displacement error {err_u:e}");
            assert!(err_r < 1e-9, "ν = {nu}: reactions off by {err_r:e}");
            assert!((fmag - RHO * acc * l * b * c).abs() < 1e-12 * fmag);
        }
    }

    /// Test 4. A bar 0 ≤ x ≤ L spinning at ω about the z axis (through x = 0), held at x = 0: body
    /// force ρ ω² (x, y, 0), the full [`BodyShape::Centrifugal`] field. Choice: the bar is put
    /// symmetric about y = 0 and z = 0 (|y| ≤ b/2, |z| ≤ c/2) with ν = 0, supports u_x = 0 on x =
    /// 0, u_y = 0 on the plane y = 0, u_z = 0 on the plane z = 0 (all satisfied by the exact
    /// solution by symmetry). With ν = 0 the exact 3D solution is then σ_xx = ρ ω² (L² − x²)/2 (the
    /// bar rotating about its end, e.g. Timoshenko, *Strength of Materials*) plus σ_yy = ρ ω² (b²/4
    /// − y²)/2 from the y part, other components zero. (With ν ≠ 0 the uniaxial field is not
    /// compatible: the lateral strain −ν σ_xx/E, quadratic in x, needs extra stresses of relative
    /// order ν (b/L)², so the 1D formula would only be approximate.) u is cubic, not in the tetra10
    /// space: the error must fall with h.
    ///
    /// Measured (max over nodes with x ≥ L/10 of |σ_xx − exact| / (ρω²L²/2)): 20×2×2 cells 6.1e-4,
    /// 40×4×4 cells 1.5e-4 (ratio 4.08, O(h²)); over all nodes the same (6.1e-4, 1.5e-4). σ_yy
    /// error / (ρω²b²/8) (a small field, 2 and 4 cells across): 0.245 and 0.061.
    #[test]
    fn spinning_bar_converges_to_rotating_bar_stress() {
        let (l, b, c) = (0.2, 0.02, 0.02);
        let omega: f64 = 600.0; // rad/s
        let material = Material {
            poisson_ratio: 0.0,
            ..Material::STEEL
        };
        let s0 = RHO * omega * omega * l * l / 2.0;
        let mut errs = Vec::new();
        for (nx, nyz) in [(20, 2), (40, 4)] {
            let mesh = box_tet10(l, b, c, nx, nyz, nyz)
                .unwrap()
                .map_nodes(|_, p| [p[0], p[1] - b / 2.0, p[2] - c / 2.0])
                .unwrap();
            let f: Vec<f64> = body_force_load(&mesh, RHO, BodyShape::Centrifugal)
                .iter()
                .map(|v| omega * omega * v)
                .collect();
            let mut prescribed: Vec<(usize, f64)> = Vec::new();
            prescribed.extend(nodes_at(&mesh, 0, 0.0).iter().map(|n| (3 * n, 0.0)));
            prescribed.extend(nodes_at(&mesh, 1, 0.0).iter().map(|n| (3 * n + 1, 0.0)));
            prescribed.extend(nodes_at(&mesh, 2, 0.0).iter().map(|n| (3 * n + 2, 0.0)));
            let problem = StaticProblem {
                mesh: &mesh,
                material,
                prescribed,
                loads: vec![f],
                quadrature: QuadratureChoice::Auto,
            };
            let sol = solve_static(&problem).unwrap();
            let field = stress_field(&mesh, &material, &sol.displacements[0]).unwrap();
            let (mut away, mut all, mut yy): (f64, f64, f64) = (0.0, 0.0, 0.0);
            for (n, p) in mesh.nodes().iter().enumerate() {
                let s = field.averaged[n];
                let e = (s[0] - RHO * omega * omega * (l * l - p[0] * p[0]) / 2.0).abs() / s0;
                all = all.max(e);
                if p[0] >= l / 10.0 - 1e-12 {
                    away = away.max(e);
                }
                let syy = RHO * omega * omega * (b * b / 4.0 - p[1] * p[1]) / 2.0;
                yy = yy.max((s[1] - syy).abs() / (RHO * omega * omega * b * b / 8.0));
            }
            eprintln!(
                "spinning bar {nx}×{nyz}×{nyz}: σ_xx error away from x = 0 {away:.2e}, \
                 everywhere {all:.2e}; σ_yy error {yy:.2e}"
            );
            errs.push(away);
        }
        let ratio = errs[0] / errs[1];
        eprintln!("spinning bar: error ratio on halving h {ratio:.2}");
        assert!(errs[0] < 1e-2, "coarse error {}", errs[0]);
        assert!(ratio > 3.0, "error ratio {ratio}");
    }
}
