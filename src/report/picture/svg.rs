//! SVG composition: the view images with their markers, captions and axis triads, the title and
//! the colour scale with its ticks and "over" swatch.

use std::fmt::Write as _;

use base64::Engine as _;
use nalgebra::Vector3;

use super::PictureOptions;
use super::colour_map::colour_map;
use super::raster::OVER_COLOUR;
use super::view::{Frame, ViewGeom};

/// Outer margin of the SVG (px).
const MARGIN: f64 = 12.0;
/// Height of the title band (px).
const TITLE_H: f64 = 40.0;
/// Height of the caption band under each view (px).
const CAPTION_H: f64 = 44.0;
/// Width of the colour-scale column at the right (px).
const BAR_COLUMN: f64 = 122.0;
/// Marker circle radius (px).
const MARKER_R: f64 = 8.0;

/// A view ready to be placed: its frame, image placement, PNG and marker.
pub(super) struct RenderedView {
    pub(super) frame: Frame,
    pub(super) geom: ViewGeom,
    pub(super) png: Vec<u8>,
    /// Image pixel position of the marker and whether it is hidden.
    pub(super) marker: Option<([f64; 2], bool)>,
}

/// Width (px) of the column the view images are centred in, for an SVG `width` px wide.
pub(super) fn image_column_width(width: f64) -> f64 {
    width - 2.0 * MARGIN - BAR_COLUMN
}

/// Escapes text for SVG content and attribute values.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn hex(c: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

/// Tick values for a colour scale over [lo, hi]: 5–7 "nice" values (steps 1, 2, 2.5 or 5 × 10^k)
/// inside the range, or 6 evenly spaced values from lo to hi when no nice step gives 5–7.
fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = hi - lo;
    let e0 = (span / 6.0).log10().floor() as i32;
    // (distance from 6 ticks, step, first multiple of step, count)
    let mut best: Option<(u64, f64, i64, i64)> = None;
    for e in e0 - 1..=e0 + 1 {
        for m in [1.0, 2.0, 5.0, 2.5] {
            let step = m * 10f64.powi(e);
            let first = (lo / step - 1e-9).ceil() as i64;
            let last = (hi / step + 1e-9).floor() as i64;
            let n = last - first + 1;
            let dist = (n - 6).unsigned_abs();
            if (5..=7).contains(&n) && best.is_none_or(|(d, ..)| dist < d) {
                best = Some((dist, step, first, n));
            }
        }
    }
    match best {
        Some((_, step, first, n)) => (first..first + n).map(|k| k as f64 * step).collect(),
        None => (0..6).map(|i| lo + span * i as f64 / 5.0).collect(),
    }
}

/// Formats tick values with the fewest decimals (≤ 6) that show them all exactly.
fn tick_labels(ticks: &[f64]) -> Vec<String> {
    let step = if ticks.len() > 1 {
        (ticks[1] - ticks[0]).abs()
    } else {
        1.0
    };
    let d = (0..=6)
        .find(|&d| {
            let f = 10f64.powi(d);
            ticks
                .iter()
                .all(|v| ((v * f).round() / f - v).abs() <= 1e-6 * step)
        })
        .unwrap_or(6) as usize;
    ticks.iter().map(|v| format!("{:.d$}", v + 0.0)).collect()
}

/// A value with 4 significant digits, trailing zeros removed.
fn fmt_value(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{}", v + 0.0);
    }
    let d = (3 - v.abs().log10().floor() as i32).clamp(0, 6) as usize;
    let s = format!("{v:.d$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// FNV-1a hash (for an id unique to this picture).
fn fnv(s: &str) -> u64 {
    s.bytes().fold(0xcbf29ce484222325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x100000001b3)
    })
}

/// The SVG: title, the views stacked vertically (image, marker, triad, caption), colour scale.
pub(super) fn compose_svg(views: &[RenderedView], options: &PictureOptions, width: f64) -> String {
    let avail_w = image_column_width(width);
    let mut body = String::new();
    let mut y = MARGIN + TITLE_H;
    let views_top = y;
    for v in views {
        let (iw, ih) = (f64::from(v.geom.width), f64::from(v.geom.height));
        let x0 = MARGIN + ((avail_w - iw) / 2.0).max(0.0).floor();
        let b64 = base64::engine::general_purpose::STANDARD.encode(&v.png);
        let _ = writeln!(
            body,
            r#"<image x="{x0}" y="{y}" width="{iw}" height="{ih}" preserveAspectRatio="none" href="data:image/png;base64,{b64}"/>"#
        );
        if let Some(([mx, my], hidden)) = v.marker {
            marker_svg(
                &mut body,
                [x0 + mx, y + my],
                hidden,
                &options.marker_label,
                [x0, x0 + iw],
                y,
            );
        }
        let cy = y + ih;
        triad_svg(
            &mut body,
            &v.frame,
            [MARGIN + 20.0, cy + CAPTION_H / 2.0 + 6.0],
        );
        let _ = writeln!(
            body,
            r##"<text x="{}" y="{:.1}" font-size="13" fill="#222">{}</text>"##,
            MARGIN + 56.0,
            cy + CAPTION_H / 2.0 + 4.5,
            esc(&v.frame.caption)
        );
        y = cy + CAPTION_H;
    }
    let views_h = y - views_top;

    // Colour scale.
    let [lo, hi] = options.range;
    let col_x = width - MARGIN - BAR_COLUMN + 14.0;
    let bar_w = 20.0;
    let unit_y = views_top + 14.0;
    let over_y = unit_y + 10.0;
    let over_h = 16.0;
    let bar_top = over_y + over_h + 10.0;
    let bar_h = (0.55 * views_h).clamp(160.0, 420.0);
    let bar_bot = bar_top + bar_h;
    let id = format!(
        "cbar{:016x}",
        fnv(&format!("{}|{lo}|{hi}|{}", options.title, options.width_px))
    );
    let mut bar = String::new();
    let _ = writeln!(
        bar,
        r#"<defs><linearGradient id="{id}" x1="0" y1="1" x2="0" y2="0">"#
    );
    const STOPS: usize = 32;
    for k in 0..=STOPS {
        let t = k as f64 / STOPS as f64;
        let _ = writeln!(
            bar,
            r#"<stop offset="{t:.4}" stop-color="{}"/>"#,
            hex(colour_map(t))
        );
    }
    bar.push_str("</linearGradient></defs>\n");
    let _ = writeln!(
        bar,
        r##"<text x="{col_x}" y="{unit_y}" font-size="13" font-weight="bold" fill="#222">{}</text>"##,
        esc(&options.unit)
    );
    let _ = writeln!(
        bar,
        r##"<rect x="{col_x}" y="{over_y}" width="{bar_w}" height="{over_h}" fill="{}" stroke="#333" stroke-width="1"/>"##,
        hex(OVER_COLOUR)
    );
    let _ = writeln!(
        bar,
        r##"<text x="{}" y="{}" font-size="13" fill="#222">&gt; {}</text>"##,
        col_x + bar_w + 9.0,
        over_y + over_h / 2.0 + 4.5,
        esc(&fmt_value(hi))
    );
    let _ = writeln!(
        bar,
        r##"<rect x="{col_x}" y="{bar_top}" width="{bar_w}" height="{bar_h}" fill="url(#{id})" stroke="#333" stroke-width="1"/>"##
    );
    let tv = ticks(lo, hi);
    for (v, label) in tv.iter().zip(tick_labels(&tv)) {
        let ty = bar_bot - (v - lo) / (hi - lo) * bar_h;
        let _ = writeln!(
            bar,
            r##"<line x1="{}" y1="{ty:.2}" x2="{}" y2="{ty:.2}" stroke="#333" stroke-width="1"/>"##,
            col_x + bar_w,
            col_x + bar_w + 5.0
        );
        let _ = writeln!(
            bar,
            r##"<text x="{}" y="{:.2}" font-size="13" fill="#222">{}</text>"##,
            col_x + bar_w + 9.0,
            ty + 4.5,
            esc(&label)
        );
    }

    let height = (y.max(bar_bot + 10.0) + MARGIN).ceil();
    let mut s = String::with_capacity(body.len() + bar.len() + 1024);
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="sans-serif">"#
    );
    let _ = writeln!(s, "<title>{}</title>", esc(&options.title));
    let _ = writeln!(
        s,
        r##"<rect x="0" y="0" width="{width}" height="{height}" fill="#ffffff"/>"##
    );
    let _ = writeln!(
        s,
        r##"<text x="{MARGIN}" y="{}" font-size="18" font-weight="bold" fill="#111">{}</text>"##,
        MARGIN + 20.0,
        esc(&options.title)
    );
    s.push_str(&body);
    s.push_str(&bar);
    s.push_str("</svg>\n");
    s
}

/// Marker circle with a white halo and its label; dashed and "(behind)" when hidden.
fn marker_svg(
    s: &mut String,
    [cx, cy]: [f64; 2],
    hidden: bool,
    label: &str,
    [xl, xr]: [f64; 2],
    top: f64,
) {
    let dash = if hidden {
        r#" stroke-dasharray="4 3""#
    } else {
        ""
    };
    let label = if hidden {
        format!("{label} (behind)")
    } else {
        label.to_string()
    };
    let _ = writeln!(
        s,
        r##"<circle cx="{cx:.1}" cy="{cy:.1}" r="{MARKER_R}" fill="none" stroke="#ffffff" stroke-width="4"{dash}/>"##
    );
    let _ = writeln!(
        s,
        r##"<circle cx="{cx:.1}" cy="{cy:.1}" r="{MARKER_R}" fill="none" stroke="#000000" stroke-width="1.6"{dash}/>"##
    );
    let est_w = 0.58 * 13.0 * label.chars().count() as f64;
    let (tx, anchor) = if cx + MARKER_R + 4.0 + est_w > xr && cx - MARKER_R - 4.0 - est_w >= xl {
        (cx - MARKER_R - 4.0, "end")
    } else {
        (cx + MARKER_R + 4.0, "start")
    };
    let ty = if cy - MARKER_R - 4.0 < top + 14.0 {
        cy + MARKER_R + 14.0
    } else {
        cy - MARKER_R - 2.0
    };
    let _ = writeln!(
        s,
        r##"<text x="{tx:.1}" y="{ty:.1}" text-anchor="{anchor}" font-size="13" font-weight="bold" fill="#000000" stroke="#ffffff" stroke-width="3" stroke-linejoin="round" paint-order="stroke">{}</text>"##,
        esc(&label)
    );
}

/// Small axis triad centred at `o`: projected x, y, z arrows; an axis along the view direction is
/// drawn as ⊙ (towards the viewer) or ⊗ (away).
fn triad_svg(s: &mut String, f: &Frame, o: [f64; 2]) {
    const LEN: f64 = 20.0;
    for (k, name) in ["x", "y", "z"].iter().enumerate() {
        // a full dot product with the unit vector (not just the k-th component): it keeps the sign
        // of zero components, which shows in the formatted coordinates ("-0.0")
        let e = Vector3::ith(k, 1.0);
        let (dx, dy) = (e.dot(&f.right) * LEN, -e.dot(&f.up) * LEN);
        if (dx * dx + dy * dy).sqrt() < 0.25 * LEN {
            let towards = e.dot(&f.toward) > 0.0;
            let _ = writeln!(
                s,
                r##"<circle cx="{:.1}" cy="{:.1}" r="3.5" fill="none" stroke="#333" stroke-width="1"/>"##,
                o[0], o[1]
            );
            if towards {
                let _ = writeln!(
                    s,
                    r##"<circle cx="{:.1}" cy="{:.1}" r="1.2" fill="#333"/>"##,
                    o[0], o[1]
                );
            } else {
                let _ = writeln!(
                    s,
                    r##"<path d="M{:.1} {:.1}l5 5m0 -5l-5 5" stroke="#333" stroke-width="1"/>"##,
                    o[0] - 2.5,
                    o[1] - 2.5
                );
            }
            let _ = writeln!(
                s,
                r##"<text x="{:.1}" y="{:.1}" font-size="12" fill="#333">{name}</text>"##,
                o[0] - 12.0,
                o[1] + 4.0
            );
            continue;
        }
        let _ = writeln!(
            s,
            r##"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="#333" stroke-width="1.3"/>"##,
            o[0],
            o[1],
            o[0] + dx,
            o[1] + dy
        );
        // label beyond the tip, anchored away from the origin so nearly parallel axes don't collide
        let anchor = if dx < -0.15 * LEN {
            "end"
        } else if dx > 0.15 * LEN {
            "start"
        } else {
            "middle"
        };
        let lx = o[0] + dx + dx.signum() * 3.0 * f64::from(u8::from(anchor != "middle"));
        let ly = o[1]
            + dy
            + if dy < -0.15 * LEN {
                -4.0
            } else if dy > 0.15 * LEN {
                13.0
            } else {
                4.0
            };
        let _ = writeln!(
            s,
            r##"<text x="{lx:.1}" y="{ly:.1}" font-size="12" text-anchor="{anchor}" fill="#333">{name}</text>"##
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::picture::test_util::single_tet10;
    use crate::report::picture::{SurfaceField, render_svg, tet10_surface};

    #[test]
    fn svg_is_self_contained_with_ticks_and_escaped_title() {
        let mesh = single_tet10();
        let (v, t) = tet10_surface(&mesh).unwrap();
        let vals: Vec<f64> = v.iter().map(|p| 0.25 * p[0]).collect();
        let f = SurfaceField {
            vertices_mm: &v,
            triangles: &t,
            values: &vals,
        };
        let o = PictureOptions {
            title: "tet <1> & von Mises".into(),
            range: [0.0, 250.0],
            marker_mm: f.peak().map(|p| p.0),
            marker_label: "peak 250 MPa".into(),
            ..Default::default()
        };
        assert_eq!(f.peak(), Some(([1000.0, 0.0, 0.0], 250.0)));
        let svg = render_svg(&f, &o).unwrap();
        assert!(svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""));
        assert!(svg.trim_end().ends_with("</svg>"));
        assert_eq!(svg.matches("data:image/png;base64,").count(), 2);
        assert_eq!(svg.matches("http").count(), 1, "only the xmlns URI"); // no external reference
        assert!(!svg.contains("xlink"));
        for label in ["0", "50", "100", "150", "200", "250"] {
            assert!(svg.contains(&format!(">{label}</text>")), "tick {label}");
        }
        assert!(svg.contains("&gt; 250</text>"));
        assert!(svg.contains("tet &lt;1&gt; &amp; von Mises"));
        assert!(!svg.contains("<1>"));
        assert_eq!(svg.matches("<text").count(), svg.matches("</text>").count());
        assert!(svg.contains("font-family=\"sans-serif\""));
        assert_eq!(svg.matches("Plan view").count(), 1);
        assert_eq!(svg.matches("Oblique view").count(), 1);
        // deterministic
        assert_eq!(svg, render_svg(&f, &o).unwrap());
    }

    #[test]
    fn ticks_are_nice_and_inside() {
        for (lo, hi) in [
            (0.0, 250.0),
            (0.0, 227.3),
            (0.0, 7.9),
            (0.0, 8.9),
            (-3.0, 17.0),
            (12.5, 13.1),
            (0.0, 1.0),
            (100.0, 1000.0),
            (0.0, 1e-4),
        ] {
            let t = ticks(lo, hi);
            assert!((5..=7).contains(&t.len()), "{lo}..{hi}: {t:?}");
            assert!(t.windows(2).all(|w| w[1] > w[0]));
            let tol = 1e-9 * (hi - lo);
            assert!(t[0] >= lo - tol && *t.last().unwrap() <= hi + tol, "{t:?}");
            let labels = tick_labels(&t);
            let mut dedup = labels.clone();
            dedup.dedup();
            assert_eq!(dedup.len(), labels.len(), "{labels:?}");
        }
        assert_eq!(
            tick_labels(&ticks(0.0, 1.0)),
            ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]
        );
        assert_eq!(fmt_value(227.3), "227.3");
        assert_eq!(fmt_value(250.0), "250");
    }
}
