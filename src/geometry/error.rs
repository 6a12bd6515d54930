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
        // a value that {:.6} would print as 0 (a rounding artefact of 1e-14) in full
        let c = |v: f64| {
            if v != 0.0 && v.abs() < 5e-7 {
                format!("{v:e}")
            } else {
                format!("{v:.6}")
            }
        };
        write!(f, "({}, {}, {})", c(self.0[0]), c(self.0[1]), c(self.0[2]))
    }
}

/// The boundary loops of an open surface ([`super::gaps::measure_gaps`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gaps {
    /// Closed loops of boundary edges.
    pub loops: usize,
    /// Width of the widest loop (2 |A| / P), in the mesh's units.
    pub widest: f64,
    /// A point of the widest loop (its centre).
    pub at: nalgebra::Vector3<f64>,
    /// The widest is narrower than [`super::gaps::ARTEFACT_WIDTH_REL`] of the bounding-box diagonal.
    pub artefact: bool,
}

/// The holes of an open mesh, said for the engineer (see [`super::gaps`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GapsNote(pub Option<Gaps>);

impl fmt::Display for GapsNote {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Some(g) = self.0 else { return Ok(()) };
        write!(
            f,
            "; {} hole(s), the widest {:.3e} file units across near {}",
            g.loops,
            g.widest,
            Location::from(g.at)
        )?;
        if g.artefact {
            write!(
                f,
                ": a crack far narrower than any feature, vertices that should coincide written \
                 apart (an export artefact, beyond the welding tolerance): export again with a \
                 finer tolerance, or merge vertices (e.g. MeshLab's \"Merge Close Vertices\")"
            )
        } else {
            write!(
                f,
                ": a missing face, not a rounding: repair the surface in CAD and export it again \
                 as a closed solid"
            )
        }
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
        "open mesh: {count} boundary edge(s) used by only one triangle (a hole in the surface); e.g. the edge {from} – {to}{gaps}"
    )]
    Open {
        count: usize,
        from: Location,
        to: Location,
        /// What the holes look like (empty when not measured).
        gaps: GapsNote,
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
