//! SVG plots of the reports (plotters' SVG backend: no system libraries, text as SVG `<text>`).

use anyhow::{Result, anyhow};
use plotters::prelude::*;

/// One named line of a chart.
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

/// Axis scaling of a line chart.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    Linear,
    Log,
}

const COLOURS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

fn range(series: &[Series], pick: impl Fn(&(f64, f64)) -> f64, scale: Scale) -> (f64, f64) {
    let values = series
        .iter()
        .flat_map(|s| s.points.iter().map(&pick))
        .filter(|v| v.is_finite() && (scale == Scale::Linear || *v > 0.0));
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    match scale {
        Scale::Log => (lo / 1.5, hi * 1.5),
        Scale::Linear => {
            let pad = 0.05 * (hi - lo).max(1e-12);
            (lo - pad, hi + pad)
        }
    }
}

/// Tick label: short plain numbers (`20`, `0.05`) between 1e-3 and 1e4, powers of ten as `1e-6`
/// and other values as `2e-6` outside it.
fn tick(v: f64, scale: Scale) -> String {
    let plain = |v: f64| {
        let s = format!("{v:.6}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    match scale {
        Scale::Log => {
            let exp = v.log10().floor();
            let mantissa = v / 10f64.powf(exp);
            if (1e-3..1e4).contains(&v) {
                plain(v)
            } else if (mantissa - mantissa.round()).abs() < 1e-6 {
                if mantissa.round() == 1.0 {
                    format!("1e{exp}")
                } else {
                    format!("{:.0}e{exp}", mantissa.round())
                }
            } else {
                format!("{v:.1e}")
            }
        }
        Scale::Linear => plain(v),
    }
}

/// A line chart with markers, one line per series, as SVG text.
pub fn line_chart(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    x_scale: Scale,
    y_scale: Scale,
) -> Result<String> {
    let (x0, x1) = range(series, |p| p.0, x_scale);
    let (y0, y1) = range(series, |p| p.1, y_scale);
    if !(x0.is_finite() && x1.is_finite() && y0.is_finite() && y1.is_finite()) {
        return Err(anyhow!("{title}: nothing to plot"));
    }
    let mut svg = String::new();
    {
        let whole = SVGBackend::with_string(&mut svg, (960, 640)).into_drawing_area();
        whole.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        // the legend sits in its own column right of the plot, never on the data
        let longest = series
            .iter()
            .map(|s| s.name.chars().count())
            .max()
            .unwrap_or(0);
        let legend_px = (40 + 8 * longest as u32).clamp(110, 320);
        let (root, legend) = whole.split_horizontally(960 - legend_px);
        draw_legend(&legend, series)?;
        let builder = |root| {
            let mut b = ChartBuilder::on(root);
            b.caption(title, ("sans-serif", 22))
                .margin(12)
                .x_label_area_size(52)
                .y_label_area_size(90);
            b
        };
        macro_rules! draw {
            ($chart:expr) => {{
                let mut chart = $chart.map_err(|e| anyhow!("{e}"))?;
                chart
                    .configure_mesh()
                    .x_desc(x_label)
                    .y_desc(y_label)
                    .axis_desc_style(("sans-serif", 16))
                    .label_style(("sans-serif", 14))
                    .light_line_style(RGBColor(235, 235, 235))
                    .x_label_formatter(&|v| tick(*v, x_scale))
                    .y_label_formatter(&|v| tick(*v, y_scale))
                    .draw()
                    .map_err(|e| anyhow!("{e}"))?;
                for (k, s) in series.iter().enumerate() {
                    let colour = COLOURS[k % COLOURS.len()];
                    let points: Vec<(f64, f64)> = s
                        .points
                        .iter()
                        .copied()
                        .filter(|p| p.0.is_finite() && p.1.is_finite())
                        .filter(|p| {
                            (x_scale == Scale::Linear || p.0 > 0.0)
                                && (y_scale == Scale::Linear || p.1 > 0.0)
                        })
                        .collect();
                    chart
                        .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                        .map_err(|e| anyhow!("{e}"))?;
                    if points.len() <= 60 {
                        chart
                            .draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                            .map_err(|e| anyhow!("{e}"))?;
                    }
                }
            }};
        }
        match (x_scale, y_scale) {
            (Scale::Log, Scale::Log) => {
                draw!(builder(&root).build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale()))
            }
            (Scale::Log, Scale::Linear) => {
                draw!(builder(&root).build_cartesian_2d((x0..x1).log_scale(), y0..y1))
            }
            (Scale::Linear, Scale::Log) => {
                draw!(builder(&root).build_cartesian_2d(x0..x1, (y0..y1).log_scale()))
            }
            (Scale::Linear, Scale::Linear) => {
                draw!(builder(&root).build_cartesian_2d(x0..x1, y0..y1))
            }
        }
        whole.present().map_err(|e| anyhow!("{e}"))?;
    }
    Ok(svg)
}

/// The legend of a line chart, one entry per series, top-down in its own drawing area.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    series: &[Series],
) -> Result<()> {
    let font = ("sans-serif", 15).into_font();
    for (k, s) in series.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        let y = 60 + 24 * k as i32;
        area.draw(&PathElement::new(
            vec![(4, y), (28, y)],
            colour.stroke_width(3),
        ))
        .map_err(|e| anyhow!("{e:?}"))?;
        area.draw(&Text::new(s.name.clone(), (34, y - 8), font.clone()))
            .map_err(|e| anyhow!("{e:?}"))?;
    }
    Ok(())
}

/// A bar chart of one value per label, as SVG text.
pub fn bar_chart(title: &str, y_label: &str, bars: &[(String, f64)]) -> Result<String> {
    let top = bars.iter().map(|b| b.1).fold(0.0f64, f64::max) * 1.1;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (960, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let n = bars.len() as u32;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(48)
            .y_label_area_size(80)
            // `a..b` segmented has the segments a..=b: one per bar is 0..n−1
            .build_cartesian_2d((0..n.saturating_sub(1)).into_segmented(), 0.0..top)
            .map_err(|e| anyhow!("{e}"))?;
        let labels: Vec<String> = bars.iter().map(|b| b.0.clone()).collect();
        chart
            .configure_mesh()
            .disable_x_mesh()
            .y_desc(y_label)
            .axis_desc_style(("sans-serif", 16))
            .label_style(("sans-serif", 14))
            .y_label_formatter(&|v| tick(*v, Scale::Linear))
            .x_labels(bars.len())
            .x_label_formatter(&|v| match v {
                SegmentValue::CenterOf(i) => labels.get(*i as usize).cloned().unwrap_or_default(),
                _ => String::new(),
            })
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .draw_series(bars.iter().enumerate().map(|(i, b)| {
                let i = i as u32;
                let mut bar = Rectangle::new(
                    [
                        (SegmentValue::Exact(i), 0.0),
                        (SegmentValue::Exact(i + 1), b.1),
                    ],
                    COLOURS[0].filled(),
                );
                bar.set_margin(0, 0, 12, 12);
                bar
            }))
            .map_err(|e| anyhow!("{e}"))?;
        // the value over each bar
        chart
            .draw_series(bars.iter().enumerate().map(|(i, b)| {
                Text::new(
                    format!("{:.1}", b.1),
                    (SegmentValue::CenterOf(i as u32), b.1 + 0.015 * top),
                    TextStyle::from(("sans-serif", 14).into_font()).pos(
                        plotters::style::text_anchor::Pos::new(
                            plotters::style::text_anchor::HPos::Center,
                            plotters::style::text_anchor::VPos::Bottom,
                        ),
                    ),
                )
            }))
            .map_err(|e| anyhow!("{e}"))?;
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    Ok(svg)
}

/// A labelled point of a scatter chart; `highlight` draws it filled and larger.
pub struct LabelledPoint {
    pub label: String,
    pub x: f64,
    pub y: f64,
    pub highlight: bool,
}

/// A scatter chart of labelled points (highlighted ones filled and joined by a line in x order:
/// e.g. a Pareto front), as SVG text.
pub fn scatter_chart(
    title: &str,
    x_label: &str,
    y_label: &str,
    points: &[LabelledPoint],
    highlight_name: &str,
) -> Result<String> {
    let series = [Series {
        name: String::new(),
        points: points.iter().map(|p| (p.x, p.y)).collect(),
    }];
    let (x0, x1) = range(&series, |p| p.0, Scale::Linear);
    let (y0, y1) = range(&series, |p| p.1, Scale::Linear);
    if !(x0.is_finite() && x1.is_finite() && y0.is_finite() && y1.is_finite()) {
        return Err(anyhow!("{title}: nothing to plot"));
    }
    // room for the labels right of the points
    let (x0, x1) = (x0, x1 + 0.15 * (x1 - x0).max(1e-12));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (960, 640)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(52)
            .y_label_area_size(90)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .axis_desc_style(("sans-serif", 16))
            .label_style(("sans-serif", 14))
            .light_line_style(RGBColor(235, 235, 235))
            .x_label_formatter(&|v| tick(*v, Scale::Linear))
            .y_label_formatter(&|v| tick(*v, Scale::Linear))
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        let mut front: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.highlight)
            .map(|p| (p.x, p.y))
            .collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(front, COLOURS[3].stroke_width(2)))
            .map_err(|e| anyhow!("{e}"))?;
        for p in points {
            let (colour, size) = if p.highlight {
                (COLOURS[3], 7)
            } else {
                (COLOURS[0], 5)
            };
            let style = if p.highlight {
                colour.filled()
            } else {
                colour.stroke_width(2)
            };
            // the marker and its label beside it, offset in pixels
            let element = EmptyElement::at((p.x, p.y))
                + Circle::new((0, 0), size, style)
                + Text::new(p.label.clone(), (10, -7), ("sans-serif", 14).into_font());
            chart
                .draw_series(std::iter::once(element))
                .map_err(|e| anyhow!("{e}"))?;
        }
        // the key, top left inside the plot
        let key = [
            (COLOURS[3], format!("{highlight_name} (filled)")),
            (COLOURS[0], "dominated (open)".to_string()),
        ];
        for (k, (colour, text)) in key.iter().enumerate() {
            let y = 70 + 22 * k as i32;
            let style = if k == 0 {
                colour.filled()
            } else {
                colour.stroke_width(2)
            };
            root.draw(&Circle::new((120, y), 6, style))
                .map_err(|e| anyhow!("{e:?}"))?;
            root.draw(&Text::new(
                text.clone(),
                (132, y - 8),
                ("sans-serif", 15).into_font(),
            ))
            .map_err(|e| anyhow!("{e:?}"))?;
        }
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    Ok(svg)
}
