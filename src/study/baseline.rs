//! The regression gate: a committed baseline of each design's peak pin force and mass, and the
//! comparison of the latest study results against it (SPEC "Outputs", issue "The study").
//!
//! A design regresses when its peak force moves by more than `rtol_force` (default 0.5 %) or its
//! mass by more than `rtol_mass` (default 0.1 %) relative to the baseline; a design missing from
//! either side, or one that failed in the study, fails the check too.

use super::FailedDesign;
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Default relative tolerance on the peak pin force.
pub const DEFAULT_RTOL_FORCE: f64 = 0.005;
/// Default relative tolerance on the mass.
pub const DEFAULT_RTOL_MASS: f64 = 0.001;

/// What the baseline holds per design.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BaselineEntry {
    pub design: String,
    pub peak_pin_force_n: f64,
    pub mass_kg: f64,
}

/// `reports/baseline.json`: per design id (file stem), the figures CI holds it to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Baseline {
    pub program_version: String,
    pub designs: BTreeMap<String, BaselineEntry>,
}

/// The part of `results.json` the check reads.
#[derive(Debug, Clone, Deserialize)]
pub struct ResultsView {
    pub designs: Vec<DesignView>,
    #[serde(default)]
    pub failed: Vec<FailedDesign>,
}

#[derive(Debug, Clone, Deserialize)]
pub struct DesignView {
    pub mass: MassView,
    pub dynamics: DynamicsView,
}

#[derive(Debug, Clone, Deserialize)]
pub struct MassView {
    pub design: String,
    pub id: String,
    pub mass_kg: f64,
}

#[derive(Debug, Clone, Deserialize)]
pub struct DynamicsView {
    pub peak_pin_force_n: f64,
}

impl Baseline {
    /// The baseline the given results would set.
    pub fn from_results(results: &ResultsView) -> Self {
        Baseline {
            program_version: env!("CARGO_PKG_VERSION").into(),
            designs: results
                .designs
                .iter()
                .map(|d| {
                    let entry = BaselineEntry {
                        design: d.mass.design.clone(),
                        peak_pin_force_n: d.dynamics.peak_pin_force_n,
                        mass_kg: d.mass.mass_kg,
                    };
                    (d.mass.id.clone(), entry)
                })
                .collect(),
        }
    }

    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("{}: cannot read the baseline", path.display()))?;
        serde_json::from_str(&text)
            .with_context(|| format!("{}: not a baseline file", path.display()))
    }
}

/// Reads `results.json` as written by the study.
pub fn read_results(path: &Path) -> Result<ResultsView> {
    let text = std::fs::read_to_string(path).with_context(|| {
        format!(
            "{}: cannot read the study results (run `rodstudy study` first)",
            path.display()
        )
    })?;
    serde_json::from_str(&text)
        .with_context(|| format!("{}: not a study results file", path.display()))
}

/// Verdict for one design.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CheckRow {
    pub id: String,
    pub baseline_force_n: Option<f64>,
    pub force_n: Option<f64>,
    pub force_rel_change: Option<f64>,
    pub baseline_mass_kg: Option<f64>,
    pub mass_kg: Option<f64>,
    pub mass_rel_change: Option<f64>,
    /// `ok`, `regressed`, `missing from results`, `not in baseline`, or `failed: …`.
    pub verdict: String,
}

impl CheckRow {
    pub fn passed(&self) -> bool {
        self.verdict == "ok"
    }
}

/// Compares results with the baseline, design by design (sorted by id).
pub fn check(
    baseline: &Baseline,
    results: &ResultsView,
    rtol_force: f64,
    rtol_mass: f64,
) -> Vec<CheckRow> {
    let mut ids: Vec<String> = baseline.designs.keys().cloned().collect();
    for d in &results.designs {
        if !ids.contains(&d.mass.id) {
            ids.push(d.mass.id.clone());
        }
    }
    ids.sort();
    let rel = |new: f64, old: f64| (new - old) / old;
    // NaN never passes: `within` is false for it.
    let within = |c: f64, tol: f64| c.abs() <= tol;
    let mut rows: Vec<CheckRow> = ids
        .into_iter()
        .map(|id| {
            let base = baseline.designs.get(&id);
            let now = results.designs.iter().find(|d| d.mass.id == id);
            let force_rel_change = base
                .zip(now)
                .map(|(b, n)| rel(n.dynamics.peak_pin_force_n, b.peak_pin_force_n));
            let mass_rel_change = base.zip(now).map(|(b, n)| rel(n.mass.mass_kg, b.mass_kg));
            let verdict = match (base, now) {
                (Some(_), None) => "missing from results".to_string(),
                (None, Some(_)) => "not in baseline".to_string(),
                _ if force_rel_change.is_some_and(|c| !within(c, rtol_force))
                    || mass_rel_change.is_some_and(|c| !within(c, rtol_mass)) =>
                {
                    "regressed".to_string()
                }
                _ => "ok".to_string(),
            };
            CheckRow {
                baseline_force_n: base.map(|b| b.peak_pin_force_n),
                force_n: now.map(|n| n.dynamics.peak_pin_force_n),
                force_rel_change,
                baseline_mass_kg: base.map(|b| b.mass_kg),
                mass_kg: now.map(|n| n.mass.mass_kg),
                mass_rel_change,
                verdict,
                id,
            }
        })
        .collect();
    for f in &results.failed {
        let id = Path::new(&f.file)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| f.file.clone());
        let verdict = format!("failed: {}", f.error);
        match rows.iter_mut().find(|r| r.id == id) {
            Some(row) => row.verdict = verdict,
            None => rows.push(CheckRow {
                id,
                baseline_force_n: None,
                force_n: None,
                force_rel_change: None,
                baseline_mass_kg: None,
                mass_kg: None,
                mass_rel_change: None,
                verdict,
            }),
        }
    }
    rows
}

/// The diff table for people.
pub fn check_table(rows: &[CheckRow], rtol_force: f64, rtol_mass: f64) -> String {
    let num =
        |x: Option<f64>, digits: usize| x.map_or("—".to_string(), |v| format!("{v:.digits$}"));
    let pct = |x: Option<f64>| x.map_or("—".to_string(), |v| format!("{:+.4} %", v * 100.0));
    let mut out = String::from(
        "| design | baseline force [N] | force [N] | change | baseline mass [kg] | mass [kg] | change | verdict |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.id,
            num(r.baseline_force_n, 2),
            num(r.force_n, 2),
            pct(r.force_rel_change),
            num(r.baseline_mass_kg, 6),
            num(r.mass_kg, 6),
            pct(r.mass_rel_change),
            r.verdict
        ));
    }
    out.push_str(&format!(
        "\ntolerances: peak force {:.3} %, mass {:.3} %\n",
        rtol_force * 100.0,
        rtol_mass * 100.0
    ));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn results(force: f64, mass: f64) -> ResultsView {
        ResultsView {
            designs: vec![DesignView {
                mass: MassView {
                    design: "Rod".into(),
                    id: "rod".into(),
                    mass_kg: mass,
                },
                dynamics: DynamicsView {
                    peak_pin_force_n: force,
                },
            }],
            failed: vec![],
        }
    }

    #[test]
    fn drift_beyond_the_tolerance_regresses() {
        let base = Baseline::from_results(&results(7000.0, 3.0));
        let ok = check(&base, &results(7030.0, 3.002), 0.005, 0.001);
        assert!(ok[0].passed(), "{ok:?}");
        let bad = check(&base, &results(7040.0, 3.0), 0.005, 0.001);
        assert_eq!(bad[0].verdict, "regressed");
        let bad = check(&base, &results(7000.0, 3.004), 0.005, 0.001);
        assert_eq!(bad[0].verdict, "regressed");
        let nan = check(&base, &results(f64::NAN, 3.0), 0.005, 0.001);
        assert_eq!(nan[0].verdict, "regressed", "a NaN never passes");
    }

    #[test]
    fn missing_new_and_failed_designs_fail() {
        let base = Baseline::from_results(&results(7000.0, 3.0));
        let mut none = results(7000.0, 3.0);
        none.designs.clear();
        assert_eq!(
            check(&base, &none, 0.005, 0.001)[0].verdict,
            "missing from results"
        );
        let empty = Baseline {
            program_version: "x".into(),
            designs: BTreeMap::new(),
        };
        assert_eq!(
            check(&empty, &results(7000.0, 3.0), 0.005, 0.001)[0].verdict,
            "not in baseline"
        );
        none.failed.push(FailedDesign {
            file: "designs/rod.stl".into(),
            error: "open mesh".into(),
            ..FailedDesign::default()
        });
        let rows = check(&base, &none, 0.005, 0.001);
        assert_eq!(rows.len(), 1);
        assert_eq!(rows[0].verdict, "failed: open mesh");
    }
}
