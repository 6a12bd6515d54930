//! The local fatigue pictures of one design's cycle: the factor on the rod's surface
//! (`local_fatigue.svg`) and the Haigh diagram at the critical node (`haigh.svg`).
//!
//! **The map** draws 1/S at every surface node, S the local (FKM) safety factor
//! ([`crate::rod::cycle::local_fatigue`]): the fraction of the component fatigue limit (with j_D)
//! the cycle's load reaches, so that the critical point is the hottest colour, on the scale
//! [0, 1/S_min] with S_min the smallest over the judged nodes (marked). Nodes in the bands around
//! the fixed bore and the sharp edges, not judged, may exceed it: grey, as in the stress pictures.
//!
//! **The Haigh diagram** (FKM guideline, 6th ed. 2012, §4.4, Fig. 4.4.1) at the critical node: the
//! component's line σ_a(σ_m) for the larger surface component σ_1 (σ_WK,1 and M_σ; its four
//! regions, [`crate::fatigue::HaighLine`]), the cycle's point (σ_m, σ_a) of σ_1 and of σ_2 (with its
//! own line when its σ_WK differs: another χ*), and the load line of the overload case to the
//! limit point of σ_1 (F2: the ray from the origin; F1: straight up).

use anyhow::Result;
use std::path::Path;

use super::atomic_write::write_atomic;
use super::picture::{PictureOptions, render_tet10_field};
use super::plots::{Scale, Series, line_chart};
use crate::fatigue::{HaighLine, OverloadCase};
use crate::fem::TetMesh;
use crate::rod::cycle::LocalFatigueSolution;
use crate::stages::records::{DesignCycle, LocalComponent};

/// Writes `dir/local_fatigue.svg` and `dir/haigh.svg` and records their paths in the record's
/// `local_fatigue` (nothing without it).
pub fn write_fatigue_pictures(
    record: &mut DesignCycle,
    mesh: &TetMesh,
    local: &LocalFatigueSolution,
    dir: &Path,
) -> Result<()> {
    let Some(l) = record.local_fatigue.as_mut() else {
        return Ok(());
    };
    let s_min = l.safety_factor;
    let values: Vec<f64> = local
        .safety_factor
        .iter()
        .map(|s| {
            if s.is_finite() && *s > 0.0 {
                1.0 / s
            } else {
                0.0
            }
        })
        .collect();
    let map = dir.join("local_fatigue.svg");
    let svg = render_tet10_field(
        mesh,
        &values,
        &PictureOptions {
            title: format!(
                "local fatigue (FKM): 1/S, the fraction of the component fatigue limit (jD {:.2}) the cycle reaches",
                l.j_d
            ),
            unit: "1/S".into(),
            range: [0.0, if s_min.is_finite() { 1.0 / s_min } else { 1.0 }],
            marker_mm: Some(l.at_mm),
            marker_label: format!(
                "lowest S = {s_min:.2} (χ* {:.2}/mm, n {:.3})",
                l.chi_star_per_mm, l.support_factor
            ),
            width_px: 960,
        },
    )?;
    write_atomic(&map, svg.as_bytes())?;
    let haigh = dir.join("haigh.svg");
    write_atomic(
        &haigh,
        haigh_svg(&l.sigma1, &l.sigma2, l.overload)?.as_bytes(),
    )?;
    l.map_picture = Some(map);
    l.haigh_picture = Some(haigh);
    Ok(())
}

/// The Haigh diagram of the two components (MPa) under `overload` as SVG text.
pub fn haigh_svg(
    s1: &LocalComponent,
    s2: &LocalComponent,
    overload: OverloadCase,
) -> Result<String> {
    let line_of = |c: &LocalComponent| HaighLine {
        sigma_wk_pa: c.sigma_wk_mpa * 1e6,
        m: c.mean_stress_sensitivity,
    };
    let l1 = line_of(s1);
    let [_, _, _, r5] = l1.corners();
    // the mean-stress range: the line's corners and the points, with a margin
    let reach = [s1.mean_mpa.abs(), s2.mean_mpa.abs(), 1.3e-6 * r5[0]]
        .into_iter()
        .fold(0.0, f64::max)
        * 1.2;
    let polyline = |l: &HaighLine| -> Vec<(f64, f64)> {
        let mut xs: Vec<f64> = vec![-reach, reach];
        xs.extend(
            l.corners()
                .iter()
                .map(|c| c[0] * 1e-6)
                .filter(|x| x.abs() < reach),
        );
        xs.sort_by(f64::total_cmp);
        xs.iter()
            .map(|&x| (x, l.amplitude_at(x * 1e6) * 1e-6))
            .collect()
    };
    let mut series = vec![Series {
        name: format!(
            "FKM line of σ1 (σWK {:.1} MPa, Mσ {:.3})",
            s1.sigma_wk_mpa, s1.mean_stress_sensitivity
        ),
        points: polyline(&l1),
    }];
    if (s2.sigma_wk_mpa - s1.sigma_wk_mpa).abs() > 1e-3 * s1.sigma_wk_mpa {
        series.push(Series {
            name: format!("FKM line of σ2 (σWK {:.1} MPa)", s2.sigma_wk_mpa),
            points: polyline(&line_of(s2)),
        });
    }
    let sa1 = s1.amplitude_mpa.abs();
    series.push(Series {
        name: format!("σ1 of the cycle ({:.1}, {:.1}) MPa", s1.mean_mpa, sa1),
        points: vec![(s1.mean_mpa, sa1)],
    });
    series.push(Series {
        name: format!(
            "σ2 of the cycle ({:.1}, {:.1}) MPa",
            s2.mean_mpa,
            s2.amplitude_mpa.abs()
        ),
        points: vec![(s2.mean_mpa, s2.amplitude_mpa.abs())],
    });
    if sa1 > 0.0 {
        let limit = l1.limit_point(sa1 * 1e6, s1.mean_mpa * 1e6, overload);
        let start = match overload {
            OverloadCase::ConstantRatio => (0.0, 0.0),
            OverloadCase::ConstantMean => (s1.mean_mpa, 0.0),
        };
        series.push(Series {
            name: format!(
                "load line ({}) to σAK {:.1} MPa",
                match overload {
                    OverloadCase::ConstantRatio => "F2, constant R",
                    OverloadCase::ConstantMean => "F1, constant mean",
                },
                limit[1] * 1e-6
            ),
            points: vec![start, (limit[0] * 1e-6, limit[1] * 1e-6)],
        });
    }
    line_chart(
        "Haigh diagram at the critical node (FKM, local stresses)",
        "mean stress σm [MPa]",
        "amplitude σa [MPa]",
        &series,
        Scale::Linear,
        Scale::Linear,
    )
}
