//! The z-buffer rasteriser: supersampled, Gouraud-interpolated values, head-light shading, box
//! filter to RGBA with coverage alpha; and the exact hidden-point test for the marker.

use nalgebra::Vector3;
use rayon::prelude::*;

use super::colour_map::colour_map;
use super::view::ViewGeom;

/// Samples per pixel along each axis (the raster is drawn at this multiple and box-filtered down).
pub const SUPERSAMPLE: usize = 3;
/// Ambient part of the shading: a face seen edge-on keeps this fraction of its colour.
pub const AMBIENT: f64 = 0.35;
/// Colour of values above the colour range (light grey: unlike any Turbo colour).
pub const OVER_COLOUR: [u8; 3] = [205, 205, 205];
/// Output pixel rows per band (the unit of parallel work).
const BAND_ROWS: usize = 16;

/// Lambert head-light factor `AMBIENT + (1 − AMBIENT)·|n·v|` of triangle `t` over positions `x`
/// seen from the unit direction `toward`; 0 for a degenerate triangle.
pub(super) fn shade(toward: &Vector3<f64>, x: &[[f64; 3]], t: [usize; 3]) -> f32 {
    let [a, b, c] = t.map(|i| Vector3::from(x[i]));
    let n = (b - a).cross(&(c - a));
    let l = n.norm();
    if l == 0.0 || !l.is_finite() {
        return 0.0;
    }
    (AMBIENT + (1.0 - AMBIENT) * (n.dot(toward) / l).abs()) as f32
}

/// Twice the signed area of (a, b, p) in the plane.
#[inline]
fn edge(a: [f64; 3], b: [f64; 3], px: f64, py: f64) -> f64 {
    (b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0])
}

/// Colour of one covered sample, before the box filter.
#[inline]
fn sample_colour(t: f32, shade: f32) -> [f32; 3] {
    let c = if t > 1.0 + 1e-5 {
        OVER_COLOUR
    } else {
        colour_map(f64::from(t))
    };
    [
        f32::from(c[0]) * shade,
        f32::from(c[1]) * shade,
        f32::from(c[2]) * shade,
    ]
}

/// Z-buffered, supersampled rasterisation of one view; straight-alpha RGBA, row-major, top row
/// first, alpha = coverage.
pub(super) fn rasterise(
    triangles: &[[usize; 3]],
    uvd: &[[f64; 3]],
    t_vals: &[f32],
    shades: &[f32],
    geom: &ViewGeom,
) -> Vec<u8> {
    let ss = SUPERSAMPLE;
    let (w, h) = (geom.width as usize, geom.height as usize);
    let ws = w * ss;
    // Vertex positions in sample units (x right, y down) and depth (larger = nearer).
    let sp: Vec<[f64; 3]> = uvd
        .par_iter()
        .map(|p| {
            let [x, y] = geom.pixel(*p);
            [x * ss as f64, y * ss as f64, p[2]]
        })
        .collect();

    // Bin the triangles into bands of output rows (counting sort, index order kept).
    let band_s = (BAND_ROWS * ss) as f64;
    let n_bands = h.div_ceil(BAND_ROWS);
    let hs = (h * ss) as f64;
    let ranges: Vec<Option<(u32, u32)>> = triangles
        .par_iter()
        .zip(shades)
        .map(|(t, &sh)| {
            if sh <= 0.0 {
                return None;
            }
            let ys = [sp[t[0]][1], sp[t[1]][1], sp[t[2]][1]];
            let (ymin, ymax) = (ys[0].min(ys[1]).min(ys[2]), ys[0].max(ys[1]).max(ys[2]));
            if ymax < 0.0 || ymin > hs {
                return None;
            }
            let b = |y: f64| ((y.max(0.0) / band_s) as usize).min(n_bands - 1) as u32;
            Some((b(ymin), b(ymax)))
        })
        .collect();
    let mut start = vec![0usize; n_bands + 1];
    for &(b0, b1) in ranges.iter().flatten() {
        for b in b0..=b1 {
            start[b as usize + 1] += 1;
        }
    }
    for b in 0..n_bands {
        start[b + 1] += start[b];
    }
    let mut fill = start.clone();
    let mut list = vec![0u32; start[n_bands]];
    for (k, r) in ranges.iter().enumerate() {
        if let Some((b0, b1)) = *r {
            for b in b0..=b1 {
                list[fill[b as usize]] = k as u32;
                fill[b as usize] += 1;
            }
        }
    }

    let mut rgba = vec![0u8; w * h * 4];
    rgba.par_chunks_mut(BAND_ROWS * w * 4)
        .enumerate()
        .for_each(|(b, out)| {
            let rows = out.len() / (w * 4);
            let rows_s = rows * ss;
            let y0 = b * BAND_ROWS * ss;
            let mut depth = vec![f32::NEG_INFINITY; rows_s * ws];
            let mut tbuf = vec![0f32; rows_s * ws];
            let mut sbuf = vec![0f32; rows_s * ws];
            for &k in &list[start[b]..start[b + 1]] {
                let k = k as usize;
                let t = triangles[k];
                let (a, bb, c) = (sp[t[0]], sp[t[1]], sp[t[2]]);
                let area = edge(a, bb, c[0], c[1]);
                if area.abs() < 1e-12 {
                    continue; // seen edge-on
                }
                let inv = 1.0 / area;
                let xmin = a[0].min(bb[0]).min(c[0]);
                let xmax = a[0].max(bb[0]).max(c[0]);
                let ymin = a[1].min(bb[1]).min(c[1]);
                let ymax = a[1].max(bb[1]).max(c[1]);
                let i0 = (xmin - 0.5).ceil().max(0.0);
                let i1 = (xmax - 0.5).floor().min(ws as f64 - 1.0);
                let j0 = (ymin - 0.5).ceil().max(y0 as f64);
                let j1 = (ymax - 0.5).floor().min((y0 + rows_s) as f64 - 1.0);
                if i1 < i0 || j1 < j0 {
                    continue;
                }
                let (ta, tb, tc) = (t_vals[t[0]], t_vals[t[1]], t_vals[t[2]]);
                let shade = shades[k];
                const EPS: f64 = -1e-9;
                for j in j0 as usize..=j1 as usize {
                    let py = j as f64 + 0.5;
                    let row = (j - y0) * ws;
                    for i in i0 as usize..=i1 as usize {
                        let px = i as f64 + 0.5;
                        let wa = edge(bb, c, px, py) * inv;
                        let wb = edge(c, a, px, py) * inv;
                        let wc = edge(a, bb, px, py) * inv;
                        if wa < EPS || wb < EPS || wc < EPS {
                            continue;
                        }
                        let d = (wa * a[2] + wb * bb[2] + wc * c[2]) as f32;
                        let idx = row + i;
                        if d > depth[idx] {
                            depth[idx] = d;
                            tbuf[idx] = (wa as f32) * ta + (wb as f32) * tb + (wc as f32) * tc;
                            sbuf[idx] = shade;
                        }
                    }
                }
            }
            // Box filter ss × ss samples → one pixel.
            let full = (ss * ss) as f32;
            for r in 0..rows {
                for x in 0..w {
                    let mut acc = [0f32; 3];
                    let mut n = 0usize;
                    for sy in 0..ss {
                        let row = (r * ss + sy) * ws + x * ss;
                        for idx in row..row + ss {
                            if depth[idx] > f32::NEG_INFINITY {
                                let col = sample_colour(tbuf[idx], sbuf[idx]);
                                acc[0] += col[0];
                                acc[1] += col[1];
                                acc[2] += col[2];
                                n += 1;
                            }
                        }
                    }
                    if n > 0 {
                        let o = (r * w + x) * 4;
                        let nf = n as f32;
                        out[o] = (acc[0] / nf).round().clamp(0.0, 255.0) as u8;
                        out[o + 1] = (acc[1] / nf).round().clamp(0.0, 255.0) as u8;
                        out[o + 2] = (acc[2] / nf).round().clamp(0.0, 255.0) as u8;
                        out[o + 3] = (255.0 * nf / full).round() as u8;
                    }
                }
            }
        });
    rgba
}

/// Whether surface lies nearer to the viewer than the projected point `p` (u, v, d) by more than
/// `tol` mm at the same (u, v): exact test against every triangle, no pixel rounding.
pub(super) fn is_hidden(triangles: &[[usize; 3]], uvd: &[[f64; 3]], p: [f64; 3], tol: f64) -> bool {
    triangles.par_iter().any(|t| {
        let (a, b, c) = (uvd[t[0]], uvd[t[1]], uvd[t[2]]);
        let area = edge(a, b, c[0], c[1]);
        if area.abs() < f64::MIN_POSITIVE {
            return false;
        }
        let wa = edge(b, c, p[0], p[1]) / area;
        let wb = edge(c, a, p[0], p[1]) / area;
        let wc = edge(a, b, p[0], p[1]) / area;
        let eps = -1e-9;
        wa >= eps && wb >= eps && wc >= eps && wa * a[2] + wb * b[2] + wc * c[2] > p[2] + tol
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::picture::test_util::{
        covered_span, decode_pngs, distance_to_map, pixel, square_options, two_squares,
    };
    use crate::report::picture::{SurfaceField, render_svg};

    #[test]
    fn gradient_square_plan_view_colours() {
        let v = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        // second triangle clockwise: inconsistent orientation must not matter
        let t = [[0, 1, 2], [0, 3, 2]];
        let vals = [0.0, 1.0, 1.0, 0.0];
        let f = SurfaceField {
            vertices_mm: &v,
            triangles: &t,
            values: &vals,
        };
        let svg = render_svg(&f, &square_options([0.0, 1.0])).unwrap();
        let imgs = decode_pngs(&svg);
        assert_eq!(imgs.len(), 2);
        let plan = &imgs[0];
        let y = plan.1 / 2;
        let (x0, x1) = covered_span(plan, y);
        assert!(x1 - x0 > 200, "square only {} px wide", x1 - x0);
        for frac in [0.25, 0.75] {
            let x = x0 + ((x1 - x0) as f64 * frac).round() as usize;
            let c = pixel(plan, x, y);
            assert_eq!(c[3], 255);
            let d = distance_to_map(c, frac - 0.01, frac + 0.01);
            assert!(d <= 2, "at {frac}: {c:?} is {d} away from the map");
            // and clearly not the colour of the other quarter
            assert!(distance_to_map(c, 1.0 - frac - 0.02, 1.0 - frac + 0.02) > 20);
        }
        // background: corners and just left of the square are transparent
        assert_eq!(pixel(plan, 0, 0)[3], 0);
        assert_eq!(pixel(plan, plan.0 - 1, plan.1 - 1)[3], 0);
        assert_eq!(pixel(plan, x0 - 3, y), [0, 0, 0, 0]);
        // the oblique view shades the same square darker (seen at an angle)
        let obl = &imgs[1];
        let yo = obl.1 / 2;
        let (o0, o1) = covered_span(obl, yo);
        let c = pixel(obl, (o0 + o1) / 2, yo);
        let m = colour_map(0.5);
        assert!(
            c[1] < m[1] && c[1] > (0.3 * f64::from(m[1])) as u8,
            "{c:?} vs {m:?}"
        );
    }

    #[test]
    fn z_buffer_nearer_square_wins() {
        for front_first in [false, true] {
            let (v, t, vals) = two_squares(front_first);
            let f = SurfaceField {
                vertices_mm: &v,
                triangles: &t,
                values: &vals,
            };
            let svg = render_svg(&f, &square_options([0.0, 1.0])).unwrap();
            let plan = &decode_pngs(&svg)[0];
            let y = plan.1 / 2;
            let (x0, x1) = covered_span(plan, y);
            let at = |frac: f64| pixel(plan, x0 + ((x1 - x0) as f64 * frac) as usize, y);
            let [r, g, b] = colour_map(0.8);
            assert_eq!(
                at(0.5),
                [r, g, b, 255],
                "overlap, front_first {front_first}"
            );
            assert_eq!(at(0.85), [r, g, b, 255]);
            let [r, g, b] = colour_map(0.2);
            assert_eq!(at(0.15), [r, g, b, 255]);
        }
    }

    #[test]
    fn over_range_gets_over_colour() {
        let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let t = [[0, 1, 2]];
        let vals = [5.0, 5.0, 5.0];
        let f = SurfaceField {
            vertices_mm: &v,
            triangles: &t,
            values: &vals,
        };
        let svg = render_svg(&f, &square_options([0.0, 4.0])).unwrap();
        let plan = &decode_pngs(&svg)[0];
        let c = pixel(plan, plan.0 / 4, plan.1 * 3 / 4);
        assert_eq!(c, [205, 205, 205, 255]);
        assert!(svg.contains("&gt; 4</text>"), "over swatch label");
    }

    #[test]
    fn hidden_marker_is_labelled_behind() {
        let (v, t, vals) = two_squares(false);
        let f = SurfaceField {
            vertices_mm: &v,
            triangles: &t,
            values: &vals,
        };
        // on the far square A under B: hidden in plan view, visible in the oblique view
        let mut o = square_options([0.0, 1.0]);
        o.marker_mm = Some([0.75, 0.5, 0.0]);
        o.marker_label = "peak 0.2 MPa".into();
        let svg = render_svg(&f, &o).unwrap();
        assert_eq!(svg.matches("peak 0.2 MPa (behind)</text>").count(), 1);
        assert_eq!(svg.matches("peak 0.2 MPa</text>").count(), 1);
        assert_eq!(svg.matches("stroke-dasharray").count(), 2);
        // on the near square B: visible in both
        o.marker_mm = Some([0.75, 0.5, 1.0]);
        let svg = render_svg(&f, &o).unwrap();
        assert!(!svg.contains("(behind)"));
        assert!(!svg.contains("stroke-dasharray"));
        assert_eq!(svg.matches("peak 0.2 MPa</text>").count(), 2);
        assert_eq!(svg.matches("<circle").count(), 4 + 1 + 1); // 2 per marker, plan triad ⊙ (2)
    }
}
