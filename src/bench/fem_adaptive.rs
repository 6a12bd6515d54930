//! Benchmark of stage 3's adaptive loop: where each design's time goes, per
//! iteration and phase. Each design runs `rodstudy fem DESIGN --json --no-pictures` in its own
//! process, cold, as a user runs it; the per-iteration phases come from its record
//! (`fx.adaptive[k].timings`, [`crate::rod::records::StepTimings`]): the mesh (gmsh, with the STL's
//! classification on the first), the analysis (assembly, symbolic analysis, factorisation, solves,
//! stresses with recovery and error estimate) and the rest (sizing the next mesh). The shares are
//! against the loop's own total, so they travel between machines better than the seconds. Where
//! gmsh made the meshes, a third table splits each mesh into gmsh's own phases
//! ([`MeshPhases`]: the model, 1D, 2D, 3D with HXT's optimisation, order 2) and the calls around
//! them (qualities, write, and the read on this side).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};

use crate::rod::records::MeshPhases;

/// One iteration of one design.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct IterationRow {
    pub iteration: usize,
    pub dofs: usize,
    pub mesh_s: f64,
    pub assembly_s: f64,
    pub symbolic_s: f64,
    pub factorisation_s: f64,
    pub solve_s: f64,
    /// Stresses, recovery, error estimate and peaks of both cases.
    pub stress_s: f64,
    /// The iteration's wall time less its mesh and analysis: sizing the next mesh.
    pub rest_s: f64,
    pub seconds: f64,
    /// Estimated relative error of the F_x and F_y peaks after this iteration.
    pub estimated_error_rel: [f64; 2],
    /// The mesh's own phases (gmsh's, and the read), where the mesher reported them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh_phases: Option<MeshPhases>,
}

/// One design's loop.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DesignRow {
    pub design: String,
    pub iterations: Vec<IterationRow>,
    /// Why the loop stopped (`converged`, `size_floor`, …).
    pub stop: String,
    pub target_error_rel: f64,
    /// Wall time of the loop (`fem.total_s`), s.
    pub loop_s: f64,
    /// Wall time of the whole command (with reading the design, the buckling check, the VTU
    /// files), s.
    pub command_s: f64,
}

/// The benchmark of every design.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AdaptiveBench {
    pub designs: Vec<DesignRow>,
}

/// Runs the adaptive stage of each STL in `files` in a child process of `exe`.
pub fn bench_fem_adaptive(exe: &Path, files: &[PathBuf]) -> Result<AdaptiveBench> {
    let mut designs = Vec::new();
    for stl in files {
        let out = tempfile::tempdir()?;
        let start = Instant::now();
        let output = Command::new(exe)
            .arg("fem")
            .arg(stl)
            .args(["--json", "--no-pictures", "--out"])
            .arg(out.path())
            .output()?;
        let command_s = start.elapsed().as_secs_f64();
        if !output.status.success() {
            bail!(
                "{}: {}",
                stl.display(),
                String::from_utf8_lossy(&output.stderr).trim()
            );
        }
        let v: serde_json::Value = serde_json::from_slice(&output.stdout)?;
        designs.push(design_row(stl, &v, command_s)?);
    }
    Ok(AdaptiveBench { designs })
}

/// The rows of one `fem --json` record.
fn design_row(stl: &Path, v: &serde_json::Value, command_s: f64) -> Result<DesignRow> {
    let num = |x: &serde_json::Value| x.as_f64().unwrap_or(f64::NAN);
    let fx = v["fx"]["adaptive"].as_array();
    let fy = v["fy"]["adaptive"].as_array();
    let (Some(fx), Some(fy)) = (fx, fy) else {
        bail!(
            "{}: the record has no adaptive sequence (a fixed mesh?)",
            stl.display()
        );
    };
    let iterations = fx
        .iter()
        .zip(fy)
        .map(|(x, y)| {
            let t = &x["timings"];
            let (mesh_s, analysis_s, seconds) =
                (num(&t["mesh_s"]), num(&t["analysis_s"]), num(&x["seconds"]));
            IterationRow {
                iteration: x["iteration"].as_u64().unwrap_or(0) as usize,
                dofs: x["dofs"].as_u64().unwrap_or(0) as usize,
                mesh_s,
                assembly_s: num(&t["assembly_s"]),
                symbolic_s: num(&t["symbolic_s"]),
                factorisation_s: num(&t["factorisation_s"]),
                solve_s: num(&t["solve_s"]),
                stress_s: num(&t["stress_s"]),
                rest_s: seconds - mesh_s - analysis_s,
                seconds,
                estimated_error_rel: [
                    num(&x["estimated_error_rel"]),
                    num(&y["estimated_error_rel"]),
                ],
                mesh_phases: serde_json::from_value(t["mesh_phases"].clone()).ok(),
            }
        })
        .collect();
    let adaptive = &v["mesh"]["adaptive"];
    Ok(DesignRow {
        design: stl
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        iterations,
        stop: adaptive["stop"].as_str().unwrap_or("").to_string(),
        target_error_rel: num(&adaptive["target_error_rel"]),
        loop_s: num(&v["fem"]["total_s"]),
        command_s,
    })
}

/// The tables for people: per iteration, then per design with the shares of the loop's time.
pub fn markdown(b: &AdaptiveBench) -> String {
    let mut s = String::from(
        "Stage 3's adaptive loop, each design in its own process (`fem DESIGN --json --no-pictures`)\n\n\
         | design | iteration | DOFs | mesh [s] | assembly [s] | symbolic [s] | factorisation [s] | solves [s] | stresses, recovery, estimate [s] | sizing, rest [s] | iteration [s] | est. error F_x / F_y |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for d in &b.designs {
        for r in &d.iterations {
            s.push_str(&format!(
                "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.1} % / {:.1} % |\n",
                d.design,
                r.iteration,
                r.dofs,
                r.mesh_s,
                r.assembly_s,
                r.symbolic_s,
                r.factorisation_s,
                r.solve_s,
                r.stress_s,
                r.rest_s,
                r.seconds,
                100.0 * r.estimated_error_rel[0],
                100.0 * r.estimated_error_rel[1]
            ));
        }
    }
    s.push_str(
        "\n| design | iterations | stop | loop [s] | command [s] | mesh | assembly | symbolic | factorisation | solves | stresses, estimate | rest |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for d in &b.designs {
        let sum = |f: fn(&IterationRow) -> f64| d.iterations.iter().map(f).sum::<f64>();
        let share = |x: f64| format!("{:.0} %", 100.0 * x / d.loop_s);
        s.push_str(&format!(
            "| {} | {} | {} | {:.1} | {:.1} | {} | {} | {} | {} | {} | {} | {} |\n",
            d.design,
            d.iterations.len(),
            d.stop,
            d.loop_s,
            d.command_s,
            share(sum(|r| r.mesh_s)),
            share(sum(|r| r.assembly_s)),
            share(sum(|r| r.symbolic_s)),
            share(sum(|r| r.factorisation_s)),
            share(sum(|r| r.solve_s)),
            share(sum(|r| r.stress_s)),
            share(
                d.loop_s
                    - sum(|r| r.mesh_s
                        + r.assembly_s
                        + r.symbolic_s
                        + r.factorisation_s
                        + r.solve_s
                        + r.stress_s)
            ),
        ));
    }
    let phased: Vec<(&DesignRow, &IterationRow, &MeshPhases)> = b
        .designs
        .iter()
        .flat_map(|d| {
            d.iterations
                .iter()
                .filter_map(move |r| r.mesh_phases.as_ref().map(|p| (d, r, p)))
        })
        .collect();
    if !phased.is_empty() {
        s.push_str(
            "\nThe meshes phase by phase [s] (gmsh's own wall times; `model`: the classification on \
             the first mesh, the options alone where the gmsh session built the model while the \
             last mesh was solved; HXT's optimisation is part of 3D; `read`: the mesh read back \
             here)\n\n\
             | design | iteration | mesh [s] | model | 1D | 2D | 3D | of it HXT optimisation | order 2 | qualities | write | read |\n\
             |---|---|---|---|---|---|---|---|---|---|---|---|\n",
        );
        let f = |x: Option<f64>| x.map_or("–".to_string(), |v| format!("{v:.2}"));
        for (d, r, p) in phased {
            s.push_str(&format!(
                "| {} | {} | {:.2} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                d.design,
                r.iteration,
                r.mesh_s,
                f(p.model),
                f(p.mesh_1d),
                f(p.mesh_2d),
                f(p.mesh_3d),
                f(p.hxt_optimise),
                f(p.order_2),
                f(p.qualities),
                f(p.write),
                f(p.read),
            ));
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_becomes_rows_whose_phases_add_up() {
        let step = |it: u64, e: f64| {
            serde_json::json!({"iteration": it, "dofs": 1000 * (it + 1), "estimated_error_rel": e,
                "seconds": 3.0, "timings": {"mesh_s": 1.0, "analysis_s": 1.5, "assembly_s": 0.2,
                "symbolic_s": 0.1, "factorisation_s": 0.9, "solve_s": 0.1, "stress_s": 0.2}})
        };
        let v = serde_json::json!({
            "fx": {"adaptive": [step(0, 0.2), step(1, 0.02)]},
            "fy": {"adaptive": [step(0, 0.1), step(1, 0.01)]},
            "mesh": {"adaptive": {"stop": "converged", "target_error_rel": 0.03}},
            "fem": {"total_s": 6.0}
        });
        let mut d = design_row(Path::new("designs/x.stl"), &v, 7.0).unwrap();
        assert!(d.iterations.iter().all(|r| r.mesh_phases.is_none()));
        assert!(
            !markdown(&AdaptiveBench {
                designs: vec![d.clone()]
            })
            .contains("phase by phase")
        );
        // a record whose mesher reported its phases gets the third table
        let mut phased = v.clone();
        phased["fx"]["adaptive"][1]["timings"]["mesh_phases"] = serde_json::json!({
            "model": 0.01, "mesh_1d": 0.2, "mesh_2d": 0.4, "mesh_3d": 0.3, "order_2": 0.05,
            "qualities": 0.02, "write": 0.1, "read": 0.03});
        let p = design_row(Path::new("designs/x.stl"), &phased, 7.0).unwrap();
        assert_eq!(p.iterations[1].mesh_phases.unwrap().mesh_2d, Some(0.4));
        assert!(markdown(&AdaptiveBench { designs: vec![p] }).contains(
            "| x | 1 | 1.00 | 0.01 | 0.20 | 0.40 | 0.30 | – | 0.05 | 0.02 | 0.10 | 0.03 |"
        ));
        d.design = "x".into();
        assert_eq!(d.design, "x");
        assert_eq!(d.iterations.len(), 2);
        let r = &d.iterations[1];
        assert_eq!(r.estimated_error_rel, [0.02, 0.01]);
        assert!((r.rest_s - 0.5).abs() < 1e-12);
        let md = markdown(&AdaptiveBench { designs: vec![d] });
        // the shares of the summary add up to the loop (mesh 33 %, analysis 50 %, rest 17 %)
        assert!(
            md.contains(
                "| x | 2 | converged | 6.0 | 7.0 | 33 % | 7 % | 3 % | 30 % | 3 % | 7 % | 17 % |"
            ),
            "{md}"
        );
        // a fixed mesh has no sequence
        let fixed = serde_json::json!({"fx": {}, "fy": {}});
        assert!(design_row(Path::new("y.stl"), &fixed, 1.0).is_err());
    }
}
