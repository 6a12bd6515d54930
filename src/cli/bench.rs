//! `rodstudy bench mass [--triangles N] [--repeats R] [--json]`, `bench fem [DESIGN...] [--size MM]
//! [--force N] [--json]`, `bench fem DESIGN --mesh FILE [--force N] [--repeats K] [--ccx] [--json]`,
//! `bench dynamics [DESIGN]`, `bench contact [--n-side N...] [--repeats R] [--json]`

use crate::bench::mass::bench_mass;
use crate::mechanism::{DrivenScene, MechanismParams, RodInertia, bench_driven};
use crate::stages;
use crate::stages::dynamics::{mechanism_for, rod_inertia};
use anyhow::Result;
use clap::Subcommand;
use std::path::PathBuf;

#[derive(Subcommand)]
pub enum BenchCommand {
    /// Stage 1 on a generated torus mesh: read, weld, validate, integrate vs reading the bytes.
    Mass {
        /// Approximate number of triangles of the generated mesh (at least 1000).
        #[arg(long, default_value_t = 1_000_000, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1000..))]
        triangles: usize,
        /// Repeats per step (at least 1); the median is reported.
        #[arg(long, default_value_t = 5, value_parser = at_least_one)]
        repeats: usize,
        #[arg(long)]
        json: bool,
    },
    /// Stage 3: mesh, assembly, symbolic analysis, factorisation, solve and stress times and
    /// peak memory per design at one mesh size (each design in its own process for the memory).
    /// With `--mesh FILE`: the fixed-mesh path of one design (`fem DESIGN --mesh FILE`) phase by
    /// phase: read (native and meshio), rod-frame mapping, analysis, VTU, pictures, and the whole
    /// command with and without pictures.
    Fem {
        /// STL designs (default: every design in designs/; exactly one with `--mesh`).
        designs: Vec<PathBuf>,
        /// A volume mesh of the design (in its units and pose): time the fixed-mesh path.
        #[arg(long)]
        mesh: Option<PathBuf>,
        /// With `--mesh`: repeats per phase (at least 1); the median is reported.
        #[arg(long, default_value_t = 3, requires = "mesh", value_parser = at_least_one)]
        repeats: usize,
        /// With `--mesh`: also run CalculiX on the same mesh (pipeline/ccx_peer.py).
        #[arg(long, requires = "mesh")]
        ccx: bool,
        /// The adaptive loop (the study's stage 3) per design, iteration and phase: mesh,
        /// assembly, symbolic analysis, factorisation, solves, stresses with the estimate.
        #[arg(long, conflicts_with = "mesh")]
        adaptive: bool,
        /// Element size [mm] (default 5; not with `--mesh`, which is the mesh, nor `--adaptive`,
        /// which sizes its own meshes).
        #[arg(long, conflicts_with_all = ["mesh", "adaptive"])]
        size: Option<f64>,
        /// Load of both cases [N] (default: each design's peak pin force; not with `--adaptive`,
        /// which loads each design with its own).
        #[arg(long, conflicts_with = "adaptive")]
        force: Option<f64>,
        #[arg(long)]
        json: bool,
    },
    /// Stage 2: the full driven scene (5000 steps) through the multibody core against the
    /// closed form, for one design (default: the thesis' original rod, ch. 3 data).
    Dynamics {
        /// An STL design whose rod is used instead of the thesis' original rod.
        design: Option<PathBuf>,
        /// Repeats per method (at least 1); the median is reported.
        #[arg(long, default_value_t = 11, value_parser = at_least_one)]
        repeats: usize,
        #[arg(long)]
        json: bool,
    },
    /// Contact against the linear solve of the same mesh, in the same process: the two-eye
    /// plate, pin A pushed along AB with a clearance, pin B fixed, against a uniform traction on
    /// bore A with bore B clamped.
    Contact {
        /// Divisions per bore quarter (one plate per value; 6 ≈ 26 kDOF, 10 ≈ 94 kDOF).
        #[arg(long = "n-side", default_values_t = [6, 10], value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(2..))]
        n_side: Vec<usize>,
        /// Repeats per solve (at least 1); the median is reported.
        #[arg(long, default_value_t = 3, value_parser = at_least_one)]
        repeats: usize,
        /// A design's rod instead of the plate: its STL, with `--mesh`.
        #[arg(long, requires = "mesh")]
        design: Option<PathBuf>,
        /// The rod's mesh in the rod frame, millimetres (the mesher's `mesh/fixed/rod.msh`).
        #[arg(long, requires = "design")]
        mesh: Option<PathBuf>,
        /// The pin force along AB with `--design`, N.
        #[arg(long, default_value_t = 20e3)]
        force: f64,
        #[arg(long)]
        json: bool,
    },
    /// The cycle with contact: the study's few instants against direct contact solves at many
    /// instants spread over the cycle (the largest judged peak of each, and their times).
    ContactCycle {
        /// The STL design.
        design: PathBuf,
        /// Direct contact solves spread evenly over the cycle.
        #[arg(long, default_value_t = 36)]
        instants: usize,
        /// One fixed mesh of this size [mm] instead of the study's adaptive refinement.
        #[arg(long)]
        size: Option<f64>,
        /// Settings file (as for `study`; e.g. the engine example).
        #[arg(long)]
        config: Option<PathBuf>,
        #[arg(long)]
        json: bool,
    },
    /// Speed against error of the three bore loads (uniform, cosine, contact): the static cases
    /// on stage 3's final mesh under each, timed, their judged peaks against contact's.
    LoadModels {
        /// The STL design.
        design: PathBuf,
        /// Runs per model (the median time is reported).
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// One fixed mesh of this size [mm] instead of the study's adaptive refinement.
        #[arg(long)]
        size: Option<f64>,
        /// Settings file (as for `study`; e.g. the engine example).
        #[arg(long)]
        config: Option<PathBuf>,
        #[arg(long)]
        json: bool,
    },
}

/// The settings file's configuration (the spec's defaults without one) and stage 3's mesh mode:
/// one fixed mesh of `size` mm, else the configuration's.
fn config_and_mode(
    config: Option<&std::path::Path>,
    size: Option<f64>,
) -> Result<(crate::config::StudyConfig, crate::stages::fem::MeshMode)> {
    let config = crate::config::StudyConfig::load(config)?;
    let mode = match size {
        Some(h) => crate::stages::fem::MeshMode::Fixed(h),
        None => crate::stages::fem::MeshMode::from_config(&config),
    };
    Ok((config, mode))
}

pub fn run(command: BenchCommand) -> Result<i32> {
    match command {
        BenchCommand::Mass {
            triangles,
            repeats,
            json,
        } => {
            let b = bench_mass(triangles, repeats)?;
            if json {
                outln!("{}", serde_json::to_string_pretty(&b)?);
                return Ok(0);
            }
            outln!(
                "mass stage on a torus of {} triangles ({:.1} MB binary STL), median of {} runs:\n",
                b.triangles,
                b.file_bytes as f64 / 1e6,
                b.repeats
            );
            outln!("| step | time [ms] | triangles/s | × read bytes |\n|---|---|---|---|");
            for s in &b.steps {
                outln!(
                    "| {} | {:.1} | {:.3e} | {:.1} |",
                    s.step,
                    s.seconds * 1e3,
                    s.triangles_per_second,
                    s.ratio_to_read_bytes
                );
            }
            outln!(
                "\nvolume vs the smooth torus: {:.2e} relative (tessellation error, O(1/n²))",
                b.volume_rel_error_vs_smooth_torus
            );
            Ok(0)
        }
        BenchCommand::Fem {
            designs,
            mesh: Some(mesh),
            repeats,
            ccx,
            force,
            json,
            ..
        } => bench_fem_mesh(designs, &mesh, force, repeats, ccx, json),
        BenchCommand::Fem {
            designs,
            adaptive: true,
            json,
            ..
        } => bench_fem_adaptive(designs, json),
        BenchCommand::Fem {
            designs,
            size,
            force,
            json,
            ..
        } => bench_fem(designs, size.unwrap_or(5.0), force, json),
        BenchCommand::Contact {
            design: Some(design),
            mesh: Some(mesh),
            repeats,
            force,
            json,
            ..
        } => {
            let b = crate::bench::contact::bench_contact_rod(&design, &mesh, force, repeats)?;
            if json {
                outln!("{}", serde_json::to_string_pretty(&b)?);
            } else {
                outln!(
                    "{}: {} nodes, static cases {:.2} s, contact (F_x, 10 µm) {:.2} s, ratio \
                     {:.2}; {} rows, {} columns; {:?}",
                    design.display(),
                    b.nodes,
                    b.linear.as_secs_f64(),
                    b.contact.as_secs_f64(),
                    b.ratio,
                    b.rows,
                    b.columns,
                    b.phases
                );
            }
            Ok(0)
        }
        BenchCommand::LoadModels {
            design,
            repeats,
            size,
            config,
            json,
        } => {
            let (config, mode) = config_and_mode(config.as_deref(), size)?;
            let b = crate::bench::load_models::bench_load_models(&design, &config, &mode, repeats)?;
            if json {
                outln!("{}", serde_json::to_string_pretty(&b)?);
                return Ok(0);
            }
            outln!(
                "{}: {} nodes{}; estimated discretisation error {}",
                b.design,
                b.nodes,
                if b.half_model { " (half model)" } else { "" },
                b.discretisation_error_rel
                    .iter()
                    .map(|(n, e)| format!("{n} {:.2} %", 100.0 * e))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            outln!("| model | time [s] | × uniform | judged peaks [MPa] | from contact |");
            outln!("|---|---|---|---|---|");
            for r in &b.runs {
                let cell = |f: &dyn Fn(&(String, f64, f64)) -> String| {
                    r.cases.iter().map(f).collect::<Vec<_>>().join(", ")
                };
                outln!(
                    "| {} | {:.2} | {:.2} | {} | {} |",
                    r.model,
                    r.seconds,
                    r.time_vs_uniform,
                    r.error
                        .clone()
                        .unwrap_or_else(|| cell(&|c| format!("{} {:.2}", c.0, c.1))),
                    cell(&|c| format!("{} {:.1} %", c.0, 100.0 * c.2))
                );
            }
            Ok(0)
        }
        BenchCommand::ContactCycle {
            design,
            instants,
            size,
            config,
            json,
        } => {
            let (config, mode) = config_and_mode(config.as_deref(), size)?;
            let b = crate::bench::contact_cycle::bench_contact_cycle(
                &design, &config, &mode, instants,
            )?;
            if json {
                outln!("{}", serde_json::to_string_pretty(&b)?);
            } else {
                outln!(
                    "{}: {} nodes; linear cycle ({} instants) max {:.2} MPa in {:.1} s; contact at \
                     the {} chosen instants max {:.2} MPa in {:.1} s; contact at {} instants max \
                     {:.2} MPa in {:.1} s; chosen against direct {:+.2} %",
                    b.design,
                    b.nodes,
                    b.linear_instants,
                    b.linear_max_mpa,
                    b.linear_s,
                    b.chosen.len(),
                    b.chosen_max_mpa,
                    b.chosen_s,
                    b.direct.len(),
                    b.direct_max_mpa,
                    b.direct_s,
                    100.0 * b.chosen_vs_direct_rel
                );
                for i in &b.chosen {
                    outln!(
                        "  {:>5.0}° {}: linear {:.2} MPa, contact {:.2} MPa ({:+.1} %), arcs {:.0}° / {:.0}°",
                        i.crank_angle_deg,
                        i.reason,
                        i.linear_mpa,
                        i.contact_mpa,
                        100.0 * i.change_rel,
                        i.arc_a_deg,
                        i.arc_b_deg
                    );
                }
            }
            Ok(0)
        }
        BenchCommand::Contact {
            n_side,
            repeats,
            json,
            ..
        } => bench_contact(&n_side, repeats, json),
        BenchCommand::Dynamics {
            design,
            repeats,
            json,
        } => {
            let (name, params, rod) = match &design {
                Some(path) => {
                    let m = stages::mass::mass(&stages::mass::load(path)?)?;
                    (m.design.clone(), mechanism_for(&m, true), rod_inertia(&m))
                }
                None => (
                    "thesis original rod (ch. 3)".to_string(),
                    MechanismParams::default(),
                    RodInertia::thesis_original(),
                ),
            };
            let scene = DrivenScene::default();
            let b = bench_driven(&params, &rod, &scene, repeats)?;
            if json {
                outln!("{}", serde_json::to_string_pretty(&b)?);
                return Ok(0);
            }
            outln!(
                "driven scene ({} steps, {} samples) for {name}, median of {} runs:\n",
                b.steps,
                b.samples,
                b.repeats
            );
            outln!("| model | per scene [ms] | per step [µs] | × closed form |\n|---|---|---|---|");
            outln!(
                "| closed-form Newton–Euler | {:.3} | {:.3} | 1.0 |",
                b.closed_form_scene_s * 1e3,
                b.closed_form_per_step_s * 1e6
            );
            outln!(
                "| multibody core (9 coordinates, Newton–Raphson, multipliers) | {:.3} | {:.3} | {:.1} |",
                b.multibody_scene_s * 1e3,
                b.multibody_per_step_s * 1e6,
                b.ratio_multibody_over_closed_form
            );
            outln!(
                "| refined peak only (closed form, one revolution) | {:.4} | — | {:.3} |",
                b.peak_only_s * 1e3,
                b.peak_only_s / b.closed_form_scene_s
            );
            outln!(
                "\npeak {:.3} N; multibody vs closed form: max relative difference {:.2e}",
                b.peak_pin_force_n,
                b.max_rel_diff
            );
            Ok(0)
        }
    }
}

/// `bench fem DESIGN --mesh FILE`: [`crate::bench::fem_mesh`].
fn bench_fem_mesh(
    designs: Vec<PathBuf>,
    mesh: &std::path::Path,
    force: Option<f64>,
    repeats: usize,
    ccx: bool,
    json: bool,
) -> Result<i32> {
    let [design] = designs.as_slice() else {
        anyhow::bail!("bench fem --mesh FILE takes exactly one design (the STL the mesh is of)");
    };
    let force = match force {
        Some(f) if f.is_finite() && f > 0.0 => f,
        Some(f) => anyhow::bail!("--force must be a positive number of newtons, got {f}"),
        None => {
            let config = crate::config::StudyConfig::load(None)?;
            super::fem::peak_force(&stages::mass::load(design)?, &config)?
        }
    };
    let b = crate::bench::fem_mesh::bench_fem_mesh(design, mesh, force, repeats, ccx)?;
    if json {
        outln!("{}", serde_json::to_string_pretty(&b)?);
    } else {
        out!("{}", crate::bench::fem_mesh::markdown(&b));
    }
    Ok(0)
}

/// `bench fem --adaptive`: [`crate::bench::fem_adaptive`].
fn bench_fem_adaptive(designs: Vec<PathBuf>, json: bool) -> Result<i32> {
    let files = if designs.is_empty() {
        crate::geometry::design::find_stl_files(&[PathBuf::from("designs")])?
    } else {
        crate::geometry::design::find_stl_files(&designs)?
    };
    let b = crate::bench::fem_adaptive::bench_fem_adaptive(&std::env::current_exe()?, &files)?;
    if json {
        outln!("{}", serde_json::to_string_pretty(&b)?);
    } else {
        out!("{}", crate::bench::fem_adaptive::markdown(&b));
    }
    Ok(0)
}

/// Runs `rodstudy fem --json` for each design in a child process (so VmHWM is that design's own
/// peak memory) and tabulates the stage times.
fn bench_fem(designs: Vec<PathBuf>, size: f64, force: Option<f64>, json: bool) -> Result<i32> {
    let files = if designs.is_empty() {
        crate::geometry::design::find_stl_files(&[PathBuf::from("designs")])?
    } else {
        crate::geometry::design::find_stl_files(&designs)?
    };
    let exe = std::env::current_exe()?;
    let mut rows = Vec::new();
    for stl in &files {
        let out = tempfile::tempdir()?;
        let mut cmd = std::process::Command::new(&exe);
        cmd.arg("fem")
            .arg(stl)
            .args(["--json", "--size", &size.to_string(), "--out"])
            .arg(out.path());
        if let Some(f) = force {
            cmd.args(["--force", &f.to_string()]);
        }
        let output = cmd.output()?;
        if !output.status.success() {
            anyhow::bail!(
                "{}: {}",
                stl.display(),
                String::from_utf8_lossy(&output.stderr).trim()
            );
        }
        let v: serde_json::Value = serde_json::from_slice(&output.stdout)?;
        rows.push((stl.clone(), v));
    }
    if json {
        let all: Vec<&serde_json::Value> = rows.iter().map(|r| &r.1).collect();
        outln!("{}", serde_json::to_string_pretty(&all)?);
        return Ok(0);
    }
    outln!("FEM at {size} mm, each design in its own process\n");
    outln!(
        "| design | DOFs | elements | mesh [s] | assembly [s] | symbolic [s] | factorisation [s] | solve, 2 cases [s] | stress [s] | nnz(L) | peak memory [MB] |\n|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for (stl, v) in &rows {
        let f = &v["fem"];
        let t = &f["timings"];
        let s = |x: &serde_json::Value| x.as_f64().map_or("—".into(), |v| format!("{v:.2}"));
        outln!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            stl.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            f["dofs"],
            f["elements"],
            s(&v["mesh"]["seconds"]),
            s(&t["assembly_s"]),
            s(&t["symbolic_s"]),
            s(&t["factorisation_s"]),
            s(&t["solve_s"]),
            s(&t["stress_s"]),
            f["nnz_l"],
            v["peak_memory_mb"]
                .as_f64()
                .map_or("—".into(), |m| format!("{m:.0}"))
        );
    }
    Ok(0)
}

/// `bench contact`: [`crate::bench::contact::bench_contact`] per plate.
fn bench_contact(n_side: &[usize], repeats: usize, json: bool) -> Result<i32> {
    let mut rows = Vec::new();
    if !json {
        outln!(
            "contact against the linear solve, two-eye plate, median of {repeats} runs\n\n\
             | n_side | DOFs | linear [s] | contact [s] | contact / linear | rows | columns | \
             iterations | assembly [s] | factorisation [s] | compliance [s] | active set [s] | \
             rest [s] |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|"
        );
    }
    for &n in n_side {
        let b = crate::bench::contact::bench_contact(n, repeats)?;
        if !json {
            let p = &b.phases;
            outln!(
                "| {} | {} | {:.2} | {:.2} | {:.2} | {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
                b.n_side,
                b.dofs,
                b.linear.as_secs_f64(),
                b.contact.as_secs_f64(),
                b.ratio,
                b.rows,
                b.columns,
                b.iterations,
                p.assembly_s,
                p.factorisation_s,
                p.columns_s,
                p.active_set_s,
                p.rest_s
            );
        }
        rows.push(b);
    }
    if json {
        outln!("{}", serde_json::to_string_pretty(&rows)?);
    }
    Ok(0)
}

/// `--repeats`: a whole number ≥ 1.
fn at_least_one(v: &str) -> std::result::Result<usize, String> {
    match v.parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!(
            "'{v}' is not a number of repeats (a whole number ≥ 1)"
        )),
    }
}
