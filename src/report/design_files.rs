//! Per-design and all-design files of stage 2 and the cycle: the pin-force history (CSV and plot),
//! the cycle's stress history (CSV and plot), and |F_A| of all designs in one plot.

use super::plots;
use super::ranking;
use crate::mechanism::DrivenResult;
use crate::stages::records::DesignCycle;
use crate::study::results::StudyResults;
use anyhow::Result;
use serde::Serialize;

/// (id, name, pin-force history) of every design that passed stage 2, in ranking order.
pub fn histories(results: &StudyResults) -> Vec<(String, String, &DrivenResult)> {
    ranking::ranking(results)
        .iter()
        .filter_map(|r| {
            let h = results
                .designs
                .iter()
                .find(|d| d.mass.id == r.mass.id)
                .map(|d| &d.history)
                .or_else(|| {
                    results
                        .failed
                        .iter()
                        .find(|f| f.mass.as_ref().is_some_and(|m| m.id == r.mass.id))
                        .and_then(|f| f.history.as_ref())
                })?;
            Some((r.mass.id.clone(), r.mass.design.clone(), h))
        })
        .collect()
}

/// The points of one history over its first crank revolution: (φ − φ₀ [°], value).
fn first_turn(h: &DrivenResult, value: impl Fn(usize) -> f64) -> Vec<(f64, f64)> {
    // the loads' period: one revolution, or the four-stroke cycle with a gas force
    let turns = if h.gas_force_n.is_some() { 2.0 } else { 1.0 };
    let span = turns * std::f64::consts::TAU;
    (0..h.t_s.len())
        .take_while(|&k| h.phi_rad[k] - h.phi_rad[0] <= span + 1e-9)
        .map(|k| ((h.phi_rad[k] - h.phi_rad[0]).to_degrees(), value(k)))
        .collect()
}

/// "one revolution", or with a gas force "the four-stroke cycle (720°)": the span of the loads.
pub fn load_span(with_gas: bool) -> &'static str {
    if with_gas {
        "the four-stroke cycle (720°)"
    } else {
        "one revolution"
    }
}

/// One design's pin force over the first revolution (the four-stroke cycle with a gas force):
/// The driven scene of a study as the plots' titles name it: "φ = 40πt, gravity on" for the
/// spec's scene.
pub fn scene_label(config: &crate::config::StudyConfig) -> String {
    let w = config.driven.omega_rad_s;
    let per_pi = w / std::f64::consts::PI;
    let speed = if (per_pi - per_pi.round()).abs() < 1e-9 * per_pi.abs().max(1.0) {
        format!("{}πt", per_pi.round())
    } else {
        format!("{w:.4} t")
    };
    format!(
        "φ = {speed}, gravity {}",
        if config.driven.gravity { "on" } else { "off" }
    )
}

/// |F_A| and its components; `scene` from [`scene_label`].
pub fn design_pin_force_plot(design: &str, h: &DrivenResult, scene: &str) -> Result<String> {
    let series = vec![
        plots::Series {
            name: "|F_A|".into(),
            points: first_turn(h, |k| h.fa_abs_n[k]),
        },
        plots::Series {
            name: "F_Ax".into(),
            points: first_turn(h, |k| h.fa_x_n[k]),
        },
        plots::Series {
            name: "F_Ay".into(),
            points: first_turn(h, |k| h.fa_y_n[k]),
        },
    ];
    plots::line_chart(
        &format!("{design}: crank–rod pin force ({scene})"),
        "crank angle φ [°] (0 = top dead centre)",
        "force by the crank on the rod at A [N] (global frame)",
        &series,
        plots::Scale::Linear,
        plots::Scale::Linear,
    )
}

/// |F_A| over the first crank revolution, all designs in one plot.
pub fn pin_force_plot(
    histories: &[(String, String, &DrivenResult)],
    scene: &str,
) -> Result<String> {
    let series: Vec<plots::Series> = histories
        .iter()
        .map(|(_, design, h)| plots::Series {
            name: design.clone(),
            points: first_turn(h, |k| h.fa_abs_n[k]),
        })
        .collect();
    let with_gas = histories.iter().any(|(_, _, h)| h.gas_force_n.is_some());
    plots::line_chart(
        &format!("Crank–rod pin force over {} ({scene})", load_span(with_gas)),
        "crank angle φ [°] (0 = top dead centre)",
        "|F_A| [N]",
        &series,
        plots::Scale::Linear,
        plots::Scale::Linear,
    )
}

/// `cycle.csv` of one design: per instant the crank angle, the time, the judged max von Mises, the
/// fixed bore's reaction and the dynamics' F_B (rod frame, N).
pub fn cycle_csv(c: &DesignCycle) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "crank_angle_deg",
        "time_s",
        "max_von_mises_away_from_fixed_mpa",
        "reaction_b_x_n",
        "reaction_b_y_n",
        "reaction_b_z_n",
        "dynamics_f_b_x_n",
        "dynamics_f_b_y_n",
    ])?;
    for h in &c.history {
        w.write_record(
            [
                h.crank_angle_deg,
                h.time_s,
                h.max_von_mises_away_from_fixed_mpa,
                h.reaction_b_n[0],
                h.reaction_b_n[1],
                h.reaction_b_n[2],
                h.dynamics_f_b_n[0],
                h.dynamics_f_b_n[1],
            ]
            .map(|v| format!("{v:e}")),
        )?;
    }
    Ok(w.into_inner()?)
}

/// `cycle.svg` of one design: the judged max von Mises over one revolution (or the four-stroke
/// cycle).
pub fn cycle_plot(design: &str, c: &DesignCycle) -> Result<String> {
    let series = vec![plots::Series {
        name: "max von Mises".into(),
        points: c
            .history
            .iter()
            .map(|h| (h.crank_angle_deg, h.max_von_mises_away_from_fixed_mpa))
            .collect(),
    }];
    plots::line_chart(
        &format!(
            "{design}: max von Mises over {} (inertia relief)",
            load_span(c.cycle_span_deg.is_some())
        ),
        "crank angle φ [°] (0 = top dead centre)",
        "max von Mises away from the fixed bore [MPa]",
        &series,
        plots::Scale::Linear,
        plots::Scale::Linear,
    )
}

/// `pin_force.csv` of one design: the pin-force history ([`write_history_csv`]).
pub fn pin_force_csv(design: &str, run: &DrivenResult) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    write_history_csv(&mut w, design, run)?;
    Ok(w.into_inner()?)
}

/// The pin-force history as CSV rows (with a `design` column, so several designs share a file).
/// With a gas force (an `[engine] pressure_trace`) the rows gain a last column `gas_force_n`, the
/// force p·A on the piston [N, positive towards the crank]; without one the columns are exactly
/// those of the thesis' rig, so default files stay byte-identical.
pub fn write_history_csv<W: std::io::Write>(
    w: &mut csv::Writer<W>,
    design: &str,
    run: &DrivenResult,
) -> Result<()> {
    for k in 0..run.t_s.len() {
        let row = HistoryRow {
            design,
            t_s: run.t_s[k],
            phi_rad: run.phi_rad[k],
            fa_x_n: run.fa_x_n[k],
            fa_y_n: run.fa_y_n[k],
            fa_abs_n: run.fa_abs_n[k],
            fb_x_n: run.fb_x_n[k],
            fb_y_n: run.fb_y_n[k],
            fb_abs_n: run.fb_abs_n[k],
            crank_torque_nm: run.crank_torque_nm[k],
        };
        match &run.gas_force_n {
            None => w.serialize(row)?,
            Some(gas) => w.serialize(HistoryRowGas {
                design: row.design,
                t_s: row.t_s,
                phi_rad: row.phi_rad,
                fa_x_n: row.fa_x_n,
                fa_y_n: row.fa_y_n,
                fa_abs_n: row.fa_abs_n,
                fb_x_n: row.fb_x_n,
                fb_y_n: row.fb_y_n,
                fb_abs_n: row.fb_abs_n,
                crank_torque_nm: row.crank_torque_nm,
                gas_force_n: gas[k],
            })?,
        }
    }
    Ok(())
}

#[derive(Serialize)]
struct HistoryRow<'a> {
    design: &'a str,
    t_s: f64,
    phi_rad: f64,
    fa_x_n: f64,
    fa_y_n: f64,
    fa_abs_n: f64,
    fb_x_n: f64,
    fb_y_n: f64,
    fb_abs_n: f64,
    crank_torque_nm: f64,
}

/// [`HistoryRow`] with the gas force.
#[derive(Serialize)]
struct HistoryRowGas<'a> {
    design: &'a str,
    t_s: f64,
    phi_rad: f64,
    fa_x_n: f64,
    fa_y_n: f64,
    fa_abs_n: f64,
    fb_x_n: f64,
    fb_y_n: f64,
    fb_abs_n: f64,
    crank_torque_nm: f64,
    gas_force_n: f64,
}

#[cfg(test)]
mod tests {
    use super::scene_label;
    use crate::config::StudyConfig;

    #[test]
    fn the_plots_name_the_studys_scene() {
        let mut c = StudyConfig::default();
        assert_eq!(scene_label(&c), "φ = 40πt, gravity on");
        c.driven.omega_rad_s = 20.0 * std::f64::consts::PI;
        c.driven.gravity = false;
        assert_eq!(scene_label(&c), "φ = 20πt, gravity off");
        c.driven.omega_rad_s = 100.0;
        assert_eq!(scene_label(&c), "φ = 100.0000 t, gravity off");
    }
}
