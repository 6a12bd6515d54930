//! The Pareto front of a study: the designs no other design beats on every objective at once —
//! lower mass, lower peak crank–rod pin force, higher stress safety factor (the static criterion's
//! yield / governing stress). Without stage 3 (or for designs it could not judge) the front is
//! taken on mass and force alone.
//!
//! a dominates b ⇔ a is no worse than b on every objective and better on at least one
//! (K. Deb, *Multi-Objective Optimization using Evolutionary Algorithms*, 2001, §2.4).

use crate::study::results::StudyResults;
use serde::Serialize;

/// One design's objectives and whether it is on the front.
#[derive(Debug, Clone, Serialize)]
pub struct ParetoRow {
    pub design: String,
    pub id: String,
    pub mass_kg: f64,
    pub peak_pin_force_n: f64,
    /// Static stress safety factor; empty when stage 3 did not judge the design.
    pub safety_factor: Option<f64>,
    pub on_front: bool,
    /// The ids of the designs that dominate it, `; `-joined.
    pub dominated_by: String,
}

/// Whether `a` dominates `b` (objectives: mass ↓, force ↓, safety factor ↑ when both have one).
fn dominates(a: &ParetoRow, b: &ParetoRow, with_sf: bool) -> bool {
    let mut no_worse = a.mass_kg <= b.mass_kg && a.peak_pin_force_n <= b.peak_pin_force_n;
    let mut better = a.mass_kg < b.mass_kg || a.peak_pin_force_n < b.peak_pin_force_n;
    if with_sf {
        let (sa, sb) = (
            a.safety_factor.unwrap_or(f64::NEG_INFINITY),
            b.safety_factor.unwrap_or(f64::NEG_INFINITY),
        );
        no_worse &= sa >= sb;
        better |= sa > sb;
    }
    no_worse && better
}

/// The designs that passed every stage, with the front marked (in the study's design order).
pub fn pareto(results: &StudyResults) -> Vec<ParetoRow> {
    let mut rows: Vec<ParetoRow> = results
        .designs
        .iter()
        .map(|d| ParetoRow {
            design: d.mass.design.clone(),
            id: d.mass.id.clone(),
            mass_kg: d.mass.mass_kg,
            peak_pin_force_n: d.dynamics.peak_pin_force_n,
            safety_factor: d.fem.as_ref().map(|f| f.criterion.safety_factor),
            on_front: false,
            dominated_by: String::new(),
        })
        .collect();
    let with_sf = !rows.is_empty() && rows.iter().all(|r| r.safety_factor.is_some());
    let by: Vec<Vec<String>> = rows
        .iter()
        .map(|b| {
            rows.iter()
                .filter(|a| dominates(a, b, with_sf))
                .map(|a| a.id.clone())
                .collect()
        })
        .collect();
    for (r, by) in rows.iter_mut().zip(by) {
        r.on_front = by.is_empty();
        r.dominated_by = by.join("; ");
    }
    rows
}

/// What the front is taken on, for the reports.
pub fn objectives(results: &StudyResults) -> &'static str {
    if !results.designs.is_empty() && results.designs.iter().all(|d| d.fem.is_some()) {
        "mass (lower), peak crank–rod pin force (lower), static stress safety factor (higher)"
    } else {
        "mass (lower), peak crank–rod pin force (lower); stage 3 did not judge every design"
    }
}

/// `pareto.md`.
pub fn markdown(results: &StudyResults) -> String {
    let rows = pareto(results);
    let mut s = format!(
        "# Pareto front\n\nDesigns not dominated on {}: no other design is at least as good on all of them and better on one.\n\n| design | mass [kg] | peak pin force [N] | safety factor | on the front | dominated by |\n|---|---|---|---|---|---|\n",
        objectives(results)
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {:.4} | {:.1} | {} | {} | {} |\n",
            r.design,
            r.mass_kg,
            r.peak_pin_force_n,
            r.safety_factor
                .map_or("—".to_string(), |v| format!("{v:.2}")),
            if r.on_front { "yes" } else { "no" },
            r.dominated_by
        ));
    }
    s
}

/// `pareto.csv`.
pub fn csv(results: &StudyResults) -> anyhow::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in pareto(results) {
        w.serialize(r)?;
    }
    Ok(w.into_inner()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(id: &str, m: f64, f: f64, sf: Option<f64>) -> ParetoRow {
        ParetoRow {
            design: id.into(),
            id: id.into(),
            mass_kg: m,
            peak_pin_force_n: f,
            safety_factor: sf,
            on_front: false,
            dominated_by: String::new(),
        }
    }

    #[test]
    fn domination_by_hand() {
        let a = row("a", 1.0, 10.0, Some(2.0));
        let b = row("b", 2.0, 20.0, Some(1.0));
        let c = row("c", 2.0, 20.0, Some(3.0));
        // a is lighter, lower force, safer than b
        assert!(dominates(&a, &b, true) && !dominates(&b, &a, true));
        // c is safer than a but heavier: neither dominates
        assert!(!dominates(&a, &c, true) && !dominates(&c, &a, true));
        // without the safety factor a dominates c
        assert!(dominates(&a, &c, false));
        // nobody dominates itself (no strict improvement)
        assert!(!dominates(&a, &a, true));
    }
}
