//! `rodstudy solve DECK.inp [--out DIR] [--json] [--extrapolation exact|calculix]`: linear static,
//! buckling and frequency analysis of a CalculiX/Abaqus input deck (the subset of
//! `docs/solve.md`, read by [`crate::deck`]). Warnings go to standard error and into the JSON.

use crate::deck::{self, SolveOptions, output};
use crate::fem::nodal_stress::Extrapolation;
use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Clone, Copy, Debug, ValueEnum)]
enum ExtrapolationArg {
    /// The exact inverse of the 4-point rule (a uniform stress is reproduced to round-off).
    Exact,
    /// CalculiX's 5-decimal table (1.92705, -0.30902): reproduces ccx's nodal stresses.
    Calculix,
}

#[derive(Args)]
pub struct SolveArgs {
    /// The input deck (CalculiX/Abaqus): C3D10 and C3D4 solids, several materials, *SURFACE,
    /// *TRANSFORM, *EQUATION, *INCLUDE; *STATIC, *BUCKLE and *FREQUENCY steps with *BOUNDARY,
    /// *CLOAD, *DLOAD (P1-P4, GRAV, CENTRIF), *DSLOAD; output U, S, E, RF. The accepted subset
    /// is the table of docs/solve.md; everything else is refused, every line at once.
    deck: PathBuf,
    /// Folder for DECK.json and DECK_stepN.vtu (default: reports/solve/DECK).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print the JSON document instead of the summary.
    #[arg(long)]
    json: bool,
    /// Corner extrapolation of the integration-point stresses.
    #[arg(long, value_enum, default_value = "exact")]
    extrapolation: ExtrapolationArg,
}

pub fn run(args: SolveArgs) -> Result<i32> {
    let t = Instant::now();
    let model = deck::read_deck(&args.deck)?;
    let extrapolation = match args.extrapolation {
        ExtrapolationArg::Exact => Extrapolation::Exact,
        ExtrapolationArg::Calculix => Extrapolation::CalculiX,
    };
    // the solve's refusals (a mechanism, an inverted element) name the deck, as its read's do
    let sol =
        deck::solve_model_at(&args.deck, &model, SolveOptions { extrapolation }).map_err(|e| {
            match e {
                crate::fem::FemError::Parse { .. } => anyhow::anyhow!("{e}"),
                e => anyhow::anyhow!("{}: {e}", args.deck.display()),
            }
        })?;
    for w in &sol.warnings {
        eprintln!("warning: {w}");
    }
    let stem = args
        .deck
        .file_stem()
        .map_or_else(|| "deck".into(), |s| s.to_string_lossy().into_owned());
    let out = args
        .out
        .unwrap_or_else(|| PathBuf::from("reports/solve").join(&stem));
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let mut doc = output::json_document(&args.deck, &sol, extrapolation);
    for k in 0..sol.steps.len() {
        output::write_step_vtu(&out.join(format!("{stem}_step{}.vtu", k + 1)), &sol, k)?;
    }
    doc["wall_s"] = serde_json::json!(t.elapsed().as_secs_f64());
    let json_path = out.join(format!("{stem}.json"));
    std::fs::write(&json_path, serde_json::to_string_pretty(&doc)? + "\n")
        .with_context(|| format!("writing {}", json_path.display()))?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&doc)?);
        return Ok(0);
    }
    outln!(
        "{}: {} nodes, {} elements, {} DOFs, {} step(s); wall {:.2} s; results in {}",
        args.deck.display(),
        sol.node_ids.len(),
        sol.elements.len(),
        sol.dofs,
        sol.steps.len(),
        t.elapsed().as_secs_f64(),
        out.display()
    );
    for st in &sol.steps {
        outln!(
            "step {} (line {}): residual {:.1e}, applied load {:?}",
            st.step,
            st.line,
            st.residual_rel,
            st.applied_total
        );
        if let Some(eig) = &st.eigen {
            for (k, b) in eig.buckling_factors.iter().enumerate() {
                outln!("  buckling factor {}: {b:.7e}", k + 1);
            }
            for (k, f) in eig.frequencies.iter().enumerate() {
                outln!(
                    "  frequency {}: {f:.7e} cycles/time (eigenvalue {:.7e})",
                    k + 1,
                    eig.eigenvalues[k]
                );
            }
        }
        for (name, r) in &st.reaction_totals {
            outln!(
                "  reaction total {name}: [{:.6e}, {:.6e}, {:.6e}]",
                r[0],
                r[1],
                r[2]
            );
        }
        for (name, set) in &st.node_sets {
            for (i, id) in set.nodes.iter().enumerate().take(20) {
                let mut line = format!("  {name} node {id}:");
                if let Some(u) = &set.u {
                    let _ = std::fmt::Write::write_fmt(
                        &mut line,
                        format_args!(" U {:.6e} {:.6e} {:.6e}", u[i][0], u[i][1], u[i][2]),
                    );
                }
                if let Some(s) = &set.s {
                    let _ = std::fmt::Write::write_fmt(
                        &mut line,
                        format_args!(
                            " S {:.6e} {:.6e} {:.6e} {:.6e} {:.6e} {:.6e}",
                            s[i][0], s[i][1], s[i][2], s[i][3], s[i][4], s[i][5]
                        ),
                    );
                }
                if let Some(r) = &set.rf {
                    let _ = std::fmt::Write::write_fmt(
                        &mut line,
                        format_args!(" RF {:.6e} {:.6e} {:.6e}", r[i][0], r[i][1], r[i][2]),
                    );
                }
                outln!("{line}");
            }
        }
    }
    Ok(0)
}
