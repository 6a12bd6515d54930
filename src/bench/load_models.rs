//! `bench load-models DESIGN`: speed against error of the three ways a pin's force can enter the
//! rod ([`BoreLoad`]): stage 3's final mesh, then the static cases on it under the uniform
//! traction, the cosine pressure and contact, each timed (median of `repeats`) and its judged
//! peaks compared with contact's, the model whose pressure follows from the mechanics
//! ([`crate::rod::load_models`]). The times are the whole static analysis of the cases on that
//! mesh (solve, stresses, recovery, estimate), as the study runs it (the half model where the
//! study solved one).

use anyhow::{Context, Result};
use serde::Serialize;

use super::median_time;
use crate::config::StudyConfig;
use crate::rod::half_model::solve_rod_on;
use crate::rod::pin_load::BoreLoad;
use crate::rod::{BoreSpec, RodOptions};
use crate::stages::fem::{FemLoads, MeshMode};

/// One load model on the final mesh.
#[derive(Clone, Debug, Serialize)]
pub struct LoadModelRun {
    /// `uniform`, `cosine` or `contact`.
    pub model: String,
    /// Median wall time of the static cases, s, and that time over the uniform traction's.
    pub seconds: f64,
    pub time_vs_uniform: f64,
    /// Per case (`fx`, `fy`): the judged peak, MPa, and |P − P_contact| / P_contact.
    pub cases: Vec<(String, f64, f64)>,
    /// Why the model could not be solved (e.g. a cosine pressure across a capless big end).
    pub error: Option<String>,
}

/// The comparison on one design.
#[derive(Clone, Debug, Serialize)]
pub struct LoadModelsBench {
    pub design: String,
    /// Nodes of the mesh solved (the half model's, if one).
    pub nodes: usize,
    pub half_model: bool,
    /// The estimated discretisation error of each case on this mesh (the adaptive loop's, of the
    /// model the study solved under).
    pub discretisation_error_rel: Vec<(String, f64)>,
    pub runs: Vec<LoadModelRun>,
}

/// Runs stage 3 (`mode`) on `design_file`, then the static cases on its final mesh under each
/// load model, `repeats` times each.
pub fn bench_load_models(
    design_file: &std::path::Path,
    config: &StudyConfig,
    mode: &MeshMode,
    repeats: usize,
) -> Result<LoadModelsBench> {
    let design = crate::stages::mass::load(design_file)?;
    let loads = FemLoads::of_design(&design, config)?;
    let mut config = *config;
    config.fem.load_model_error = false;
    let work =
        std::env::temp_dir().join(format!("rodstudy-bench-load-models-{}", std::process::id()));
    let f = crate::stages::fem::fem(&design, &loads, &config, &work, mode)?;
    let _ = std::fs::remove_dir_all(&work);
    let stage = &f.mesh;
    let half = f.solution.result.half_model.as_ref();
    let mesh = match half {
        Some(h) => h.half_of(&stage.mesh)?,
        None => stage.mesh.clone(),
    };
    let options = RodOptions {
        fixed_band_m: Some(stage.fixed_band_m),
        singular_band_m: Some(stage.singular_band_m),
        singular_edges_m: stage.singular_edges_m.clone(),
        fy_force_n: loads.transverse_n,
        mirror_plane_z_m: half.map(|h| h.plane_z_m()),
        ..RodOptions::default()
    };
    let material = crate::fem::Material::from(&config.fem);
    let mut runs = Vec::new();
    let mut peaks: Vec<Option<Vec<(String, f64)>>> = Vec::new();
    for model in [BoreLoad::Uniform, BoreLoad::Cosine, BoreLoad::Contact] {
        let spec = BoreSpec {
            bore_load: model,
            ..stage.bores.clone()
        };
        let (time, solved) = median_time(repeats, || {
            solve_rod_on(mesh.clone(), &material, &spec, loads.force_n, &options)
        });
        let (p, error) = match solved {
            Ok((_, s)) => (
                Some(
                    s.result
                        .cases
                        .0
                        .iter()
                        .map(|c| (c.name.clone(), c.max_von_mises_away_from_fixed_mpa))
                        .collect::<Vec<_>>(),
                ),
                None,
            ),
            Err(e) => (None, Some(format!("{e}"))),
        };
        peaks.push(p);
        runs.push(LoadModelRun {
            model: model.name().to_string(),
            seconds: time.as_secs_f64(),
            time_vs_uniform: 0.0,
            cases: Vec::new(),
            error,
        });
    }
    let contact = peaks[2]
        .clone()
        .context("the contact model could not be solved on the final mesh")?;
    let uniform_s = runs[0].seconds;
    for (run, p) in runs.iter_mut().zip(&peaks) {
        run.time_vs_uniform = run.seconds / uniform_s;
        if let Some(p) = p {
            run.cases = p
                .iter()
                .zip(&contact)
                .map(|((name, v), (_, c))| (name.clone(), *v, (v - c).abs() / c))
                .collect();
        }
    }
    Ok(LoadModelsBench {
        design: design_file.display().to_string(),
        nodes: mesh.n_nodes(),
        half_model: half.is_some(),
        discretisation_error_rel: f
            .record
            .fem
            .cases
            .0
            .iter()
            .map(|c| (c.name.clone(), c.estimated_discretisation_error_rel))
            .collect(),
        runs,
    })
}
