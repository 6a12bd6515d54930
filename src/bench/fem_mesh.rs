//! Benchmark of the fixed-mesh path (`rodstudy fem DESIGN --mesh FILE`), phase by phase in one
//! process: loading the design, its rod-frame surface and singular edges, reading the mesh
//! natively and through meshio (the reference the native readers replaced), moving it into the
//! rod frame, the analysis (assembly, symbolic analysis, factorisation, solves, stresses with
//! recovery and error estimate), the VTU files and the pictures. Each phase is the median of
//! `repeats` runs; the ratios are against the native read plus the analysis (`fem.total_s`), the
//! part no output can avoid. Then the whole command, in child processes as a user runs it, as it
//! is (pictures, buckling), without pictures, and without pictures and buckling, and optionally
//! CalculiX on the same mesh (`pipeline/ccx_peer.py`: both static cases, and `*BUCKLE`).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};

use super::median_time;
use crate::config::StudyConfig;
use crate::fem::estimate::estimate_error;
use crate::fem::recovery::recover_stress;
use crate::fem::stress::{nodes_away_from, stress_field};
use crate::fem::{Material, TetMesh};
use crate::mesher::{read_volume_mesh_meshio, read_volume_mesh_native, volume_reader};
use crate::report::fields::{write_fem_pictures, write_fem_vtus};
use crate::rod::facets::reentrant_edges;
use crate::rod::solve::{RodOptions, RodSolution, solve_rod_fields};
use crate::stages;
use crate::stages::fem::FEATURE_ANGLE_DEG;
use crate::stages::rod_surface::rod_frame_surface;

/// One timed phase.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Phase {
    /// What was timed.
    pub phase: String,
    /// Median wall time, s.
    pub seconds: f64,
    /// `seconds` / the reference (native read + analysis).
    pub ratio: f64,
    /// Whether `fem --mesh` does it (false: the reference meshio read, and the sub-phases of the
    /// analysis timed on their own, which are inside it).
    pub in_fem_run: bool,
}

/// The whole `rodstudy fem --mesh` command in a child process.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct WholeRun {
    /// The extra arguments (beyond `fem DESIGN --mesh FILE --force F --json --out DIR`).
    pub extra_args: Vec<String>,
    /// Median wall time of the process, s.
    pub wall_s: f64,
    /// Its own `fem.total_s` (of the run with the median wall time), s.
    pub fem_total_s: f64,
    /// Its `mesh.seconds` (reading and moving the mesh), s.
    pub mesh_s: f64,
    /// Its `buckling_s` (the buckling analysis on the factorised K), s; `None` with
    /// `--no-buckling`.
    pub buckling_s: Option<f64>,
    /// wall / fem.total_s.
    pub ratio_to_fem_total: f64,
    /// wall / (fem.total_s + buckling_s): the whole command against all the analysis it made.
    pub ratio_to_analysis: f64,
    /// Its `buckling_load_factor`.
    pub buckling_load_factor: Option<f64>,
}

/// CalculiX on the same mesh (`pipeline/ccx_peer.py --json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CcxRun {
    /// ccx's wall time for both load cases (deck writing and .frd reading excluded), s.
    pub ccx_wall_s: f64,
    /// ccx's wall time for `*BUCKLE` under the F_x load on the same mesh (its own static
    /// pre-stress solve included), s.
    pub ccx_buckle_wall_s: f64,
    /// ccx's buckling factor and ours on the same mesh (the run with buckling).
    pub buckling_factor: f64,
    pub ours_buckling_factor: Option<f64>,
    /// ccx's nodally averaged von Mises maxima, F_x and F_y, MPa.
    pub max_von_mises_averaged_mpa: [f64; 2],
    /// Ours on the same mesh (the run above), MPa.
    pub ours_max_von_mises_averaged_mpa: [f64; 2],
    /// Each whole `fem --mesh` run of [`MeshPathBench::runs`] / ccx's wall time for the same
    /// work: both static cases, plus `*BUCKLE` for a run that computes buckling.
    pub ratio_fem_runs_to_ccx: Vec<f64>,
}

/// What [`bench_fem_mesh`] measures.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MeshPathBench {
    pub design: PathBuf,
    pub mesh_file: PathBuf,
    /// The reader `fem --mesh` uses for it.
    pub reader: String,
    pub force_n: f64,
    pub repeats: usize,
    pub nodes: usize,
    pub elements: usize,
    pub dofs: usize,
    /// Native read + analysis (`fem.total_s`), s: the reference of the ratios.
    pub reference_s: f64,
    /// meshio path / native read.
    pub meshio_over_native_read: f64,
    /// Whether the native and the meshio path gave the same mesh, bit for bit.
    pub native_equals_meshio: bool,
    pub phases: Vec<Phase>,
    /// `fem --mesh` as a command, with and without pictures.
    pub runs: Vec<WholeRun>,
    pub ccx: Option<CcxRun>,
    /// The 1-minute load average (/proc/loadavg) before and after, when available: other work on
    /// the machine stretches every phase.
    pub load_average: [Option<f64>; 2],
}

fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

fn same_mesh(a: &TetMesh, b: &TetMesh) -> bool {
    a.elements() == b.elements()
        && a.n_nodes() == b.n_nodes()
        && a.nodes()
            .iter()
            .zip(b.nodes())
            .all(|(p, q)| p.map(f64::to_bits) == q.map(f64::to_bits))
}

/// Times the fixed-mesh path of `design` on `mesh_file` (in the design's units and pose) under
/// `force_n`; with `ccx`, also runs CalculiX on the same mesh.
pub fn bench_fem_mesh(
    design_file: &Path,
    mesh_file: &Path,
    force_n: f64,
    repeats: usize,
    ccx: bool,
) -> Result<MeshPathBench> {
    let load_before = load_average();
    let config = StudyConfig::load(None)?;
    let work = tempfile::tempdir()?;
    let mut phases: Vec<(String, f64, bool)> = Vec::new();
    let mut phase = |name: &str, d: std::time::Duration, in_run: bool| {
        phases.push((name.to_string(), d.as_secs_f64(), in_run));
    };

    let (t, design) = median_time(repeats, || stages::mass::load(design_file));
    let design = design?;
    phase("load the design (STL, sidecar, validation)", t, true);
    let (t, _) = median_time(repeats, || rod_frame_surface(&design, true));
    phase(
        "rod-frame surface simplified to 5 µm for gmsh (not on the --mesh path)",
        t,
        false,
    );
    let (t, surface) = median_time(repeats, || rod_frame_surface(&design, false));
    phase("rod-frame surface as exported (what --mesh uses)", t, true);
    let (t, singular) = median_time(repeats, || {
        reentrant_edges(&surface.vertices, &surface.triangles, FEATURE_ANGLE_DEG)
            .into_iter()
            .map(|s| s.map(|p| p.map(|v| v * 1e-3)))
            .collect::<Vec<[[f64; 3]; 2]>>()
    });
    phase("its sharp re-entrant edges (singularities)", t, true);

    let reader = volume_reader(mesh_file)?;
    let (t_native, read) = median_time(repeats, || read_volume_mesh_native(mesh_file, "mm"));
    let read = read.with_context(|| format!("{}: native read", mesh_file.display()))?;
    phase("read the mesh, native", t_native, true);
    let (t_meshio, by_meshio) = median_time(repeats, || {
        read_volume_mesh_meshio(mesh_file, "mm", work.path())
    });
    let by_meshio = by_meshio.with_context(|| format!("{}: meshio path", mesh_file.display()))?;
    phase(
        "read the mesh, meshio path (Python, convert, .rodmesh; reference)",
        t_meshio,
        false,
    );
    let native_equals_meshio = same_mesh(&read, &by_meshio);

    // as fem_user_mesh moves it (checked against the stage below)
    let f = surface.frame;
    let s = surface.to_metres * 1e3;
    let (t, mesh) = median_time(repeats, || {
        read.map_nodes(|_, p| {
            let q = nalgebra::Vector3::new(p[0], p[1], p[2]) * s - f.origin;
            [q.dot(&f.x), q.dot(&f.y), q.dot(&f.z)]
        })
    });
    let mesh = mesh?;
    phase("move into the rod frame (and validate)", t, true);

    let material = Material::from(&config.fem);
    let bores = surface.bores();
    let options = RodOptions {
        fixed_band_m: Some(config.fem.fixed_band_mm * 1e-3),
        singular_edges_m: singular.clone(),
        singular_band_m: Some(config.fem.singular_band_mm * 1e-3),
        ..RodOptions::default()
    };
    let mut solutions: Vec<RodSolution> = Vec::new();
    for _ in 0..repeats.max(1) {
        solutions.push(solve_rod_fields(
            &mesh, &material, &bores, force_n, &options,
        )?);
    }
    solutions.sort_by(|a, b| a.result.total_s.total_cmp(&b.result.total_s));
    let solution = solutions.swap_remove(solutions.len() / 2);
    drop(solutions);
    let r = &solution.result;
    let t = &r.timings;
    let secs = std::time::Duration::from_secs_f64;
    phase("analysis: assembly", secs(t.assembly_s), true);
    phase(
        "analysis: symbolic analysis (nested-dissection ordering)",
        secs(t.symbolic_s),
        true,
    );
    phase("analysis: factorisation", secs(t.factorisation_s), true);
    phase("analysis: solves (2 cases)", secs(t.solve_s), true);
    phase(
        "analysis: stresses, recovery, error estimate, peaks (2 cases)",
        secs(t.stress_s),
        true,
    );
    let rest = r.total_s - t.assembly_s - t.symbolic_s - t.factorisation_s - t.solve_s - t.stress_s;
    phase(
        "analysis: the rest (boundary, bores, loads, checks)",
        secs(rest.max(0.0)),
        true,
    );
    // the stress phase's parts, each on its own (inside the line above)
    let u = &solution.displacements;
    let (ts, fields) = median_time(repeats, || {
        [
            stress_field(&mesh, &material, &u[0]),
            stress_field(&mesh, &material, &u[1]),
        ]
    });
    let [f0, f1] = fields;
    let fields = [f0?, f1?];
    phase("  of which: stresses at the nodes (2 cases)", ts, false);
    let (tr, recovered) = median_time(repeats, || {
        [
            recover_stress(&mesh, &material, &u[0]),
            recover_stress(&mesh, &material, &u[1]),
        ]
    });
    let [r0, r1] = recovered;
    let recovered = [r0?, r1?];
    phase("  of which: recovery (2 cases)", tr, false);
    let away = &solution.away_from_fixed;
    let (te, _) = median_time(repeats, || {
        for c in 0..2 {
            estimate_error(&mesh, &material, &u[c], &fields[c], &recovered[c], away)
                .expect("estimated once already");
        }
    });
    phase("  of which: error estimate (2 cases)", te, false);
    let (tb, _) = median_time(repeats, || {
        nodes_away_from(&mesh, &solution.fixed.faces, options.fixed_band_m.unwrap())
    });
    phase(
        "  of which: band around the fixed bore (one distance pass)",
        tb,
        false,
    );

    let out = work.path().join("fields");
    let mut result = solution.result.clone();
    let (t, done) = median_time(repeats, || {
        write_fem_vtus(&mut result, &solution, &mesh, &out, "fem")
    });
    done?;
    phase("write the VTU files (2)", t, true);
    let (t, done) = median_time(repeats, || {
        write_fem_pictures(&mut result, &solution, &mesh, &out)
    });
    done?;
    phase("draw the pictures (2 SVG)", t, true);

    // the stage itself moves the mesh as above
    let stage = stages::fem::fem_user_mesh(
        &design,
        &stages::fem::FemLoads::of_design(&design, &config)?.with_force(force_n),
        &config,
        work.path(),
        mesh_file,
        false,
    )?;
    if !same_mesh(&stage.mesh.mesh, &mesh) {
        bail!("the benchmark moved the mesh differently from the stage");
    }
    let averaged = |f: &crate::rod::FemResult| {
        f.cases
            .iter()
            .map(|c| c.max_von_mises_averaged_mpa)
            .collect::<Vec<_>>()
    };
    if averaged(&stage.record.fem) != averaged(r) {
        bail!("the benchmark's analysis differs from the stage's");
    }

    let reference_s = t_native.as_secs_f64() + r.total_s;
    let phases: Vec<Phase> = phases
        .into_iter()
        .map(|(phase, seconds, in_fem_run)| Phase {
            ratio: seconds / reference_s,
            phase,
            seconds,
            in_fem_run,
        })
        .collect();

    let runs = whole_runs(
        design_file,
        mesh_file,
        force_n,
        repeats,
        &[
            vec![],
            vec!["--no-pictures".to_string()],
            vec!["--no-buckling".to_string(), "--no-pictures".to_string()],
        ],
    )?;
    let ccx = if ccx {
        Some(ccx_run(&mesh, force_n, work.path(), r, &runs)?)
    } else {
        None
    };
    Ok(MeshPathBench {
        design: design_file.to_path_buf(),
        mesh_file: mesh_file.to_path_buf(),
        reader: format!("{reader:?}"),
        force_n,
        repeats: repeats.max(1),
        nodes: mesh.n_nodes(),
        elements: mesh.n_elements(),
        dofs: r.dofs,
        reference_s,
        meshio_over_native_read: t_meshio.as_secs_f64() / t_native.as_secs_f64(),
        native_equals_meshio,
        phases,
        runs,
        ccx,
        load_average: [load_before, load_average()],
    })
}

/// `rodstudy fem DESIGN --mesh FILE --force F --json --out TMP [extra]` for each of `variants`,
/// `repeats` times, interleaved (so that other work on the machine falls on all alike).
fn whole_runs(
    design: &Path,
    mesh: &Path,
    force_n: f64,
    repeats: usize,
    variants: &[Vec<String>],
) -> Result<Vec<WholeRun>> {
    let exe = std::env::current_exe()?;
    let mut rows = vec![Vec::new(); variants.len()];
    for _ in 0..repeats.max(1) {
        for (extra, rows) in variants.iter().zip(&mut rows) {
            let out = tempfile::tempdir()?;
            let t0 = Instant::now();
            let o = Command::new(&exe)
                .arg("fem")
                .arg(design)
                .arg("--mesh")
                .arg(mesh)
                .args(["--force", &force_n.to_string(), "--json", "--out"])
                .arg(out.path())
                .args(extra)
                .output()?;
            let wall = t0.elapsed().as_secs_f64();
            if !o.status.success() {
                bail!(
                    "rodstudy fem --mesh {}: {}",
                    mesh.display(),
                    String::from_utf8_lossy(&o.stderr).trim()
                );
            }
            let v: serde_json::Value = serde_json::from_slice(&o.stdout)?;
            let total = v["fem"]["total_s"].as_f64().unwrap_or(f64::NAN);
            let mesh_s = v["mesh"]["seconds"].as_f64().unwrap_or(f64::NAN);
            let buckling = (v["buckling_s"].as_f64(), v["buckling_load_factor"].as_f64());
            rows.push((wall, total, mesh_s, buckling));
        }
    }
    Ok(variants
        .iter()
        .zip(rows)
        .map(|(extra, mut rows)| {
            rows.sort_by(|a, b| a.0.total_cmp(&b.0));
            let (wall_s, fem_total_s, mesh_s, (buckling_s, load_factor)) = rows[rows.len() / 2];
            WholeRun {
                extra_args: extra.clone(),
                wall_s,
                fem_total_s,
                mesh_s,
                buckling_s,
                buckling_load_factor: load_factor,
                ratio_to_fem_total: wall_s / fem_total_s,
                ratio_to_analysis: wall_s / (fem_total_s + buckling_s.unwrap_or(0.0)),
            }
        })
        .collect())
}

/// CalculiX on `mesh` (rod frame) through `pipeline/ccx_peer.py --json`.
fn ccx_run(
    mesh: &TetMesh,
    force_n: f64,
    work: &Path,
    ours: &crate::rod::FemResult,
    runs: &[WholeRun],
) -> Result<CcxRun> {
    let rodmesh = work.join("rod_frame.rodmesh");
    crate::mesher::write_rodmesh(mesh, &rodmesh)?;
    let python = crate::python_env::python()?;
    let peer = |extra: &[&str]| -> Result<serde_json::Value> {
        let o = crate::python_env::output_within(
            Command::new(&python)
                .arg(crate::python_env::pipeline_script("ccx_peer.py"))
                .arg(&rodmesh)
                .args(["--force", &force_n.to_string(), "--json"])
                .args(extra),
            crate::python_env::pipeline_timeout(),
        )
        .context("ccx_peer.py")?;
        if !o.status.success() {
            bail!("ccx_peer.py: {}", String::from_utf8_lossy(&o.stderr).trim());
        }
        let text = String::from_utf8_lossy(&o.stdout);
        let line = text
            .lines()
            .rev()
            .find(|l| l.starts_with('{'))
            .context("ccx_peer.py printed no JSON")?;
        Ok(serde_json::from_str(line)?)
    };
    let v = peer(&[])?;
    let ccx_wall_s = v["ccx_wall_s"].as_f64().context("ccx_wall_s")?;
    let b = peer(&["--buckle"])?;
    let ccx_buckle_wall_s = b["ccx_wall_s"].as_f64().context("ccx_wall_s")?;
    let vm = |c: &str| {
        v[c]["max_von_mises_averaged_mpa"]
            .as_f64()
            .unwrap_or(f64::NAN)
    };
    Ok(CcxRun {
        ccx_wall_s,
        ccx_buckle_wall_s,
        buckling_factor: b["buckling_factor"].as_f64().unwrap_or(f64::NAN),
        ours_buckling_factor: runs.iter().find_map(|r| r.buckling_load_factor),
        max_von_mises_averaged_mpa: [vm("fx"), vm("fy")],
        ours_max_von_mises_averaged_mpa: ["fx", "fy"].map(|c| {
            ours.cases
                .get(c)
                .map_or(f64::NAN, |c| c.max_von_mises_averaged_mpa)
        }),
        ratio_fem_runs_to_ccx: runs
            .iter()
            .map(|r| {
                let peer = if r.buckling_s.is_some() {
                    ccx_wall_s + ccx_buckle_wall_s
                } else {
                    ccx_wall_s
                };
                r.wall_s / peer
            })
            .collect(),
    })
}

/// The benchmark as a Markdown table, with the command that made it.
pub fn markdown(b: &MeshPathBench) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "fixed-mesh path of {} on {} ({} nodes, {} tet10, {} DOFs; read by {}), {:.1} N, median of {} runs\n",
        b.design.display(),
        b.mesh_file.display(),
        b.nodes,
        b.elements,
        b.dofs,
        b.reader,
        b.force_n,
        b.repeats
    );
    if let [Some(a), Some(z)] = b.load_average {
        let _ = writeln!(
            s,
            "load average {a:.1} before, {z:.1} after, on {} cores\n",
            std::thread::available_parallelism().map_or(0, |n| n.get())
        );
    }
    let _ = writeln!(
        s,
        "| phase | time [s] | × (native read + analysis) | in `fem --mesh` |\n|---|---|---|---|"
    );
    for p in &b.phases {
        let _ = writeln!(
            s,
            "| {} | {:.3} | {:.3} | {} |",
            p.phase,
            p.seconds,
            p.ratio,
            if p.in_fem_run { "yes" } else { "—" }
        );
    }
    let _ = writeln!(
        s,
        "\nreference (native read + analysis `fem.total_s`): {:.3} s; meshio path / native read: {:.1}×; same mesh bit for bit: {}",
        b.reference_s, b.meshio_over_native_read, b.native_equals_meshio
    );
    let _ = writeln!(
        s,
        "\n| `fem --mesh` command | wall [s] | fem.total_s [s] | buckling_s [s] | mesh.seconds [s] | wall / fem.total_s | wall / (fem.total_s + buckling_s) |\n|---|---|---|---|---|---|---|"
    );
    for r in &b.runs {
        let _ = writeln!(
            s,
            "| `--json{}` | {:.2} | {:.2} | {} | {:.3} | {:.2} | {:.2} |",
            r.extra_args
                .iter()
                .map(|a| format!(" {a}"))
                .collect::<String>(),
            r.wall_s,
            r.fem_total_s,
            r.buckling_s.map_or("—".into(), |b| format!("{b:.2}")),
            r.mesh_s,
            r.ratio_to_fem_total,
            r.ratio_to_analysis
        );
    }
    if let Some(c) = &b.ccx {
        let ratios: Vec<String> = b
            .runs
            .iter()
            .zip(&c.ratio_fem_runs_to_ccx)
            .map(|(r, x)| {
                format!(
                    "`--json{}` {x:.2}",
                    r.extra_args
                        .iter()
                        .map(|a| format!(" {a}"))
                        .collect::<String>()
                )
            })
            .collect();
        let _ = writeln!(
            s,
            "\nCalculiX on the same mesh (`pipeline/ccx_peer.py`, SPOOLES): both static cases {:.2} s, `*BUCKLE` under F_x {:.2} s (factor {:.4} / ours {}); `fem --mesh` / ccx doing the same work (static, plus `*BUCKLE` for a run with buckling): {}; averaged von Mises F_x {:.4} / {:.4} MPa, F_y {:.4} / {:.4} MPa (ccx / ours)",
            c.ccx_wall_s,
            c.ccx_buckle_wall_s,
            c.buckling_factor,
            c.ours_buckling_factor
                .map_or("—".into(), |f| format!("{f:.4}")),
            ratios.join(", "),
            c.max_von_mises_averaged_mpa[0],
            c.ours_max_von_mises_averaged_mpa[0],
            c.max_von_mises_averaged_mpa[1],
            c.ours_max_von_mises_averaged_mpa[1]
        );
    }
    s
}
