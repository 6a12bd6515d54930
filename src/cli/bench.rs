//! `rodstudy bench mass [--triangles N] [--repeats R] [--json]`

use crate::bench::mass::bench_mass;
use anyhow::Result;
use clap::Subcommand;

#[derive(Subcommand)]
pub enum BenchCommand {
    /// Stage 1 on a generated torus mesh: read, weld, validate, integrate vs reading the bytes.
    Mass {
        /// Approximate number of triangles of the generated mesh.
        #[arg(long, default_value_t = 1_000_000)]
        triangles: usize,
        /// Repeats per step; the median is reported.
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        #[arg(long)]
        json: bool,
    },
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
                println!("{}", serde_json::to_string_pretty(&b)?);
                return Ok(0);
            }
            println!(
                "mass stage on a torus of {} triangles ({:.1} MB binary STL), median of {} runs:\n",
                b.triangles,
                b.file_bytes as f64 / 1e6,
                b.repeats
            );
            println!("| step | time [ms] | triangles/s | × read bytes |\n|---|---|---|---|");
            for s in &b.steps {
                println!(
                    "| {} | {:.1} | {:.3e} | {:.1} |",
                    s.step,
                    s.seconds * 1e3,
                    s.triangles_per_second,
                    s.ratio_to_read_bytes
                );
            }
            println!(
                "\nvolume vs the smooth torus: {:.2e} relative (tessellation error, O(1/n²))",
                b.volume_rel_error_vs_smooth_torus
            );
            Ok(0)
        }
    }
}
