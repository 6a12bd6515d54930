//! Benchmark of stage 1 on a generated mesh of about a million triangles: read, weld,
//! validate and integrate, each against the time to merely read the file's bytes in the same
//! process (`ratio_to_read_bytes`), which travels between machines better than seconds.

use super::median_time;
use crate::geometry::mass_properties::MassProperties;
use crate::geometry::primitives::{binary_stl, to_soup, torus};
use crate::geometry::stl_file::read_stl_file;
use crate::geometry::validate::validate;
use crate::geometry::weld::weld;
use anyhow::{Context, Result};
use serde::Serialize;
use std::f64::consts::PI;
use std::time::{Duration, Instant};

/// One row of the benchmark: a step, its median time and its throughput.
#[derive(Debug, Clone, Serialize)]
pub struct StepTime {
    pub step: String,
    pub seconds: f64,
    pub triangles_per_second: f64,
    /// Time relative to reading the file's bytes (the reference run).
    pub ratio_to_read_bytes: f64,
}

/// What `rodstudy bench mass` measures.
#[derive(Debug, Clone, Serialize)]
pub struct MassBench {
    pub triangles: usize,
    pub file_bytes: usize,
    pub repeats: usize,
    pub steps: Vec<StepTime>,
    /// Relative error of the tessellated torus' volume against the smooth torus 2π²Rr².
    pub volume_rel_error_vs_smooth_torus: f64,
}

/// Median wall time of `repeats` runs of `f` on a fresh `input()` each, made outside the clock.
fn median_time_of<I, T>(
    repeats: usize,
    mut input: impl FnMut() -> I,
    mut f: impl FnMut(I) -> T,
) -> (Duration, T) {
    let mut out = None;
    let mut times: Vec<Duration> = (0..repeats.max(1))
        .map(|_| {
            let i = input();
            drop(out.take());
            let start = Instant::now();
            out = Some(f(i));
            start.elapsed()
        })
        .collect();
    times.sort();
    (times[times.len() / 2], out.expect("at least one run"))
}

/// Times each step on a torus of about `triangles` triangles written as binary STL.
pub fn bench_mass(triangles: usize, repeats: usize) -> Result<MassBench> {
    let (major, minor) = (0.1, 0.03);
    let m = ((triangles as f64 / 4.0).sqrt().round() as usize).max(3);
    let n = (triangles / (2 * m)).max(3);
    let soup = to_soup(&torus(major, minor, n, m));
    let dir = tempfile::tempdir().context("cannot create a temporary folder")?;
    let path = dir.path().join("bench_torus.stl");
    std::fs::write(&path, binary_stl(&soup))?;
    drop(soup);

    let read = || std::fs::read(&path).expect("benchmark file is readable");
    let (t_read, bytes) = median_time(repeats, read);
    let file_bytes = bytes.len();
    drop(bytes);
    // As `rodstudy mass` reads a file: binary records decoded as they are read.
    let (t_parse, (soup, _)) = median_time(repeats, || read_stl_file(&path).expect("valid STL"));
    let (t_weld, mesh) = median_time(repeats, || weld(&soup));
    // Validation takes the mesh by value: each run gets a copy made before its clock starts.
    let (t_validate, valid) = median_time_of(
        repeats,
        || mesh.clone(),
        |m| validate(m).expect("valid mesh"),
    );
    let (t_integrate, props) = median_time(repeats, || MassProperties::of_mesh(&valid.mesh, 1.0));
    let (t_total, _) = median_time(repeats, || {
        let (soup, _) = read_stl_file(&path).expect("valid STL");
        let valid = validate(weld(&soup)).expect("valid mesh");
        MassProperties::of_mesh(&valid.mesh, 1.0)
    });
    let count = valid.mesh.triangles.len();
    let base = t_read.as_secs_f64();
    let step = |name: &str, t: std::time::Duration| StepTime {
        step: name.into(),
        seconds: t.as_secs_f64(),
        triangles_per_second: count as f64 / t.as_secs_f64(),
        ratio_to_read_bytes: t.as_secs_f64() / base,
    };
    let smooth = 2.0 * PI * PI * major * minor * minor;
    Ok(MassBench {
        triangles: count,
        file_bytes,
        repeats,
        steps: vec![
            step("read file bytes (reference)", t_read),
            step("read + decode STL", t_parse),
            step("weld vertices", t_weld),
            step("validate topology", t_validate),
            step("integrate mass properties", t_integrate),
            step("total: read, parse, weld, validate, integrate", t_total),
        ],
        volume_rel_error_vs_smooth_torus: (props.volume - smooth) / smooth,
    })
}
