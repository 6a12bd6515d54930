//! Reading STL files (binary and ASCII) into a triangle soup, refusing what is not an STL.
//!
//! Parsing is done by `stl_io`; this file decides the format itself and works around what
//! `stl_io` gets wrong on real exports:
//! - a binary file whose 80-byte header starts with `solid` (many CAD exporters write that) is
//!   recognised by its exact size, 84 + 50·n bytes, and its header neutralised before parsing;
//! - an ASCII file whose first line is a bare `solid` (no name) is given a name;
//! - truncated binaries, empty files and files that are neither format get their own error;
//! - non-finite coordinates (which `stl_io` passes silently) are counted and refused.

use super::error::MeshError;
use std::io::Cursor;
use std::path::Path;

/// Three vertices of one triangle, in the file's units and single precision as stored.
pub type RawTriangle = [[f32; 3]; 3];

/// Which of the two STL encodings a file uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StlFormat {
    Binary,
    Ascii,
}

/// Reads an STL file from disk. See [`parse_stl`].
pub fn read_stl_file(path: &Path) -> Result<(Vec<RawTriangle>, StlFormat), MeshError> {
    parse_stl(std::fs::read(path)?)
}

/// Decides the encoding of `bytes` and parses every triangle, checking all coordinates are finite.
pub fn parse_stl(mut bytes: Vec<u8>) -> Result<(Vec<RawTriangle>, StlFormat), MeshError> {
    let format = detect_format(&bytes)?;
    if format == StlFormat::Binary && bytes.starts_with(b"solid") {
        // stl_io probes for ASCII by the first word; the size already proved this is binary.
        bytes[..5].copy_from_slice(b"SOLID");
    }
    if format == StlFormat::Ascii {
        bytes = name_a_bare_solid_line(bytes);
    }
    let mut cursor = Cursor::new(bytes);
    let reader = stl_io::create_stl_reader(&mut cursor).map_err(|e| match format {
        StlFormat::Ascii => MeshError::Ascii(e.to_string()),
        StlFormat::Binary => MeshError::NotStl(e.to_string()),
    })?;
    let mut triangles = Vec::with_capacity(reader.size_hint().0);
    for (index, triangle) in reader.enumerate() {
        let triangle = triangle.map_err(|e| match format {
            StlFormat::Ascii => MeshError::Ascii(format!("triangle {index}: {e}")),
            StlFormat::Binary => MeshError::NotStl(format!("triangle {index}: {e}")),
        })?;
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
