//! PNG encoding of the view images within a size budget (colour channels rounded to 7 or 6 bits
//! when exact colours do not fit).
//!
//! (`::png` below is the `png` crate, not this module.)

use std::borrow::Cow;

use anyhow::{Context, Result};
use rayon::prelude::*;

/// PNG size budget per image pixel (bytes): above it, the colour channels are rounded to 7 bits
/// (then 6) before encoding, which keeps the SVG of a rod at 960 px near 300 KB.
const PNG_BUDGET_BYTES_PER_PIXEL: f64 = 0.42;

/// The images (RGBA, width, height) as PNGs, together within the size budget if possible: exact
/// colours if they fit, else 7-bit channels, else 6-bit channels (kept even if still over).
pub(super) fn encode_within_budget(images: &[(&[u8], u32, u32)]) -> Result<Vec<Vec<u8>>> {
    let pixels: usize = images
        .iter()
        .map(|&(_, w, h)| w as usize * h as usize)
        .sum();
    let budget = (PNG_BUDGET_BYTES_PER_PIXEL * pixels as f64) as usize;
    let mut pngs = Vec::new();
    for step in [1u8, 2, 4] {
        pngs = images
            .par_iter()
            .map(|&(rgba, w, h)| encode_png(&quantise(rgba, step), w, h))
            .collect::<Result<Vec<_>>>()?;
        if pngs.iter().map(Vec::len).sum::<usize>() <= budget {
            break;
        }
    }
    Ok(pngs)
}

/// Colour channels rounded to multiples of `step` (alpha kept); `step` 1 returns the input.
fn quantise(rgba: &[u8], step: u8) -> Cow<'_, [u8]> {
    if step <= 1 {
        return Cow::Borrowed(rgba);
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
    Cow::Owned(out)
}

/// RGBA 8-bit PNG, default compression.
fn encode_png(rgba: &[u8], width: u32, height: u32) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    {
        let mut enc = ::png::Encoder::new(&mut out, width, height);
        enc.set_color(::png::ColorType::Rgba);
        enc.set_depth(::png::BitDepth::Eight);
        enc.set_compression(::png::Compression::default());
        let mut writer = enc.write_header().context("PNG header")?;
        writer.write_image_data(rgba).context("PNG data")?;
        writer.finish().context("PNG end")?;
    }
    Ok(out)
}
