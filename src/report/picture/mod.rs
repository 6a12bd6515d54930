//! Stress pictures for the study report: a scalar field (von Mises stress, MPa) drawn on the
//! boundary surface of the tetrahedral mesh, as one self-contained SVG.
//!
//! What it draws: two orthographic views of the rod stacked vertically — a plan view looking along
//! −z (both eyes, the shank, the fillets) and an oblique view from +z tilted towards −y and a little
//! from +x (top face and the −y flank, so the thickness and the side faces' stress show). Each view
//! is a colour-mapped, shaded raster (an embedded PNG, `data:` URI, no external reference, so it
//! displays inside an HTML `<img>` opened from `file://`) with vector annotations on top: a title, a
//! vertical colour scale with 5–7 tick labels and an "over" swatch for values above the range, a
//! marker at the peak in every view (dashed and labelled "(behind)" where other surface hides it)
//! and a one-line caption per view with a small axis triad.
//!
//! Rendering: per view, the surface triangles are projected orthographically and rasterised with a
//! z-buffer at [`SUPERSAMPLE`]² samples per pixel, then box-filtered down (anti-aliasing; the alpha
//! channel is the coverage, the background stays transparent). The scalar is interpolated per
//! sample (barycentric, i.e. Gouraud of the value, then colour-mapped), not flat per triangle. The
//! colour is multiplied by a head-light Lambert factor `AMBIENT + (1 − AMBIENT)·|n·v|` of the
//! triangle's normal `n` and the view direction `v` (absolute value: triangle orientation need not
//! be consistent); a face seen face-on keeps its exact colour-map colour. Values above the range get
//! the light grey [`OVER_COLOUR`] (no Turbo colour is grey, so "over" cannot be misread as a value
//! on the scale), values below it the colour of the minimum. The images are RGBA 8-bit PNGs with
//! default compression; if both together would exceed 0.42 bytes per pixel (a typical rod at
//! 960 px does: smooth gradients compress poorly), the colour channels are first rounded to 7 bits
//! (then 6), which keeps such an SVG near 300 KB instead of ~390 KB at no visible cost.
//!
//! Why a software rasteriser: no install footprint (no GPU, display server, browser or Python in
//! the study), deterministic output (the same mesh and field give the same bytes whatever the number
//! of threads: each band of rows is drawn by one thread, triangles in index order), and it runs
//! inside the study in a fraction of a second (≈ 0.2 s for a rod of 40–220 k surface triangles at
//! 960 px; bands in parallel with rayon).
//!
//! Colour map: Turbo (A. Mikhailov, "Turbo, An Improved Rainbow Colormap for Visualization", Google
//! AI Blog, 2019), evaluated with the degree-5 polynomial approximation published with it (Ruofei
//! Du's GLSL `TurboColormap`, gist mikhailov-work/0d177465a8151eb6ede1768d51d476c7); see
//! [`colour_map()`].
//!
//! Layout: `colour_map` (Turbo), `surface` (boundary surface of a tet10 mesh), `view` (view
//! frames, projection, image placement), `raster` (z-buffer, supersampling, shading, hidden test),
//! `png` (quantisation, encoding within the size budget), `svg` (composition, colour scale, ticks,
//! marker, triad); this file holds the public types and [`render_svg`], which runs them in turn.

mod colour_map;
mod png;
mod raster;
mod surface;
mod svg;
#[cfg(test)]
mod test_util;
mod view;

use anyhow::{Result, ensure};
use nalgebra::Vector3;
use rayon::prelude::*;

use crate::fem::mesh::TetMesh;

pub use colour_map::colour_map;
pub use raster::{AMBIENT, OVER_COLOUR, SUPERSAMPLE};
pub use surface::{SurfaceMesh, tet10_surface};

use raster::{is_hidden, rasterise, shade};
use svg::{RenderedView, compose_svg, image_column_width};
use view::{Frame, ViewGeom};

/// Linear surface triangles over mesh nodes, with a value per node.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceField<'a> {
    /// Positions, mm. May hold vertices that no triangle uses (e.g. all nodes of a mesh); they are
    /// ignored.
    pub vertices_mm: &'a [[f64; 3]],
    /// Indices into `vertices_mm`; orientation need not be consistent.
    pub triangles: &'a [[usize; 3]],
    /// One value per vertex (e.g. MPa).
    pub values: &'a [f64],
}

impl SurfaceField<'_> {
    /// The largest value over the vertices used by a triangle, with its position (mm); the first
    /// such vertex on ties. `None` without triangles or when a used index is out of range.
    pub fn peak(&self) -> Option<([f64; 3], f64)> {
        let mut best: Option<(usize, f64)> = None;
        for &i in self.triangles.iter().flatten() {
            let v = *self.values.get(i)?;
            self.vertices_mm.get(i)?;
            if best.is_none_or(|(j, b)| v > b || (v == b && i < j)) {
                best = Some((i, v));
            }
        }
        best.map(|(i, v)| (self.vertices_mm[i], v))
    }
}

/// What to draw around the field.
#[derive(Clone, Debug, PartialEq)]
pub struct PictureOptions {
    /// Title line, e.g. "design1 — von Mises, F_y case (F = 9 876 N)".
    pub title: String,
    /// Unit of the values, shown above the colour scale ("MPa").
    pub unit: String,
    /// Colour scale [min, max]; values above max get [`OVER_COLOUR`], values below min the colour
    /// of min.
    pub range: [f64; 2],
    /// A point to mark in every view (mm), typically the peak.
    pub marker_mm: Option<[f64; 3]>,
    /// Marker label, e.g. "peak 227.3 MPa" (" (behind)" is appended where the point is hidden).
    pub marker_label: String,
    /// Total SVG width in px (320–8192).
    pub width_px: u32,
}

impl Default for PictureOptions {
    /// Untitled, MPa, range [0, 1], no marker, 960 px wide.
    fn default() -> Self {
        PictureOptions {
            title: String::new(),
            unit: "MPa".into(),
            range: [0.0, 1.0],
            marker_mm: None,
            marker_label: "peak".into(),
            width_px: 960,
        }
    }
}

/// Draws a nodal field of a tet10 mesh (one value per mesh node) on the mesh's boundary surface:
/// [`tet10_surface`] then [`render_svg`].
pub fn render_tet10_field(
    mesh: &TetMesh,
    values: &[f64],
    options: &PictureOptions,
) -> Result<String> {
    let (vertices_mm, triangles) = tet10_surface(mesh)?;
    render_svg(
        &SurfaceField {
            vertices_mm: &vertices_mm,
            triangles: &triangles,
            values,
        },
        options,
    )
}

/// Draws `field` in two views (plan along −z, oblique) as one self-contained SVG; see the module
/// documentation for what is drawn.
///
/// Errors: no triangles, an index out of range, `values` not one per vertex, a non-finite position
/// or value on the surface, a range that is not finite and increasing, a width outside 320–8192 px,
/// a non-finite marker, or a surface of zero extent.
pub fn render_svg(field: &SurfaceField, options: &PictureOptions) -> Result<String> {
    let used = validate(field, options)?;
    let [lo, hi] = options.range;
    let width = f64::from(options.width_px);

    // Bounding box of the used vertices (for the hidden-marker tolerance).
    let mut bmin = [f64::INFINITY; 3];
    let mut bmax = [f64::NEG_INFINITY; 3];
    for (p, _) in field.vertices_mm.iter().zip(&used).filter(|(_, u)| **u) {
        for j in 0..3 {
            bmin[j] = bmin[j].min(p[j]);
            bmax[j] = bmax[j].max(p[j]);
        }
    }
    let diag = (Vector3::from(bmax) - Vector3::from(bmin)).norm();
    ensure!(diag > 0.0, "the surface has zero extent");

    // Normalised values, shared by the views.
    let t_vals: Vec<f32> = field
        .values
        .par_iter()
        .map(|v| ((v - lo) / (hi - lo)) as f32)
        .collect();

    let avail_w = image_column_width(width);
    let max_view_h = 0.7 * width;
    let views = [Frame::plan(), Frame::oblique()];
    let mut rasters = Vec::with_capacity(views.len());
    for frame in views {
        let uvd: Vec<[f64; 3]> = field
            .vertices_mm
            .par_iter()
            .map(|p| frame.project(*p))
            .collect();
        let geom = ViewGeom::fit(&uvd, &used, avail_w, max_view_h)?;
        let shades: Vec<f32> = field
            .triangles
            .par_iter()
            .map(|t| shade(&frame.toward, field.vertices_mm, *t))
            .collect();
        let rgba = rasterise(field.triangles, &uvd, &t_vals, &shades, &geom);
        let marker = options.marker_mm.map(|m| {
            let p = frame.project(m);
            let hidden = is_hidden(field.triangles, &uvd, p, 0.01 * diag);
            (geom.pixel(p), hidden)
        });
        rasters.push((frame, geom, rgba, marker));
    }

    let images: Vec<_> = rasters
        .iter()
        .map(|(_, g, rgba, _)| (rgba.as_slice(), g.width, g.height))
        .collect();
    let pngs = png::encode_within_budget(&images)?;
    let rendered: Vec<RenderedView> = rasters
        .into_iter()
        .zip(pngs)
        .map(|((frame, geom, _, marker), png)| RenderedView {
            frame,
            geom,
            png,
            marker,
        })
        .collect();
    Ok(compose_svg(&rendered, options, width))
}

/// Checks the inputs; returns which vertices the triangles use.
fn validate(field: &SurfaceField, options: &PictureOptions) -> Result<Vec<bool>> {
    let n = field.vertices_mm.len();
    ensure!(!field.triangles.is_empty(), "no triangles to draw");
    ensure!(
        field.values.len() == n,
        "{} values for {} vertices (one per vertex expected)",
        field.values.len(),
        n
    );
    let mut used = vec![false; n];
    for (k, t) in field.triangles.iter().enumerate() {
        for &i in t {
            ensure!(
                i < n,
                "triangle {k} refers to vertex {i}, but there are {n} vertices"
            );
            used[i] = true;
        }
    }
    for (i, _) in used.iter().enumerate().filter(|(_, u)| **u) {
        let p = field.vertices_mm[i];
        ensure!(
            p.iter().all(|c| c.is_finite()),
            "vertex {i} has a non-finite position {p:?}"
        );
        ensure!(
            field.values[i].is_finite(),
            "vertex {i} has a non-finite value {}",
            field.values[i]
        );
    }
    let [lo, hi] = options.range;
    ensure!(
        lo.is_finite() && hi.is_finite() && hi > lo,
        "colour range [{lo}, {hi}] must be finite and increasing"
    );
    ensure!(
        (320..=8192).contains(&options.width_px),
        "width {} px outside 320..=8192",
        options.width_px
    );
    if let Some(m) = options.marker_mm {
        ensure!(
            m.iter().all(|c| c.is_finite()),
            "marker {m:?} is not finite"
        );
    }
    Ok(used)
}

#[cfg(test)]
mod tests {
    use super::test_util::{decode_pngs, square_options};
    use super::*;
    use std::time::Instant;

    #[test]
    fn bad_inputs_are_errors() {
        let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let vals = [0.0, 1.0, 2.0];
        let ok = SurfaceField {
            vertices_mm: &v,
            triangles: &[[0, 1, 2]],
            values: &vals,
        };
        let o = square_options([0.0, 2.0]);
        assert!(render_svg(&ok, &o).is_ok());
        let bad_index = SurfaceField {
            triangles: &[[0, 1, 3]],
            ..ok
        };
        assert!(render_svg(&bad_index, &o).is_err());
        let short = SurfaceField {
            values: &vals[..2],
            ..ok
        };
        assert!(render_svg(&short, &o).is_err());
        let nan = [0.0, f64::NAN, 1.0];
        assert!(render_svg(&SurfaceField { values: &nan, ..ok }, &o).is_err());
        assert!(render_svg(&ok, &square_options([2.0, 2.0])).is_err());
        let mut narrow = o.clone();
        narrow.width_px = 100;
        assert!(render_svg(&ok, &narrow).is_err());
        let point = SurfaceField {
            triangles: &[[0, 0, 0]],
            ..ok
        };
        assert!(render_svg(&point, &o).is_err());
    }

    /// A rod-like plate with two through bores (structured tet10 mesh) and a smooth synthetic
    /// field peaking at the small-end bore: render time and size.
    #[test]
    fn two_eye_plate_picture() {
        use crate::fem::mesh::structured::{TwoEyePlate, two_eye_plate};
        let p = TwoEyePlate {
            n_side: 12,
            n_radial: 6,
            n_shank: 20,
            n_z: 6,
            curved: true,
            ..Default::default()
        };
        let mesh = two_eye_plate(&p).unwrap();
        let (v, t) = tet10_surface(&mesh).unwrap();
        let vals: Vec<f64> = v
            .iter()
            .map(|q| {
                let r = ((q[0] - 180.0).powi(2) + (q[1] - 12.5).powi(2)).sqrt();
                60.0 + 0.4 * q[0] + 150.0 * (-(r / 15.0).powi(2)).exp() + 0.5 * q[2]
            })
            .collect();
        let f = SurfaceField {
            vertices_mm: &v,
            triangles: &t,
            values: &vals,
        };
        let (pk, pv) = f.peak().unwrap();
        let o = PictureOptions {
            title: "two-eye plate — synthetic field".into(),
            range: [0.0, 250.0],
            marker_mm: Some(pk),
            marker_label: format!("peak {pv:.1} MPa"),
            ..Default::default()
        };
        let t0 = Instant::now();
        let svg = render_svg(&f, &o).unwrap();
        let dt = t0.elapsed();
        println!(
            "two-eye plate: {} triangles, {:.0} ms, SVG {} KB",
            t.len(),
            dt.as_secs_f64() * 1e3,
            svg.len() / 1024
        );
        assert!(svg.len() < 400 * 1024);
        if let Ok(dir) = std::env::var("RODSTUDY_PICTURE_OUT") {
            std::fs::write(format!("{dir}/two_eye_plate.svg"), &svg).unwrap();
        }
    }

    /// Values of a named ASCII DataArray of a rodstudy VTU.
    fn vtu_array(text: &str, name: &str) -> Vec<f64> {
        let key = format!("Name=\"{name}\"");
        let i = text.find(&key).unwrap();
        let start = i + text[i..].find('>').unwrap() + 1;
        let end = start + text[start..].find("</DataArray>").unwrap();
        text[start..end]
            .split_ascii_whitespace()
            .map(|s| s.parse().unwrap())
            .collect()
    }

    /// Real rods: reports/designN/fem_fy.vtu (averaged von Mises), those present. Ignored: needs the
    /// study's output. `RODSTUDY_PICTURE_OUT=dir cargo test --release --lib picture -- --ignored
    /// --nocapture` also writes the SVGs.
    #[test]
    #[ignore]
    fn real_rod_pictures() {
        for design in ["design1", "design2", "design3", "design4", "design5"] {
            let path = format!("{}/reports/{design}/fem_fy.vtu", env!("CARGO_MANIFEST_DIR"));
            let Ok(text) = std::fs::read_to_string(&path) else {
                println!("{path} not found, skipped");
                continue;
            };
            let xyz = vtu_array(&text, "coordinates_mm");
            let vm = vtu_array(&text, "von_mises_averaged_MPa");
            let conn = vtu_array(&text, "connectivity");
            let nodes: Vec<[f64; 3]> = xyz
                .chunks(3)
                .map(|c| [c[0] * 1e-3, c[1] * 1e-3, c[2] * 1e-3])
                .collect();
            let elems: Vec<[usize; 10]> = conn
                .chunks(10)
                .map(|c| std::array::from_fn(|a| c[a] as usize))
                .collect();
            let mesh = TetMesh::new(nodes, elems).unwrap();
            let t0 = Instant::now();
            let (v, t) = tet10_surface(&mesh).unwrap();
            let t_surface = t0.elapsed();
            let f = SurfaceField {
                vertices_mm: &v,
                triangles: &t,
                values: &vm,
            };
            let (pk, pv) = f.peak().unwrap();
            let o = PictureOptions {
                title: format!("{design} — von Mises (nodal average), F_y case"),
                range: [0.0, (pv * 0.9).round()],
                marker_mm: Some(pk),
                marker_label: format!("peak {pv:.1} MPa"),
                ..Default::default()
            };
            let t1 = Instant::now();
            let svg = render_svg(&f, &o).unwrap();
            let dt = t1.elapsed();
            let pngs = decode_pngs(&svg);
            println!(
                "{design}: {} surface triangles; surface {:.0} ms, render {:.0} ms; SVG {} KB; \
                 images {:?}; peak {pv:.1} MPa at {pk:.1?}",
                t.len(),
                t_surface.as_secs_f64() * 1e3,
                dt.as_secs_f64() * 1e3,
                svg.len() / 1024,
                pngs.iter().map(|p| (p.0, p.1)).collect::<Vec<_>>()
            );
            assert!(svg.len() < 400 * 1024);
            if let Ok(dir) = std::env::var("RODSTUDY_PICTURE_OUT") {
                std::fs::write(format!("{dir}/{design}_fy.svg"), &svg).unwrap();
            }
        }
    }

    /// SHA-256 of `s`, lower-case hex.
    fn sha256_hex(s: &str) -> String {
        use sha2::Digest;
        sha2::Sha256::digest(s.as_bytes())
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect()
    }

    /// Pins the bytes of the pictures: two structured tet10 meshes with deterministic fields drawn
    /// through [`render_tet10_field`] (marker visible and hidden, values over the range, escaped
    /// title, two widths). The hashes were taken from the code before `fem/picture.rs` was split
    /// into `report/picture/`; the split (and any later refactoring) must not change a byte, since
    /// the study's committed pictures are checked byte for byte.
    #[test]
    fn picture_bytes_unchanged() {
        use crate::fem::mesh::structured::{TwoEyePlate, box_tet10, two_eye_plate};
        let plate = two_eye_plate(&TwoEyePlate {
            n_side: 12,
            n_radial: 6,
            n_shank: 20,
            n_z: 6,
            curved: true,
            ..Default::default()
        })
        .unwrap();
        let vals: Vec<f64> = plate
            .nodes()
            .iter()
            .map(|p| {
                let q = p.map(|c| c * 1e3);
                let r = ((q[0] - 180.0).powi(2) + (q[1] - 12.5).powi(2)).sqrt();
                60.0 + 0.4 * q[0] + 150.0 * (-(r / 15.0).powi(2)).exp() + 0.5 * q[2]
            })
            .collect();
        let (i_max, v_max) = vals
            .iter()
            .enumerate()
            .fold((0, f64::MIN), |b, (i, &v)| if v > b.1 { (i, v) } else { b });
        let o = PictureOptions {
            title: "two-eye plate — synthetic field".into(),
            range: [0.0, 250.0],
            marker_mm: Some(plate.nodes()[i_max].map(|c| c * 1e3)),
            marker_label: format!("peak {v_max:.1} MPa"),
            ..Default::default()
        };
        let plate_svg = render_tet10_field(&plate, &vals, &o).unwrap();

        let block = box_tet10(0.12, 0.03, 0.02, 48, 12, 8).unwrap();
        let vals: Vec<f64> = block
            .nodes()
            .iter()
            .enumerate()
            .map(|(i, p)| {
                // smooth part plus deterministic per-node noise (poorly compressible: the PNGs
                // exceed the size budget and go through `quantise`)
                let noise = (i as u64).wrapping_mul(2_654_435_761) % 1000;
                40.0 * (p[0] * 60.0).sin() + 2e3 * p[1] + 0.05 * noise as f64 + 40.0
            })
            .collect();
        let o = PictureOptions {
            title: "box <tet10> & \"quoted\"".into(),
            unit: "N/mm²".into(),
            range: [12.5, 97.3],
            // centre of the bottom face: hidden in the plan view
            marker_mm: Some([60.0, 15.0, 0.0]),
            marker_label: "bottom".into(),
            width_px: 700,
        };
        let block_svg = render_tet10_field(&block, &vals, &o).unwrap();
        let got = [sha256_hex(&plate_svg), sha256_hex(&block_svg)];
        println!("picture hashes: {got:?}");
        assert!(block_svg.contains("bottom (behind)"));
        assert_eq!(
            got,
            [
                "0f277b04c0167bac84f935e0aabe164d6ebd57998872a6933b2d5b14cd503c2d",
                "d1c91c98788a942f7713f162a2e165e988c47e902a5549615383fc401fe915fa",
            ]
        );
    }
}
