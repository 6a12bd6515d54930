//! The field files of one design, written after its stages have computed them: the ParaView files
//! of stage 3 (`<stem>_fx.vtu`, `_fy.vtu`: displacement, averaged and recovered von Mises, the
//! stress tensor, the bore sets, the error indicator) and of the cycle (`cycle.vtu`: max von Mises
//! over the revolution, the Goodman and the local (FKM) fatigue factors, χ*, the signed
//! alternating and mean stresses), and the
//! stress pictures of both (`von_mises_fx.svg`, `_fy.svg`, `von_mises_cycle.svg`), and the
//! buckling mode when it was computed (`buckling_mode.vtu`). The records get the paths written.

use super::atomic_write::write_atomic;
use super::vtu::{VtuField, write_vtu};
use crate::fem::TetMesh;
use crate::fem::buckling::BucklingMode;
use crate::fem::error::{FemError, Result};
use crate::fem::estimate::ErrorEstimate;
use crate::fem::stress::StressField;
use crate::report::picture::{PictureOptions, render_tet10_field};
use crate::rod::BoreSurface;
use crate::rod::cycle::{CycleSolution, LocalFatigueSolution, UnitSolutions};
use crate::rod::records::{FemResult, LoadCaseResult};
use crate::rod::solve::RodSolution;
use crate::stages::records::DesignCycle;
use std::path::{Path, PathBuf};

/// Writes the ParaView files `<dir>/<stem>_fx.vtu` and `_fy.vtu` of the fields `solution` on
/// `mesh`, and the pictures of the von Mises field `<dir>/von_mises_fx.svg` and `_fy.svg`, and
/// records their paths in the figures `result` (the solution's own, as the stage reports them).
pub fn write_fem_fields(
    result: &mut FemResult,
    solution: &RodSolution,
    mesh: &TetMesh,
    dir: &Path,
    stem: &str,
) -> Result<()> {
    write_fem_files(result, solution, mesh, dir, stem, FemFiles::VtuAndPictures)
}

/// Writes the buckling mode φ₁ (largest component 1, dimensionless; a point field `mode` and
/// its magnitude) of the load factor λ₁ to `<dir>/buckling_mode.vtu`; returns the path.
pub fn write_buckling_mode(dir: &Path, mesh: &TetMesh, mode: &BucklingMode) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).map_err(|e| FemError::io(dir, e))?;
    let path = dir.join("buckling_mode.vtu");
    let magnitude: Vec<f64> = mode
        .mode
        .chunks_exact(3)
        .map(|d| (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt())
        .collect();
    let factor = vec![mode.load_factor; mesh.n_nodes()];
    let load = vec![mode.load_n; mesh.n_nodes()];
    write_vtu(
        &path,
        mesh,
        &[
            VtuField {
                name: "buckling_mode",
                components: 3,
                data: &mode.mode,
            },
            VtuField {
                name: "buckling_mode_magnitude",
                components: 1,
                data: &magnitude,
            },
            VtuField {
                name: "buckling_load_factor",
                components: 1,
                data: &factor,
            },
            VtuField {
                name: "reference_compression_N",
                components: 1,
                data: &load,
            },
        ],
        &[],
    )?;
    Ok(path)
}

/// The ParaView files of [`write_fem_fields`] alone (`<stem>_fx.vtu`, `_fy.vtu`, and
/// `buckling_mode.vtu` when the solution has a mode), no pictures.
pub fn write_fem_vtus(
    result: &mut FemResult,
    solution: &RodSolution,
    mesh: &TetMesh,
    dir: &Path,
    stem: &str,
) -> Result<()> {
    write_fem_files(result, solution, mesh, dir, stem, FemFiles::Vtu)
}

/// The pictures of [`write_fem_fields`] alone (`<dir>/von_mises_fx.svg`, `_fy.svg`).
pub fn write_fem_pictures(
    result: &mut FemResult,
    solution: &RodSolution,
    mesh: &TetMesh,
    dir: &Path,
) -> Result<()> {
    write_fem_files(result, solution, mesh, dir, "", FemFiles::Pictures)
}

/// Which of stage 3's files [`write_fem_files`] writes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum FemFiles {
    Vtu,
    Pictures,
    VtuAndPictures,
}

/// Stage 3's files: each written by its own task, the tasks in parallel (they share nothing but
/// the read-only solution), so that the whole costs about its longest file on two cores.
fn write_fem_files(
    result: &mut FemResult,
    solution: &RodSolution,
    mesh: &TetMesh,
    dir: &Path,
    stem: &str,
    which: FemFiles,
) -> Result<()> {
    use rayon::prelude::*;
    std::fs::create_dir_all(dir).map_err(|e| FemError::io(dir, e))?;
    let vtus = which != FemFiles::Pictures;
    let pictures = which != FemFiles::Vtu;
    let vtu_paths: Vec<PathBuf> = result
        .cases
        .iter()
        .map(|c| dir.join(format!("{stem}_{}.vtu", c.name)))
        .collect();
    let picture_paths: Vec<PathBuf> = result
        .cases
        .iter()
        .map(|c| dir.join(format!("von_mises_{}.svg", c.name)))
        .collect();
    type Task<'a> = Box<dyn FnOnce() -> Result<()> + Send + 'a>;
    let mut tasks: Vec<Task> = Vec::new();
    for (c, case) in result.cases.iter().enumerate() {
        if vtus {
            let path = &vtu_paths[c];
            tasks.push(Box::new(move || {
                write_case_vtu(
                    path,
                    mesh,
                    &solution.displacements[c],
                    &solution.stresses[c],
                    &solution.estimates[c],
                    &solution.fixed,
                    &solution.loaded,
                    &solution.away_from_fixed,
                )
            }));
        }
        if pictures {
            let path = &picture_paths[c];
            tasks.push(Box::new(move || {
                write_case_picture(path, mesh, &solution.stresses[c], case)
            }));
        }
    }
    if let (true, Some(mode)) = (vtus, &solution.buckling) {
        tasks.push(Box::new(move || {
            write_buckling_mode(dir, mesh, mode).map(|_| ())
        }));
    }
    tasks.into_par_iter().map(|t| t()).collect::<Result<()>>()?;
    for ((case, vtu), picture) in result.cases.iter_mut().zip(vtu_paths).zip(picture_paths) {
        if vtus {
            case.vtu = Some(vtu);
        }
        if pictures {
            case.picture = Some(picture);
        }
    }
    Ok(())
}

/// The picture of one case: the nodally averaged von Mises stress on the surface, the colour
/// scale up to the judged peak (away from the fixed bore and the singular edges; the singular
/// peaks above it get the scale's "over" colour) and that peak marked.
fn write_case_picture(
    path: &Path,
    mesh: &TetMesh,
    field: &StressField,
    case: &LoadCaseResult,
) -> Result<()> {
    let values: Vec<f64> = field
        .von_mises_averaged()
        .iter()
        .map(|v| v * 1e-6)
        .collect();
    let peak = case.max_von_mises_away_from_fixed_mpa;
    let label = crate::rod::cases::label(&case.name);
    let svg = render_tet10_field(
        mesh,
        &values,
        &PictureOptions {
            title: format!(
                "von Mises stress [MPa], {label} case: {:.0} N on the crank-pin bore, small-end bore fixed",
                case.force_n
            ),
            unit: "MPa".into(),
            range: [0.0, if peak > 0.0 { peak } else { 1.0 }],
            marker_mm: Some(case.max_von_mises_away_from_fixed_at_mm),
            marker_label: format!(
                "peak {peak:.1} MPa ± {:.1} %",
                100.0 * case.estimated_error_rel
            ),
            width_px: 960,
        },
    )
    .map_err(|e| FemError::Check(format!("{}: picture: {e:#}", path.display())))?;
    let tmp = path.with_extension("svg.tmp");
    std::fs::write(&tmp, svg).map_err(|e| FemError::io(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| FemError::io(path, e))?;
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn write_case_vtu(
    path: &Path,
    mesh: &TetMesh,
    u: &[f64],
    field: &StressField,
    estimate: &ErrorEstimate,
    fixed: &BoreSurface,
    loaded: &BoreSurface,
    away: &[bool],
) -> Result<()> {
    let u_mm: Vec<f64> = u.iter().map(|v| v * 1e3).collect();
    let vm_mpa: Vec<f64> = field
        .von_mises_averaged()
        .iter()
        .map(|v| v * 1e-6)
        .collect();
    let vm_rec_mpa: Vec<f64> = estimate
        .recovered_von_mises_pa
        .iter()
        .map(|v| v * 1e-6)
        .collect();
    let err_mpa: Vec<f64> = estimate
        .element_von_mises_error_pa
        .iter()
        .map(|v| v * 1e-6)
        .collect();
    let sig_mpa: Vec<f64> = field
        .averaged
        .iter()
        .flat_map(|s| s.map(|v| v * 1e-6))
        .collect();
    let mut set = vec![0.0; mesh.n_nodes()];
    for &n in &loaded.nodes {
        set[n] = 1.0;
    }
    for &n in &fixed.nodes {
        set[n] = 2.0;
    }
    let near: Vec<f64> = away.iter().map(|a| if *a { 0.0 } else { 1.0 }).collect();
    let cell_vm: Vec<f64> = field
        .von_mises_element_max()
        .iter()
        .map(|v| v * 1e-6)
        .collect();
    write_vtu(
        path,
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
                data: &vm_mpa,
            },
            VtuField {
                name: "von_mises_recovered_MPa",
                components: 1,
                data: &vm_rec_mpa,
            },
            VtuField {
                name: "stress_averaged_MPa",
                components: 6,
                data: &sig_mpa,
            },
            VtuField {
                name: "bore_set_1loaded_2fixed",
                components: 1,
                data: &set,
            },
            VtuField {
                name: "near_fixed_band",
                components: 1,
                data: &near,
            },
        ],
        &[
            VtuField {
                name: "von_mises_max_unaveraged_MPa",
                components: 1,
                data: &cell_vm,
            },
            VtuField {
                name: "von_mises_error_indicator_MPa",
                components: 1,
                data: &err_mpa,
            },
        ],
    )
}

fn write_cycle_vtu(
    path: &Path,
    mesh: &TetMesh,
    cycle: &CycleSolution,
    units: &UnitSolutions,
    local: &LocalFatigueSolution,
    gerber: bool,
) -> anyhow::Result<()> {
    // off the surface: the local factor as ∞ (1e6), χ* as 0
    let local_factor: Vec<f64> = local.safety_factor.iter().map(|v| v.min(1e6)).collect();
    let chi_per_mm: Vec<f64> = local.chi_star_per_m.iter().map(|v| v * 1e-3).collect();
    let mpa = |v: &[f64]| v.iter().map(|x| x * 1e-6).collect::<Vec<_>>();
    // ∞ (an unloaded node) is written as a large finite number: ParaView reads no "inf"
    let factor: Vec<f64> = cycle
        .fatigue_safety_factor
        .iter()
        .map(|v| v.min(1e6))
        .collect();
    let judged: Vec<f64> = units
        .judged
        .iter()
        .map(|j| if *j { 1.0 } else { 0.0 })
        .collect();
    write_vtu(
        path,
        mesh,
        &[
            VtuField {
                name: "von_mises_max_over_cycle_MPa",
                components: 1,
                data: &mpa(&cycle.max_von_mises_pa),
            },
            VtuField {
                name: if gerber {
                    "fatigue_safety_factor_gerber"
                } else {
                    "fatigue_safety_factor_goodman"
                },
                components: 1,
                data: &factor,
            },
            VtuField {
                name: "local_fatigue_safety_factor_fkm",
                components: 1,
                data: &local_factor,
            },
            VtuField {
                name: "chi_star_per_mm",
                components: 1,
                data: &chi_per_mm,
            },
            VtuField {
                name: "signed_von_mises_alternating_MPa",
                components: 1,
                data: &mpa(&cycle.alternating_pa),
            },
            VtuField {
                name: "signed_von_mises_mean_MPa",
                components: 1,
                data: &mpa(&cycle.mean_pa),
            },
            VtuField {
                name: "judged_node",
                components: 1,
                data: &judged,
            },
        ],
        &[],
    )?;
    Ok(())
}

fn write_cycle_picture(
    path: &Path,
    mesh: &TetMesh,
    cycle: &CycleSolution,
    record: &DesignCycle,
) -> anyhow::Result<()> {
    let values: Vec<f64> = cycle.max_von_mises_pa.iter().map(|v| v * 1e-6).collect();
    let peak = record.max_von_mises_over_cycle_mpa;
    let svg = render_tet10_field(
        mesh,
        &values,
        &PictureOptions {
            title: format!(
                "max von Mises over one revolution [MPa] (inertia relief, {:.0} rad/s)",
                record.omega_rad_s
            ),
            unit: "MPa".into(),
            range: [0.0, if peak > 0.0 { peak } else { 1.0 }],
            marker_mm: Some(record.location_of_max_mm),
            marker_label: format!(
                "max {peak:.1} MPa at φ = {:.0}°",
                record.crank_angle_of_max_deg
            ),
            width_px: 960,
        },
    )?;
    write_atomic(path, svg.as_bytes())?;
    Ok(())
}

/// Writes `dir/cycle.vtu`, `dir/von_mises_cycle.svg` and the local fatigue pictures
/// ([`super::fatigue_pictures`]) of the cycle stage and records their paths in `record`.
pub fn write_cycle_fields(
    record: &mut DesignCycle,
    mesh: &TetMesh,
    cycle: &CycleSolution,
    units: &UnitSolutions,
    local: &LocalFatigueSolution,
    dir: &Path,
) -> anyhow::Result<()> {
    use anyhow::Context;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let vtu = dir.join("cycle.vtu");
    write_cycle_vtu(
        &vtu,
        mesh,
        cycle,
        units,
        local,
        !record.mean_stress.is_goodman(),
    )?;
    let picture = dir.join("von_mises_cycle.svg");
    write_cycle_picture(&picture, mesh, cycle, record)?;
    super::fatigue_pictures::write_fatigue_pictures(record, mesh, local, dir)?;
    record.vtu = Some(vtu);
    record.picture = Some(picture);
    Ok(())
}
