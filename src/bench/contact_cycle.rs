//! `bench contact-cycle DESIGN`: what solving contact at the few instants that matter
//! ([`crate::rod::cycle::contact_instants::instants_that_matter`], the study's scheme) costs
//! against direct contact solves at many instants spread over the cycle: the largest judged peak
//! over the direct instants against the largest over the chosen ones, and the time of each scheme
//! beside the linear cycle's.

use std::time::Instant;

use anyhow::{Context, Result};
use serde::Serialize;

use crate::config::StudyConfig;
use crate::rod::cycle::contact_instants::{ContactInstant, contact_instants, instants_that_matter};
use crate::stages::fem::{FemLoads, MeshMode};

/// The comparison of one design.
#[derive(Clone, Debug, Serialize)]
pub struct ContactCycleBench {
    pub design: String,
    pub nodes: usize,
    /// The linear cycle: its instants, its maximum (MPa) and the stage's wall time (s).
    pub linear_instants: usize,
    pub linear_max_mpa: f64,
    pub linear_s: f64,
    /// The study's scheme: contact at the instants that matter.
    pub chosen: Vec<ContactInstant>,
    pub chosen_max_mpa: f64,
    pub chosen_s: f64,
    /// Direct contact solves at `direct.len()` instants evenly spread over the cycle.
    pub direct: Vec<ContactInstant>,
    pub direct_max_mpa: f64,
    pub direct_s: f64,
    /// (chosen max − direct max) / direct max: what the cheaper scheme misses (≤ 0 when the
    /// direct instants find a larger peak).
    pub chosen_vs_direct_rel: f64,
}

/// Runs stage 3 (`mode`) and the cycle of `design` under `config`, then contact at the chosen
/// instants and at `direct` instants evenly spread over the cycle.
pub fn bench_contact_cycle(
    design_file: &std::path::Path,
    config: &StudyConfig,
    mode: &MeshMode,
    direct: usize,
) -> Result<ContactCycleBench> {
    let design = crate::stages::mass::load(design_file)?;
    let mass = crate::stages::mass::mass(&design)?;
    let loads = FemLoads::of_design(&design, config)?;
    let work = std::env::temp_dir().join(format!(
        "rodstudy-bench-contact-cycle-{}",
        std::process::id()
    ));
    let f = crate::stages::fem::fem(&design, &loads, config, &work, mode)?;
    let _ = std::fs::remove_dir_all(&work);
    let t = Instant::now();
    let mut no_contact = *config;
    no_contact.fem.load_model_error = false;
    let c = crate::stages::cycle::cycle(&mass, &f.mesh, &no_contact)?;
    let linear_s = t.elapsed().as_secs_f64();
    let instants = crate::stages::cycle::cycle_instants(&mass, &f.mesh, config)?;
    let options = crate::stages::cycle::cycle_options(&mass, &f.mesh, config);
    let material = crate::fem::Material::from(&config.fem);
    let history = &c.cycle.history;
    let run = |which: &[(usize, String)]| -> Result<(Vec<ContactInstant>, f64)> {
        let t = Instant::now();
        let r = contact_instants(
            &f.mesh.mesh,
            &material,
            &f.mesh.bores,
            &options,
            &instants,
            history,
            which,
        )
        .context("contact at the instants")?;
        Ok((r.instants, t.elapsed().as_secs_f64()))
    };
    let (chosen, chosen_s) = run(&instants_that_matter(&instants, c.cycle.max_instant))?;
    let n = instants.len();
    let step = (n / direct.max(1)).max(1);
    let spread: Vec<(usize, String)> = (0..n)
        .step_by(step)
        .map(|k| (k, "direct".to_string()))
        .collect();
    let (direct, direct_s) = run(&spread)?;
    let max = |v: &[ContactInstant]| v.iter().map(|i| i.contact_mpa).fold(0.0, f64::max);
    let (chosen_max_mpa, direct_max_mpa) = (max(&chosen), max(&direct));
    Ok(ContactCycleBench {
        design: design_file.display().to_string(),
        nodes: f.mesh.mesh.n_nodes(),
        linear_instants: n,
        linear_max_mpa: c.record.max_von_mises_over_cycle_mpa,
        linear_s,
        chosen,
        chosen_max_mpa,
        chosen_s,
        direct,
        direct_max_mpa,
        direct_s,
        chosen_vs_direct_rel: (chosen_max_mpa - direct_max_mpa) / direct_max_mpa,
    })
}
