//! The columns of the ranking, defined once: each is a key, when it is shown, its fields in
//! `ranking.csv` (name and value) and its header and cell in the table for people (`ranking.md`,
//! the table of `index.html`). [`COLUMNS`] is in the order of `ranking.csv`; [`TABLE`] lists, by key,
//! the columns the table for people shows, in its order. A per-case column expands into one column
//! per load case of [`crate::rod::cases::STATIC_CASES`], its CSV names prefixed by the case's name
//! (`fx_von_mises_away_from_fixed_mpa`) and its header naming the case's label (`σ F_x [MPa]`).
//!
//! Adding a column is an entry in [`COLUMNS`] (and its key in [`TABLE`] to show it to people).

use serde::{Serialize, Serializer};

use super::rank_row::{ROD_BODY_ALONE, RankRow, Status, is_rod_body_alone};
use crate::rod::LoadCaseResult;
use crate::rod::cases::{LoadCase, STATIC_CASES};

/// One CSV field's value (empty where a stage was skipped or failed).
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A number (SI, stresses in MPa).
    Num(Option<f64>),
    /// A count.
    Count(Option<usize>),
    /// Text.
    Text(String),
    /// Yes or no (`true`/`false`).
    Flag(bool),
}

impl Serialize for Value {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Value::Num(Some(v)) => s.serialize_f64(*v),
            Value::Count(Some(n)) => s.serialize_u64(*n as u64),
            Value::Num(None) | Value::Count(None) => s.serialize_none(),
            Value::Text(t) => s.serialize_str(t),
            Value::Flag(b) => s.serialize_bool(*b),
        }
    }
}

/// When a column is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shown {
    /// In every study.
    Always,
    /// When some design has the engine's axial peaks (a study with a pressure trace).
    EngineLoads,
    /// When some design has a buckling load factor.
    Buckling,
}

/// A design's CSV field: its name and value.
pub type DesignField = (&'static str, fn(&RankRow) -> Value);
/// A design's cell for people: its header and text.
pub type DesignCell = (&'static str, fn(&RankRow) -> String);
/// A case's CSV field: the name after the case's and the value.
pub type CaseField = (&'static str, fn(Option<&LoadCaseResult>) -> Value);
/// A case's cell for people: the header before and after the case's label, and the text.
pub type CaseCell = (
    &'static str,
    &'static str,
    fn(Option<&LoadCaseResult>) -> String,
);

/// What a column holds.
pub enum Cells {
    /// A figure of the design.
    Design {
        /// The CSV fields: name and value.
        csv: &'static [DesignField],
        /// The header and the cell in the table for people.
        table: Option<DesignCell>,
    },
    /// A figure per load case.
    PerCase {
        /// The CSV fields: the name after the case's (`{case}_{suffix}`) and the value.
        csv: &'static [CaseField],
        /// The header around the case's label (`{before}{label}{after}`) and the cell.
        table: Option<CaseCell>,
    },
}

/// One column of the ranking.
pub struct Column {
    /// How [`TABLE`] names it.
    pub key: &'static str,
    /// When it is shown.
    pub shown: Shown,
    /// What it holds.
    pub cells: Cells,
}

const DASH: &str = "—";

fn dash() -> String {
    DASH.to_string()
}

fn case_of<'a>(r: &RankRow<'a>, case: &LoadCase) -> Option<&'a LoadCaseResult> {
    r.fem.and_then(|f| f.fem.cases.get(case.name))
}

fn max_displacement_mm(r: &RankRow) -> Option<f64> {
    r.fem.map(|f| f.fem.cases.max_of(|c| c.max_displacement_mm))
}

fn engine_peak(n: Option<f64>, at: Option<f64>) -> String {
    match (n, at) {
        (Some(n), Some(at)) => format!("{n:.0} at {at:.0}°"),
        _ => dash(),
    }
}

/// The columns, in the order of `ranking.csv`.
pub const COLUMNS: &[Column] = &[
    Column {
        key: "rank",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("rank", |r| Value::Count(r.rank))],
            table: Some(("rank", |r| r.rank.map_or_else(dash, |k| k.to_string()))),
        },
    },
    Column {
        key: "design",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("design", |r| Value::Text(r.mass.design.clone()))],
            table: Some(("design", |r| r.mass.design.clone())),
        },
    },
    Column {
        key: "id",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("id", |r| Value::Text(r.mass.id.clone()))],
            table: None,
        },
    },
    Column {
        key: "mass",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("mass_kg", |r| Value::Num(Some(r.mass.mass_kg)))],
            table: Some(("mass [kg]", |r| format!("{:.4}", r.mass.mass_kg))),
        },
    },
    Column {
        key: "l1",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("l1_m", |r| Value::Num(Some(r.mass.l1_m)))],
            table: Some(("l1 [mm]", |r| format!("{:.2}", r.mass.l1_m * 1e3))),
        },
    },
    Column {
        key: "i_zz",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("i_zz_kgm2", |r| Value::Num(Some(r.mass.i_zz_kgm2)))],
            table: Some(("I_zz [kg·m²]", |r| format!("{:.5}", r.mass.i_zz_kgm2))),
        },
    },
    Column {
        key: "i_xx",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("i_xx_kgm2", |r| Value::Num(Some(r.mass.i_xx_kgm2)))],
            table: Some(("I_xx [kg·m²]", |r| format!("{:.6}", r.mass.i_xx_kgm2))),
        },
    },
    Column {
        key: "peak_pin_force",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("peak_pin_force_n", |r| Value::Num(r.peak_force_n()))],
            table: Some(("peak pin force [N]", |r| {
                r.peak_force_n().map_or_else(dash, |v| format!("{v:.1}"))
            })),
        },
    },
    Column {
        key: "peak_compression",
        shown: Shown::EngineLoads,
        cells: Cells::Design {
            csv: &[
                ("peak_compression_n", |r| {
                    Value::Num(r.dynamics.and_then(|d| d.peak_compression_n))
                }),
                ("peak_compression_crank_angle_deg", |r| {
                    Value::Num(r.dynamics.and_then(|d| d.peak_compression_crank_angle_deg))
                }),
            ],
            table: Some(("peak compression [N] at φ", |r| {
                let d = r.dynamics;
                engine_peak(
                    d.and_then(|d| d.peak_compression_n),
                    d.and_then(|d| d.peak_compression_crank_angle_deg),
                )
            })),
        },
    },
    Column {
        key: "peak_tension",
        shown: Shown::EngineLoads,
        cells: Cells::Design {
            csv: &[
                ("peak_tension_n", |r| {
                    Value::Num(r.dynamics.and_then(|d| d.peak_tension_n))
                }),
                ("peak_tension_crank_angle_deg", |r| {
                    Value::Num(r.dynamics.and_then(|d| d.peak_tension_crank_angle_deg))
                }),
            ],
            table: Some(("peak tension [N] at φ", |r| {
                let d = r.dynamics;
                engine_peak(
                    d.and_then(|d| d.peak_tension_n),
                    d.and_then(|d| d.peak_tension_crank_angle_deg),
                )
            })),
        },
    },
    Column {
        key: "stress",
        shown: Shown::Always,
        cells: Cells::PerCase {
            csv: &[
                ("von_mises_away_from_fixed_mpa", |c| {
                    Value::Num(c.map(|c| c.max_von_mises_away_from_fixed_mpa))
                }),
                ("estimated_error_rel", |c| {
                    Value::Num(c.map(|c| c.estimated_error_rel))
                }),
                ("von_mises_averaged_mpa", |c| {
                    Value::Num(c.map(|c| c.max_von_mises_averaged_mpa))
                }),
                ("von_mises_unaveraged_mpa", |c| {
                    Value::Num(c.map(|c| c.max_von_mises_unaveraged_mpa))
                }),
            ],
            table: Some(("σ ", " [MPa]", |c| {
                c.map_or_else(dash, |c| {
                    format!(
                        "{:.1} ± {:.1} % / {:.1} / {:.1}",
                        c.max_von_mises_away_from_fixed_mpa,
                        100.0 * c.estimated_error_rel,
                        c.max_von_mises_averaged_mpa,
                        c.max_von_mises_unaveraged_mpa
                    )
                })
            })),
        },
    },
    Column {
        key: "load_model",
        shown: Shown::Always,
        cells: Cells::PerCase {
            csv: &[
                ("load_model_error_rel", |c| {
                    Value::Num(c.and_then(|c| c.estimated_load_model_error_rel))
                }),
                ("contact_von_mises_mpa", |c| {
                    Value::Num(c.and_then(|c| c.load_models.as_ref().map(|m| m.contact_mpa)))
                }),
                ("cosine_von_mises_mpa", |c| {
                    Value::Num(c.and_then(|c| c.load_models.as_ref().and_then(|m| m.cosine_mpa)))
                }),
                ("uniform_von_mises_mpa", |c| {
                    Value::Num(c.and_then(|c| c.load_models.as_ref().map(|m| m.uniform_mpa)))
                }),
                ("largest_error_part", |c| {
                    Value::Text(c.map_or_else(String::new, |c| c.dominant_error().to_string()))
                }),
            ],
            table: Some((
                "σ ",
                " contact / cosine / uniform [MPa]; ε_load; largest part",
                |c| {
                    let Some(c) = c else { return dash() };
                    match (&c.load_models, c.estimated_load_model_error_rel) {
                        (Some(m), Some(e)) => format!(
                            "{:.1} / {} / {:.1}; {:.1} %; {}",
                            m.contact_mpa,
                            m.cosine_mpa.map_or_else(dash, |v| format!("{v:.1}")),
                            m.uniform_mpa,
                            100.0 * e,
                            c.dominant_error()
                        ),
                        _ => format!("not compared; {}", c.dominant_error()),
                    }
                },
            )),
        },
    },
    Column {
        key: "cycle_max",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[
                ("cycle_max_von_mises_mpa", |r| {
                    Value::Num(r.cycle.map(|c| c.max_von_mises_over_cycle_mpa))
                }),
                ("cycle_crank_angle_of_max_deg", |r| {
                    Value::Num(r.cycle.map(|c| c.crank_angle_of_max_deg))
                }),
            ],
            table: Some(("σ max over the cycle [MPa]", |r| {
                r.cycle.map_or_else(dash, |c| {
                    format!(
                        "{:.1} at φ = {:.0}°",
                        c.max_von_mises_over_cycle_mpa, c.crank_angle_of_max_deg
                    )
                })
            })),
        },
    },
    Column {
        key: "fatigue_goodman",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[
                ("fatigue_safety_factor", |r| {
                    Value::Num(r.cycle.map(|c| c.fatigue_safety_factor))
                }),
                ("contact_fatigue_safety_factor", |r| {
                    Value::Num(
                        r.cycle
                            .and_then(|c| c.contact_fatigue.as_ref())
                            .map(|f| f.contact_factor),
                    )
                }),
            ],
            table: Some(("Goodman fatigue factor (with contact)", |r| {
                r.cycle.map_or_else(dash, |c| {
                    let contact = c
                        .contact_fatigue
                        .as_ref()
                        .map_or(String::new(), |f| format!(" ({:.2})", f.contact_factor));
                    format!("{:.2}{contact}", c.fatigue_safety_factor)
                })
            })),
        },
    },
    Column {
        key: "fatigue",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("local_fatigue_safety_factor", |r| {
                Value::Num(r.cycle.and_then(|c| c.local_fatigue_safety_factor))
            })],
            table: Some(("fatigue safety factor (FKM local)", |r| {
                r.cycle
                    .and_then(|c| c.local_fatigue_safety_factor)
                    .map_or_else(dash, |s| format!("{s:.2}"))
            })),
        },
    },
    Column {
        key: "buckling",
        shown: Shown::Buckling,
        cells: Cells::Design {
            csv: &[
                ("buckling_load_factor", |r| {
                    Value::Num(r.fem.and_then(|f| f.buckling_load_factor))
                }),
                ("buckling_load_factor_contact", |r| {
                    Value::Num(r.fem.and_then(|f| f.buckling_load_factor_contact))
                }),
            ],
            table: Some(("buckling load factor (with contact)", |r| {
                r.fem.map_or_else(dash, |f| {
                    let contact = f
                        .buckling_load_factor_contact
                        .map_or(String::new(), |c| format!(" ({c:.2})"));
                    f.buckling_load_factor
                        .map_or_else(dash, |l| format!("{l:.2}{contact}"))
                })
            })),
        },
    },
    Column {
        key: "max_displacement",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("max_displacement_mm", |r| {
                Value::Num(max_displacement_mm(r))
            })],
            table: Some(("max displ. [mm]", |r| {
                max_displacement_mm(r).map_or_else(dash, |d| format!("{d:.4}"))
            })),
        },
    },
    Column {
        key: "pareto",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("pareto_front", |r| Value::Flag(r.pareto))],
            table: Some(("Pareto front", |r| {
                if r.pareto {
                    "yes".into()
                } else {
                    String::new()
                }
            })),
        },
    },
    Column {
        key: "allowed",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("allowed_mpa", |r| {
                Value::Num(r.fem.map(|f| f.criterion.allowed_mpa))
            })],
            table: None,
        },
    },
    Column {
        key: "safety_factor",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("safety_factor", |r| {
                Value::Num(r.fem.map(|f| f.criterion.safety_factor))
            })],
            table: Some(("safety factor", |r| {
                r.fem
                    .map_or_else(dash, |f| format!("{:.2}", f.criterion.safety_factor))
            })),
        },
    },
    Column {
        key: "status",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("status", |r| Value::Text(r.status.word()))],
            table: Some(("status", status_cell)),
        },
    },
    Column {
        key: "failing_on",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("failing_on", |r| Value::Text(r.failing_on()))],
            table: None,
        },
    },
    Column {
        key: "model_validity",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("model_validity", |r| Value::Text(r.model_validity()))],
            table: None,
        },
    },
    Column {
        key: "error",
        shown: Shown::Always,
        cells: Cells::Design {
            csv: &[("error", |r| match &r.status {
                Status::StageFailed { error, .. } => Value::Text(error.clone()),
                _ => Value::Text(String::new()),
            })],
            table: None,
        },
    },
];

/// The columns of the table for people, by key, in its order.
pub const TABLE: &[&str] = &[
    "rank",
    "design",
    "status",
    "safety_factor",
    "stress",
    "load_model",
    "cycle_max",
    "fatigue",
    "fatigue_goodman",
    "buckling",
    "peak_pin_force",
    "peak_compression",
    "peak_tension",
    "mass",
    "l1",
    "i_zz",
    "i_xx",
    "max_displacement",
    "pareto",
];

/// The status cell: the word, with why a design fails, where the model is out of its depth and
/// whether it is a rod body without its cap.
fn status_cell(r: &RankRow) -> String {
    let alone = if is_rod_body_alone(r.mass) {
        ROD_BODY_ALONE.to_string()
    } else {
        String::new()
    };
    let notes: Vec<String> = [r.failing_on(), r.model_validity(), alone]
        .into_iter()
        .filter(|s| !s.is_empty())
        .collect();
    if notes.is_empty() {
        r.status.word()
    } else {
        format!("{} ({})", r.status.word(), notes.join("; "))
    }
}

/// Which optional columns a study shows.
#[derive(Clone, Copy, Debug)]
pub struct Showing {
    /// Some design has the engine's axial peaks.
    pub engine: bool,
    /// Some design has a buckling load factor.
    pub buckling: bool,
}

impl Showing {
    /// Whether `column` is shown.
    pub fn shows(&self, column: &Column) -> bool {
        match column.shown {
            Shown::Always => true,
            Shown::EngineLoads => self.engine,
            Shown::Buckling => self.buckling,
        }
    }
}

fn column(key: &str) -> &'static Column {
    COLUMNS
        .iter()
        .find(|c| c.key == key)
        .unwrap_or_else(|| panic!("TABLE names a column not in COLUMNS: {key}"))
}

/// The CSV header: every shown column's fields.
pub fn csv_header(showing: Showing) -> Vec<String> {
    let mut names = Vec::new();
    for c in COLUMNS.iter().filter(|c| showing.shows(c)) {
        match &c.cells {
            Cells::Design { csv, .. } => names.extend(csv.iter().map(|(n, _)| n.to_string())),
            Cells::PerCase { csv, .. } => {
                for case in STATIC_CASES {
                    names.extend(csv.iter().map(|(n, _)| format!("{}_{n}", case.name)));
                }
            }
        }
    }
    names
}

/// One row's CSV values, in [`csv_header`] order.
pub fn csv_values(r: &RankRow, showing: Showing) -> Vec<Value> {
    let mut values = Vec::new();
    for c in COLUMNS.iter().filter(|c| showing.shows(c)) {
        match &c.cells {
            Cells::Design { csv, .. } => values.extend(csv.iter().map(|(_, v)| v(r))),
            Cells::PerCase { csv, .. } => {
                for case in STATIC_CASES {
                    let result = case_of(r, case);
                    values.extend(csv.iter().map(|(_, v)| v(result)));
                }
            }
        }
    }
    values
}

/// The headers of the table for people.
pub fn table_headers(showing: Showing) -> Vec<String> {
    let mut headers = Vec::new();
    for c in TABLE.iter().map(|k| column(k)).filter(|c| showing.shows(c)) {
        match &c.cells {
            Cells::Design {
                table: Some((h, _)),
                ..
            } => headers.push(h.to_string()),
            Cells::PerCase {
                table: Some((before, after, _)),
                ..
            } => headers.extend(
                STATIC_CASES
                    .iter()
                    .map(|case| format!("{before}{}{after}", case.label)),
            ),
            _ => {}
        }
    }
    headers
}

/// One row of the table for people, in [`table_headers`] order, with the key of each cell's
/// column.
pub fn table_cells(r: &RankRow, showing: Showing) -> Vec<(&'static str, String)> {
    let mut cells = Vec::new();
    for c in TABLE.iter().map(|k| column(k)).filter(|c| showing.shows(c)) {
        match &c.cells {
            Cells::Design {
                table: Some((_, cell)),
                ..
            } => cells.push((c.key, cell(r))),
            Cells::PerCase {
                table: Some((_, _, cell)),
                ..
            } => cells.extend(
                STATIC_CASES
                    .iter()
                    .map(|case| (c.key, cell(case_of(r, case)))),
            ),
            _ => {}
        }
    }
    cells
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every key of the table names a column with a cell for people; keys are unique.
    #[test]
    fn the_table_names_columns_that_have_cells() {
        for (i, k) in TABLE.iter().enumerate() {
            assert!(!TABLE[i + 1..].contains(k), "{k} twice");
            let shown = match &column(k).cells {
                Cells::Design { table, .. } => table.is_some(),
                Cells::PerCase { table, .. } => table.is_some(),
            };
            assert!(shown, "{k} has no cell for people");
        }
        for (i, c) in COLUMNS.iter().enumerate() {
            assert!(COLUMNS[i + 1..].iter().all(|d| d.key != c.key));
        }
    }
}
