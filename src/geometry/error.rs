//! The defects a design file can have, each with a count and one example location.
//!
//! Every variant is worded for the engineer who exported the file: what is wrong, how often,
//! and where to look (coordinates in the file's own units). The file name is added by the
//! caller ([`crate::geometry::design`]), which wraps these errors with the path.

use std::fmt;

/// A point in the file's own units, printed compactly for error messages.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Location(pub [f64; 3]);

impl From<nalgebra::Vector3<f64>> for Location {
    fn from(v: nalgebra::Vector3<f64>) -> Self {
        Location([v.x, v.y, v.z])
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [x, y, z] = self.0;
        write!(f, "({x:.6}, {y:.6}, {z:.6})")
    }
}

/// Why a mesh was refused. Reading, topology and geometry defects of one STL file.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("cannot read the file: {0}")]
    Io(#[from] std::io::Error),
    #[error("empty file (0 bytes): not an STL")]
    Empty,
    #[error("not an STL file: {0}")]
    NotStl(String),
    #[error(
        "truncated binary STL: the header declares {declared} triangles ({expected} bytes) but the file has {actual} bytes"
    )]
    Truncated {
        declared: u64,
        expected: u64,
        actual: u64,
    },
    #[error("ASCII STL cannot be parsed: {0}")]
    Ascii(String),
    #[error("the STL holds no triangles")]
    NoTriangles,
    #[error(
        "{count} non-finite coordinate(s) (NaN or infinity); the first is in triangle {triangle}"
    )]
    NonFinite { count: usize, triangle: usize },
    #[error(
        "{count} degenerate triangle(s) (zero area or a repeated vertex); e.g. triangle {triangle} at {at}"
    )]
    Degenerate {
        count: usize,
        triangle: usize,
        at: Location,
    },
    #[error(
        "open mesh: {count} boundary edge(s) used by only one triangle (a hole in the surface); e.g. the edge {from} – {to}"
    )]
    Open {
        count: usize,
        from: Location,
        to: Location,
    },
    #[error(
        "non-manifold mesh: {count} edge(s) shared by more than two triangles; e.g. the edge {from} – {to} ({faces} triangles)"
    )]
    NonManifold {
        count: usize,
        faces: usize,
        from: Location,
        to: Location,
    },
    #[error(
        "inconsistently oriented triangles: {count} edge(s) traversed in the same direction by both of their triangles (some triangles are flipped); e.g. the edge {from} – {to}"
    )]
    Inconsistent {
        count: usize,
        from: Location,
        to: Location,
    },
    #[error(
        "{count} separate shells where one solid was expected; e.g. a second shell of {triangles} triangles near {at}"
    )]
    MultipleShells {
        count: usize,
        triangles: usize,
        at: Location,
    },
    #[error("the closed surface encloses no volume (signed volume {volume:e} in file units)")]
    ZeroVolume { volume: f64 },
}
