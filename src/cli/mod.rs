//! The command-line interface: argument parsing and printing, over the library's stages.
//!
//! Exit status: 0 when everything asked for succeeded, 1 when some design failed (the others
//! are still reported), 2 for a usage error or a failure that stops the whole command.
//!
//! Standard output is written through `out!` and `outln!`: a reader that closes the pipe
//! early (`rodstudy mass … --json | head -c 10`) is a normal end, the command stops quietly
//! with status 0 (the unwinding runs the destructors: temporary folders are removed).

/// `print!` to standard output; a closed pipe ends the command quietly ([`write_out`]).
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cli::write_out(format_args!($($arg)*))
    };
}

/// `println!` to standard output; a closed pipe ends the command quietly ([`write_out`]).
macro_rules! outln {
    () => {
        $crate::cli::write_out(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::cli::write_out(format_args!("{}\n", format_args!($($arg)*)))
    };
}

mod bench;
mod check;
mod cycle;
mod dynamics;
mod fem;
mod integrators;
mod mass;
mod merge;
mod mesh_args;
mod pipeline;
mod settings;
mod solve;
mod study;
mod sweep;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "rodstudy",
    version,
    about = "Connecting-rod design studies: mass properties from STL, crank–slider pin forces, tet10 FEM"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Mass properties of STL designs (files or folders): volume, mass, centroid, inertia,
    /// principal axes, and l1, offset, I_zz, I_xx in the mechanism frame.
    Mass(mass::MassArgs),
    /// Stage 2: the crank–slider with each design's rod (peak crank–rod pin force).
    #[command(subcommand)]
    Dynamics(dynamics::DynamicsCommand),
    /// Stage 3: tet10 FEM of one design under F_x and F_y (the design's peak pin force).
    Fem(fem::FemArgs),
    /// Stress over one crank revolution (inertia relief, superposition) and the fatigue safety
    /// factor, on stage 3's mesh.
    Cycle(cycle::CycleArgs),
    /// Work–precision comparison of the integrators on the free run (thesis ch. 4).
    Integrators(integrators::IntegratorsArgs),
    /// Run every stage that exists on every design of a folder and write the reports.
    Study(study::StudyArgs),
    /// Merge the shards of a split study (`study --shard K/N`) into the one-machine reports.
    Merge(merge::MergeArgs),
    /// Compare the latest study results with the committed baseline (the CI regression gate).
    Check(check::CheckArgs),
    /// Benchmarks, reported as ratios against a reference run in the same process.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// Create (or check) the project-local Python environment the pipeline scripts use.
    Setup,
    /// Run a script of `pipeline/` with the project's Python environment.
    Pipeline(pipeline::PipelineArgs),
    /// Parameter sweeps: generate rods from a Latin-hypercube sample of the design parameters.
    #[command(subcommand)]
    Sweep(sweep::SweepCommand),
    /// Linear static analysis of a CalculiX/Abaqus input deck (C3D10/C3D4; NAFEMS LE10 and users' models).
    Solve(solve::SolveArgs),
}

/// Why writing to standard output stopped the command: the unwinding payload [`main`] turns
/// into an exit status.
struct StdoutFailed(i32);

/// Writes to standard output. When the reader has gone (a broken pipe) the command unwinds
/// without a panic message and [`main`] returns 0; another write error is said once, status 2.
pub(crate) fn write_out(args: std::fmt::Arguments<'_>) {
    use std::io::Write;
    let mut stdout = std::io::stdout().lock();
    if let Err(e) = stdout.write_fmt(args) {
        let code = if e.kind() == std::io::ErrorKind::BrokenPipe {
            0
        } else {
            eprintln!("error: cannot write to standard output: {e}");
            2
        };
        std::panic::resume_unwind(Box::new(StdoutFailed(code)));
    }
}

/// Parses the command line, runs the command, prints errors; returns the exit status.
pub fn main() -> i32 {
    match std::panic::catch_unwind(run_command) {
        Ok(code) => code,
        Err(payload) => match payload.downcast::<StdoutFailed>() {
            Ok(stopped) => stopped.0,
            Err(panic) => std::panic::resume_unwind(panic),
        },
    }
}

fn run_command() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() { 2 } else { 0 };
        }
    };
    let result = match cli.command {
        Command::Mass(args) => mass::run(args),
        Command::Dynamics(command) => dynamics::run(command),
        Command::Fem(args) => fem::run(args),
        Command::Cycle(args) => cycle::run(args),
        Command::Integrators(args) => integrators::run(args),
        Command::Study(args) => study::run(args),
        Command::Merge(args) => merge::run(args),
        Command::Check(args) => check::run(args),
        Command::Bench(command) => bench::run(command),
        Command::Setup => pipeline::setup(),
        Command::Pipeline(args) => pipeline::run(args),
        Command::Sweep(command) => sweep::run(command),
        Command::Solve(args) => solve::run(args),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            2
        }
    }
}
