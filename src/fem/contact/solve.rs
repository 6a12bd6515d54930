//! The contact solve: one factorisation of K, the contact condensed on the wall nodes, the
//! active-set iteration on the condensed problem, one more solve for the displacement.
//!
//! Unknowns: the body's displacement u = u_S + Φ α (u_S on the stiffness held by the prescribed
//! DOFs and the support S of the floating motions Φ, [`super::modes`]), the wall pressures λ
//! ([`super::weights`]) and the translations w of the force-driven pins. Equations:
//!
//! - K_S u_S = f + Cᵀλ (C: the rows λ_b ↦ Σ_a D_ba e_a at the wall nodes);
//! - weighted gaps G = D g₀ + C (u_S + Φα) − B w ≥ 0, λ ≥ 0, λ_b G_b = 0
//!   ((B w)_b = c_b · w, c_b = Σ_a D_ba e_a);
//! - the floating motions in balance: Φᵀ(f + Cᵀλ) = 0; each force-driven pin in balance:
//!   Σ_b λ_b c_b = F.
//!
//! Eliminating u_S = K_S⁻¹(f + Cᵀλ) gives the mixed complementarity problem of [`super::lcp`]
//! with S = C K_S⁻¹ Cᵀ, h = D g₀ + C K_S⁻¹ f, y = (α, w), Z = [CΦ, −B], q = (−Φᵀf, −F).
//! The combinations y with Z y = 0 move nothing against a pin (the rotation about a lone fixed
//! pin with the force-driven pins following it, the sliding along the pins): their equations
//! cannot be met by contact. Their body part α_f is held (y restricted to the complement of the
//! α_f, the pins' translations left free so that each pin still carries its whole force) and
//! the support S carries the out-of-balance, reported as the [`super::problem::Restraint`].
//! With the rotations taken about the fixed pin's axis, the held rotation about that pin is a
//! pure rotation, and the support's reaction a pure couple about the pin's axis (plus a force
//! along it for the sliding).
//!
//! Cost: one assembly and one Cholesky factorisation (of K in the wall nodes' radial frames,
//! the radial equations last), the columns of S that the active-set iteration needs (the rows
//! ever active) by dense triangular solves with the factor's trailing block
//! ([`super::compliance`]), dense Cholesky of the active block per iteration, and two more
//! solves (the free and the final displacement). The factor, E and the columns of S do not
//! depend on the loads: [`super::system::ContactSystem`] keeps them for the next solve of the
//! same body and pins, which costs the active set, the columns not computed before and the two
//! displacement solves.

use std::time::Instant;

use super::check::check;
use super::cylinder::PinMotion;
use super::lcp::{MixedLcp, solve as solve_lcp};
use super::measures::summarise;
use super::problem::{ContactProblem, ContactSolution, ContactTimings};
use super::system::ContactSystem;
use super::weights::Wall;
use crate::fem::boundary::{dot, norm};
use crate::fem::error::Result;

/// Solves `problem`; a solution that fails its check ([`super::check`]) is refused.
pub fn solve_contact(problem: &ContactProblem) -> Result<ContactSolution> {
    let system = ContactSystem::new(problem)?;
    let mut solution = system.solve(problem)?;
    solution.timings.assembly_s = system.setup.assembly_s;
    solution.timings.factorisation_s = system.setup.factorisation_s;
    solution.timings.rest_s += system.setup.rest_s;
    Ok(solution)
}

impl ContactSystem<'_> {
    /// Solves `problem` (which may differ from the system's only in its loads and its pins'
    /// forces) with the system's factor; a solution that fails its check ([`super::check`]) is
    /// refused. The timings are this solve's (assembly and factorisation 0: the system's).
    pub fn solve(&self, problem: &ContactProblem) -> Result<ContactSolution> {
        self.accepts(problem)?;
        let mesh = self.mesh;
        let n = mesh.n_dofs();
        let (walls, fl, k, nz) = (&self.walls, &self.fl, self.fl.k(), self.nz);
        let mut timings = ContactTimings::default();
        let t = Instant::now();
        let loads = if problem.loads.is_empty() {
            vec![0.0; n]
        } else {
            problem.loads.clone()
        };
        let mut x0 = self.rhs_of(&loads);
        self.solve_k(&mut x0);
        let u0 = self.to_full(&x0);
        // rows: (wall, b)
        let rows: Vec<(usize, usize)> = walls
            .iter()
            .enumerate()
            .flat_map(|(w, wall)| (0..wall.len()).map(move |b| (w, b)))
            .collect();
        let h: Vec<f64> = walls
            .iter()
            .flat_map(|w| w.weighted(&w.gaps(&u0, [0.0; 3])))
            .collect();
        let force_of = |w: usize| match problem.cylinders[w].motion {
            PinMotion::Force(fv) => fv,
            PinMotion::Fixed => [0.0; 3],
        };
        let mut q = vec![0.0; nz];
        for (nd, x) in mesh.nodes().iter().enumerate() {
            for (i, qi) in q.iter_mut().take(k).enumerate() {
                let mode = fl.mode_at(i, *x);
                *qi -= (0..3).map(|j| mode[j] * loads[3 * nd + j]).sum::<f64>();
            }
        }
        for (p, &w) in self.force_pins.iter().enumerate() {
            let fv = force_of(w);
            q[k + 2 * p] = -dot(fv, walls[w].basis.0);
            q[k + 2 * p + 1] = -dot(fv, walls[w].basis.1);
        }
        let qe: Vec<f64> = self
            .range
            .iter()
            .map(|&i| (0..nz).map(|r| q[r] * self.basis[(r, i)]).sum())
            .collect();

        // the first active set: rows closed or penetrating at the start, and rows facing each
        // force-driven pin's force and (on a floating body) the fixed pins' reaction
        let mut total_force = [0.0; 3];
        for (i, v) in loads.iter().enumerate() {
            total_force[i % 3] += v;
        }
        for &w in &self.force_pins {
            let fv = force_of(w);
            for j in 0..3 {
                total_force[j] += fv[j];
            }
        }
        let facing = |wall: &Wall, a: usize, dir: [f64; 3]| {
            let l = norm(dir);
            l > 0.0 && dot(wall.e[a], dir) >= 0.5 * l
        };
        let initial: Vec<bool> = rows
            .iter()
            .map(|&(w, b)| {
                let wall = &walls[w];
                wall.g0[b] <= 0.0
                    || match problem.cylinders[w].motion {
                        PinMotion::Force(fv) => facing(wall, b, fv),
                        PinMotion::Fixed => k > 0 && facing(wall, b, total_force.map(|v| -v)),
                    }
            })
            .collect();
        let hmax = h.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let lcp = MixedLcp {
            h,
            e: self.e.clone(),
            q: qe,
            initial,
            gap_tol: 1e-10 * hmax.max(f64::MIN_POSITIVE),
            max_iterations: 60,
        };
        timings.rest_s += t.elapsed().as_secs_f64();
        let mut columns_s = 0.0;
        let mut computed = 0;
        let mut columns = |js: &[usize]| -> Result<Vec<Vec<f64>>> {
            let t = Instant::now();
            let (out, new) = self.columns(js);
            computed += new;
            columns_s += t.elapsed().as_secs_f64();
            Ok(out)
        };
        let t = Instant::now();
        let sol = solve_lcp(&lcp, &mut columns)?;
        timings.columns_s = columns_s;
        timings.active_set_s = t.elapsed().as_secs_f64() - columns_s;

        // y = Q η = (α, w)
        let t = Instant::now();
        let y: Vec<f64> = (0..nz)
            .map(|r| {
                self.range
                    .iter()
                    .zip(&sol.eta)
                    .map(|(&i, eta)| self.basis[(r, i)] * eta)
                    .sum()
            })
            .collect();
        let pressures: Vec<Vec<f64>> = walls
            .iter()
            .map(|w| sol.lambda[w.offset..w.offset + w.len()].to_vec())
            .collect();
        let mut f = loads;
        for (w, lam) in walls.iter().zip(&pressures) {
            w.add_forces(lam, &mut f);
        }
        let mut x = self.rhs_of(&f);
        self.solve_k(&mut x);
        let mut u = self.to_full(&x);
        fl.add_motion(mesh, &y[..k], &mut u);
        let pins: Vec<[f64; 3]> = (0..walls.len())
            .map(|w| match self.force_pins.iter().position(|&fw| fw == w) {
                Some(p) => {
                    let (t1, t2) = walls[w].basis;
                    std::array::from_fn(|j| y[k + 2 * p] * t1[j] + y[k + 2 * p + 1] * t2[j])
                }
                None => [0.0; 3],
            })
            .collect();
        let contact_forces: Vec<Vec<f64>> = walls
            .iter()
            .zip(&pressures)
            .map(|(w, lam)| {
                let mut fc = vec![0.0; n];
                w.add_forces(lam, &mut fc);
                fc
            })
            .collect();
        // an elastic pin's own deflection under the pressure opens the gaps
        let deflections: Vec<Vec<f64>> = self
            .elastic
            .iter()
            .zip(&pressures)
            .map(|(pin, lam)| pin.as_ref().map_or_else(Vec::new, |p| p.deflection(lam)))
            .collect();
        let (chk, mut restraint, reactions) =
            check(problem, &u, &pressures, &pins, &deflections, &fl.support)?;
        restraint.free_motions = self.free_motions;
        let cylinders = walls
            .iter()
            .zip(&pressures)
            .zip(&pins)
            .zip(deflections)
            .map(|(((w, lam), pin), deflection)| {
                let mut gaps = w.gaps(&u, *pin);
                for (g, d) in gaps.iter_mut().zip(&deflection) {
                    *g += d;
                }
                let mut c = summarise(w, lam, &gaps, *pin);
                c.pin_deflection_m = deflection;
                c
            })
            .collect();
        timings.rest_s += t.elapsed().as_secs_f64();
        chk.verify(&problem.tolerances)?;
        Ok(ContactSolution {
            displacements: u,
            contact_forces,
            reactions,
            cylinders,
            restraint,
            check: chk,
            iterations: sol.iterations,
            rows: self.m,
            columns: computed,
            equations: self.equations(),
            timings,
        })
    }
}
