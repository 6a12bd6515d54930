//! The tetrahedra of a volume mesh file as a native reader ([`super::msh`], [`super::inp`]) read
//! them, and their finishing into a [`TetMesh`]. The native readers give the mesh the meshio path
//! gives, node for node and bit for bit (`tests/mesh_readers.rs`): [`RawVolume::finish`] repeats
//! what `mesh_rod.py convert` does after meshio has read a file:
//!
//! * only tetrahedra are kept: 10-node ones (VTK tetra10 order: corners 0-3, then the midside
//!   nodes of edges 01, 12, 02, 03, 13, 23) as they are, in file order; 4-node ones are promoted to
//!   straight-sided tet10 (one new node per distinct edge at its midpoint, the new nodes numbered
//!   after the file's in the lexicographic order of their sorted corner pairs, as numpy's
//!   `unique(axis=0)` numbers them); a file with both kinds, or with none, is refused; surface,
//!   line and point elements are dropped;
//! * nodes no tetrahedron uses are dropped, the others keep their file order;
//! * the coordinates are the file's numbers times the unit (mm: × 1e-3, m: × 1), so that the
//!   mesh is in metres.

use std::path::Path;

use crate::fem::TetMesh;
use crate::fem::error::{FemError, Result};

/// Tetrahedra of a file as read, before [`RawVolume::finish`]: coordinates in the file's
/// numbers, 0-based indices into `nodes` (file order).
#[derive(Clone, Debug, Default)]
pub struct RawVolume {
    /// Node coordinates as written in the file (file order).
    pub nodes: Vec<[f64; 3]>,
    /// 10-node tetrahedra, VTK order, file order.
    pub tet10: Vec<[usize; 10]>,
    /// 4-node tetrahedra, file order.
    pub tet4: Vec<[usize; 4]>,
    /// Kinds of elements dropped (surface, line, point elements), for messages.
    pub dropped: Vec<String>,
    /// The file's id and line of each node (parallel to `nodes`; empty when the reader does not
    /// know them), for messages.
    pub node_labels: Vec<FileLabel>,
    /// The file's id and line of each tetrahedron (parallel to `tet10`, or to `tet4`).
    pub tet_labels: Vec<FileLabel>,
}

/// Where an entity of a mesh file is: its id in the file and its 1-based line (0: not known,
/// e.g. in a gmsh file read by mshio).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FileLabel {
    pub id: i64,
    pub line: usize,
}

/// `what` `k` of a file by its id in the file, else by its place in the file (1-based); the
/// line, where known, goes before the message (`file:line: …`).
fn describe(labels: &[FileLabel], k: usize, what: &str) -> String {
    labels.get(k).map_or_else(
        || {
            format!(
                "{what} {} (counting the file's tetrahedra and their nodes only)",
                k + 1
            )
        },
        |l| format!("{what} {}", l.id),
    )
}

/// VTK tetra10 edges, in the order of the midside nodes 4..9 (the same table as `mesh_rod.py`).
const TET10_EDGES: [(usize, usize); 6] = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)];

/// The factor from the file's numbers to metres: "mm" → 1e-3, "m" → 1.
pub fn unit_scale(units: &str) -> Result<f64> {
    match units {
        "mm" => Ok(1e-3),
        "m" => Ok(1.0),
        _ => Err(FemError::InvalidInput(format!(
            "mesh units must be mm or m, got {units}"
        ))),
    }
}

impl RawVolume {
    /// The mesh in metres (`scale` from [`unit_scale`]), as `mesh_rod.py convert` makes it (see
    /// the module documentation); `path` names the file in errors.
    pub fn finish(self, path: &Path, scale: f64) -> Result<TetMesh> {
        let whole = |message: String| FemError::Parse {
            path: path.to_path_buf(),
            line: 0,
            message,
        };
        let RawVolume {
            mut nodes,
            tet10,
            tet4,
            dropped,
            node_labels,
            tet_labels,
        } = self;
        // a node no tetrahedron uses is dropped below, whatever it holds (as meshio's path does)
        let mut used = vec![false; nodes.len()];
        for n in tet10.iter().flatten().chain(tet4.iter().flatten()) {
            used[*n] = true;
        }
        if let Some(k) =
            (0..nodes.len()).find(|&k| used[k] && !nodes[k].iter().all(|v| v.is_finite()))
        {
            return Err(FemError::Parse {
                path: path.to_path_buf(),
                line: node_labels.get(k).map_or(0, |l| l.line),
                message: format!(
                    "{} has a non-finite coordinate {:?}",
                    describe(&node_labels, k, "node"),
                    nodes[k]
                ),
            });
        }
        let tets: Vec<[usize; 10]> = match (tet10.is_empty(), tet4.is_empty()) {
            (false, false) => {
                return Err(whole(
                    "mixes 4-node and 10-node tetrahedra; give one kind".into(),
                ));
            }
            (true, true) => {
                let mut kinds = dropped;
                kinds.sort();
                kinds.dedup();
                return Err(whole(format!(
                    "has no tetrahedra (element types: {})",
                    if kinds.is_empty() {
                        "none".to_string()
                    } else {
                        kinds.join(", ")
                    }
                )));
            }
            (false, true) => tet10,
            (true, false) => promote_tet4(&mut nodes, &tet4),
        };
        // keep the nodes the tets use, renumbered in their file order
        let mut remap = vec![usize::MAX; nodes.len()];
        for el in &tets {
            for &n in el {
                remap[n] = 0;
            }
        }
        let mut kept = Vec::with_capacity(nodes.len());
        for (i, r) in remap.iter_mut().enumerate() {
            if *r == 0 {
                *r = kept.len();
                let p = nodes[i];
                kept.push([p[0] * scale, p[1] * scale, p[2] * scale]);
            }
        }
        let elements = tets.iter().map(|el| el.map(|n| remap[n])).collect();
        TetMesh::new(kept, elements).map_err(|e| match e {
            FemError::MidsideNodeOrder {
                element,
                local,
                edge: [a, b],
                ..
            } => FemError::Parse {
                path: path.to_path_buf(),
                line: tet_labels.get(element).map_or(0, |l| l.line),
                message: format!(
                    "{}: its node {} ({}) is not near the midpoint of the edge between its \
                     corners {} and {}: the nodes are not in the order VTK and CalculiX use \
                     (corners 1-4, then the midside nodes of edges 1-2, 2-3, 3-1, 1-4, 2-4, \
                     3-4), or the mesh is corrupt",
                    describe(&tet_labels, element, "element"),
                    local + 1,
                    describe(&node_labels, tets[element][local], "node"),
                    a + 1,
                    b + 1
                ),
            },
            e => whole(e.to_string()),
        })
    }

    /// [`RawVolume::finish`] for a mesh a user gives: also checks every element's Jacobian (as
    /// the assembly would, later and without the file's ids), and names a bad element by the
    /// file's id and line.
    pub fn finish_checked(self, path: &Path, scale: f64) -> Result<TetMesh> {
        let labels = self.tet_labels.clone();
        let mesh = self.finish(path, scale)?;
        check_elements(&mesh, path, &labels)?;
        Ok(mesh)
    }
}

/// Checks det J > 0 at every element's quadrature points and nodes ([`TetMesh::check_jacobians`]),
/// naming a bad element by `labels` (the file's ids and lines; empty: by its place in the file).
pub fn check_elements(mesh: &TetMesh, path: &Path, labels: &[FileLabel]) -> Result<()> {
    mesh.check_jacobians(crate::fem::QuadratureChoice::Auto)
        .map(|_| ())
        .map_err(|e| name_element(path, labels, e))
}

/// An element's error with the element named as the file names it.
fn name_element(path: &Path, labels: &[FileLabel], e: FemError) -> FemError {
    let FemError::NegativeJacobian { element, .. } = e else {
        return e;
    };
    let message = e.to_string();
    let detail = message
        .split_once(": ")
        .map_or(message.as_str(), |(_, rest)| rest);
    FemError::Parse {
        path: path.to_path_buf(),
        line: labels.get(element).map_or(0, |l| l.line),
        message: format!(
            "{}: {detail}; check its node order (VTK/CalculiX: corners 1-2-3 anticlockwise seen \
             from corner 4, then the midside nodes of edges 1-2, 2-3, 3-1, 1-4, 2-4, 3-4) and its \
             nodes' coordinates",
            describe(labels, element, "element")
        ),
    }
}

/// Linear tets → straight-sided tet10 exactly as `pipeline/meshing/rodmesh.py`'s `promote_tetra4` (numpy): the
/// new nodes are appended in the lexicographic order of the sorted edges, at 0.5 (a + b).
fn promote_tet4(nodes: &mut Vec<[f64; 3]>, tets: &[[usize; 4]]) -> Vec<[usize; 10]> {
    let key = |el: &[usize; 4], k: usize| {
        let (a, b) = TET10_EDGES[k];
        let (a, b) = (el[a], el[b]);
        (a.min(b), a.max(b))
    };
    let mut edges: Vec<(usize, usize)> = tets
        .iter()
        .flat_map(|el| (0..6).map(move |k| key(el, k)))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let n0 = nodes.len();
    for &(a, b) in &edges {
        let (pa, pb) = (nodes[a], nodes[b]);
        nodes.push(std::array::from_fn(|j| 0.5 * (pa[j] + pb[j])));
    }
    tets.iter()
        .map(|el| {
            let mut t = [0usize; 10];
            t[..4].copy_from_slice(el);
            for k in 0..6 {
                t[4 + k] = n0 + edges.binary_search(&key(el, k)).expect("edge listed");
            }
            t
        })
        .collect()
}
