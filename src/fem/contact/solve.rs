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
//! solves (the free and the final displacement).

use std::time::Instant;

use super::check::check;
use super::compliance::{Compliance, NodalFrames};
use super::cylinder::PinMotion;
use super::lcp::{MixedLcp, solve as solve_lcp};
use super::measures::summarise;
use super::modes::floating;
use super::problem::{ContactProblem, ContactSolution, ContactTimings};
use super::weights::Wall;
use crate::fem::assembly::{DofMap, assemble};
use crate::fem::boundary::{dot, norm};
use crate::fem::error::{FemError, Result};
use crate::fem::ordering::nested_dissection;
use crate::fem::solver::{CholeskyFactor, SymbolicFactor};

/// Solves `problem`; a solution that fails its check ([`super::check`]) is refused.
pub fn solve_contact(problem: &ContactProblem) -> Result<ContactSolution> {
    let mesh = problem.mesh;
    let n = mesh.n_dofs();
    problem.material.validate()?;
    if problem.cylinders.is_empty() {
        return Err(FemError::InvalidInput("contact: no cylinder".into()));
    }
    if !problem.loads.is_empty() && problem.loads.len() != n {
        return Err(FemError::InvalidInput(format!(
            "contact: the load vector has {} entries, the mesh {n} DOFs",
            problem.loads.len()
        )));
    }
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
    let n_eq = dofs.n_eq();

    // K_S, factorised once
    let mut timings = ContactTimings::default();
    let t = Instant::now();
    let asm = assemble(mesh, &problem.material, problem.quadrature, &dofs)?;
    timings.assembly_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    // in the wall nodes' radial frames, the radial equations last ([`super::compliance`])
    let rotated =
        NodalFrames::new(&walls, &dofs).and_then(|f| f.rotate_matrix(&asm.k).map(|k| (f, k)));
    let order = nested_dissection(mesh, &dofs)?;
    let (frames, factor) = match rotated {
        Some((f, k_rot)) => {
            let order = f.order_last(&order);
            let symbolic = SymbolicFactor::analyse(&k_rot, Some(&order))?;
            (Some(f), CholeskyFactor::factorise(&symbolic, &k_rot)?)
        }
        None => {
            let symbolic = SymbolicFactor::analyse(&asm.k, Some(&order))?;
            (None, CholeskyFactor::factorise(&symbolic, &asm.k)?)
        }
    };
    timings.factorisation_s = t.elapsed().as_secs_f64();
    // K x = b through the factor (of K' = Tᵀ K T when rotated: x = T K'⁻¹ Tᵀ b)
    let solve_k = |b: &mut [f64]| {
        if let Some(f) = &frames {
            f.rotate(b, true);
        }
        factor.solve_in_place(b, 1);
        if let Some(f) = &frames {
            f.rotate(b, false);
        }
    };

    let t = Instant::now();
    let loads = if problem.loads.is_empty() {
        vec![0.0; n]
    } else {
        problem.loads.clone()
    };
    let to_full = |x: &[f64]| -> Vec<f64> {
        (0..n)
            .map(|d| dofs.eq(d).map_or(dofs.value(d), |q| x[q]))
            .collect()
    };
    let rhs_of = |f: &[f64]| -> Vec<f64> {
        let mut b = asm.dirichlet_rhs.clone();
        for (d, v) in f.iter().enumerate() {
            if let Some(q) = dofs.eq(d) {
                b[q] += v;
            }
        }
        b
    };
    let mut x0 = rhs_of(&loads);
    solve_k(&mut x0);
    let u0 = to_full(&x0);
    // rows: (wall, b); the equation numbers of the wall nodes' DOFs
    let rows: Vec<(usize, usize)> = walls
        .iter()
        .enumerate()
        .flat_map(|(w, wall)| (0..wall.len()).map(move |b| (w, b)))
        .collect();
    let h: Vec<f64> = walls
        .iter()
        .flat_map(|w| w.weighted(&w.gaps(&u0, [0.0; 3])))
        .collect();
    // Z = [CΦ, −B]
    let force_pins: Vec<usize> = (0..walls.len())
        .filter(|&w| matches!(problem.cylinders[w].motion, PinMotion::Force(_)))
        .collect();
    let nz = k + 2 * force_pins.len();
    let mut z = vec![vec![0.0; nz]; m];
    for (j, &(w, b)) in rows.iter().enumerate() {
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
    let mut q = vec![0.0; nz];
    for (nd, x) in mesh.nodes().iter().enumerate() {
        for (i, qi) in q.iter_mut().take(k).enumerate() {
            let mode = fl.mode_at(i, *x);
            *qi -= (0..3).map(|j| mode[j] * loads[3 * nd + j]).sum::<f64>();
        }
    }
    for (p, &w) in force_pins.iter().enumerate() {
        let PinMotion::Force(fv) = problem.cylinders[w].motion else {
            unreachable!()
        };
        q[k + 2 * p] = -dot(fv, walls[w].basis.0);
        q[k + 2 * p + 1] = -dot(fv, walls[w].basis.1);
    }
    // the null space of Z: combinations (α, w) that move nothing against a pin. Their body
    // part α is held (the pins' translations stay free, so each pin still carries its whole
    // force): y is restricted to the complement of the held α-directions
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
    let basis = proj.eigenvectors;
    let range: Vec<usize> = (0..nz).filter(|&i| proj.eigenvalues[i] < 0.5).collect();
    let e: Vec<Vec<f64>> = z
        .iter()
        .map(|row| {
            range
                .iter()
                .map(|&i| (0..nz).map(|r| row[r] * basis[(r, i)]).sum())
                .collect()
        })
        .collect();
    let qe: Vec<f64> = range
        .iter()
        .map(|&i| (0..nz).map(|r| q[r] * basis[(r, i)]).sum())
        .collect();

    // the first active set: rows closed or penetrating at the start, and rows facing each
    // force-driven pin's force and (on a floating body) the fixed pins' reaction
    let mut total_force = [0.0; 3];
    for (i, v) in loads.iter().enumerate() {
        total_force[i % 3] += v;
    }
    for cyl in &problem.cylinders {
        if let PinMotion::Force(fv) = cyl.motion {
            for j in 0..3 {
                total_force[j] += fv[j];
            }
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
        e,
        q: qe,
        initial,
        gap_tol: 1e-10 * hmax.max(f64::MIN_POSITIVE),
        max_iterations: 60,
    };
    // eq numbers of the wall nodes' DOFs, to apply C to a vector of equations
    let eqs: Vec<Vec<[Option<usize>; 3]>> = walls
        .iter()
        .map(|w| {
            w.nodes
                .iter()
                .map(|&nd| std::array::from_fn(|j| dofs.eq(3 * nd + j)))
                .collect()
        })
        .collect();
    let compliance = match &frames {
        Some(f) => Compliance::trailing(&factor, &walls, &f.radial())?,
        None => Compliance::solves(&factor, n_eq, &walls, &eqs),
    };
    timings.rest_s += t.elapsed().as_secs_f64();
    let mut columns_s = 0.0;
    let mut columns = |js: &[usize]| -> Result<Vec<Vec<f64>>> {
        let t = Instant::now();
        let out = compliance.columns(js);
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
            range
                .iter()
                .zip(&sol.eta)
                .map(|(&i, eta)| basis[(r, i)] * eta)
                .sum()
        })
        .collect();
    let pressures: Vec<Vec<f64>> = walls
        .iter()
        .map(|w| sol.lambda[w.offset..w.offset + w.len()].to_vec())
        .collect();
    let mut f = loads.clone();
    for (w, lam) in walls.iter().zip(&pressures) {
        w.add_forces(lam, &mut f);
    }
    let mut x = rhs_of(&f);
    solve_k(&mut x);
    let mut u = to_full(&x);
    fl.add_motion(mesh, &y[..k], &mut u);
    let pins: Vec<[f64; 3]> = (0..walls.len())
        .map(|w| match force_pins.iter().position(|&fw| fw == w) {
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
    let (chk, mut restraint, reactions) = check(problem, &u, &pressures, &pins, &fl.support)?;
    restraint.free_motions = free_motions;
    let cylinders = walls
        .iter()
        .zip(&pressures)
        .zip(&pins)
        .map(|((w, lam), pin)| summarise(w, lam, &w.gaps(&u, *pin), *pin))
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
        rows: m,
        columns: sol.columns,
        equations: n_eq,
        timings,
    })
}
