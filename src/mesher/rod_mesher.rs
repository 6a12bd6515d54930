//! The meshes of stage 3 from the rod-frame STL: one fixed-size mesh, or the meshes the adaptive
//! loop asks for ([`crate::rod::adapt::Mesher`]), each in its own folder of the work directory,
//! with gmsh's classified surface cached between them; the loop's meshes of an STL in one gmsh
//! session ([`GmshSession`]) while it serves them.

use std::path::{Path, PathBuf};

use super::gmsh::{
    MeshReport, MeshRequest, MeshedRod, StepInRodFrame, mesh_step_with, mesh_stl, mesh_stl_with,
};
use super::gmsh_session::GmshSession;
use super::size_field::write_size_field;
use crate::fem::error::{FemError, Result};
use crate::fem::mesh::TetMesh;
use crate::rod::adapt::{MeshAsk, Mesher};
use crate::rod::records::MeshPhases;

/// gmsh on one rod: its surface (an STL in millimetres, in the rod frame), or the exact geometry
/// of its STEP file moved into the rod frame.
pub struct GmshRodMesher {
    python: PathBuf,
    script: PathBuf,
    stl: PathBuf,
    /// The exact geometry, when the design is a STEP file: meshed instead of the STL, with curved
    /// elements.
    step: Option<StepInRodFrame>,
    /// Cache of gmsh's classified surface, shared by every mesh of this surface.
    geometry: PathBuf,
    work_dir: PathBuf,
    /// What the design is called in progress messages.
    label: String,
    /// The report of the last mesh made.
    pub last_report: Option<MeshReport>,
    /// The meshes that needed one of the mesher's fallbacks: `<fallback>` for the fixed mesh,
    /// `mesh <iteration>: <fallback>` for an adaptive one.
    pub fallbacks: Vec<String>,
    /// The gmsh session of the adaptive loop, while it serves (started by the first mesh).
    session: Option<GmshSession>,
    /// Whether the loop may still use a session (not for a STEP, not after one failed, not with
    /// `RODSTUDY_GMSH_SESSION=0`).
    session_wanted: bool,
}

/// Environment variable: `0` makes every mesh of the adaptive loop in a fresh process (the same
/// meshes; for comparing the two routes, or if a session misbehaves).
pub const GMSH_SESSION_VAR: &str = "RODSTUDY_GMSH_SESSION";

impl GmshRodMesher {
    /// A mesher of the binary STL `stl_bytes` (written to `work_dir/rod_frame.stl`) whose meshes
    /// go under `work_dir`; `digest` (of the STL's bytes) keys the classified-surface cache.
    pub fn new(
        python: &Path,
        script: &Path,
        stl_bytes: &[u8],
        digest: &str,
        work_dir: &Path,
        label: &str,
    ) -> Result<Self> {
        std::fs::create_dir_all(work_dir).map_err(|e| FemError::io(work_dir, e))?;
        let stl = work_dir.join("rod_frame.stl");
        let tmp = work_dir.join(".rod_frame.stl.tmp");
        std::fs::write(&tmp, stl_bytes).map_err(|e| FemError::io(&tmp, e))?;
        std::fs::rename(&tmp, &stl).map_err(|e| FemError::io(&stl, e))?;
        Ok(GmshRodMesher {
            python: python.to_path_buf(),
            script: script.to_path_buf(),
            stl,
            step: None,
            geometry: work_dir.join(format!("classified-{}.msh", &digest[..16])),
            work_dir: work_dir.to_path_buf(),
            label: label.to_string(),
            last_report: None,
            fallbacks: Vec::new(),
            session: None,
            session_wanted: std::env::var(GMSH_SESSION_VAR).map_or(true, |v| v != "0"),
        })
    }

    /// Meshes the exact geometry of `step` (curved tet10) instead of the STL surface.
    pub fn with_step(mut self, step: StepInRodFrame) -> Self {
        self.step = Some(step);
        self.session_wanted = false;
        self
    }

    /// The mesh of `ask` from the gmsh session (started on first use), or `None` where the
    /// session does not serve: a STEP, a session that has failed (it is dropped, and says why
    /// once), or `RODSTUDY_GMSH_SESSION=0`.
    fn mesh_in_session(
        &mut self,
        ask: &MeshAsk<'_>,
        field: Option<&Path>,
        dir: &Path,
    ) -> Option<MeshedRod> {
        if !self.session_wanted {
            return None;
        }
        let session = match self.session.take() {
            Some(session) => Ok(session),
            None => GmshSession::start(&self.python, &self.script, &self.stl, &self.geometry),
        };
        let meshed = session.and_then(|session| {
            self.session
                .insert(session)
                .mesh(ask.size_m * 1e3, field, dir, "rod")
        });
        match meshed {
            Ok(m) => Some(m),
            Err(e) => {
                eprintln!(
                    "{}: mesh {}: the gmsh session stopped ({}); this mesh and the rest in fresh processes",
                    self.label,
                    ask.iteration,
                    e.to_string().lines().next().unwrap_or_default()
                );
                self.session = None;
                self.session_wanted = false;
                None
            }
        }
    }

    /// Whether the meshes are made from the exact geometry (a STEP file).
    pub fn exact_geometry(&self) -> bool {
        self.step.is_some()
    }

    /// One mesh of uniform size `size_mm` (with a size field: its cap) into `dir`, with its
    /// `.rodmesh` hand-off file.
    pub fn mesh_into(
        &self,
        size_mm: f64,
        size_field: Option<&Path>,
        dir: &Path,
    ) -> Result<MeshedRod> {
        self.mesh_into_reading(size_mm, size_field, dir, false)
    }

    /// [`Self::mesh_into`]; `native_read`: no `.rodmesh`, the `.msh` read natively (the same mesh
    /// bit for bit, without meshio's conversion).
    fn mesh_into_reading(
        &self,
        size_mm: f64,
        size_field: Option<&Path>,
        dir: &Path,
        native_read: bool,
    ) -> Result<MeshedRod> {
        if let Some(step) = &self.step {
            return mesh_step_with(
                &self.python,
                &self.script,
                step,
                &MeshRequest {
                    size_mm,
                    size_field,
                    geometry: None,
                    name: Some("rod"),
                    native_read,
                },
                dir,
            );
        }
        mesh_stl_with(
            &self.python,
            &self.script,
            &self.stl,
            &MeshRequest {
                size_mm,
                size_field,
                geometry: Some(&self.geometry),
                name: Some("rod"),
                native_read,
            },
            dir,
        )
    }

    /// One mesh of uniform size `size_mm` into `dir`, without the classified-surface cache (each
    /// size classifies the surface afresh, as a refinement study on its own wants).
    pub fn uncached(&self, size_mm: f64, dir: &Path) -> Result<MeshedRod> {
        if self.step.is_some() {
            return self.mesh_into(size_mm, None, dir);
        }
        mesh_stl(&self.python, &self.script, &self.stl, size_mm, dir)
    }

    /// The one fixed-size mesh of stage 3 (`work_dir/fixed`).
    pub fn fixed(&mut self, size_mm: f64) -> Result<MeshedRod> {
        let meshed = self.mesh_into(size_mm, None, &self.work_dir.join("fixed"))?;
        self.fallbacks.extend(meshed.report.fallback.clone());
        self.last_report = Some(meshed.report.clone());
        Ok(meshed)
    }
}

impl Mesher for GmshRodMesher {
    /// The mesh the adaptive loop asks for, in `work_dir/adapt<iteration>`. gmsh can fail to
    /// remesh a faceted surface coarsely where thin features meet ("overlapping facets"); the
    /// mesher then tries its fallbacks ([`super::policy::FALLBACKS`]), and a mesh that still fails
    /// is asked again with all sizes × 0.8, twice at most.
    fn last_phases(&self) -> Option<MeshPhases> {
        self.last_report.as_ref().and_then(|r| r.phases_s)
    }

    fn mesh(&mut self, ask: &MeshAsk<'_>) -> Result<(TetMesh, f64)> {
        let dir = self.work_dir.join(format!("adapt{}", ask.iteration));
        std::fs::create_dir_all(&dir)
            .map_err(|e| FemError::Mesher(format!("{}: {e}", dir.display())))?;
        let field_path = dir.join("size_field.bin");
        let mut scale = 1.0;
        let mut tries = 0;
        let served = if self.session_wanted {
            let field = match ask.size_map {
                Some((m, s)) => {
                    write_size_field(&field_path, m, s, 1e3, ask.above_z_m)?;
                    Some(field_path.as_path())
                }
                None => None,
            };
            self.mesh_in_session(ask, field, &dir)
        } else {
            None
        };
        let meshed = if let Some(m) = served {
            m
        } else {
            loop {
                let field = match ask.size_map {
                    Some((m, s)) => {
                        let scaled: Vec<f64> = s.iter().map(|v| v * scale).collect();
                        write_size_field(&field_path, m, &scaled, 1e3, ask.above_z_m)?;
                        Some(field_path.as_path())
                    }
                    None => None,
                };
                // the loop's meshes are read natively: no meshio conversion, no .rodmesh
                match self.mesh_into_reading(ask.size_m * 1e3 * scale, field, &dir, true) {
                    Ok(m) => break m,
                    Err(e) if tries < 2 => {
                        eprintln!(
                            "{}: mesh {} failed, sizes × {:.2} next: {}",
                            self.label,
                            ask.iteration,
                            0.8 * scale,
                            e.to_string().lines().last().unwrap_or_default()
                        );
                        scale *= 0.8;
                        tries += 1;
                    }
                    Err(e) => return Err(e),
                }
            }
        };
        let secs = meshed.report.seconds_wall.max(meshed.report.seconds_total);
        if let Some(f) = &meshed.report.fallback {
            self.fallbacks.push(format!("mesh {}: {f}", ask.iteration));
        }
        self.last_report = Some(meshed.report);
        Ok((meshed.mesh, secs))
    }
}
