//! gmsh MSH 4.1 files (ASCII and binary) read natively through the `mshio` crate.
//!
//! Format: the gmsh reference manual, "MSH file format" (version 4.1,
//! <https://gmsh.info/doc/texinfo/gmsh.html#MSH-file-format>): `$MeshFormat` (`4.1 FILE-TYPE
//! DATA-SIZE`, file type 0 ASCII, 1 binary), `$Entities`, `$Nodes` (blocks per entity: node tags,
//! then x y z), `$Elements` (blocks per entity and element type: element tag, then the node tags);
//! other sections are skipped. Element type 11 is the 10-node tetrahedron, type 4 the 4-node one.
//!
//! Node order: gmsh's 10-node tetrahedron numbers its midside nodes along edges 01, 12, 20, 30,
//! **32, 31** (manual, "Node ordering"), VTK's along 01, 12, 02, 03, **13, 23**: the last two are
//! swapped here (meshio's `_gmsh_to_meshio_order` does the same permutation,
//! `[0, 1, 2, 3, 4, 5, 6, 7, 9, 8]`), so that the mesh is in the VTK order used throughout.
//!
//! Nodes are numbered in the order they appear in the file (node blocks in order), as meshio
//! numbers them; elements refer to them by tag. One limit of `mshio` 0.4: when the tags of the
//! `$Nodes` section are contiguous (max − min + 1 = count, as gmsh always writes them) it keeps no
//! tags and the tag of the i-th node in file order is taken to be min + i; a file with contiguous
//! but permuted tags would be misnumbered (and then refused by the mesh validation: midside nodes
//! off their edges). Sparse tags are read as written.
//!
//! Versions other than 4.1 (2.2, 4.0) are read by meshio instead ([`super::volume`]).

use std::collections::HashMap;
use std::path::Path;

use mshio::mshfile::ElementType;

use super::raw_volume::{FileLabel, RawVolume};
use crate::fem::TetMesh;
use crate::fem::error::{FemError, Result};

/// gmsh's 10-node tetrahedron → VTK's: swap the midside nodes 8 and 9.
pub const GMSH_TO_VTK_TET10: [usize; 10] = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8];

fn perr(path: &Path, line: usize, message: impl Into<String>) -> FemError {
    FemError::Parse {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

/// The version in the `$MeshFormat` section at the start of `path` ("4.1", "2.2", ...).
pub fn msh_version(path: &Path) -> Result<String> {
    use std::io::Read;
    let mut head = Vec::with_capacity(256);
    std::fs::File::open(path)
        .and_then(|f| f.take(256).read_to_end(&mut head))
        .map_err(|e| FemError::io(path, e))?;
    header_fields(path, &head).map(|(v, _, _)| v)
}

/// Version, file type and data size from the first two lines.
fn header_fields(path: &Path, bytes: &[u8]) -> Result<(String, u32, u32)> {
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(256)]);
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    if lines.next() != Some("$MeshFormat") {
        return Err(perr(path, 1, "not a gmsh mesh: '$MeshFormat' expected"));
    }
    let fields: Vec<&str> = lines.next().unwrap_or("").split_whitespace().collect();
    match fields.as_slice() {
        [v, t, d] => {
            let t = t
                .parse()
                .map_err(|_| perr(path, 2, format!("bad file type '{t}'")))?;
            let d = d
                .parse()
                .map_err(|_| perr(path, 2, format!("bad data size '{d}'")))?;
            Ok((v.to_string(), t, d))
        }
        _ => Err(perr(
            path,
            2,
            "expected 'VERSION FILE-TYPE DATA-SIZE' after $MeshFormat",
        )),
    }
}

/// 1-based line of the byte at `offset` (for a binary file: the line count of the text up to it).
fn line_of(bytes: &[u8], offset: usize) -> usize {
    1 + bytes[..offset.min(bytes.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

/// The end of the `$EndElements` line (the sections a mesh needs, `$MeshFormat` to `$Elements`), or
/// the whole file without one (mshio then reports the missing section).
fn mesh_sections_end(bytes: &[u8]) -> usize {
    const END: &[u8] = b"\n$EndElements";
    bytes
        .windows(END.len())
        .position(|w| w == END)
        .map_or(bytes.len(), |i| {
            let after = i + END.len();
            match bytes[after..].iter().position(|&b| b == b'\n') {
                Some(nl) => after + nl + 1,
                None => bytes.len(),
            }
        })
}

/// Reads the tetrahedra of a gmsh MSH 4.1 file (ASCII or binary); see the module documentation.
pub fn read_msh(path: &Path) -> Result<RawVolume> {
    let bytes = std::fs::read(path).map_err(|e| FemError::io(path, e))?;
    let (version, file_type, data_size) = header_fields(path, &bytes)?;
    if version != "4.1" {
        return Err(perr(
            path,
            2,
            format!("MSH version {version}: only 4.1 is read natively"),
        ));
    }
    // mshio panics on sizes it has no parser for: refuse them first
    if file_type > 1 || !(data_size == 4 || data_size == 8) {
        return Err(perr(
            path,
            2,
            format!("file type {file_type} / data size {data_size}: expected 0 or 1 and 4 or 8"),
        ));
    }
    // what follows the elements (gmsh's $Periodic, $Parametrizations of a classified surface,
    // $NodeData, …; MSH 4.1 orders the sections so) is not parsed: a gmsh-classified rod's
    // reparametrisation is three quarters of its file and, in mshio, of its reading time
    let bytes = &bytes[..mesh_sections_end(&bytes)];
    let msh = mshio::parse_msh_bytes(bytes).map_err(|e| {
        let offset = e
            .backtrace
            .first()
            .map_or(0, |(i, _)| i.as_ptr() as usize - bytes.as_ptr() as usize);
        let what: Vec<String> = e
            .backtrace
            .iter()
            .rev()
            .map(|(_, k)| match k.context() {
                Some(c) => c.to_string(),
                None => k.to_string(),
            })
            .collect();
        perr(path, line_of(bytes, offset), what.join(": "))
    })?;
    let nodes_section = msh
        .data
        .nodes
        .as_ref()
        .ok_or_else(|| perr(path, 0, "no $Nodes section"))?;
    let elements_section = msh
        .data
        .elements
        .as_ref()
        .ok_or_else(|| perr(path, 0, "no $Elements section"))?;

    // nodes in file order, and node tag → that index
    let mut raw = RawVolume::default();
    let sparse = nodes_section
        .node_blocks
        .iter()
        .any(|b| b.node_tags.is_some());
    let mut tag_index: HashMap<u64, usize> = HashMap::new();
    for block in &nodes_section.node_blocks {
        let first = raw.nodes.len();
        if let Some(tags) = &block.node_tags {
            for (&tag, &i) in tags {
                if tag_index.insert(tag, first + i).is_some() {
                    return Err(perr(path, 0, format!("node tag {tag} appears twice")));
                }
            }
        }
        raw.nodes
            .extend(block.nodes.iter().map(|n| [n.x, n.y, n.z]));
    }
    if sparse && tag_index.len() != raw.nodes.len() {
        return Err(perr(
            path,
            0,
            format!(
                "{} nodes but {} node tags",
                raw.nodes.len(),
                tag_index.len()
            ),
        ));
    }
    let min_tag = nodes_section.min_node_tag;
    let n_nodes = raw.nodes.len();
    let index = |tag: u64| -> Option<usize> {
        if sparse {
            tag_index.get(&tag).copied()
        } else {
            tag.checked_sub(min_tag)
                .map(|i| i as usize)
                .filter(|&i| i < n_nodes)
        }
    };
    let unknown = |tag: u64, element: u64| {
        perr(
            path,
            0,
            format!("element {element} refers to node tag {tag}, which $Nodes does not define"),
        )
    };
    for block in &elements_section.element_blocks {
        match block.element_type {
            ElementType::Tet10 => {
                for el in &block.elements {
                    let mut t = [0usize; 10];
                    for (a, &from) in GMSH_TO_VTK_TET10.iter().enumerate() {
                        let tag = el.nodes[from];
                        t[a] = index(tag).ok_or_else(|| unknown(tag, el.element_tag))?;
                    }
                    raw.tet10.push(t);
                    raw.tet_labels.push(FileLabel {
                        id: el.element_tag as i64,
                        line: 0,
                    });
                }
            }
            ElementType::Tet4 => {
                for el in &block.elements {
                    let mut t = [0usize; 4];
                    for (a, &tag) in el.nodes.iter().enumerate() {
                        t[a] = index(tag).ok_or_else(|| unknown(tag, el.element_tag))?;
                    }
                    raw.tet4.push(t);
                    raw.tet_labels.push(FileLabel {
                        id: el.element_tag as i64,
                        line: 0,
                    });
                }
            }
            other => raw.dropped.push(format!("{other:?}")),
        }
    }
    Ok(raw)
}
/// Reads a gmsh MSH 4.1 file (ASCII or binary) exactly, its numbers in `units` ("mm" or "m"),
/// into a mesh in metres.
pub fn read_msh_exactly(path: &Path, units: &str) -> Result<TetMesh> {
    let scale = super::raw_volume::unit_scale(units)?;
    read_msh(path)?.finish(path, scale)
}

/// Reads a binary gmsh MSH 4.1 file that the pipeline wrote in place of an ASCII one
/// (`pipeline/meshing/quality.py`, `written_mesh`: 0.1 s less per mesh) as the ASCII file would have
/// been read: each coordinate rounded to the 16 significant digits gmsh's ASCII writer prints
/// (`"%.16g"`), so that the mesh, and every result from it, is the ASCII file's to the last bit.
/// (A user's binary file is read exactly, by [`read_msh_exactly`].)
pub fn read_msh_as_ascii(path: &Path, units: &str) -> Result<TetMesh> {
    let scale = super::raw_volume::unit_scale(units)?;
    let mut raw = read_msh(path)?;
    for v in raw.nodes.iter_mut().flatten() {
        *v = as_printed_16g(*v);
    }
    raw.finish(path, scale)
}

/// `v` as C's `printf("%.16g", v)` prints it and a correct parser reads it back: rounded to 16
/// significant digits (both correctly rounded, so `{:.15e}`'s 16 digits are `%.16g`'s).
pub(super) fn as_printed_16g(v: f64) -> f64 {
    if !v.is_finite() {
        return v;
    }
    format!("{v:.15e}")
        .parse()
        .expect("a formatted float parses")
}
