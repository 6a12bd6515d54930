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
//! [`colour_map`].

use std::fmt::Write as _;

use anyhow::{Context, Result, bail, ensure};
use base64::Engine as _;
use rayon::prelude::*;

use super::boundary::boundary_faces;
use super::mesh::TetMesh;

/// Samples per pixel along each axis (the raster is drawn at this multiple and box-filtered down).
pub const SUPERSAMPLE: usize = 3;
/// Ambient part of the shading: a face seen edge-on keeps this fraction of its colour.
pub const AMBIENT: f64 = 0.35;
/// Colour of values above the colour range (light grey: unlike any Turbo colour).
pub const OVER_COLOUR: [u8; 3] = [205, 205, 205];

/// Tilt of the oblique view from +z towards −y (degrees).
const OBLIQUE_TILT_DEG: f64 = 38.0;
/// Turn of the oblique view towards +x (degrees).
const OBLIQUE_YAW_DEG: f64 = 15.0;
/// Output pixel rows per band (the unit of parallel work).
const BAND_ROWS: usize = 16;
/// Blank pixels around the model in each view image.
const PAD_PX: f64 = 8.0;
/// Outer margin of the SVG (px).
const MARGIN: f64 = 12.0;
/// Height of the title band (px).
const TITLE_H: f64 = 40.0;
/// Height of the caption band under each view (px).
const CAPTION_H: f64 = 44.0;
/// Width of the colour-scale column at the right (px).
const BAR_COLUMN: f64 = 122.0;
/// PNG size budget per image pixel (bytes): above it, the colour channels are rounded to 7 bits
/// (then 6) before encoding, which keeps the SVG of a rod at 960 px near 300 KB.
const PNG_BUDGET_BYTES_PER_PIXEL: f64 = 0.42;
/// Marker circle radius (px).
const MARKER_R: f64 = 8.0;

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

/// Turbo colour map at `t` ∈ [0, 1] (clamped; NaN maps to 0), 8-bit sRGB.
///
/// Source: A. Mikhailov, "Turbo, An Improved Rainbow Colormap for Visualization", Google AI Blog,
/// 2019; this is the polynomial approximation published with it (R. Du, GLSL `TurboColormap`, gist
/// mikhailov-work/0d177465a8151eb6ede1768d51d476c7), whose coefficients are used unchanged, the
/// result clamped to [0, 1] per channel and rounded. Endpoints: `colour_map(0) = [35, 23, 27]`
/// (near black), `colour_map(1) = [144, 13, 0]` (dark red). On [0.1, 1] the hue falls monotonically
/// from blue (≈ 225°) through cyan, green, yellow and orange to red; the lightness rises from dark
/// blue to the yellow-green middle and falls again to dark red.
pub fn colour_map(t: f64) -> [u8; 3] {
    const R4: [f64; 4] = [0.13572138, 4.61539260, -42.66032258, 132.13108234];
    const G4: [f64; 4] = [0.09140261, 2.19418839, 4.84296658, -14.18503333];
    const B4: [f64; 4] = [0.10667330, 12.64194608, -60.58204836, 110.36276771];
    const R2: [f64; 2] = [-152.94239396, 59.28637943];
    const G2: [f64; 2] = [4.27729857, 2.82956604];
    const B2: [f64; 2] = [-89.90310912, 27.34824973];
    let x = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let v4 = [1.0, x, x * x, x * x * x];
    let v2 = [x.powi(4), x.powi(5)];
    let ch = |c4: [f64; 4], c2: [f64; 2]| {
        let v = c4[0] * v4[0]
            + c4[1] * v4[1]
            + c4[2] * v4[2]
            + c4[3] * v4[3]
            + c2[0] * v2[0]
            + c2[1] * v2[1];
        (v.clamp(0.0, 1.0) * 255.0).round() as u8
    };
    [ch(R4, R2), ch(G4, G2), ch(B4, B2)]
}

/// Vertices (mm) and triangles of a surface, as [`tet10_surface`] returns them.
pub type SurfaceMesh = (Vec<[f64; 3]>, Vec<[usize; 3]>);

/// Boundary surface of a tet10 mesh as linear triangles, positions in mm.
///
/// Returns all mesh nodes converted from metres to mm (same indices as the mesh, so a nodal field
/// such as the averaged von Mises stress can be passed as [`SurfaceField::values`] unchanged;
/// interior nodes are simply not referenced) and the triangles: each 6-node boundary face (corners
/// c0 c1 c2, midside m01 m12 m20) is split into (c0, m01, m20), (m01, c1, m12), (m20, m12, c2) and
/// (m01, m12, m20), all oriented like the face (outward normal).
pub fn tet10_surface(mesh: &TetMesh) -> super::Result<SurfaceMesh> {
    let faces = boundary_faces(mesh)?;
    let vertices = mesh
        .nodes()
        .iter()
        .map(|p| [p[0] * 1e3, p[1] * 1e3, p[2] * 1e3])
        .collect();
    let mut triangles = Vec::with_capacity(4 * faces.len());
    for f in &faces {
        let [c0, c1, c2, m01, m12, m20] = f.nodes;
        triangles.extend_from_slice(&[
            [c0, m01, m20],
            [m01, c1, m12],
            [m20, m12, c2],
            [m01, m12, m20],
        ]);
    }
    Ok((vertices, triangles))
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
    let diag = norm(sub(bmax, bmin));
    ensure!(diag > 0.0, "the surface has zero extent");

    // Normalised values, shared by the views.
    let t_vals: Vec<f32> = field
        .values
        .par_iter()
        .map(|v| ((v - lo) / (hi - lo)) as f32)
        .collect();

    let avail_w = width - 2.0 * MARGIN - BAR_COLUMN;
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
            .map(|t| frame.shade(field.vertices_mm, *t))
            .collect();
        let rgba = rasterise(field.triangles, &uvd, &t_vals, &shades, &geom);
        let marker = options.marker_mm.map(|m| {
            let p = frame.project(m);
            let hidden = is_hidden(field.triangles, &uvd, p, 0.01 * diag);
            (geom.pixel(p), hidden)
        });
        rasters.push((frame, geom, rgba, marker));
    }

    // PNG encoding within the size budget: exact colours if they fit, else 7- or 6-bit channels.
    let pixels: usize = rasters
        .iter()
        .map(|r| r.1.width as usize * r.1.height as usize)
        .sum();
    let budget = (PNG_BUDGET_BYTES_PER_PIXEL * pixels as f64) as usize;
    let mut pngs = Vec::new();
    for step in [1u8, 2, 4] {
        pngs = rasters
            .par_iter()
            .map(|(_, g, rgba, _)| encode_png(&quantise(rgba, step), g.width, g.height))
            .collect::<Result<Vec<_>>>()?;
        if pngs.iter().map(Vec::len).sum::<usize>() <= budget {
            break;
        }
    }
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

/// An orthographic view: screen right, screen up and the direction towards the viewer (unit,
/// right-handed: right × up = toward).
#[derive(Clone, Debug)]
struct Frame {
    right: [f64; 3],
    up: [f64; 3],
    toward: [f64; 3],
    caption: String,
}

impl Frame {
    fn plan() -> Frame {
        Frame {
            right: [1.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            toward: [0.0, 0.0, 1.0],
            caption: "Plan view from +z (looking along −z)".into(),
        }
    }

    fn oblique() -> Frame {
        let (tilt, yaw) = (OBLIQUE_TILT_DEG.to_radians(), OBLIQUE_YAW_DEG.to_radians());
        let toward = [yaw.sin() * tilt.cos(), -tilt.sin(), yaw.cos() * tilt.cos()];
        let y = [0.0, 1.0, 0.0];
        let up = normalise(sub(y, scale(toward, dot(y, toward))));
        let right = cross(up, toward);
        Frame {
            right,
            up,
            toward,
            caption: format!(
                "Oblique view from +z, tilted {OBLIQUE_TILT_DEG}° towards −y and {OBLIQUE_YAW_DEG}° \
                 towards +x (top face and −y flank)"
            ),
        }
    }

    /// (u, v, d): right, up, towards the viewer (mm).
    fn project(&self, p: [f64; 3]) -> [f64; 3] {
        [dot(p, self.right), dot(p, self.up), dot(p, self.toward)]
    }

    /// Lambert head-light factor of a triangle; 0 for a degenerate triangle.
    fn shade(&self, x: &[[f64; 3]], t: [usize; 3]) -> f32 {
        let n = cross(sub(x[t[1]], x[t[0]]), sub(x[t[2]], x[t[0]]));
        let l = norm(n);
        if l == 0.0 || !l.is_finite() {
            return 0.0;
        }
        (AMBIENT + (1.0 - AMBIENT) * (dot(n, self.toward) / l).abs()) as f32
    }
}

/// Placement of a view's image: model (u, v) in mm → image pixels.
#[derive(Clone, Copy, Debug)]
struct ViewGeom {
    umin: f64,
    vmax: f64,
    /// px per mm.
    scale: f64,
    width: u32,
    height: u32,
}

impl ViewGeom {
    /// Fits the used vertices into at most `avail_w` × `max_h` px with [`PAD_PX`] around.
    fn fit(uvd: &[[f64; 3]], used: &[bool], avail_w: f64, max_h: f64) -> Result<ViewGeom> {
        let (mut umin, mut umax, mut vmin, mut vmax) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for (p, _) in uvd.iter().zip(used).filter(|(_, u)| **u) {
            umin = umin.min(p[0]);
            umax = umax.max(p[0]);
            vmin = vmin.min(p[1]);
            vmax = vmax.max(p[1]);
        }
        let (su, sv) = (umax - umin, vmax - vmin);
        let tiny = 1e-9 * su.max(sv);
        let mut s = f64::INFINITY;
        if su > tiny {
            s = s.min((avail_w - 2.0 * PAD_PX) / su);
        }
        if sv > tiny {
            s = s.min((max_h - 2.0 * PAD_PX) / sv);
        }
        if !(s.is_finite() && s > 0.0) {
            bail!("the surface has zero extent in a view");
        }
        Ok(ViewGeom {
            umin,
            vmax,
            scale: s,
            width: (su * s + 2.0 * PAD_PX).ceil() as u32,
            height: (sv * s + 2.0 * PAD_PX).ceil() as u32,
        })
    }

    /// Image pixel coordinates (x right, y down) of a projected point.
    fn pixel(&self, p: [f64; 3]) -> [f64; 2] {
        [
            PAD_PX + (p[0] - self.umin) * self.scale,
            PAD_PX + (self.vmax - p[1]) * self.scale,
        ]
    }
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
fn rasterise(
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
fn is_hidden(triangles: &[[usize; 3]], uvd: &[[f64; 3]], p: [f64; 3], tol: f64) -> bool {
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

/// Colour channels rounded to multiples of `step` (alpha kept); `step` 1 returns the input.
fn quantise(rgba: &[u8], step: u8) -> std::borrow::Cow<'_, [u8]> {
    if step <= 1 {
        return std::borrow::Cow::Borrowed(rgba);
    }
    let q = u16::from(step);
    let out = rgba
        .iter()
        .enumerate()
        .map(|(i, &b)| {
            if i % 4 == 3 {
                b
            } else {
                ((u16::from(b) + q / 2) / q * q).min(255) as u8
            }
        })
        .collect();
    std::borrow::Cow::Owned(out)
}

/// RGBA 8-bit PNG, default compression.
fn encode_png(rgba: &[u8], width: u32, height: u32) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::default());
        let mut writer = enc.write_header().context("PNG header")?;
        writer.write_image_data(rgba).context("PNG data")?;
        writer.finish().context("PNG end")?;
    }
    Ok(out)
}

struct RenderedView {
    frame: Frame,
    geom: ViewGeom,
    png: Vec<u8>,
    /// Image pixel position of the marker and whether it is hidden.
    marker: Option<([f64; 2], bool)>,
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

fn compose_svg(views: &[RenderedView], options: &PictureOptions, width: f64) -> String {
    let avail_w = width - 2.0 * MARGIN - BAR_COLUMN;
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
        let mut e = [0.0; 3];
        e[k] = 1.0;
        let (dx, dy) = (dot(e, f.right) * LEN, -dot(e, f.up) * LEN);
        if (dx * dx + dy * dy).sqrt() < 0.25 * LEN {
            let towards = dot(e, f.toward) > 0.0;
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

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

fn normalise(a: [f64; 3]) -> [f64; 3] {
    scale(a, 1.0 / norm(a))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    /// The embedded PNGs of an SVG, decoded: (width, height, RGBA).
    fn decode_pngs(svg: &str) -> Vec<(usize, usize, Vec<u8>)> {
        const KEY: &str = "data:image/png;base64,";
        svg.match_indices(KEY)
            .map(|(i, _)| {
                let start = i + KEY.len();
                let end = start + svg[start..].find('"').unwrap();
                let bytes = base64::engine::general_purpose::STANDARD
                    .decode(&svg[start..end])
                    .unwrap();
                let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
                    .read_info()
                    .unwrap();
                let mut buf = vec![0; reader.output_buffer_size().unwrap()];
                let info = reader.next_frame(&mut buf).unwrap();
                assert_eq!(info.color_type, png::ColorType::Rgba);
                assert_eq!(info.bit_depth, png::BitDepth::Eight);
                buf.truncate(info.buffer_size());
                (info.width as usize, info.height as usize, buf)
            })
            .collect()
    }

    fn pixel(img: &(usize, usize, Vec<u8>), x: usize, y: usize) -> [u8; 4] {
        let o = (y * img.0 + x) * 4;
        img.2[o..o + 4].try_into().unwrap()
    }

    /// First and last fully covered column of row `y`.
    fn covered_span(img: &(usize, usize, Vec<u8>), y: usize) -> (usize, usize) {
        let xs: Vec<usize> = (0..img.0).filter(|&x| pixel(img, x, y)[3] == 255).collect();
        (*xs.first().unwrap(), *xs.last().unwrap())
    }

    /// Smallest largest-channel difference between `c` and the colour map over [t0, t1].
    fn distance_to_map(c: [u8; 4], t0: f64, t1: f64) -> i32 {
        (0..=200)
            .map(|k| {
                let m = colour_map(t0 + (t1 - t0) * k as f64 / 200.0);
                (0..3)
                    .map(|j| (i32::from(c[j]) - i32::from(m[j])).abs())
                    .max()
                    .unwrap()
            })
            .min()
            .unwrap()
    }

    fn hue(c: [u8; 3]) -> f64 {
        let [r, g, b] = c.map(|v| f64::from(v) / 255.0);
        let (mx, mn) = (r.max(g).max(b), r.min(g).min(b));
        let d = mx - mn;
        let h = if d == 0.0 {
            0.0
        } else if mx == r {
            60.0 * ((g - b) / d).rem_euclid(6.0)
        } else if mx == g {
            60.0 * ((b - r) / d + 2.0)
        } else {
            60.0 * ((r - g) / d + 4.0)
        };
        // red that has wrapped past 0 (magenta side) counts as just below 360 − treat > 300 as < 0
        if h > 300.0 { h - 360.0 } else { h }
    }

    #[test]
    fn colour_map_endpoints_and_monotone_hue() {
        assert_eq!(colour_map(0.0), [35, 23, 27]);
        assert_eq!(colour_map(1.0), [144, 13, 0]);
        assert_eq!(colour_map(-3.0), colour_map(0.0));
        assert_eq!(colour_map(7.0), colour_map(1.0));
        assert_eq!(colour_map(f64::NAN), colour_map(0.0));
        let (a, b, c) = (colour_map(0.0), colour_map(0.5), colour_map(1.0));
        assert!(a != b && b != c && a != c);
        // blue, then green, then red dominate
        let m = colour_map(0.15);
        assert!(m[2] > m[0] && m[2] > m[1], "{m:?}");
        let m = colour_map(0.5);
        assert!(m[1] > m[0] && m[1] > m[2], "{m:?}");
        let m = colour_map(0.9);
        assert!(m[0] > m[1] && m[0] > m[2], "{m:?}");
        // hue non-increasing on [0.1, 1], from blue to red
        let hues: Vec<f64> = (10..=100)
            .map(|k| hue(colour_map(k as f64 / 100.0)))
            .collect();
        assert!(hues[0] > 200.0 && hues[0] < 250.0, "{}", hues[0]);
        assert!(*hues.last().unwrap() < 15.0);
        for w in hues.windows(2) {
            assert!(w[1] <= w[0] + 1.0, "hue rises: {:?}", w);
        }
    }

    fn square_options(range: [f64; 2]) -> PictureOptions {
        PictureOptions {
            title: "test".into(),
            range,
            ..Default::default()
        }
    }

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

    fn two_squares(front_first: bool) -> (Vec<[f64; 3]>, Vec<[usize; 3]>, Vec<f64>) {
        // A: [0, 1]² at z = 0, value 0.2; B: [0.5, 1.5] × [0, 1] at z = 1, value 0.8
        let mut v = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.5, 0.0, 1.0],
            [1.5, 0.0, 1.0],
            [1.5, 1.0, 1.0],
            [0.5, 1.0, 1.0],
        ];
        let mut vals = vec![0.2, 0.2, 0.2, 0.2, 0.8, 0.8, 0.8, 0.8];
        if front_first {
            v.rotate_left(4);
            vals.rotate_left(4);
        }
        let t = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
        (v, t, vals)
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

    fn single_tet10() -> TetMesh {
        let c = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let mut nodes = c.to_vec();
        for [a, b] in crate::fem::shape::TET10_EDGES {
            nodes.push(std::array::from_fn(|j| 0.5 * (c[a][j] + c[b][j])));
        }
        TetMesh::new(nodes, vec![std::array::from_fn(|i| i)]).unwrap()
    }

    #[test]
    fn tet10_surface_of_one_tet() {
        let mesh = single_tet10();
        let (v, t) = tet10_surface(&mesh).unwrap();
        assert_eq!(v.len(), 10);
        assert_eq!(t.len(), 16);
        for (p, q) in v.iter().zip(mesh.nodes()) {
            for j in 0..3 {
                assert!((p[j] - 1e3 * q[j]).abs() < 1e-9);
            }
        }
        assert_eq!(v[1], [1000.0, 0.0, 0.0]);
        // every node is used; the triangles tile the surface: total area, equal quarters, outward
        let mut used = [false; 10];
        let centroid = [250.0; 3];
        let mut total = 0.0;
        for tri in &t {
            for &i in tri {
                used[i] = true;
            }
            let n = cross(sub(v[tri[1]], v[tri[0]]), sub(v[tri[2]], v[tri[0]]));
            let area = 0.5 * norm(n);
            let on_slanted = tri
                .iter()
                .all(|&i| (v[i].iter().sum::<f64>() - 1000.0).abs() < 1e-9);
            let expected = if on_slanted {
                3f64.sqrt() / 2.0 * 1e6
            } else {
                0.5e6
            } / 4.0;
            assert!((area - expected).abs() < 1e-6 * expected, "{tri:?}: {area}");
            assert!(
                dot(n, sub(v[tri[0]], centroid)) > 0.0,
                "{tri:?} points inwards"
            );
            total += area;
        }
        assert!(used.iter().all(|u| *u));
        assert!((total - (1.5e6 + 3f64.sqrt() / 2.0 * 1e6)).abs() < 1e-3);
    }

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
