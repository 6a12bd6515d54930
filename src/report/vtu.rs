//! ParaView output: VTK XML unstructured grid (.vtu), ASCII, quadratic tetrahedra (VTK cell type 24,
//! whose node order is rodstudy's). Coordinates are written in millimetres; field names carry units.

use std::fmt::Write as _;
use std::path::Path;

use crate::fem::TetMesh;
use crate::fem::error::{FemError, Result};

/// VTK_QUADRATIC_TETRA.
pub const VTK_QUADRATIC_TETRA: u8 = 24;

/// A named data array: `components` values per point (or cell).
#[derive(Clone, Copy, Debug)]
pub struct VtuField<'a> {
    /// Name shown in ParaView (include the unit).
    pub name: &'a str,
    /// Components per entry (1 scalar, 3 vector, 6 symmetric tensor).
    pub components: usize,
    /// Values, entry after entry.
    pub data: &'a [f64],
}

fn data_array(s: &mut String, f: &VtuField, expected: usize) -> Result<()> {
    if f.data.len() != f.components * expected {
        return Err(FemError::InvalidInput(format!(
            "VTU field {} has {} values, expected {}",
            f.name,
            f.data.len(),
            f.components * expected
        )));
    }
    let _ = writeln!(
        s,
        r#"<DataArray type="Float64" Name="{}" NumberOfComponents="{}" format="ascii">"#,
        f.name, f.components
    );
    // written in place (no string per value): the same bytes as joining `{v:e}` with spaces
    for row in f.data.chunks(f.components) {
        for (k, v) in row.iter().enumerate() {
            if k > 0 {
                s.push(' ');
            }
            let _ = write!(s, "{v:e}");
        }
        s.push('\n');
    }
    s.push_str("</DataArray>\n");
    Ok(())
}

/// Writes `mesh` (coordinates in mm) with point and cell data to `path`.
pub fn write_vtu(
    path: &Path,
    mesh: &TetMesh,
    point_data: &[VtuField],
    cell_data: &[VtuField],
) -> Result<()> {
    let (np, nc) = (mesh.n_nodes(), mesh.n_elements());
    let mut s = String::with_capacity(100 * np + 120 * nc);
    s.push_str("<?xml version=\"1.0\"?>\n<!-- rodstudy FEM result; coordinates in mm -->\n");
    s.push_str("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n");
    let _ = writeln!(
        s,
        "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{np}\" NumberOfCells=\"{nc}\">"
    );
    s.push_str("<PointData>\n");
    for f in point_data {
        data_array(&mut s, f, np)?;
    }
    s.push_str("</PointData>\n<CellData>\n");
    for f in cell_data {
        data_array(&mut s, f, nc)?;
    }
    s.push_str("</CellData>\n<Points>\n");
    let pts: Vec<f64> = mesh
        .nodes()
        .iter()
        .flat_map(|p| p.map(|v| v * 1e3))
        .collect();
    data_array(
        &mut s,
        &VtuField {
            name: "coordinates_mm",
            components: 3,
            data: &pts,
        },
        np,
    )?;
    s.push_str(
        "</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n",
    );
    for el in mesh.elements() {
        for (k, n) in el.iter().enumerate() {
            if k > 0 {
                s.push(' ');
            }
            let _ = write!(s, "{n}");
        }
        s.push('\n');
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for e in 0..nc {
        let _ = write!(s, "{} ", 10 * (e + 1));
    }
    s.push_str("\n</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for _ in 0..nc {
        let _ = write!(s, "{VTK_QUADRATIC_TETRA} ");
    }
    s.push_str("\n</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    std::fs::write(path, s).map_err(|e| FemError::io(path, e))
}
