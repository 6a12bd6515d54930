//! Reading STL files (binary and ASCII) into a triangle soup, refusing what is not an STL.
//!
//! Binary files are decoded here (fixed 50-byte records: no parser needed, and no copy of the
//! whole file in memory); ASCII is parsed by `stl_io`. This file decides the format itself and
//! works around what `stl_io` gets wrong on real exports:
//! - a binary file whose 80-byte header starts with `solid` (many CAD exporters write that) is
//!   recognised by its exact size, 84 + 50·n bytes, whatever its header says;
//! - an ASCII file whose first line is a bare `solid` (no name) is given a name;
//! - truncated binaries, empty files and files that are neither format get their own error;
//! - non-finite coordinates (which `stl_io` passes silently) are counted and refused.

use super::error::MeshError;
use rayon::prelude::*;
use std::io::{Cursor, Read};
use std::path::Path;

/// Three vertices of one triangle, in the file's units and single precision as stored.
pub type RawTriangle = [[f32; 3]; 3];

/// Which of the two STL encodings a file uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StlFormat {
    Binary,
    Ascii,
}

/// Size of one binary triangle record: normal, three corners (12 little-endian f32) and a
/// 2-byte attribute.
const RECORD: usize = 50;

/// Records decoded per block when a binary file is streamed from disk (3.2 MB of file).
const BLOCK_RECORDS: usize = 65_536;

/// Reads an STL file from disk. See [`parse_stl`]; the result is the same, but a binary file
/// (recognised by its size, as in [`parse_stl`]) is decoded block by block as it is read, so its
/// bytes are never all in memory beside the triangles.
pub fn read_stl_file(path: &Path) -> Result<(Vec<RawTriangle>, StlFormat), MeshError> {
    let mut file = std::fs::File::open(path)?;
    let size = file.metadata()?.len();
    let mut header = [0u8; 84];
    if size >= 84 {
        file.read_exact(&mut header)?;
        let declared = u64::from(u32::from_le_bytes([
            header[80], header[81], header[82], header[83],
        ]));
        if size == 84 + RECORD as u64 * declared {
            return read_binary_records(&mut file, declared as usize);
        }
    }
    // Not binary by its size: read it whole and let `parse_stl` decide (ASCII or a refusal).
    let mut bytes = Vec::with_capacity(size as usize);
    if size >= 84 {
        bytes.extend_from_slice(&header);
    }
    file.read_to_end(&mut bytes)?;
    parse_stl(bytes)
}

/// Streams `count` binary records from `file` (positioned after the header) into triangles.
fn read_binary_records(
    file: &mut std::fs::File,
    count: usize,
) -> Result<(Vec<RawTriangle>, StlFormat), MeshError> {
    if count == 0 {
        return Err(MeshError::NoTriangles);
    }
    let mut triangles = vec![[[0f32; 3]; 3]; count];
    let mut block = vec![0u8; BLOCK_RECORDS.min(count) * RECORD];
    for out in triangles.chunks_mut(BLOCK_RECORDS) {
        let bytes = &mut block[..out.len() * RECORD];
        file.read_exact(bytes)?;
        decode_records(bytes, out);
    }
    check_finite(&triangles)?;
    Ok((triangles, StlFormat::Binary))
}

/// Decodes whole 50-byte records into `out` (one triangle per record), in parallel.
fn decode_records(bytes: &[u8], out: &mut [RawTriangle]) {
    const PER_TASK: usize = 8192;
    bytes
        .par_chunks(PER_TASK * RECORD)
        .zip(out.par_chunks_mut(PER_TASK))
        .for_each(|(bytes, out)| {
            for (record, triangle) in bytes.chunks_exact(RECORD).zip(out) {
                let f = |k: usize| {
                    let at = 12 + 4 * k;
                    f32::from_le_bytes([record[at], record[at + 1], record[at + 2], record[at + 3]])
                };
                *triangle = [[f(0), f(1), f(2)], [f(3), f(4), f(5)], [f(6), f(7), f(8)]];
            }
        });
}

/// Decides the encoding of `bytes` and parses every triangle, checking all coordinates are finite.
pub fn parse_stl(mut bytes: Vec<u8>) -> Result<(Vec<RawTriangle>, StlFormat), MeshError> {
    let format = detect_format(&bytes)?;
    if format == StlFormat::Binary {
        // The size proved the layout: 84-byte header, then n records.
        let records = &bytes[84..];
        let count = records.len() / RECORD;
        if count == 0 {
            return Err(MeshError::NoTriangles);
        }
        let mut triangles = vec![[[0f32; 3]; 3]; count];
        decode_records(records, &mut triangles);
        check_finite(&triangles)?;
        return Ok((triangles, format));
    }
    bytes = name_a_bare_solid_line(bytes);
    let mut cursor = Cursor::new(bytes);
    let reader =
        stl_io::create_stl_reader(&mut cursor).map_err(|e| MeshError::Ascii(e.to_string()))?;
    let mut triangles = Vec::with_capacity(reader.size_hint().0);
    for (index, triangle) in reader.enumerate() {
        let triangle = triangle.map_err(|e| MeshError::Ascii(format!("triangle {index}: {e}")))?;
        triangles.push(triangle.vertices.map(|v| v.0));
    }
    if triangles.is_empty() {
        return Err(MeshError::NoTriangles);
    }
    check_finite(&triangles)?;
    Ok((triangles, format))
}

/// Binary when the size is exactly 84 + 50·n for the count n in the header; ASCII when the
/// file starts with `solid` and its first bytes are text; otherwise a precise refusal.
fn detect_format(bytes: &[u8]) -> Result<StlFormat, MeshError> {
    if bytes.is_empty() {
        return Err(MeshError::Empty);
    }
    let declared = (bytes.len() >= 84).then(|| {
        u64::from(u32::from_le_bytes([
            bytes[80], bytes[81], bytes[82], bytes[83],
        ]))
    });
    let actual = bytes.len() as u64;
    if let Some(n) = declared
        && actual == 84 + 50 * n
    {
        return Ok(StlFormat::Binary);
    }
    let looks_like_text = bytes
        .iter()
        .take(1024)
        .all(|&b| b == b'\t' || b == b'\n' || b == b'\r' || (0x20..0x7f).contains(&b));
    let trimmed = bytes.trim_ascii_start();
    if trimmed.starts_with(b"solid") && looks_like_text {
        return Ok(StlFormat::Ascii);
    }
    match declared {
        Some(n) if actual < 84 + 50 * n && first_record_is_plausible(bytes) => {
            Err(MeshError::Truncated {
                declared: n,
                expected: 84 + 50 * n,
                actual,
            })
        }
        Some(n) => Err(MeshError::NotStl(format!(
            "not ASCII (no leading 'solid') and not binary (the header declares {n} triangles = {} bytes, the file has {actual})",
            84 + 50 * n
        ))),
        None => Err(MeshError::NotStl(format!(
            "{actual} bytes is too short for a binary STL (84-byte minimum) and the file does not start with 'solid'"
        ))),
    }
}

/// Whether the first 50-byte triangle record of a would-be binary STL holds ordinary floats
/// (finite, below 1e9 in magnitude), which tells a cut-off STL from some other file.
fn first_record_is_plausible(bytes: &[u8]) -> bool {
    bytes.len() >= 84 + 50
        && bytes[84..132].chunks_exact(4).all(|c| {
            let x = f32::from_le_bytes([c[0], c[1], c[2], c[3]]);
            x.is_finite() && x.abs() < 1e9
        })
}

/// `stl_io` requires `solid NAME` at the very start; leading blanks are dropped and a first
/// line that is a bare `solid` gets the name `unnamed`.
fn name_a_bare_solid_line(bytes: Vec<u8>) -> Vec<u8> {
    let rest = bytes.trim_ascii_start();
    let line_end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
    if rest[..line_end].trim_ascii() == b"solid" {
        [&b"solid unnamed"[..], &rest[line_end..]].concat()
    } else if rest.len() != bytes.len() {
        rest.to_vec()
    } else {
        bytes
    }
}

fn check_finite(triangles: &[RawTriangle]) -> Result<(), MeshError> {
    let bad = |t: &RawTriangle| t.iter().flatten().filter(|c| !c.is_finite()).count();
    let all_finite = triangles
        .par_chunks(8192)
        .all(|chunk| chunk.iter().flatten().flatten().all(|c| c.is_finite()));
    if all_finite {
        return Ok(());
    }
    let count: usize = triangles.iter().map(bad).sum();
    match triangles.iter().position(|t| bad(t) > 0) {
        Some(triangle) => Err(MeshError::NonFinite { count, triangle }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn binary(header: &[u8], triangles: &[RawTriangle]) -> Vec<u8> {
        let mut out = vec![0u8; 80];
        out[..header.len()].copy_from_slice(header);
        out.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
        for t in triangles {
            out.extend_from_slice(&[0u8; 12]);
            for c in t.iter().flatten() {
                out.extend_from_slice(&c.to_le_bytes());
            }
            out.extend_from_slice(&[0u8; 2]);
        }
        out
    }

    const TRI: RawTriangle = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    #[test]
    fn binary_with_solid_header_is_read_as_binary() {
        let bytes = binary(b"solid exported by a CAD system", &[TRI, TRI]);
        let (tris, format) = parse_stl(bytes).unwrap();
        assert_eq!(format, StlFormat::Binary);
        assert_eq!(tris, vec![TRI, TRI]);
    }

    #[test]
    fn a_file_is_read_as_its_bytes_are_parsed() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.stl");
        // More triangles than one block of the streamed reader, the header starting with solid.
        let many: Vec<RawTriangle> = (0..BLOCK_RECORDS + 1234)
            .map(|t| {
                let x = t as f32 * 0.25;
                [[x, -0.0, 1.5], [x + 1.0, 2.0, -3.0], [0.0, x, 7.0]]
            })
            .collect();
        let text = "solid\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n";
        let mut truncated = binary(b"x", &[TRI, TRI, TRI]);
        truncated.truncate(84 + 120);
        let mut nan = TRI;
        nan[2][0] = f32::INFINITY;
        for bytes in [
            binary(b"solid exported by a CAD system", &many),
            binary(b"x", &[TRI, nan, TRI]),
            text.as_bytes().to_vec(),
            truncated,
            b"solid".to_vec(),
            vec![],
            binary(b"x", &[]),
        ] {
            std::fs::write(&path, &bytes).unwrap();
            let read = read_stl_file(&path);
            let parsed = parse_stl(bytes);
            assert_eq!(format!("{read:?}"), format!("{parsed:?}"));
        }
    }

    #[test]
    fn ascii_with_bare_solid_line_is_read() {
        let text = "solid\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n";
        let (tris, format) = parse_stl(text.as_bytes().to_vec()).unwrap();
        assert_eq!(format, StlFormat::Ascii);
        assert_eq!(tris, vec![TRI]);
    }

    #[test]
    fn truncated_binary_names_the_sizes() {
        let mut bytes = binary(b"x", &[TRI, TRI, TRI]);
        bytes.truncate(84 + 120);
        assert!(first_record_is_plausible(&bytes));
        let err = parse_stl(bytes).unwrap_err();
        assert!(matches!(
            err,
            MeshError::Truncated {
                declared: 3,
                expected: 234,
                actual: 204
            }
        ));
    }

    #[test]
    fn nan_in_binary_is_refused() {
        let mut t = TRI;
        t[1][2] = f32::NAN;
        let err = parse_stl(binary(b"x", &[TRI, t])).unwrap_err();
        assert!(
            matches!(
                err,
                MeshError::NonFinite {
                    count: 1,
                    triangle: 1
                }
            ),
            "{err}"
        );
    }

    #[test]
    fn empty_short_and_foreign_files_are_refused() {
        assert!(matches!(parse_stl(vec![]), Err(MeshError::Empty)));
        assert!(matches!(
            parse_stl(b"hello".to_vec()),
            Err(MeshError::NotStl(_))
        ));
        // A compressed file: header then pseudo-random bytes.
        let mut state = 12345u32;
        let noise = (0..4000).map(|_| {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 24) as u8
        });
        let png: Vec<u8> = b"\x89PNG\r\n\x1a\n".iter().copied().chain(noise).collect();
        assert!(matches!(parse_stl(png), Err(MeshError::NotStl(_))));
        let text = "This is a README, not a mesh. ".repeat(10).into_bytes();
        assert!(matches!(parse_stl(text), Err(MeshError::NotStl(_))));
        assert!(matches!(
            parse_stl(binary(b"x", &[])),
            Err(MeshError::NoTriangles)
        ));
    }
}
