//! The ranking (SPEC "Outputs"): one structure, three renderings (`ranking.md`, `ranking.csv`, the
//! table of `index.html`), so every report gives the same order and the same columns (defined once,
//! in [`super::columns`]).
//!
//! Order: designs that meet the stress criterion first, then by peak pin force, lowest first.
//! Without the FEM stage no design is judged on stress and the order is by force alone. A design
//! whose FEM stage failed keeps its mass and peak force but is not ranked: it follows the ranked
//! designs, without a rank, with the failing stage and its message as its status.

use crate::study::results::{DesignResult, FailedDesign, StudyResults};
use anyhow::Result;

use super::columns::{self, Showing};

pub use super::rank_row::{ROD_BODY_ALONE, RankRow, Status, is_rod_body_alone};

/// The ranking of a study: every design that passed stage 1, in report order.
pub fn ranking(results: &StudyResults) -> Vec<RankRow<'_>> {
    let front: Vec<String> = super::pareto::pareto(results)
        .into_iter()
        .filter(|r| r.on_front)
        .map(|r| r.id)
        .collect();
    let fails = |d: &DesignResult| d.fem.as_ref().is_some_and(|f| !f.criterion.pass);
    let mut done: Vec<&DesignResult> = results.designs.iter().collect();
    done.sort_by(|a, b| {
        is_rod_body_alone(&a.mass)
            .cmp(&is_rod_body_alone(&b.mass))
            .then(fails(a).cmp(&fails(b)))
            .then(
                a.dynamics
                    .peak_pin_force_n
                    .total_cmp(&b.dynamics.peak_pin_force_n),
            )
    });
    let mut partial: Vec<&FailedDesign> =
        results.failed.iter().filter(|f| f.mass.is_some()).collect();
    let force = |f: &FailedDesign| {
        f.dynamics
            .as_ref()
            .map_or(f64::INFINITY, |d| d.peak_pin_force_n)
    };
    partial.sort_by(|a, b| force(a).total_cmp(&force(b)).then(a.file.cmp(&b.file)));
    let mut rows: Vec<RankRow> = done
        .into_iter()
        .enumerate()
        .map(|(k, d)| RankRow {
            rank: Some(k + 1),
            mass: &d.mass,
            dynamics: Some(&d.dynamics),
            fem: d.fem.as_ref(),
            cycle: d.cycle.as_ref(),
            pareto: front.contains(&d.mass.id),
            buckling_required: results.config.criterion.buckling_factor,
            status: match &d.fem {
                None => Status::NotJudged,
                Some(f) if f.criterion.pass => Status::Pass,
                Some(_) => Status::Fail,
            },
        })
        .collect();
    rows.extend(partial.into_iter().filter_map(|f| {
        Some(RankRow {
            rank: None,
            mass: f.mass.as_ref()?,
            dynamics: f.dynamics.as_ref(),
            fem: None,
            cycle: None,
            pareto: false,
            buckling_required: results.config.criterion.buckling_factor,
            status: Status::StageFailed {
                stage: f.stage.clone(),
                error: f.error.clone(),
            },
        })
    }));
    rows
}

/// Which optional columns the study shows ([`super::columns::Showing`]).
pub fn showing(results: &StudyResults) -> Showing {
    Showing {
        engine: has_engine_loads(results),
        buckling: has_buckling(results),
    }
}

/// `ranking.csv`: the columns of [`super::columns::COLUMNS`] (SI units but stresses in MPa; empty
/// where a stage was skipped or failed).
pub fn csv(results: &StudyResults) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let showing = showing(results);
    let rows = ranking(results);
    if !rows.is_empty() {
        w.write_record(columns::csv_header(showing))?;
    }
    for r in rows {
        w.serialize(columns::csv_values(&r, showing))?;
    }
    Ok(w.into_inner()?)
}

/// Whether any design of the study has a buckling load factor (then the tables get its column).
pub fn has_buckling(results: &StudyResults) -> bool {
    results.designs.iter().any(|d| {
        d.fem
            .as_ref()
            .is_some_and(|f| f.buckling_load_factor.is_some())
    })
}

/// Whether any design has the engine's axial peaks (a study with a pressure trace): then the
/// tables get the peak compression and tension columns after the peak pin force.
pub fn has_engine_loads(results: &StudyResults) -> bool {
    results
        .designs
        .iter()
        .any(|d| d.dynamics.peak_compression_n.is_some())
}

/// The sentence that says how the ranking orders and what the stress columns hold.
pub fn explanation(results: &StudyResults) -> String {
    let c = &results.config.criterion;
    if results.stages_skipped.iter().any(|s| s == "fem") {
        return "The FEM stage was skipped: no design is judged on stress; ranked by the peak crank–rod pin force of the driven crank–slider, lowest first.".into();
    }
    format!(
        "Designs that meet the stress criterion first (max von Mises away from the fixed bore ≤ yield {} MPa / safety factor {} = {:.1} MPa, in both the F_x and F_y cases{}{}), then by the peak crank–rod pin force of the driven crank–slider, lowest first; a design whose FEM stage failed keeps its mass and force but is not ranked. Stresses [MPa] per case: away from the fixed bore and from sharp re-entrant edges (the convergent measure, judged) ± its estimated error / nodally averaged / raw element-nodal peak (at the fixed edge, a singularity, shown for reference).",
        c.yield_mpa,
        c.safety_factor,
        c.yield_mpa / c.safety_factor,
        if c.with_error {
            ", the peak plus its estimated error"
        } else {
            ""
        },
        if c.fatigue && !results.stages_skipped.iter().any(|s| s == "cycle") {
            format!(
                "; and a local fatigue safety factor (FKM guideline, local stresses: support, roughness, mean stress at every surface node; jD {}) ≥ {} over {} with inertia relief, Rm {} MPa; the {} factor against Se {} / Sut {} MPa is shown beside it",
                results.config.material.j_s
                    * results.config.material.j_f
                    * results.config.material.j_g,
                c.fatigue_safety_factor,
                if results.config.engine.pressure_trace.is_some() {
                    "the four-stroke cycle (720°, with the gas force)"
                } else {
                    "one revolution"
                },
                results.config.material.ultimate_mpa,
                if results.config.material.mean_stress.is_goodman() {
                    "Goodman"
                } else {
                    "Gerber"
                },
                results.config.material.endurance_mpa,
                results.config.material.ultimate_mpa
            )
        } else {
            String::new()
        }
    ) + &if has_buckling(results) {
        format!(
            " Buckling: a linear buckling load factor ≥ {} under the peak compression (small-end bore fixed, the compression on the big-end bore) is required too.",
            c.buckling_factor
        )
    } else {
        String::new()
    } + if has_engine_loads(results) {
        " Engine loads (a cylinder pressure trace): the F_x case carries the peak pin force (the firing compression), the F_y case the largest pin force across the rod over the cycle (inertia; the gas force acts along the rod); the peak compression and tension are along A→B at the crank pin, with their crank angles (0 = firing top dead centre)."
    } else {
        ""
    } + if results.designs.iter().any(|d| is_rod_body_alone(&d.mass)) {
        " A rod body drawn without its cap (a partial pin bore) is ranked after the complete rods: in the engine the cap runs with the rod, so its mass, pin force and stresses lack the cap's and are not comparable with those of a complete rod (give the rod with its cap, as a second body of the same file, to compare it)."
    } else {
        ""
    }
}

/// Per design, the sentences that say where the model is out of its depth.
pub fn validity_notes(results: &StudyResults) -> Vec<(String, String)> {
    ranking(results)
        .into_iter()
        .filter_map(|r| r.fem.map(|f| (r.mass.design.clone(), f)))
        .flat_map(|(d, f)| {
            f.criterion
                .model_validity
                .iter()
                .map(move |m| (d.clone(), m.clone()))
        })
        .collect()
}

/// What the error bar of a case's judged peak is made of, in words: the discretisation part, the
/// geometry part (an STL's facets) and which dominates.
pub fn error_split(case: &crate::rod::LoadCaseResult) -> String {
    let label = crate::rod::cases::label(&case.name);
    let d = case.estimated_discretisation_error_rel;
    let head = format!(
        "{label} {:.1} MPa ± {:.1} %",
        case.max_von_mises_away_from_fixed_mpa,
        100.0 * case.estimated_error_rel
    );
    let mut parts = vec![format!("{:.1} % discretisation", 100.0 * d)];
    match case.estimated_geometry_error_rel {
        None => parts.push("geometry not estimated".into()),
        Some(g) if g == 0.0 && case.smooth_surface_peak_mpa.is_none() => {
            parts.push("no geometry part (the exact geometry)".into())
        }
        Some(g) => parts.push(format!("{:.1} % geometry (the STL's facets)", 100.0 * g)),
    }
    match (case.estimated_load_model_error_rel, &case.load_models) {
        (Some(l), Some(m)) => parts.push(format!(
            "{:.1} % load model (uniform {:.1} against contact {:.1} MPa)",
            100.0 * l,
            m.uniform_mpa,
            m.contact_mpa
        )),
        _ => parts.push("load model not compared".into()),
    }
    format!(
        "{head} = {}: the {} dominates",
        parts.join(" + "),
        case.dominant_error()
    )
}

/// The error bars of all judged peaks of `fem` ([`error_split`]), from the last case to the first
/// (F_y before F_x).
pub fn error_splits(fem: &crate::rod::FemResult) -> String {
    fem.cases
        .iter()
        .rev()
        .map(error_split)
        .collect::<Vec<_>>()
        .join("; ")
}

/// Per design, the error bars of its judged peaks split into discretisation and geometry.
pub fn error_notes(results: &StudyResults) -> Vec<(String, String)> {
    ranking(results)
        .into_iter()
        .filter_map(|r| r.fem.map(|f| (r.mass.design.clone(), f)))
        .map(|(d, f)| {
            let cases = error_splits(&f.fem);
            let stl = f
                .fem
                .cases
                .iter()
                .any(|c| c.smooth_surface_peak_mpa.is_some());
            (
                d,
                if stl {
                    format!("{cases}. A STEP export of the design removes the geometry part.")
                } else {
                    format!("{cases}.")
                },
            )
        })
        .collect()
}

/// The sentence above the error list.
pub const ERROR_PREAMBLE: &str = "The estimated error of each judged peak is the sum of three parts (a bound: where they move the peak the same way they add): the discretisation (the mesh: the adaptive sequence's estimate), for an STL the geometry (what the facets do: the same mesh curved onto a smooth surface through the STL's vertices and solved again; a STEP design is meshed on its exact geometry with curved elements: no geometry part), and the load model (how the pin force enters the rod: the thesis' uniform traction against frictionless contact with the pins at their clearances, both on the final mesh).";

/// Per design, the warnings of its FEM record.
pub fn fem_warnings(results: &StudyResults) -> Vec<(String, String)> {
    ranking(results)
        .into_iter()
        .filter_map(|r| r.fem.map(|f| (r.mass.design.clone(), f)))
        .flat_map(|(d, f)| {
            f.fem
                .warnings
                .iter()
                .map(move |w| (d.clone(), w.clone()))
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The sentence above the out-of-depth list.
pub const VALIDITY_PREAMBLE: &str = "The stage-3 model is linear elastic and small-displacement; these figures are beyond it (the verdict stands, the numbers are not to be read as the part's stress or deflection):";

/// `ranking.md`.
pub fn markdown(results: &StudyResults) -> String {
    let mut out = format!("# Ranking of the designs\n\n{}\n\n", explanation(results));
    let showing = showing(results);
    let headers = columns::table_headers(showing);
    out.push_str(&format!("| {} |\n", headers.join(" | ")));
    out.push_str(&format!("|{}\n", "---|".repeat(headers.len())));
    for r in ranking(results) {
        let cells: Vec<String> = columns::table_cells(&r, showing)
            .into_iter()
            .map(|(_, c)| c.replace('|', "\\|"))
            .collect();
        out.push_str(&format!("| {} |\n", cells.join(" | ")));
    }
    let errors = error_notes(results);
    if !errors.is_empty() {
        out.push_str(&format!(
            "\n## Error of the judged peaks\n\n{ERROR_PREAMBLE}\n\n"
        ));
        for (d, m) in errors {
            out.push_str(&format!("- {d}: {m}\n"));
        }
    }
    let warnings = fem_warnings(results);
    if !warnings.is_empty() {
        out.push_str("\n## FEM warnings\n\n");
        for (d, m) in warnings {
            out.push_str(&format!("- {d}: {m}\n"));
        }
    }
    let notes = validity_notes(results);
    if !notes.is_empty() {
        out.push_str(&format!(
            "\n## Out of the model's depth\n\n{VALIDITY_PREAMBLE}\n\n"
        ));
        for (d, m) in notes {
            out.push_str(&format!("- {d}: {m}\n"));
        }
    }
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

/// Escapes text for html.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The ranking as an html table (`<table id="ranking">`, one `<tr data-id="…">` per design in
/// ranking order); the design names link to their sections (`#<id>`).
pub fn html_table(results: &StudyResults) -> String {
    let mut out = String::from("<table id=\"ranking\">\n<thead><tr>");
    let showing = showing(results);
    for h in columns::table_headers(showing) {
        out.push_str(&format!("<th>{}</th>", escape(&h)));
    }
    out.push_str("</tr></thead>\n<tbody>\n");
    for r in ranking(results) {
        let id = escape(&r.mass.id);
        out.push_str(&format!(
            "<tr data-id=\"{id}\" class=\"{}\">",
            r.status.class()
        ));
        for (key, c) in columns::table_cells(&r, showing) {
            let c = escape(&c);
            if key == "design" {
                out.push_str(&format!("<td><a href=\"#{id}\">{c}</a></td>"));
            } else {
                out.push_str(&format!("<td>{c}</td>"));
            }
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody></table>\n");
    out
}
