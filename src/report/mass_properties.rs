//! `mass_properties.md` and `mass_properties.csv`: stage 1's figures of every design that passed
//! it (failed later stages included), and the failed designs.

use super::tables;
use crate::stages::records::DesignMass;
use crate::study::results::StudyResults;
use anyhow::Result;
use serde::Serialize;

pub fn markdown(results: &StudyResults) -> String {
    // every design that passed stage 1, those that failed later included
    let designs: Vec<&DesignMass> = results
        .designs
        .iter()
        .map(|d| &d.mass)
        .chain(results.failed.iter().filter_map(|f| f.mass.as_ref()))
        .collect();
    let mut out = format!(
        "# Mass properties of the designs\n\nStages run: {}. Skipped: {}.\nI_zz is about the pin axis through the centroid (the one the planar dynamics uses); I_xx is about the rod's long axis (what the thesis' Table 5.1 lists).\n\n",
        results.stages_run.join(", "),
        results.stages_skipped.join(", ")
    );
    out.push_str(&tables::mass_table(&designs));
    if !results.failed.is_empty() {
        out.push_str("\n## Failed designs\n\n");
        for f in &results.failed {
            out.push_str(&format!(
                "- `{}` ({} stage): {}\n",
                f.file, f.stage, f.error
            ));
        }
    }
    out
}

/// One row of `mass_properties.csv` (SI units; empty figures for a failed design).
#[derive(Serialize, Default)]
struct CsvRow {
    design: String,
    file: String,
    mass_kg: Option<f64>,
    volume_m3: Option<f64>,
    l1_m: Option<f64>,
    offset_m: Option<f64>,
    i_zz_kgm2: Option<f64>,
    i_xx_kgm2: Option<f64>,
    centroid_x_m: Option<f64>,
    centroid_y_m: Option<f64>,
    centroid_z_m: Option<f64>,
    peak_pin_force_n: Option<f64>,
    status: &'static str,
    /// The stage that failed (empty when none did).
    stage: String,
    error: String,
}

pub fn csv_table(results: &StudyResults) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let rows = results
        .designs
        .iter()
        .map(|d| (&d.mass, Some(&d.dynamics), None))
        .chain(
            results
                .failed
                .iter()
                .filter_map(|f| f.mass.as_ref().map(|m| (m, f.dynamics.as_ref(), Some(f)))),
        );
    for (m, dynamics, failed) in rows {
        w.serialize(CsvRow {
            design: m.design.clone(),
            file: m.file.clone(),
            mass_kg: Some(m.mass_kg),
            volume_m3: Some(m.volume_m3),
            l1_m: Some(m.l1_m),
            offset_m: Some(m.offset_m),
            i_zz_kgm2: Some(m.i_zz_kgm2),
            i_xx_kgm2: Some(m.i_xx_kgm2),
            centroid_x_m: Some(m.centroid_m[0]),
            centroid_y_m: Some(m.centroid_m[1]),
            centroid_z_m: Some(m.centroid_m[2]),
            peak_pin_force_n: dynamics.map(|d| d.peak_pin_force_n),
            status: if failed.is_some() { "failed" } else { "ok" },
            stage: failed.map(|f| f.stage.clone()).unwrap_or_default(),
            error: failed.map(|f| f.error.clone()).unwrap_or_default(),
        })?;
    }
    for f in results.failed.iter().filter(|f| f.mass.is_none()) {
        w.serialize(CsvRow {
            file: f.file.clone(),
            status: "failed",
            stage: f.stage.clone(),
            error: f.error.clone(),
            ..CsvRow::default()
        })?;
    }
    Ok(w.into_inner()?)
}
