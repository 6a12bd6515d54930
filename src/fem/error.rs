//! The one error type of the FEM stage: every failure is typed and names what failed (element, surface,
//! file), so that a bad mesh or a wrong set-up gives a clear message, never a silent number.

use std::path::PathBuf;

/// Result alias of the FEM stage.
pub type Result<T, E = FemError> = std::result::Result<T, E>;

/// Everything that can go wrong in the FEM stage.
#[derive(Debug, thiserror::Error)]
pub enum FemError {
    /// An element whose Jacobian determinant is zero or negative at a point where it is evaluated
    /// (a quadrature point or one of its nodes): inverted or degenerate element.
    #[error(
        "element {element}: Jacobian determinant {det_j:.3e} <= 0 at natural coordinates \
         ({:.4}, {:.4}, {:.4}) ({where_}); the element is inverted or degenerate",
        xi[0], xi[1], xi[2]
    )]
    NegativeJacobian {
        /// 0-based element index.
        element: usize,
        /// The determinant found.
        det_j: f64,
        /// Natural coordinates of the point.
        xi: [f64; 3],
        /// "quadrature point" or "node".
        where_: &'static str,
    },
    /// A midside node that is not closest to the midpoint of its own edge: wrong node order
    /// (e.g. gmsh's tetra10 order read as VTK's) or a corrupt mesh.
    #[error(
        "element {element}: midside node {local} (global {node}) is not near the midpoint of its \
         edge {edge:?} (VTK tetra10 order expected: corners 0-3, then edges 01, 12, 02, 03, 13, 23)"
    )]
    MidsideNodeOrder {
        /// 0-based element index.
        element: usize,
        /// Local node number 4..=9.
        local: usize,
        /// Global node index.
        node: usize,
        /// Local corner numbers of the edge.
        edge: [usize; 2],
    },
    /// Structural problems of a mesh (indices out of range, repeated nodes, NaN, empty, ...).
    #[error("invalid mesh: {0}")]
    InvalidMesh(String),
    /// A triangle face shared by more than two tetrahedra.
    #[error(
        "non-manifold mesh: the face with corner nodes {corners:?} is used by {count} tetrahedra"
    )]
    NonManifold {
        /// Global corner node indices (sorted).
        corners: [usize; 3],
        /// Number of tetrahedra using it.
        count: usize,
    },
    /// The problem cannot be posed on the mesh: a surface it loads or supports is not there, or
    /// not what the problem needs (the message says which and where).
    #[error("{0}")]
    Problem(String),
    /// Invalid input values (material, force, options, sizes).
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// File system errors, with the file.
    #[error("{}: {error}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The error (in the message, not a separate cause: a chain would print it twice).
        error: std::io::Error,
    },
    /// A mesh file that cannot be parsed.
    #[error("{}{}: {message}", path.display(), line_part(*line))]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number (0: whole file).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The mesher (gmsh, run by [`crate::mesher`]) failed.
    #[error("mesher failed: {0}")]
    Mesher(String),
    /// The sparse solver failed (e.g. the stiffness matrix is not positive definite because the
    /// model is not fully supported).
    #[error("solver: {0}")]
    Solver(String),
    /// A self-check of the computation failed (load resultant, equilibrium): a bug, never expected.
    #[error("self-check failed: {0}")]
    Check(String),
}

impl FemError {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        FemError::Io {
            path: path.into(),
            error: source,
        }
    }
}

/// `:line` of a [`FemError::Parse`], nothing for a whole file (line 0).
fn line_part(line: usize) -> String {
    if line > 0 {
        format!(":{line}")
    } else {
        String::new()
    }
}
