//! `index.html`: the study at a glance, readable from top to bottom without another tool. The
//! ranking (the same table as `ranking.md` and `ranking.csv`), where the model is out of its
//! depth, the failed designs, the study-wide plots, then one section per design: its mass
//! properties, pin-force curve, stress pictures and links to its CSV and ParaView files; last the
//! accuracy-and-speed plots of the integrators and of stage 3 when they are in the folder.
//!
//! Self-contained for `file://`: relative links only, no scripts, no fonts or styles fetched.

use super::design_files::load_span;
use super::file_safe;
use super::ranking::{self, RankRow, Status, escape};
use crate::study::results::StudyResults;
use std::fmt::Write as _;
use std::path::Path;

/// Inline style: a readable page at 100 % zoom, wide tables scroll on their own.
const STYLE: &str = "body{font-family:sans-serif;max-width:1280px;margin:1.5em auto;padding:0 1em;line-height:1.4;color:#222}\
h1{margin-bottom:.2em}h2{margin-top:2em;border-bottom:1px solid #ccc}\
.scroll{overflow-x:auto}table{border-collapse:collapse;font-size:14px}\
td,th{border:1px solid #ccc;padding:3px 6px;text-align:right}\
th{background:#f2f2f2}#ranking td:nth-child(2),#ranking td:nth-child(3){text-align:left}\
#ranking td:nth-child(5),#ranking td:nth-child(6){min-width:9em}\
tr.pass td:nth-child(3){background:#dff3df}tr.fail td:nth-child(3){background:#f8d8d8}\
tr.failed td{color:#777}tr.failed td:nth-child(3){background:#eee}\
table.props td:first-child{text-align:left}table.props td:last-child{text-align:left}\
figure{margin:1em 0}figure img{max-width:960px;width:100%}figcaption{font-size:14px;color:#444}img{max-width:100%;height:auto}\
.note{color:#555;font-size:14px}code{background:#f4f4f4;padding:0 3px}";

/// The page, for the reports folder `out` (which files exist decides which pictures and links are
/// shown).
pub fn index_html(results: &StudyResults, out: &Path) -> String {
    let rows = ranking::ranking(results);
    let mut s = String::new();
    let _ = write!(
        s,
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\
<title>rodstudy: connecting-rod design study</title>\n<style>{STYLE}</style></head><body>\n\
<h1>Connecting-rod design study</h1>\n<p class=\"note\">rodstudy {} · stages run: {} · skipped: {} · {} design(s) studied, {} failed</p>\n",
        escape(&results.program_version),
        escape(&results.stages_run.join(", ")),
        escape(&if results.stages_skipped.is_empty() {
            "none".to_string()
        } else {
            results.stages_skipped.join(", ")
        }),
        results.designs.len(),
        results.failed.len()
    );
    let _ = write!(
        s,
        "<h2 id=\"ranking-section\">Ranking</h2>\n<p>{}</p>\n<div class=\"scroll\">{}</div>\n<p class=\"note\">The same table: <a href=\"ranking.md\">ranking.md</a>, <a href=\"ranking.csv\">ranking.csv</a>; every figure: <a href=\"results.json\">results.json</a>.</p>\n",
        escape(&ranking::explanation(results)),
        ranking::html_table(results)
    );
    let warnings = ranking::fem_warnings(results);
    if !warnings.is_empty() {
        s.push_str("<h3>FEM warnings</h3>\n<ul>\n");
        for (d, m) in warnings {
            let _ = writeln!(s, "<li>{}: {}</li>", escape(&d), escape(&m));
        }
        s.push_str("</ul>\n");
    }
    let notes = ranking::validity_notes(results);
    if !notes.is_empty() {
        let _ = write!(
            s,
            "<h3>Out of the model's depth</h3>\n<p>{}</p><ul>\n",
            escape(ranking::VALIDITY_PREAMBLE)
        );
        for (d, m) in notes {
            let _ = writeln!(s, "<li>{}: {}</li>", escape(&d), escape(&m));
        }
        s.push_str("</ul>\n");
    }
    if !results.failed.is_empty() {
        s.push_str("<h3>Failed designs</h3>\n<ul>\n");
        for f in &results.failed {
            let _ = writeln!(
                s,
                "<li><code>{}</code> ({} stage): {}</li>",
                escape(&f.file),
                escape(&f.stage),
                escape(&f.error)
            );
        }
        s.push_str("</ul>\n");
    }
    if !rows.is_empty() {
        s.push_str("<h2>Pin force</h2>\n");
        image(
            &mut s,
            out,
            "pin_force.svg",
            &format!(
                "|F_A| over {}, every design",
                load_span(results.config.engine.pressure_trace.is_some())
            ),
        );
        image(
            &mut s,
            out,
            "peak_force.svg",
            "Peak pin force per design, in ranking order",
        );
    }
    if !results.designs.is_empty() {
        let _ = write!(
            s,
            "<h2>Pareto front</h2>\n<p>Designs not dominated on {}; marked in the ranking's last column (<a href=\"pareto.md\">pareto.md</a>, <a href=\"pareto.csv\">pareto.csv</a>).</p>\n",
            escape(super::pareto::objectives(results))
        );
        image(
            &mut s,
            out,
            "pareto.svg",
            "mass against peak pin force; filled: on the Pareto front",
        );
    }
    for r in &rows {
        design_section(&mut s, r, out);
    }
    accuracy_section(&mut s, out);
    s.push_str("</body></html>\n");
    s
}

/// `<figure>` with an image, when the file exists in `out`.
fn image(s: &mut String, out: &Path, rel: &str, caption: &str) {
    if out.join(rel).is_file() {
        let _ = writeln!(
            s,
            "<figure><img src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
            escape(rel),
            escape(caption),
            escape(caption)
        );
    }
}

/// A link, when the file exists in `out`.
fn link(out: &Path, rel: &str, text: &str) -> Option<String> {
    out.join(rel)
        .is_file()
        .then(|| format!("<a href=\"{}\">{}</a>", escape(rel), escape(text)))
}

fn design_section(s: &mut String, r: &RankRow, out: &Path) {
    let m = r.mass;
    let dir = file_safe(&m.id);
    let _ = write!(
        s,
        "<section id=\"{}\">\n<h2>{}{}: {}</h2>\n",
        escape(&m.id),
        r.rank.map_or(String::new(), |k| format!("{k}. ")),
        escape(&m.design),
        escape(&r.status.word())
    );
    if let Status::StageFailed { stage, error } = &r.status {
        let _ = writeln!(
            s,
            "<p><b>The {} stage failed</b>: {}. The figures of the stages before it are kept below; the design is not judged on stress.</p>",
            escape(stage),
            escape(error)
        );
    }
    let mut props: Vec<(&str, String)> = vec![
        ("file", m.file.clone()),
        (
            "STL",
            format!("{}, {} triangles, units {}", m.format, m.triangles, m.units),
        ),
        ("density [kg/m³]", format!("{:.0}", m.density_kg_m3)),
        ("volume [cm³]", format!("{:.3}", m.volume_m3 * 1e6)),
        ("mass [kg]", format!("{:.4}", m.mass_kg)),
        (
            "centre distance A→B [mm]",
            format!("{:.2}", m.centre_distance_m * 1e3),
        ),
        (
            "bore radii A / B [mm]",
            format!(
                "{:.2} / {:.2}",
                m.crank_bore_radius_m * 1e3,
                m.piston_bore_radius_m * 1e3
            ),
        ),
        (
            "centroid from A: l1 / offset [mm]",
            format!("{:.2} / {:.3}", m.l1_m * 1e3, m.offset_m * 1e3),
        ),
        (
            "I_zz about the centroid [kg·m²]",
            format!("{:.6}", m.i_zz_kgm2),
        ),
        (
            "I_xx about the long axis [kg·m²]",
            format!("{:.6}", m.i_xx_kgm2),
        ),
    ];
    if let Some(d) = r.dynamics {
        props.push((
            "peak pin force [N]",
            format!(
                "{:.1} at crank angle {:.1}° (t = {:.5} s)",
                d.peak_pin_force_n, d.peak_crank_angle_deg, d.peak_time_s
            ),
        ));
    }
    if let Some(f) = r.fem {
        let c = &f.criterion;
        props.push((
            "stress criterion",
            format!(
                "{:.1} MPa ({} case{}) against {:.1} MPa allowed: safety factor {:.2}, {}",
                c.governing_mpa,
                c.governing_case,
                if c.with_error { ", with its error" } else { "" },
                c.allowed_mpa,
                c.safety_factor,
                if c.pass { "pass" } else { "fail" }
            ),
        ));
        props.push((
            "error of the judged peaks",
            format!(
                "{}{}",
                ranking::error_splits(&f.fem),
                if f.fem
                    .cases
                    .iter()
                    .any(|c| c.smooth_surface_peak_mpa.is_some())
                {
                    "; a STEP export of the design removes the geometry part"
                } else {
                    ""
                }
            ),
        ));
        for case in f.fem.cases.iter() {
            if let Some(k) = case
                .contact
                .as_ref()
                .or(case.load_models.as_ref().map(|m| &m.contact))
            {
                props.push(("pin contact", contact_line(case, k)));
            }
        }
        for w in &f.fem.warnings {
            props.push(("FEM warning", w.clone()));
        }
        let mesh = &f.mesh;
        props.push((
            "FEM mesh",
            format!(
                "{} elements, {} nodes (tet10){}",
                mesh.elements,
                mesh.nodes,
                mesh.adaptive.as_ref().map_or_else(
                    || mesh.size_mm.map_or(String::new(), |h| format!(", {h} mm")),
                    |a| format!(
                        ", adaptive: {} meshes, stop: {}",
                        a.iterations,
                        serde_json::to_value(a.stop)
                            .ok()
                            .and_then(|v| v.as_str().map(str::to_string))
                            .unwrap_or_default()
                    )
                )
            ),
        ));
    }
    if let Some(c) = r.cycle {
        props.push((
            if c.cycle_span_deg.is_some() {
                "cycle (four-stroke, 720°, gas force and inertia relief)"
            } else {
                "cycle (one revolution, inertia relief)"
            },
            format!(
                "max von Mises {:.2} MPa at φ = {:.0}°, at ({:.1}, {:.1}, {:.1}) mm; reaction at B equals the dynamics' F_B to {:.1e} of the peak pin force",
                c.max_von_mises_over_cycle_mpa,
                c.crank_angle_of_max_deg,
                c.location_of_max_mm[0],
                c.location_of_max_mm[1],
                c.location_of_max_mm[2],
                c.reaction_mismatch_rel
            ),
        ));
        props.push((
            if c.mean_stress.is_goodman() {
                "fatigue (Goodman, signed von Mises)"
            } else {
                "fatigue (Gerber, signed von Mises)"
            },
            format!(
                "safety factor {:.2} at ({:.1}, {:.1}, {:.1}) mm: σa {:.2} MPa, σm {:.2} MPa against Se {:.0} / Sut {:.0} MPa",
                c.fatigue_safety_factor,
                c.fatigue_location_mm[0],
                c.fatigue_location_mm[1],
                c.fatigue_location_mm[2],
                c.fatigue_alternating_mpa,
                c.fatigue_mean_mpa,
                c.endurance_mpa,
                c.ultimate_mpa
            ),
        ));
        if !c.contact_instants.is_empty() {
            props.push(("cycle with pin contact", contact_cycle_line(c)));
        }
        if let Some(e) = &c.contact_instants_error {
            props.push(("cycle with pin contact", format!("not solved: {e}")));
        }
    }
    if let Some(f) = r.fem
        && let Some(b) = f.buckling_load_factor
    {
        props.push((
            "buckling load factor",
            match f.buckling_load_factor_contact {
                Some(c) => format!(
                    "{b:.2} (uniform traction); {c:.2} with the compression entering bore A through contact ({:+.1} %)",
                    100.0 * (c / b - 1.0)
                ),
                None => format!("{b:.2}"),
            },
        ));
    }
    s.push_str("<table class=\"props\">\n");
    for (k, v) in props {
        let _ = writeln!(s, "<tr><td>{}</td><td>{}</td></tr>", escape(k), escape(&v));
    }
    s.push_str("</table>\n");
    image(
        s,
        out,
        &format!("{dir}/pin_force.svg"),
        &format!(
            "|F_A| and its components over {}",
            load_span(r.dynamics.is_some_and(|d| d.peak_compression_n.is_some()))
        ),
    );
    if let Some(f) = r.fem {
        for case in f.fem.cases.iter() {
            let p = case.max_von_mises_away_from_fixed_at_mm;
            image(
                s,
                out,
                &format!("{dir}/von_mises_{}.svg", case.name),
                &format!(
                    "von Mises, {} case (F = {:.0} N): peak {:.1} MPa ± {:.1} % at ({:.1}, {:.1}, {:.1}) mm in the rod frame (A at the origin, x towards B); grey: above the peak, at the fixed bore or a sharp edge (singular, not judged)",
                    crate::rod::cases::label(&case.name),
                    case.force_n,
                    case.max_von_mises_away_from_fixed_mpa,
                    100.0 * case.estimated_error_rel,
                    p[0],
                    p[1],
                    p[2]
                ),
            );
        }
    }
    if let Some(f) = r.fem {
        for case in f.fem.cases.iter() {
            image(
                s,
                out,
                &format!("{dir}/contact_{}.svg", case.name),
                &format!(
                    "{} case: the contact pressure around the crank-pin bore (frictionless contact with the pin at its clearance) against the cosine bearing pressure and the uniform traction of the same force",
                    crate::rod::cases::label(&case.name)
                ),
            );
        }
    }
    if r.cycle.is_some() {
        image(
            s,
            out,
            &format!("{dir}/von_mises_cycle.svg"),
            &format!(
                "max von Mises over {} at every point (quasi-static, inertia relief); the marked point is the judged maximum",
                load_span(r.cycle.is_some_and(|c| c.cycle_span_deg.is_some()))
            ),
        );
        image(
            s,
            out,
            &format!("{dir}/cycle.svg"),
            "the judged max von Mises at each crank angle",
        );
        if let Some(l) = r.cycle.and_then(|c| c.local_fatigue.as_ref()) {
            image(
                s,
                out,
                &format!("{dir}/local_fatigue.svg"),
                &format!(
                    "local fatigue (FKM): 1/S at every surface node; lowest S = {:.2} at ({:.1}, {:.1}, {:.1}) mm; Findley's critical plane: {:.2} at ({:.1}, {:.1}, {:.1}) mm",
                    l.safety_factor,
                    l.at_mm[0],
                    l.at_mm[1],
                    l.at_mm[2],
                    l.findley.factor,
                    l.findley.at_mm[0],
                    l.findley.at_mm[1],
                    l.findley.at_mm[2]
                ),
            );
            image(
                s,
                out,
                &format!("{dir}/haigh.svg"),
                "the Haigh diagram at the critical node: the component's line, the cycle's points, the load line to the limit",
            );
        }
    }
    // only the files of the stages this study reports (an earlier study's stay for its cache)
    let (fem, cycle) = (r.fem.is_some(), r.cycle.is_some());
    let links: Vec<String> = [
        ("pin_force.csv", "pin-force history (CSV)", true),
        (
            "cycle.csv",
            "stress and reactions over the revolution (CSV)",
            cycle,
        ),
        ("fem_fx.vtu", "F_x field (ParaView)", fem),
        ("fem_fy.vtu", "F_y field (ParaView)", fem),
        ("contact_fx.vtu", "F_x under pin contact (ParaView)", fem),
        ("contact_fy.vtu", "F_y under pin contact (ParaView)", fem),
        (
            "cycle.vtu",
            "max over the cycle and fatigue factor (ParaView)",
            cycle,
        ),
    ]
    .iter()
    .filter(|(_, _, reported)| *reported)
    .filter_map(|(f, t, _)| link(out, &format!("{dir}/{f}"), t))
    .collect();
    if !links.is_empty() {
        let _ = writeln!(s, "<p>Files: {}</p>", links.join(" · "));
    }
    s.push_str("</section>\n");
}

/// One case's pin contact for the design's table: the arcs, peak pressures, the big-end bore's
/// ovality and the clearances.
fn contact_line(
    case: &crate::rod::LoadCaseResult,
    k: &crate::rod::records::PinContactRecord,
) -> String {
    let b = match (k.arc_b_deg, k.peak_pressure_b_mpa) {
        (Some(arc), Some(p)) => format!("bore B arc {arc:.0}°, peak {p:.1} MPa"),
        _ => "bore B clamped (a force across the rod)".into(),
    };
    format!(
        "{} case{}: bore A arc {:.0}° ({:.0}° to {:.0}° from the force), peak pressure {:.1} MPa; {b}; bore A's diameter changes {:+.2} µm along the force, {:+.2} µm across; radial clearances {:.1} / {:.1} µm",
        crate::rod::cases::label(&case.name),
        match k.pins {
            crate::rod::pin_model::PinModel::Rigid => "",
            crate::rod::pin_model::PinModel::Elastic => " (elastic pins held at a rigid core)",
            crate::rod::pin_model::PinModel::ElasticEnds =>
                " (elastic pins held at the bore's faces)",
        },
        k.arc_a_deg,
        k.arc_a_ends_deg[0],
        k.arc_a_ends_deg[1],
        k.peak_pressure_a_mpa,
        k.ovality_a_along_um,
        k.ovality_a_across_um,
        k.clearance_a_um,
        k.clearance_b_um
    )
}

/// The cycle's contact instants against the linear cycle at the same instants, and the fatigue
/// factor they give.
fn contact_cycle_line(c: &crate::stages::records::DesignCycle) -> String {
    let instants: Vec<String> = c
        .contact_instants
        .iter()
        .map(|i| {
            format!(
                "φ = {:.0}° ({}): {:.2} MPa against {:.2} MPa linear ({:+.0} %), arcs {:.0}° / {:.0}°",
                i.crank_angle_deg,
                i.reason,
                i.contact_mpa,
                i.linear_mpa,
                100.0 * i.change_rel,
                i.arc_a_deg,
                i.arc_b_deg
            )
        })
        .collect();
    let fatigue = c.contact_fatigue.as_ref().map_or(String::new(), |f| {
        format!(
            "; fatigue factor over these instants {:.2} with contact against {:.2} linear ({:+.0} %; the linear cycle over every instant {:.2})",
            f.contact_factor,
            f.linear_factor_at_instants,
            100.0 * f.change_rel,
            f.linear_factor
        )
    });
    format!("{}{fatigue}", instants.join("; "))
}

/// The integrators' work–precision plots and stage 3's speed–error plots, when present.
fn accuracy_section(s: &mut String, out: &Path) {
    let mut body = String::new();
    image(
        &mut body,
        out,
        "work_precision_time.svg",
        "Free run (1 DOF): error against CPU time per integrator (rodstudy integrators)",
    );
    image(
        &mut body,
        out,
        "work_precision_evals.svg",
        "Free run (1 DOF): error against right-hand-side evaluations",
    );
    let mut fem = String::new();
    if let Ok(entries) = std::fs::read_dir(out.join("convergence")) {
        let mut dirs: Vec<String> = entries
            .filter_map(|e| e.ok())
            .filter(|e| e.path().join("convergence.svg").is_file())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        dirs.sort();
        for d in dirs {
            image(
                &mut fem,
                out,
                &format!("convergence/{d}/convergence.svg"),
                &format!(
                    "Stage 3 on {d}: estimated and true error against wall time, uniform meshes and the adaptive loop (rodstudy fem --convergence)"
                ),
            );
        }
    }
    if body.is_empty() && fem.is_empty() {
        return;
    }
    s.push_str("<h2>Accuracy and speed</h2>\n");
    s.push_str(&body);
    s.push_str(&fem);
}
