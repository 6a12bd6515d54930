//! K of a body factorised for its contact compliance ([`super::compliance`]): the one
//! factorisation the body's [`super::system::ContactSystem`] and an elastic pin
//! ([`super::elastic_pin`]) each make.

use std::time::Instant;

use super::compliance::{Compliance, NodalFrames};
use super::weights::Wall;
use crate::fem::assembly::{DofMap, assemble};
use crate::fem::element::QuadratureChoice;
use crate::fem::error::Result;
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;
use crate::fem::ordering::nested_dissection;
use crate::fem::solver::{CholeskyFactor, SymbolicFactor};

/// K of a body assembled with `dofs` and factorised for the contact compliance of `walls`: in the
/// wall nodes' radial frames with the radial equations last where the supports allow it
/// ([`super::compliance`]), else as it is with the columns solved one by one.
pub struct Factorised {
    pub dirichlet_rhs: Vec<f64>,
    pub frames: Option<NodalFrames>,
    pub factor: CholeskyFactor,
    pub compliance: Compliance,
    pub assembly_s: f64,
    pub factorisation_s: f64,
}

impl Factorised {
    pub fn new(
        mesh: &TetMesh,
        material: &Material,
        quadrature: QuadratureChoice,
        dofs: &DofMap,
        walls: &[Wall],
    ) -> Result<Factorised> {
        let t = Instant::now();
        let asm = assemble(mesh, material, quadrature, dofs)?;
        let assembly_s = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let rotated =
            NodalFrames::new(walls, dofs).and_then(|f| f.rotate_matrix(&asm.k).map(|k| (f, k)));
        let order = nested_dissection(mesh, dofs)?;
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
            Some(f) => Compliance::trailing(&factor, walls, &f.radial())?,
            None => Compliance::solves(dofs.n_eq(), walls, &eqs),
        };
        Ok(Factorised {
            dirichlet_rhs: asm.dirichlet_rhs,
            frames,
            factor,
            compliance,
            assembly_s,
            factorisation_s: t.elapsed().as_secs_f64(),
        })
    }

    /// K x = b through the factor (of K' = Tᵀ K T when rotated: x = T K'⁻¹ Tᵀ b), in place.
    pub fn solve(&self, b: &mut [f64]) {
        if let Some(f) = &self.frames {
            f.rotate(b, true);
        }
        self.factor.solve_in_place(b, 1);
        if let Some(f) = &self.frames {
            f.rotate(b, false);
        }
    }
}
