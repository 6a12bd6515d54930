//! The hand-off of a local element-size map to the mesher (`pipeline/mesh_rod.py --size-field`).
//!
//! gmsh reads it as a list-based post-processing view of scalar tetrahedra ("SS"), used as a
//! `PostView` background field (gmsh's `examples/api/adapt_mesh.py`): per tetrahedron the x, y, z
//! of its four corners, then the size at each corner, 16 values, written here as raw
//! little-endian float64. The view is the current mesh's corner tetrahedra with the sizes wanted
//! at its corner nodes; gmsh interpolates linearly inside.

use std::io::Write;
use std::path::Path;

use crate::fem::TetMesh;
use crate::fem::error::{FemError, Result};

/// Writes the size map `sizes` (one per mesh node, only corner nodes are read) of `mesh` to
/// `path`. Coordinates and sizes are multiplied by `scale` (1e3: metres → the mesher's mm). With
/// `above_z` (m), the elements wholly at or below that plane are left out (a half model is meshed
/// above it: gmsh never evaluates the field below, and searches half the tetrahedra).
pub fn write_size_field(
    path: &Path,
    mesh: &TetMesh,
    sizes: &[f64],
    scale: f64,
    above_z: Option<f64>,
) -> Result<()> {
    if sizes.len() != mesh.n_nodes() {
        return Err(FemError::InvalidInput(format!(
            "size field has {} values for {} nodes",
            sizes.len(),
            mesh.n_nodes()
        )));
    }
    if let Some((n, s)) = sizes
        .iter()
        .enumerate()
        .find(|(_, s)| !(s.is_finite() && **s > 0.0))
    {
        return Err(FemError::InvalidInput(format!(
            "size field: node {n} has size {s}"
        )));
    }
    let mut bytes = Vec::with_capacity(mesh.n_elements() * 16 * 8);
    for el in mesh.elements() {
        if let Some(c) = above_z
            && el[..4].iter().all(|&n| mesh.nodes()[n][2] <= c)
        {
            continue;
        }
        for j in 0..3 {
            for &n in &el[..4] {
                bytes.extend_from_slice(&(mesh.nodes()[n][j] * scale).to_le_bytes());
            }
        }
        for &n in &el[..4] {
            bytes.extend_from_slice(&(sizes[n] * scale).to_le_bytes());
        }
    }
    let tmp = path.with_extension("tmp");
    std::fs::File::create(&tmp)
        .and_then(|mut f| f.write_all(&bytes))
        .map_err(|e| FemError::io(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| FemError::io(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::mesh::structured::box_tet10;

    #[test]
    fn layout_is_x4_y4_z4_s4_per_tetrahedron() {
        let mesh = box_tet10(0.002, 0.001, 0.001, 1, 1, 1).unwrap();
        let sizes: Vec<f64> = (0..mesh.n_nodes())
            .map(|n| 1e-3 * (1.0 + n as f64))
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.bin");
        write_size_field(&path, &mesh, &sizes, 1e3, None).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let v: Vec<f64> = bytes
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(v.len(), 16 * mesh.n_elements());
        for (e, el) in mesh.elements().iter().enumerate() {
            let rec = &v[16 * e..16 * e + 16];
            for a in 0..4 {
                let p = mesh.nodes()[el[a]];
                assert_eq!(rec[a], p[0] * 1e3);
                assert_eq!(rec[4 + a], p[1] * 1e3);
                assert_eq!(rec[8 + a], p[2] * 1e3);
                assert_eq!(rec[12 + a], sizes[el[a]] * 1e3);
            }
        }
        let mut bad = sizes.clone();
        bad[0] = 0.0;
        assert!(write_size_field(&path, &mesh, &bad, 1e3, None).is_err());
        // two layers of cubes: above z = 0.5 mm, the upper layer's six elements only
        let two = box_tet10(0.002, 0.001, 0.001, 1, 1, 2).unwrap();
        let sizes = vec![1e-3; two.n_nodes()];
        write_size_field(&path, &two, &sizes, 1e3, Some(0.5e-3)).unwrap();
        let v: Vec<f64> = std::fs::read(&path)
            .unwrap()
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!((two.n_elements(), v.len()), (12, 16 * 6));
        for rec in v.chunks_exact(16) {
            assert!(rec[8..12].iter().all(|z| *z >= 0.5));
        }
    }
}
