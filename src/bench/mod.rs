//! Benchmarks: each stage timed against a reference run in the same process, so the figures
//! are ratios that travel between machines better than seconds.

pub mod contact;
pub mod contact_cycle;
pub mod fem_adaptive;
pub mod fem_convergence;
pub mod fem_mesh;
pub mod fem_rod;
pub mod load_models;
pub mod mass;

use std::time::{Duration, Instant};

/// Median wall time of `repeats` runs of `f` (at least one).
pub fn median_time<T>(repeats: usize, mut f: impl FnMut() -> T) -> (Duration, T) {
    let mut times = Vec::with_capacity(repeats.max(1));
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        let out = f();
        times.push(start.elapsed());
        last = Some(out);
    }
    times.sort();
    (times[times.len() / 2], last.expect("at least one run"))
}
