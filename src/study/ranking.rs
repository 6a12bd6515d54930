//! The ranking (SPEC "Outputs"): designs that meet the stress criterion first, then by peak pin
//! force, lowest first. Without the FEM stage no design is judged on stress and the order is by
//! force alone.

use super::{DesignResult, StudyResults};
use anyhow::Result;
use serde::Serialize;

/// The designs in ranking order.
pub fn ranked(results: &StudyResults) -> Vec<&DesignResult> {
    let mut order: Vec<&DesignResult> = results.designs.iter().collect();
    let fails = |d: &DesignResult| d.fem.as_ref().is_some_and(|f| !f.criterion.pass);
    order.sort_by(|a, b| {
        fails(a).cmp(&fails(b)).then(
            a.dynamics
                .peak_pin_force_n
                .total_cmp(&b.dynamics.peak_pin_force_n),
        )
    });
    order
}

/// One row of `ranking.csv` (SI units but stresses in MPa; empty where FEM was skipped).
#[derive(Serialize)]
struct Row<'a> {
    rank: usize,
    design: &'a str,
    id: &'a str,
    mass_kg: f64,
    l1_m: f64,
    i_zz_kgm2: f64,
    i_xx_kgm2: f64,
    peak_pin_force_n: f64,
    fx_von_mises_away_from_fixed_mpa: Option<f64>,
    fx_estimated_error_rel: Option<f64>,
    fx_von_mises_averaged_mpa: Option<f64>,
    fx_von_mises_unaveraged_mpa: Option<f64>,
    fy_von_mises_away_from_fixed_mpa: Option<f64>,
    fy_estimated_error_rel: Option<f64>,
    fy_von_mises_averaged_mpa: Option<f64>,
    fy_von_mises_unaveraged_mpa: Option<f64>,
    max_displacement_mm: Option<f64>,
    allowed_mpa: Option<f64>,
    safety_factor: Option<f64>,
    status: &'static str,
    /// Where the linear model is out of its depth (beyond yield, large displacement), `; `-joined.
    model_validity: String,
}

fn rows(results: &StudyResults) -> Vec<Row<'_>> {
    ranked(results)
        .into_iter()
        .enumerate()
        .map(|(k, d)| {
            let f = d.fem.as_ref();
            let fx = f.map(|f| &f.fem.fx);
            let fy = f.map(|f| &f.fem.fy);
            Row {
                rank: k + 1,
                design: &d.mass.design,
                id: &d.mass.id,
                mass_kg: d.mass.mass_kg,
                l1_m: d.mass.l1_m,
                i_zz_kgm2: d.mass.i_zz_kgm2,
                i_xx_kgm2: d.mass.i_xx_kgm2,
                peak_pin_force_n: d.dynamics.peak_pin_force_n,
                fx_von_mises_away_from_fixed_mpa: fx.map(|c| c.max_von_mises_away_from_fixed_mpa),
                fx_estimated_error_rel: fx.map(|c| c.estimated_error_rel),
                fx_von_mises_averaged_mpa: fx.map(|c| c.max_von_mises_averaged_mpa),
                fx_von_mises_unaveraged_mpa: fx.map(|c| c.max_von_mises_unaveraged_mpa),
                fy_von_mises_away_from_fixed_mpa: fy.map(|c| c.max_von_mises_away_from_fixed_mpa),
                fy_estimated_error_rel: fy.map(|c| c.estimated_error_rel),
                fy_von_mises_averaged_mpa: fy.map(|c| c.max_von_mises_averaged_mpa),
                fy_von_mises_unaveraged_mpa: fy.map(|c| c.max_von_mises_unaveraged_mpa),
                max_displacement_mm: f.map(|f| {
                    f.fem
                        .fx
                        .max_displacement_mm
                        .max(f.fem.fy.max_displacement_mm)
                }),
                allowed_mpa: f.map(|f| f.criterion.allowed_mpa),
                safety_factor: f.map(|f| f.criterion.safety_factor),
                status: match f {
                    None => "not judged (FEM skipped)",
                    Some(f) if f.criterion.pass => "pass",
                    Some(_) => "fail",
                },
                model_validity: f
                    .map(|f| {
                        f.criterion
                            .model_validity
                            .iter()
                            .map(|m| m.split(':').next().unwrap_or_default())
                            .collect::<Vec<_>>()
                            .join("; ")
                    })
                    .unwrap_or_default(),
            }
        })
        .collect()
}

/// `ranking.csv`.
pub fn csv(results: &StudyResults) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for row in rows(results) {
        w.serialize(row)?;
    }
    Ok(w.into_inner()?)
}

/// `ranking.md`.
pub fn markdown(results: &StudyResults) -> String {
    let c = &results.config.criterion;
    let mut out = format!(
        "# Ranking of the designs\n\nDesigns that meet the stress criterion first (max von Mises away from the fixed bore ≤ yield {} MPa / safety factor {} = {:.1} MPa, in both the F_x and F_y cases{}), then by the peak crank–rod pin force of the driven crank–slider, lowest first. Stresses [MPa] per case: away from the fixed bore and from sharp re-entrant edges (the convergent measure, judged) ± its estimated error / nodally averaged / raw element-nodal peak (at the fixed edge, a singularity, shown for reference).\n\n| rank | design | mass [kg] | l1 [mm] | I_zz [kg·m²] | I_xx [kg·m²] | peak pin force [N] | σ F_x [MPa] | σ F_y [MPa] | max displ. [mm] | safety factor | status |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        c.yield_mpa,
        c.safety_factor,
        c.yield_mpa / c.safety_factor,
        if c.with_error {
            ", the peak plus its estimated error"
        } else {
            ""
        }
    );
    let triple = |a: Option<f64>, e: Option<f64>, b: Option<f64>, c: Option<f64>| match (a, e, b, c)
    {
        (Some(a), Some(e), Some(b), Some(c)) => {
            format!("{a:.1} ± {:.1} % / {b:.1} / {c:.1}", 100.0 * e)
        }
        _ => "—".into(),
    };
    for r in rows(results) {
        out.push_str(&format!(
            "| {} | {} | {:.4} | {:.2} | {:.5} | {:.6} | {:.1} | {} | {} | {} | {} | {} |\n",
            r.rank,
            r.design,
            r.mass_kg,
            r.l1_m * 1e3,
            r.i_zz_kgm2,
            r.i_xx_kgm2,
            r.peak_pin_force_n,
            triple(
                r.fx_von_mises_away_from_fixed_mpa,
                r.fx_estimated_error_rel,
                r.fx_von_mises_averaged_mpa,
                r.fx_von_mises_unaveraged_mpa
            ),
            triple(
                r.fy_von_mises_away_from_fixed_mpa,
                r.fy_estimated_error_rel,
                r.fy_von_mises_averaged_mpa,
                r.fy_von_mises_unaveraged_mpa
            ),
            r.max_displacement_mm
                .map_or("—".into(), |v| format!("{v:.4}")),
            r.safety_factor.map_or("—".into(), |v| format!("{v:.2}")),
            if r.model_validity.is_empty() {
                r.status.to_string()
            } else {
                format!("{} ({})", r.status, r.model_validity)
            }
        ));
    }
    let notes: Vec<String> = results
        .designs
        .iter()
        .filter_map(|d| d.fem.as_ref().map(|f| (d, f)))
        .flat_map(|(d, f)| {
            f.criterion
                .model_validity
                .iter()
                .map(move |m| format!("- {}: {m}", d.mass.design))
        })
        .collect();
    if !notes.is_empty() {
        out.push_str(
            "\n## Out of the model's depth\n\nThe stage-3 model is linear elastic and small-displacement; these figures are beyond it (the verdict stands, the numbers are not to be read as the part's stress or deflection):\n\n",
        );
        for n in notes {
            out.push_str(&n);
            out.push('\n');
        }
    }
    if !results.failed.is_empty() {
        out.push_str("\n## Failed designs\n\n");
        for f in &results.failed {
            out.push_str(&format!("- `{}`: {}\n", f.file, f.error));
        }
    }
    out
}
