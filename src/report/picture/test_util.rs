//! Helpers shared by the picture tests: decoding the embedded PNGs, reading pixels, small meshes.

use base64::Engine as _;

use super::PictureOptions;
use super::colour_map::colour_map;
use crate::fem::mesh::TetMesh;

/// The embedded PNGs of an SVG, decoded: (width, height, RGBA).
pub(super) fn decode_pngs(svg: &str) -> Vec<(usize, usize, Vec<u8>)> {
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

/// RGBA of pixel (x, y) of a decoded image.
pub(super) fn pixel(img: &(usize, usize, Vec<u8>), x: usize, y: usize) -> [u8; 4] {
    let o = (y * img.0 + x) * 4;
    img.2[o..o + 4].try_into().unwrap()
}

/// First and last fully covered column of row `y`.
pub(super) fn covered_span(img: &(usize, usize, Vec<u8>), y: usize) -> (usize, usize) {
    let xs: Vec<usize> = (0..img.0).filter(|&x| pixel(img, x, y)[3] == 255).collect();
    (*xs.first().unwrap(), *xs.last().unwrap())
}

/// Smallest largest-channel difference between `c` and the colour map over [t0, t1].
pub(super) fn distance_to_map(c: [u8; 4], t0: f64, t1: f64) -> i32 {
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

pub(super) fn square_options(range: [f64; 2]) -> PictureOptions {
    PictureOptions {
        title: "test".into(),
        range,
        ..Default::default()
    }
}

pub(super) fn two_squares(front_first: bool) -> (Vec<[f64; 3]>, Vec<[usize; 3]>, Vec<f64>) {
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

pub(super) fn single_tet10() -> TetMesh {
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
