//! Runs the Python mesher `pipeline/mesh_rod.py` (gmsh + meshio) and reads its result.
//!
//! The interpreter path is an argument (the caller manages the project's virtual environment).
//! The script prints progress on standard error and one JSON line on standard output, which is
//! parsed into [`MeshReport`]. Every call carries the meshing policy ([`MeshPolicy`]). gmsh's
//! remeshing of a surface reconstructed from an STL can fail where tiny faces meet large ones; the
//! script then tries the policy's ladder of classification settings (reported in
//! `classify_angle_deg`, `curve_angle_deg`, `failed_attempts`), and where every setting fails, its
//! fallbacks that mesh the surface differently (`fallback`), so the result stays deterministic.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::policy::MeshPolicy;
use super::rodmesh::read_rodmesh;
use crate::fem::TetMesh;
use crate::fem::error::{FemError, Result};
use crate::rod::records::MeshPhases;

/// What the mesher reports (quality figures from gmsh's `getElementQualities`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MeshReport {
    /// Target element size, mm.
    pub size_mm: f64,
    /// Number of 10-node tetrahedra.
    pub elements: usize,
    /// Number of nodes.
    pub nodes: usize,
    /// Smallest signed inverse condition number ("minSICN") over the elements (1 = regular tet).
    pub min_sicn: f64,
    /// Mean of the elements' minSICN.
    pub mean_sicn: f64,
    /// Smallest scaled Jacobian ("minSJ"); 1 for straight-sided elements.
    pub min_scaled_jacobian: f64,
    /// Whether midside nodes were placed on the surface (else straight-sided elements).
    pub curved: bool,
    /// Dihedral angle of gmsh's surface classification that succeeded, degrees.
    #[serde(default)]
    pub classify_angle_deg: f64,
    /// Curve split angle of the classification that succeeded, degrees.
    #[serde(default)]
    pub curve_angle_deg: f64,
    /// Classification settings (and fallbacks) tried before and why they failed (gmsh errors or
    /// crashes).
    #[serde(default)]
    pub failed_attempts: Vec<serde_json::Value>,
    /// The fallback that made the mesh where every classification setting failed: `local
    /// refinement` or `STL surface kept` ([`super::policy::FALLBACKS`]); `None` for the usual mesh.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback: Option<String>,
    /// The gmsh mesh written (MSH 4.1).
    pub msh: PathBuf,
    /// The hand-off file read; `None` when the `.msh` was read natively (`--no-rodmesh`).
    #[serde(default)]
    pub rodmesh: Option<PathBuf>,
    /// Wall time of the mesher as it measured it, s.
    pub seconds_total: f64,
    /// gmsh version.
    pub gmsh_version: String,
    /// Wall time including Python start-up, s (measured here).
    #[serde(default)]
    pub seconds_wall: f64,
    /// Building the model before meshing (the classification on a first mesh), s.
    #[serde(default)]
    pub seconds_geometry: Option<f64>,
    /// The `.msh` was written binary in place of ASCII (a natively read mesh): its coordinates are
    /// read rounded as the ASCII file prints them ([`super::msh::read_msh_as_ascii`]).
    #[serde(default)]
    pub msh_binary: bool,
    /// Where the mesh's time went (gmsh's phases from its log, and the read measured here).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phases_s: Option<MeshPhases>,
    /// A STEP's curved mesh: the elements made straight-sided because their scaled Jacobian was
    /// below [`MeshPolicy::curved_sj_min`] (`pipeline/meshing/step.py`, `straighten_poor_curved`); `None` for
    /// an STL's mesh.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curved_elements_straightened: Option<usize>,
}

/// A mesh made from an STL, with the mesher's report.
#[derive(Clone, Debug)]
pub struct MeshedRod {
    /// The mesh, metres.
    pub mesh: TetMesh,
    /// The mesher's report.
    pub report: MeshReport,
}

/// Environment variable: the mesher's time limit in seconds (default 600), the pipeline's one
/// limit ([`crate::python_env::pipeline_timeout`]).
pub use crate::python_env::TIMEOUT_VAR as MESHER_TIMEOUT_VAR;
use crate::python_env::output_within;
pub(super) use crate::python_env::pipeline_timeout as mesher_timeout;

fn run(python: &Path, script: &Path, args: &[&std::ffi::OsStr]) -> Result<(String, f64)> {
    if !script.is_file() {
        return Err(FemError::Mesher(format!(
            "mesher script not found: {}",
            script.display()
        )));
    }
    let t0 = Instant::now();
    let out = output_within(
        Command::new(python).arg(script).args(args),
        mesher_timeout(),
    )
    .map_err(|e| FemError::Mesher(format!("{} {}: {e}", python.display(), script.display())))?;
    let secs = t0.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        let tail: Vec<&str> = stderr
            .lines()
            .rev()
            .take(15)
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect();
        return Err(FemError::Mesher(format!(
            "{} {} exited with {}:\n{}",
            python.display(),
            script.display(),
            out.status,
            tail.join("\n")
        )));
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    let last = stdout
        .lines()
        .rev()
        .find(|l| l.trim_start().starts_with('{'))
        .ok_or_else(|| {
            FemError::Mesher(format!(
                "no JSON report on standard output; stderr:\n{stderr}"
            ))
        })?;
    Ok((last.to_string(), secs))
}

/// Runs a meshing command of the script and reads what it made: its JSON report, and the
/// `.rodmesh` it names (or, without one, its `.msh` natively: the same mesh bit for bit,
/// [`super::volume`]), checked to hold the elements reported.
fn run_mesher(python: &Path, script: &Path, args: &[&std::ffi::OsStr]) -> Result<MeshedRod> {
    let (json, secs) = run(python, script, args)?;
    read_reported(&json, secs)
}

/// The mesh a JSON report of `mesh_rod.py` names (`secs`: the wall time measured here), read and
/// checked against the report.
pub(super) fn read_reported(json: &str, secs: f64) -> Result<MeshedRod> {
    let mut report: MeshReport = serde_json::from_str(json)
        .map_err(|e| FemError::Mesher(format!("cannot parse the mesher's report ({e}): {json}")))?;
    report.seconds_wall = secs;
    let t_read = Instant::now();
    let (mesh, file) = match &report.rodmesh {
        Some(rodmesh) => (read_rodmesh(rodmesh)?, rodmesh.clone()),
        None => {
            let mesh = if report.msh_binary {
                super::msh::read_msh_as_ascii(&report.msh, "mm")?
            } else {
                super::msh::read_msh_exactly(&report.msh, "mm")?
            };
            // gmsh's count may hold nodes no tetrahedron uses; the reader keeps the used ones
            report.nodes = mesh.n_nodes();
            (mesh, report.msh.clone())
        }
    };
    if let Some(p) = report.phases_s.as_mut() {
        p.model = report.seconds_geometry;
        p.read = Some(t_read.elapsed().as_secs_f64());
    }
    if mesh.n_elements() != report.elements {
        return Err(FemError::Mesher(format!(
            "{} has {} elements, the mesher reported {}",
            file.display(),
            mesh.n_elements(),
            report.elements
        )));
    }
    Ok(MeshedRod { mesh, report })
}

/// What to ask of the mesher beyond the STL and the output folder.
#[derive(Clone, Debug, Default)]
pub struct MeshRequest<'a> {
    /// Target (uniform) element size, mm; with a size field, the cap.
    pub size_mm: f64,
    /// A local size map ([`super::size_field`]), for adaptive refinement.
    pub size_field: Option<&'a Path>,
    /// Cache of the classified surface: written on first use, reused by later calls.
    pub geometry: Option<&'a Path>,
    /// Base name of the output files (default: the STL's stem).
    pub name: Option<&'a str>,
    /// Read the `.msh` natively and write no `.rodmesh` (`--no-rodmesh`): the adaptive loop's
    /// meshes, where meshio's conversion cost 0.5 s per mesh.
    pub native_read: bool,
}

/// Meshes `stl` (millimetres) with 10-node tetrahedra of target size `size_mm` by running
/// `python script mesh STL OUT_DIR --size SIZE`, and reads the resulting `OUT_DIR/<stem>.rodmesh`.
pub fn mesh_stl(
    python: &Path,
    script: &Path,
    stl: &Path,
    size_mm: f64,
    out_dir: &Path,
) -> Result<MeshedRod> {
    mesh_stl_with(
        python,
        script,
        stl,
        &MeshRequest {
            size_mm,
            ..MeshRequest::default()
        },
        out_dir,
    )
}

/// [`mesh_stl`] with a size field, a classified-surface cache and an output name.
pub fn mesh_stl_with(
    python: &Path,
    script: &Path,
    stl: &Path,
    request: &MeshRequest<'_>,
    out_dir: &Path,
) -> Result<MeshedRod> {
    let size_mm = request.size_mm;
    if !(size_mm.is_finite() && size_mm > 0.0) {
        return Err(FemError::InvalidInput(format!(
            "mesh size must be > 0 mm, got {size_mm}"
        )));
    }
    std::fs::create_dir_all(out_dir).map_err(|e| FemError::io(out_dir, e))?;
    let size = format!("{size_mm}");
    let policy = MeshPolicy::standard().arg();
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "mesh".as_ref(),
        stl.as_os_str(),
        out_dir.as_os_str(),
        "--size".as_ref(),
        size.as_ref(),
        policy.as_ref(),
    ];
    if let Some(f) = request.size_field {
        args.extend(["--size-field".as_ref(), f.as_os_str()]);
    }
    if let Some(g) = request.geometry {
        args.extend(["--geometry".as_ref(), g.as_os_str()]);
    }
    if let Some(n) = request.name {
        args.extend(["--name".as_ref(), std::ffi::OsStr::new(n)]);
    }
    if request.native_read {
        args.push("--no-rodmesh".as_ref());
    }
    run_mesher(python, script, &args)
}

/// A STEP solid to mesh in the rod frame: `p' = scale · R (p − origin)`, R's rows the frame's
/// axes in file coordinates, `scale` millimetres per file unit.
#[derive(Clone, Debug)]
pub struct StepInRodFrame {
    pub step: PathBuf,
    pub origin: [f64; 3],
    pub axes: [[f64; 3]; 3],
    pub scale: f64,
}

/// Meshes the exact geometry of a STEP solid with curved 10-node tetrahedra (midside nodes on the
/// true surfaces, made valid by gmsh's high-order optimiser) in the rod frame, millimetres, by
/// running `python script mesh-step STEP OUT_DIR --frame O,X,Y,Z --scale S --size SIZE`, and reads the
/// resulting `OUT_DIR/<name>.rodmesh`. A mesh gmsh leaves with an inverted element is refused.
pub fn mesh_step_with(
    python: &Path,
    script: &Path,
    step: &StepInRodFrame,
    request: &MeshRequest<'_>,
    out_dir: &Path,
) -> Result<MeshedRod> {
    let size_mm = request.size_mm;
    if !(size_mm.is_finite() && size_mm > 0.0) {
        return Err(FemError::InvalidInput(format!(
            "mesh size must be > 0 mm, got {size_mm}"
        )));
    }
    std::fs::create_dir_all(out_dir).map_err(|e| FemError::io(out_dir, e))?;
    let frame: String = step
        .origin
        .iter()
        .chain(step.axes.iter().flatten())
        .map(|v| format!("{v:?}"))
        .collect::<Vec<_>>()
        .join(",");
    // one argument `--frame=…`: a value that starts with "-" would read as an option
    let frame = format!("--frame={frame}");
    let (size, scale) = (format!("{size_mm}"), format!("{:?}", step.scale));
    let policy = MeshPolicy::standard().arg();
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "mesh-step".as_ref(),
        step.step.as_os_str(),
        out_dir.as_os_str(),
        frame.as_ref(),
        policy.as_ref(),
    ];
    let tail: [&std::ffi::OsStr; 4] = [
        "--scale".as_ref(),
        scale.as_ref(),
        "--size".as_ref(),
        size.as_ref(),
    ];
    args.extend(tail);
    if let Some(f) = request.size_field {
        args.extend(["--size-field".as_ref(), f.as_os_str()]);
    }
    if let Some(n) = request.name {
        args.extend(["--name".as_ref(), std::ffi::OsStr::new(n)]);
    }
    if request.native_read {
        args.push("--no-rodmesh".as_ref());
    }
    run_mesher(python, script, &args)
}

/// Converts a user's volume mesh (anything meshio reads: gmsh .msh, Abaqus/CalculiX .inp, VTU,
/// Nastran .bdf) with `python script convert IN OUT --units UNITS` and reads the result.
/// `units` is "mm" or "m" (the input's coordinates).
pub fn convert_mesh(
    python: &Path,
    script: &Path,
    input: &Path,
    output: &Path,
    units: &str,
) -> Result<TetMesh> {
    run(
        python,
        script,
        &[
            "convert".as_ref(),
            input.as_os_str(),
            output.as_os_str(),
            "--units".as_ref(),
            units.as_ref(),
        ],
    )?;
    read_rodmesh(output)
}
