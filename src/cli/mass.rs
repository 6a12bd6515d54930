//! `rodstudy mass PATH... [--json]`

use crate::geometry::design::find_stl_files;
use crate::report::tables::mass_table;
use crate::stages;
use crate::stages::records::DesignMass;
use anyhow::Result;
use clap::Args;
use rayon::prelude::*;
use std::path::PathBuf;

#[derive(Args)]
pub struct MassArgs {
    /// STL files, or folders whose *.stl files are all taken.
    #[arg(required = true)]
    paths: Vec<PathBuf>,
    /// Print a JSON array of per-design records instead of the table.
    #[arg(long)]
    json: bool,
}

pub fn run(args: MassArgs) -> Result<i32> {
    let files = find_stl_files(&args.paths)?;
    let results: Vec<(PathBuf, Result<DesignMass>)> = files
        .into_par_iter()
        .map(|f| {
            let r = stages::mass::load(&f).map(|d| stages::mass::mass_of_solid(&d));
            (f, r)
        })
        .collect();
    let ok: Vec<&DesignMass> = results
        .iter()
        .filter_map(|(_, r)| r.as_ref().ok())
        .collect();
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&ok)?);
    } else {
        out!("{}", mass_table(&ok));
    }
    for d in &ok {
        for w in &d.warnings {
            eprintln!("warning: {}: {w}", d.file);
        }
    }
    let mut failed = 0;
    for (_, r) in &results {
        if let Err(e) = r {
            eprintln!("error: {e:#}");
            failed += 1;
        }
    }
    if failed > 0 {
        eprintln!("{failed} of {} design(s) failed", results.len());
    }
    Ok(i32::from(failed > 0))
}
