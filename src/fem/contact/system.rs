//! What a contact solve needs that does not depend on the loads: the walls, the support of the
//! floating motions, K_S and its Cholesky factor, the map E of the free unknowns into the gaps, and
//! the columns of the compliance S computed so far. One [`ContactSystem`] serves every load on
//! the same body, supports and pins ([`ContactSystem::solve`]): the instants of an engine cycle,
//! the same pins at other forces. The formulation is in [`super::solve`].
//!
//! Only the pins' forces and the nodal loads may change between solves: h, q and the first active
//! set are formed per solve; S, E and the factor are not. A column of S is computed once, the
//! first time a solve's active set needs it, and kept.

use std::collections::HashMap;
use std::sync::Mutex;
use std::time::Instant;

use super::cylinder::{Cylinder, PinMotion};
use super::elastic_pin::ElasticPin;
use super::factorised::Factorised;
use super::modes::{Floating, floating};
use super::problem::{ContactProblem, ContactTimings};
use super::weights::Wall;
use crate::fem::assembly::DofMap;
use crate::fem::boundary::dot;
use crate::fem::element::QuadratureChoice;
use crate::fem::error::{FemError, Result};
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;

/// The load-independent part of a [`ContactProblem`], factorised.
pub struct ContactSystem<'a> {
    pub(super) mesh: &'a TetMesh,
    material: Material,
    quadrature: QuadratureChoice,
    prescribed: Vec<(usize, f64)>,
    pub(super) cylinders: Vec<Cylinder>,
    pub(super) walls: Vec<Wall>,
    /// Contact rows (all walls).
    pub(super) m: usize,
    pub(super) fl: Floating,
    pub(super) dofs: DofMap,
    /// K_S factorised, with the rows' compliance.
    fact: Factorised,
    /// Per wall, its pin's own compliance where the pin is elastic ([`super::elastic_pin`]).
    pub(super) elastic: Vec<Option<ElasticPin>>,
    /// The walls of the force-driven pins, in order.
    pub(super) force_pins: Vec<usize>,
    /// Unknowns y = (α, w): k floating motions, two translations per force-driven pin.
    pub(super) nz: usize,
    /// The orthonormal basis of y's space and the indices of its columns that span the free
    /// unknowns (the complement of the held floating motions).
    pub(super) basis: nalgebra::DMatrix<f64>,
    pub(super) range: Vec<usize>,
    /// E = Z Q restricted to `range`, row by row.
    pub(super) e: Vec<Vec<f64>>,
    /// The floating motions held by the support alone.
    pub(super) free_motions: usize,
    /// Columns of S computed so far, by row.
    columns: Mutex<HashMap<usize, Vec<f64>>>,
    /// The set-up's times (assembly, factorisation, the rest in `rest_s`).
    pub(super) setup: ContactTimings,
}

impl<'a> ContactSystem<'a> {
    /// Assembles and factorises the system of `problem`'s body, supports and pins; its loads and
    /// its pins' forces are not used (only whether each pin is fixed or force-driven).
    pub fn new(problem: &ContactProblem<'a>) -> Result<ContactSystem<'a>> {
        let mesh = problem.mesh;
        let n = mesh.n_dofs();
        problem.material.validate()?;
        if problem.cylinders.is_empty() {
            return Err(FemError::InvalidInput("contact: no cylinder".into()));
        }
        let t0 = Instant::now();
        let mut walls = Vec::with_capacity(problem.cylinders.len());
        let mut m = 0;
        for (k, cyl) in problem.cylinders.iter().enumerate() {
            let w = Wall::new(mesh, cyl, k, m)?;
            m += w.len();
            walls.push(w);
        }
        let mut on_wall = vec![false; mesh.n_nodes()];
        for w in &walls {
            for &nd in &w.nodes {
                on_wall[nd] = true;
            }
        }
        let user: Vec<usize> = problem.prescribed.iter().map(|p| p.0).collect();
        if let Some(&d) = user.iter().find(|&&d| d >= n) {
            return Err(FemError::InvalidInput(format!(
                "contact: prescribed DOF {d} out of range"
            )));
        }
        // rotations about the first fixed pin's axis: a motion free about it is then a pure
        // rotation, and its held direction a pure couple (no force on the support)
        let pivot = problem
            .cylinders
            .iter()
            .find(|c| c.motion == PinMotion::Fixed)
            .map(|c| c.axis_point_m);
        let fl = floating(mesh, &user, &on_wall, pivot)?;
        let k = fl.k();
        let mut prescribed = problem.prescribed.clone();
        prescribed.extend(fl.support.iter().map(|&d| (d, 0.0)));
        let dofs = DofMap::new(n, &prescribed)?;
        let mut setup = ContactTimings {
            rest_s: t0.elapsed().as_secs_f64(),
            ..ContactTimings::default()
        };

        // K_S, factorised once
        let fact = Factorised::new(mesh, &problem.material, problem.quadrature, &dofs, &walls)?;
        setup.assembly_s = fact.assembly_s;
        setup.factorisation_s = fact.factorisation_s;
        let t = Instant::now();
        let elastic = problem
            .cylinders
            .iter()
            .zip(&walls)
            .map(|(cyl, wall)| {
                cyl.elastic
                    .as_ref()
                    .map(|e| {
                        ElasticPin::new(mesh, cyl, wall, &problem.prescribed, e, problem.quadrature)
                    })
                    .transpose()
            })
            .collect::<Result<Vec<_>>>()?;
        setup.factorisation_s += t.elapsed().as_secs_f64();

        let t = Instant::now();
        // Z = [CΦ, −B]
        let force_pins: Vec<usize> = (0..walls.len())
            .filter(|&w| matches!(problem.cylinders[w].motion, PinMotion::Force(_)))
            .collect();
        let nz = k + 2 * force_pins.len();
        let mut z = vec![vec![0.0; nz]; m];
        let rows = walls
            .iter()
            .enumerate()
            .flat_map(|(w, wall)| (0..wall.len()).map(move |b| (w, b)));
        for (j, (w, b)) in rows.enumerate() {
            let wall = &walls[w];
            for &(a, d) in &wall.weights[b] {
                let x = mesh.nodes()[wall.nodes[a]];
                for (i, zi) in z[j].iter_mut().take(k).enumerate() {
                    *zi += d * dot(wall.e[a], fl.mode_at(i, x));
                }
            }
            if let Some(p) = force_pins.iter().position(|&fw| fw == w) {
                let c = wall.force_per_pressure(b);
                z[j][k + 2 * p] = -dot(c, wall.basis.0);
                z[j][k + 2 * p + 1] = -dot(c, wall.basis.1);
            }
        }
        let (basis, range, free_motions) = free_unknowns(&z, k, nz)?;
        let e: Vec<Vec<f64>> = z
            .iter()
            .map(|row| {
                range
                    .iter()
                    .map(|&i| (0..nz).map(|r| row[r] * basis[(r, i)]).sum())
                    .collect()
            })
            .collect();
        setup.rest_s += t.elapsed().as_secs_f64();
        Ok(ContactSystem {
            mesh,
            material: problem.material,
            quadrature: problem.quadrature,
            prescribed: problem.prescribed.clone(),
            cylinders: problem.cylinders.clone(),
            walls,
            m,
            fl,
            dofs,
            fact,
            elastic,
            force_pins,
            nz,
            basis,
            range,
            e,
            free_motions,
            columns: Mutex::new(HashMap::new()),
            setup,
        })
    }

    /// Whether `problem` differs from the system's only in its loads and its pins' forces;
    /// otherwise an error that says what differs.
    pub(super) fn accepts(&self, problem: &ContactProblem) -> Result<()> {
        let same_pins = problem.cylinders.len() == self.cylinders.len()
            && problem.cylinders.iter().zip(&self.cylinders).all(|(a, b)| {
                a.axis_point_m == b.axis_point_m
                    && a.axis == b.axis
                    && a.radius_m == b.radius_m
                    && a.faces == b.faces
                    && a.nominal_bore_radius_m == b.nominal_bore_radius_m
                    && a.elastic == b.elastic
                    && matches!(
                        (a.motion, b.motion),
                        (PinMotion::Fixed, PinMotion::Fixed)
                            | (PinMotion::Force(_), PinMotion::Force(_))
                    )
            });
        let differs = if !std::ptr::eq(problem.mesh, self.mesh) {
            Some("mesh")
        } else if problem.material != self.material || problem.quadrature != self.quadrature {
            Some("material or quadrature")
        } else if problem.prescribed != self.prescribed {
            Some("prescribed DOFs")
        } else if !same_pins {
            Some("pins (geometry, walls or which are fixed)")
        } else {
            None
        };
        if let Some(what) = differs {
            return Err(FemError::InvalidInput(format!(
                "contact: a problem with other {what} than the factorised system's"
            )));
        }
        if !problem.loads.is_empty() && problem.loads.len() != self.mesh.n_dofs() {
            return Err(FemError::InvalidInput(format!(
                "contact: the load vector has {} entries, the mesh {} DOFs",
                problem.loads.len(),
                self.mesh.n_dofs()
            )));
        }
        Ok(())
    }

    /// K x = b through the factor, in place.
    pub(super) fn solve_k(&self, b: &mut [f64]) {
        self.fact.solve(b);
    }

    /// The right-hand side of K_S for the nodal forces `f` (3 per node).
    pub(super) fn rhs_of(&self, f: &[f64]) -> Vec<f64> {
        let mut b = self.fact.dirichlet_rhs.clone();
        for (d, v) in f.iter().enumerate() {
            if let Some(q) = self.dofs.eq(d) {
                b[q] += v;
            }
        }
        b
    }

    /// The displacement of every DOF from the solution `x` of the equations.
    pub(super) fn to_full(&self, x: &[f64]) -> Vec<f64> {
        (0..self.mesh.n_dofs())
            .map(|d| self.dofs.eq(d).map_or(self.dofs.value(d), |q| x[q]))
            .collect()
    }

    /// The columns S[:, j] of the rows `js`, each computed once; returns them and the number
    /// computed now.
    pub(super) fn columns(&self, js: &[usize]) -> (Vec<Vec<f64>>, usize) {
        let mut cache = self.columns.lock().unwrap_or_else(|e| e.into_inner());
        let missing: Vec<usize> = js
            .iter()
            .copied()
            .filter(|j| !cache.contains_key(j))
            .collect();
        if !missing.is_empty() {
            let mut cols = self.fact.compliance.columns(&self.fact.factor, &missing);
            // an elastic pin adds its own compliance on its wall's rows
            for (w, (wall, pin)) in self.walls.iter().zip(&self.elastic).enumerate() {
                let Some(pin) = pin else { continue };
                let here: Vec<usize> = (0..missing.len())
                    .filter(|&i| self.walls_of_row(missing[i]) == w)
                    .collect();
                let local: Vec<usize> = here.iter().map(|&i| missing[i] - wall.offset).collect();
                for (&i, pc) in here.iter().zip(pin.columns(&local)) {
                    for (b, v) in pc.iter().enumerate() {
                        cols[i][wall.offset + b] += v;
                    }
                }
            }
            for (j, col) in missing.iter().zip(cols) {
                cache.insert(*j, col);
            }
        }
        (js.iter().map(|j| cache[j].clone()).collect(), missing.len())
    }

    /// The wall of contact row `j`.
    fn walls_of_row(&self, j: usize) -> usize {
        self.walls
            .iter()
            .position(|w| j >= w.offset && j < w.offset + w.len())
            .expect("a contact row lies on a wall")
    }

    /// Equations of K_S.
    pub fn equations(&self) -> usize {
        self.dofs.n_eq()
    }
}

/// The free unknowns of y = (α, w) given Z (m × nz, the first k columns the floating motions):
/// the combinations with Z y = 0 move nothing against a pin; their body part α is held (the pins'
/// translations stay free, so that each pin still carries its whole force). Returns an orthonormal
/// basis Q of y's space, the indices of its columns spanning the complement of the held
/// directions, and how many are held.
fn free_unknowns(
    z: &[Vec<f64>],
    k: usize,
    nz: usize,
) -> Result<(nalgebra::DMatrix<f64>, Vec<usize>, usize)> {
    let zt_z = nalgebra::DMatrix::from_fn(nz, nz, |r, c| {
        z.iter().map(|row| row[r] * row[c]).sum::<f64>()
    });
    let eig = zt_z.symmetric_eigen();
    let top = eig.eigenvalues.iter().copied().fold(0.0, f64::max);
    let mut held = nalgebra::DMatrix::<f64>::zeros(nz, nz);
    let mut free_motions = 0;
    for i in (0..nz).filter(|&i| eig.eigenvalues[i] <= 1e-10 * top) {
        let alpha_part: f64 = (0..k).map(|r| eig.eigenvectors[(r, i)].powi(2)).sum();
        if alpha_part < 1e-6 {
            return Err(FemError::Solver(
                "contact: a force-driven pin whose translation changes no gap (no wall \
                 around it): it cannot carry its force"
                    .into(),
            ));
        }
        let h = nalgebra::DVector::from_fn(
            nz,
            |r, _| {
                if r < k { eig.eigenvectors[(r, i)] } else { 0.0 }
            },
        );
        held += &h * h.transpose() / alpha_part;
        free_motions += 1;
    }
    let proj = held.symmetric_eigen();
    let range: Vec<usize> = (0..nz).filter(|&i| proj.eigenvalues[i] < 0.5).collect();
    Ok((proj.eigenvectors, range, free_motions))
}
