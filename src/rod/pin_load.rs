//! How a pin's force enters its bore (`[fem] bore_load`): the two prescribed spreads as nodal forces
//! on the bore's faces, over the kernel's surface loads ([`crate::fem::load`]), or contact with the
//! pin, which is solved, not prescribed ([`super::contact_cases`]).
//!
//! A prescribed spread of a pin's force on its bore ([`BoreLoad`]) is one of:
//! - **uniform** (the thesis' setting and the default): a constant traction of resultant F over the
//!   whole bore wall, [`uniform_traction_with_resultant`];
//! - **cosine**: a pressure normal to the pin's cylinder over the half of the bore the pin presses
//!   on, p(θ) = p₀ cos θ for |θ| < 90° from the force's direction (compressive contact only, zero
//!   elsewhere), [`cosine_pressure_with_resultant`]. On a full cylinder of radius r and length L
//!   its resultant is p₀ r L π/2 (∫ cos²θ dθ over the half), the classical bearing load
//!   distribution of a pin in a bore with small clearance, as connecting-rod FEM applies it
//!   (P. S. Shenoy, A. Fatemi, *Connecting rod optimization for weight and cost reduction*, SAE
//!   2005-01-0987, after Webster, Coffell and Alfaro, 1983: a cosine over 180° of the bore).
//!   On a mesh the amplitude is not taken from that formula but solved for so that the resultant of
//!   the consistent nodal forces equals F to round-off ([`cosine_pressure_with_resultant`]).

use serde::{Deserialize, Serialize};

use crate::fem::error::Result;
use crate::fem::load::{
    SurfaceLoad, cosine_pressure_with_resultant, uniform_traction_with_resultant,
};
use crate::fem::mesh::TetMesh;

/// How a pin's force is spread over its bore (`[fem] bore_load`; see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BoreLoad {
    /// A uniform traction over the whole bore wall (the thesis' setting, the default).
    #[default]
    Uniform,
    /// A cosine pressure over the half of the bore the pin presses on.
    Cosine,
    /// Frictionless contact with a rigid pin of the bore's radius less the clearance
    /// ([`super::contact_cases`]): the arc and the pressure follow from the solve.
    Contact,
}

impl BoreLoad {
    /// Whether this is the default (uniform), e.g. to leave it out of written results.
    pub fn is_uniform(&self) -> bool {
        *self == BoreLoad::Uniform
    }

    /// The name as in the configuration.
    pub fn name(self) -> &'static str {
        match self {
            BoreLoad::Uniform => "uniform",
            BoreLoad::Cosine => "cosine",
            BoreLoad::Contact => "contact",
        }
    }

    /// The load a linear, superposable analysis uses for this one: contact's closest prescribed
    /// spread is the cosine pressure on the pressed half (the arc of a pin with small clearance;
    /// docs/contact.md), the others are themselves.
    pub fn linear(self) -> BoreLoad {
        match self {
            BoreLoad::Contact => BoreLoad::Cosine,
            other => other,
        }
    }
}

/// The nodal forces of the pin force `resultant` (N) on the bore `faces` around the pin axis
/// through `centre` (m) with unit direction `axis`, spread as `kind` says; contact, which is not a
/// prescribed spread, as its linear stand-in ([`BoreLoad::linear`]).
pub fn pin_load(
    mesh: &TetMesh,
    faces: &[[usize; 6]],
    centre: [f64; 3],
    axis: [f64; 3],
    resultant: [f64; 3],
    kind: BoreLoad,
) -> Result<SurfaceLoad> {
    match kind.linear() {
        BoreLoad::Uniform => uniform_traction_with_resultant(mesh, faces, resultant),
        _ => cosine_pressure_with_resultant(mesh, faces, centre, axis, resultant),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::boundary::{boundary_faces, norm};
    use crate::fem::load::faces_area;
    use crate::fem::mesh::structured::{TwoEyePlate, two_eye_plate};
    use crate::rod::bores::{BoreSpec, find_bores};

    fn plate(curved: bool) -> (TetMesh, Vec<[usize; 6]>) {
        let mesh = two_eye_plate(&TwoEyePlate {
            n_side: 6,
            curved,
            ..TwoEyePlate::default()
        })
        .unwrap();
        let boundary = boundary_faces(&mesh).unwrap();
        let (loaded, _) = find_bores(&mesh, &boundary, &BoreSpec::default()).unwrap();
        (mesh, loaded.faces)
    }

    fn resultant(f: &[f64]) -> [f64; 3] {
        let mut r = [0.0; 3];
        for (i, v) in f.iter().enumerate() {
            r[i % 3] += v;
        }
        r
    }

    #[test]
    fn the_cosine_pressure_has_the_requested_resultant_and_presses_only_the_loaded_half() {
        for curved in [false, true] {
            let (mesh, faces) = plate(curved);
            for deg in [0.0f64, 30.0, 90.0, 137.0, 180.0, 251.0] {
                let (s, c) = deg.to_radians().sin_cos();
                let f = [7202.0 * c, 7202.0 * s, 0.0];
                let load =
                    cosine_pressure_with_resultant(&mesh, &faces, [0.0; 3], [0.0, 0.0, 1.0], f)
                        .unwrap();
                let r = resultant(&load.forces);
                let err = norm([r[0] - f[0], r[1] - f[1], r[2] - f[2]]) / 7202.0;
                assert!(err <= 1e-12, "{deg}°: {r:?} vs {f:?} ({err:e})");
                // no force on the nodes of the far half (beyond 90° from the force by more than a face)
                for (n, x) in mesh.nodes().iter().enumerate() {
                    let fv = &load.forces[3 * n..3 * n + 3];
                    let cos = (x[0] * c + x[1] * s) / x[0].hypot(x[1]).max(1e-30);
                    if x[0].hypot(x[1]) < 0.03 && cos < -0.35 {
                        assert!(fv.iter().all(|v| *v == 0.0), "{deg}°: node {n} {fv:?}");
                    }
                }
                // the amplitude against the closed form 2F/(π r L) of a half cylinder
                let p0 = 2.0 * 7202.0 / (std::f64::consts::PI * 0.025 * 0.04);
                let amp = norm(load.traction_pa);
                let rel = (amp - p0).abs() / p0;
                let tol = if curved { 2e-3 } else { 2e-2 };
                assert!(
                    rel < tol,
                    "curved {curved}, {deg}°: p0 {amp:.4e} vs {p0:.4e} ({rel:.2e})"
                );
                // half the wall is pressed
                let total = faces_area(&mesh, &faces);
                assert!(
                    (load.area_m2 / total - 0.5).abs() < 0.05,
                    "{}",
                    load.area_m2 / total
                );
            }
        }
    }

    #[test]
    fn pin_load_dispatches_and_the_uniform_default_is_today_s_traction() {
        let (mesh, faces) = plate(false);
        let f = [1000.0, -200.0, 0.0];
        let u = pin_load(
            &mesh,
            &faces,
            [0.0; 3],
            [0.0, 0.0, 1.0],
            f,
            BoreLoad::default(),
        )
        .unwrap();
        assert_eq!(
            u.forces,
            uniform_traction_with_resultant(&mesh, &faces, f)
                .unwrap()
                .forces
        );
        let c = pin_load(
            &mesh,
            &faces,
            [0.0; 3],
            [0.0, 0.0, 1.0],
            f,
            BoreLoad::Cosine,
        )
        .unwrap();
        assert_ne!(c.forces, u.forces);
    }

    #[test]
    fn a_cosine_load_is_refused_along_the_axis_and_on_a_missing_half() {
        let (mesh, faces) = plate(false);
        let axial = cosine_pressure_with_resultant(
            &mesh,
            &faces,
            [0.0; 3],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 100.0],
        );
        assert!(axial.unwrap_err().to_string().contains("perpendicular"));
        // keep only the wall on the x < 0 side: a force along +x has nothing to press on
        let half: Vec<[usize; 6]> = faces
            .iter()
            .copied()
            .filter(|f| f[..3].iter().all(|&n| mesh.nodes()[n][0] < -1e-9))
            .collect();
        let open = cosine_pressure_with_resultant(
            &mesh,
            &half,
            [0.0; 3],
            [0.0, 0.0, 1.0],
            [100.0, 0.0, 0.0],
        );
        assert!(open.unwrap_err().to_string().contains("no bore wall"));
        // pressing towards the existing half works
        let ok = cosine_pressure_with_resultant(
            &mesh,
            &half,
            [0.0; 3],
            [0.0, 0.0, 1.0],
            [-100.0, 0.0, 0.0],
        )
        .unwrap();
        assert!(ok.resultant_error_rel <= 1e-12);
    }
}
