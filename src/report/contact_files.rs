//! The files of the pins' contact of one design (the load-model comparison's contact solution, or
//! the solution itself under `[fem] bore_load = "contact"`): per case a ParaView file
//! `contact_<case>.vtu` (displacement, averaged von Mises, contact pressure and gap at the nodes)
//! and a picture `contact_<case>.svg` of the contact pressure around the crank-pin bore against
//! the angle from the pin force, beside the cosine bearing pressure of the same force and the
//! uniform traction's pressure component.

use std::path::Path;

use super::plots::{Scale, Series, line_chart};
use super::vtu::{VtuField, write_vtu};
use crate::fem::TetMesh;
use crate::fem::error::{FemError, Result};
use crate::rod::records::FemResult;
use crate::rod::solve::RodSolution;

/// Writes `contact_<case>.vtu` and `contact_<case>.svg` of each case of `solution` (a contact
/// solution on `mesh`) into `dir`.
pub fn write_contact_fields(solution: &RodSolution, mesh: &TetMesh, dir: &Path) -> Result<()> {
    let result = &solution.result;
    if solution.contact_fields.len() != result.cases.len() {
        return Err(FemError::Check(
            "contact files: the solution has no contact fields for every case".into(),
        ));
    }
    std::fs::create_dir_all(dir).map_err(|e| FemError::io(dir, e))?;
    for (c, case) in result.cases.iter().enumerate() {
        let fields = &solution.contact_fields[c];
        let u_mm: Vec<f64> = solution.displacements[c].iter().map(|v| v * 1e3).collect();
        let vm: Vec<f64> = solution.stresses[c]
            .von_mises_averaged()
            .iter()
            .map(|v| v * 1e-6)
            .collect();
        let p: Vec<f64> = fields.pressure_pa.iter().map(|v| v * 1e-6).collect();
        let g: Vec<f64> = fields.gap_m.iter().map(|v| v * 1e6).collect();
        write_vtu(
            &dir.join(format!("contact_{}.vtu", case.name)),
            mesh,
            &[
                VtuField {
                    name: "displacement_mm",
                    components: 3,
                    data: &u_mm,
                },
                VtuField {
                    name: "von_mises_averaged_MPa",
                    components: 1,
                    data: &vm,
                },
                VtuField {
                    name: "contact_pressure_MPa",
                    components: 1,
                    data: &p,
                },
                VtuField {
                    name: "contact_gap_um",
                    components: 1,
                    data: &g,
                },
            ],
            &[],
        )?;
        let svg = pressure_picture(result, solution, mesh, c)?;
        let path = dir.join(format!("contact_{}.svg", case.name));
        let tmp = path.with_extension("svg.tmp");
        std::fs::write(&tmp, svg).map_err(|e| FemError::io(&tmp, e))?;
        std::fs::rename(&tmp, &path).map_err(|e| FemError::io(&path, e))?;
    }
    Ok(())
}

/// Angular bins of the pressure picture, degrees.
const BIN_DEG: f64 = 2.0;

/// The picture of case `c`: the largest contact pressure at the crank-pin bore's wall nodes in
/// each [`BIN_DEG`] bin of the angle θ from the pin force (about the pin axis z), against the
/// cosine bearing pressure p₀ cos θ (|θ| < 90°) with p₀ = 4F/A of the same force F on the
/// bore's area A (the resultant of p₀ cos θ over a full cylinder is p₀ A/4) and the uniform
/// traction's normal component (F/A) cos θ, which pulls on the far half.
fn pressure_picture(
    result: &FemResult,
    solution: &RodSolution,
    mesh: &TetMesh,
    c: usize,
) -> Result<String> {
    let case = &result.cases.0[c];
    let fields = &solution.contact_fields[c];
    let centre = solution.loaded.centre_m;
    let d = case.direction;
    let (dx, dy) = (d[0], d[1]);
    let n_bins = (360.0 / BIN_DEG).round() as usize;
    let mut bins = vec![f64::NEG_INFINITY; n_bins];
    for &nd in &solution.loaded.nodes {
        let x = mesh.nodes()[nd];
        let (rx, ry) = (x[0] - centre[0], x[1] - centre[1]);
        // the angle from the force direction, counter-clockwise about z, in (−180, 180]
        let theta = (dx * ry - dy * rx).atan2(dx * rx + dy * ry).to_degrees();
        let b = (((theta + 180.0) / BIN_DEG).floor() as usize).min(n_bins - 1);
        bins[b] = bins[b].max(fields.pressure_pa[nd] * 1e-6);
    }
    let contact: Vec<(f64, f64)> = bins
        .iter()
        .enumerate()
        .filter(|(_, p)| p.is_finite())
        .map(|(b, p)| (-180.0 + (b as f64 + 0.5) * BIN_DEG, *p))
        .collect();
    let area_m2 = result.loaded_bore.area_mm2 * 1e-6;
    let q = case.force_n / area_m2 * 1e-6;
    let angles: Vec<f64> = (0..=360).map(|k| -180.0 + k as f64).collect();
    let cosine: Vec<(f64, f64)> = angles
        .iter()
        .map(|&t| (t, 4.0 * q * t.to_radians().cos().max(0.0)))
        .collect();
    let uniform: Vec<(f64, f64)> = angles
        .iter()
        .map(|&t| (t, q * t.to_radians().cos()))
        .collect();
    let label = crate::rod::cases::label(&case.name);
    let title = match &case.contact {
        Some(k) => format!(
            "Crank-pin bore, {label} case: contact arc {:.0}°, peak {:.1} MPa (clearance {:.1} µm)",
            k.arc_a_deg, k.peak_pressure_a_mpa, k.clearance_a_um
        ),
        None => format!("Crank-pin bore, {label} case: contact pressure"),
    };
    line_chart(
        &title,
        "angle from the pin force θ [°]",
        "pressure on the bore [MPa]",
        &[
            Series {
                name: "contact (largest in 2° bins)".into(),
                points: contact,
            },
            Series {
                name: "cosine p₀ cos θ".into(),
                points: cosine,
            },
            Series {
                name: "uniform traction, normal part".into(),
                points: uniform,
            },
        ],
        Scale::Linear,
        Scale::Linear,
    )
    .map_err(|e| FemError::Check(format!("contact picture: {e:#}")))
}
