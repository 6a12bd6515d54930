//! Benchmark of the FEM stage on one design: meshing, assembly, factorisation, solve and stress
//! times, factor size, and the peak resident memory of the process (VmHWM from /proc/self/status;
//! it is the peak of the whole process so far, so run the benchmark in a fresh process).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::fem::error::Result;
use crate::fem::material::Material;
use crate::mesher::{MeshReport, mesh_stl};
use crate::rod::bores::BoreSpec;
use crate::rod::records::FemResult;
use crate::rod::solve::{RodOptions, solve_rod};

/// What [`bench_rod`] measures.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BenchReport {
    /// The STL.
    pub stl: PathBuf,
    /// Target element size, mm.
    pub size_mm: f64,
    /// The mesher's report (including its time).
    pub mesh: MeshReport,
    /// The analysis (timings inside).
    pub result: FemResult,
    /// Factor entries × 8 bytes, MB.
    pub factor_mb: f64,
    /// Peak resident memory of the process (VmHWM), MB, when /proc is available.
    pub peak_memory_mb: Option<f64>,
}

/// Peak resident set size of this process so far (VmHWM), MB; `None` without /proc.
pub fn peak_memory_mb() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// Meshes `stl` at `size_mm` and analyses it, recording times and memory.
#[allow(clippy::too_many_arguments)]
pub fn bench_rod(
    python: &Path,
    script: &Path,
    stl: &Path,
    size_mm: f64,
    out_dir: &Path,
    material: &Material,
    bores: &BoreSpec,
    force_n: f64,
    options: &RodOptions,
) -> Result<BenchReport> {
    let meshed = mesh_stl(python, script, stl, size_mm, out_dir)?;
    let result = solve_rod(&meshed.mesh, material, bores, force_n, options)?;
    Ok(BenchReport {
        stl: stl.to_path_buf(),
        size_mm,
        mesh: meshed.report,
        factor_mb: result.nnz_l as f64 * 8.0 / 1e6,
        result,
        peak_memory_mb: peak_memory_mb(),
    })
}
