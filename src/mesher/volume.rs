//! A user's volume mesh (`fem --mesh FILE`, `cycle --mesh FILE`) into a [`TetMesh`]: gmsh MSH 4.1
//! ([`super::msh`]) and Abaqus/CalculiX `.inp` ([`super::inp`]) are read natively, in this
//! process ([`super::raw_volume`] finishes what they read as meshio's path would); everything
//! else (VTU, Nastran `.bdf`/`.nas`, gmsh MSH 2.2 and 4.0) goes through meshio
//! (`pipeline/mesh_rod.py convert`, [`super::gmsh::convert_mesh`]).

use std::path::Path;

use super::gmsh::convert_mesh;
use super::raw_volume::{RawVolume, unit_scale};
use crate::fem::TetMesh;
use crate::fem::error::{FemError, Result};

/// How a volume mesh file is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeReader {
    /// gmsh MSH 4.1 (ASCII or binary), natively ([`super::msh`]).
    GmshMsh41,
    /// Abaqus/CalculiX `.inp`, natively ([`super::inp`]).
    AbaqusInp,
    /// meshio, through `pipeline/mesh_rod.py convert` (VTU, Nastran, MSH 2.2/4.0, ...).
    Meshio,
}

/// Environment variable: `meshio` sends every volume mesh through meshio (the Python path), as
/// before the native readers; for comparisons.
pub const MESH_READER_VAR: &str = "RODSTUDY_MESH_READER";

/// Which reader takes `path`: `.inp` natively; `.msh` natively when its `$MeshFormat` says 4.1
/// (older versions go to meshio); anything else to meshio. [`MESH_READER_VAR`]` = meshio` sends
/// everything to meshio.
pub fn volume_reader(path: &Path) -> Result<VolumeReader> {
    match std::env::var(MESH_READER_VAR).as_deref() {
        Ok("meshio") => return Ok(VolumeReader::Meshio),
        Ok("native") | Ok("") | Err(_) => {}
        Ok(other) => {
            return Err(FemError::InvalidInput(format!(
                "{MESH_READER_VAR}={other}: expected native or meshio"
            )));
        }
    }
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "inp" => Ok(VolumeReader::AbaqusInp),
        "msh" => Ok(if super::msh::msh_version(path)? == "4.1" {
            VolumeReader::GmshMsh41
        } else {
            VolumeReader::Meshio
        }),
        _ => Ok(VolumeReader::Meshio),
    }
}

/// Reads `path` natively (a gmsh MSH 4.1 file or an Abaqus/CalculiX `.inp` file, by its
/// extension; others are an error, and so is a `.msh` of another version),
/// the file's numbers in `units` ("mm" or "m"), into a mesh in metres.
pub fn read_volume_mesh_native(path: &Path, units: &str) -> Result<TetMesh> {
    let scale = unit_scale(units)?;
    read_raw_native(path)?.finish(path, scale)
}

/// The tetrahedra of a gmsh MSH 4.1 or `.inp` file as read, before they are finished.
fn read_raw_native(path: &Path) -> Result<RawVolume> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "msh" => super::msh::read_msh(path),
        "inp" => super::inp::read_inp(path),
        _ => Err(FemError::InvalidInput(format!(
            "{}: not read natively (only gmsh MSH 4.1 and Abaqus/CalculiX .inp are)",
            path.display()
        ))),
    }
}

/// Reads a user's volume mesh `path` (the file's numbers in `units`, "mm" or "m") into a mesh in
/// metres: natively for gmsh MSH 4.1 and `.inp`, else through meshio (`pipeline/mesh_rod.py
/// convert` in the project's Python environment, which writes `work_dir/user.rodmesh`). Returns
/// the reader used beside the mesh.
pub fn read_volume_mesh(
    path: &Path,
    units: &str,
    work_dir: &Path,
) -> Result<(TetMesh, VolumeReader)> {
    if !path.is_file() {
        return Err(FemError::io(
            path,
            std::io::Error::new(std::io::ErrorKind::NotFound, "no such mesh file"),
        ));
    }
    let reader = volume_reader(path)?;
    if reader != VolumeReader::Meshio {
        let scale = unit_scale(units)?;
        let raw = read_raw_native(path)?;
        return Ok((raw.finish_checked(path, scale)?, reader));
    }
    let mesh = read_volume_mesh_meshio(path, units, work_dir)?;
    super::raw_volume::check_elements(&mesh, path, &[])?;
    Ok((mesh, reader))
}

/// Reads `path` through meshio (`pipeline/mesh_rod.py convert`, writing
/// `work_dir/user.rodmesh`), whatever its format: the reference the native readers are held to.
pub fn read_volume_mesh_meshio(path: &Path, units: &str, work_dir: &Path) -> Result<TetMesh> {
    unit_scale(units)?;
    let python = crate::python_env::python().map_err(|e| FemError::Mesher(format!("{e:#}")))?;
    let script = crate::python_env::pipeline_script(super::MESHER_SCRIPT);
    std::fs::create_dir_all(work_dir).map_err(|e| FemError::io(work_dir, e))?;
    convert_mesh(
        &python,
        &script,
        path,
        &work_dir.join("user.rodmesh"),
        units,
    )
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_coordinate_reads_as_its_16_digit_print() {
        // what C's printf("%.16g") prints for these doubles, read back (glibc; gmsh's ASCII MSH)
        for (v, printed) in [
            (0.1 + 0.2, "0.3"),
            (1.0 / 3.0, "0.3333333333333333"),
            (2.0 / 3.0, "0.6666666666666666"),
            (-20.0, "-20"),
            (1.0 + f64::EPSILON, "1"),
        ] {
            let expected: f64 = printed.parse().unwrap();
            assert_eq!(
                super::super::msh::as_printed_16g(v).to_bits(),
                expected.to_bits(),
                "{v:e}"
            );
        }
        // a double that needs 17 digits is not its own 16-digit print
        assert_ne!(super::super::msh::as_printed_16g(0.1 + 0.2), 0.1 + 0.2);
    }
}
