//! What stage 3 sets up once per design before any mesh: the rod-frame surface, the half model of
//! a mirror-symmetric STL, the exact geometry of a STEP, the bores, the material, the surface's
//! edges and the rod options ([`Setup`]).

use super::super::criterion::verdict;
use super::super::records::{DesignFem, LoadedDesign, MeshSummary, StageMesh};
use super::super::rod_surface::{RodFrameSurface, rod_frame_surface};
use crate::config::{StudyConfig, Symmetry};
use crate::fem::{Material, TetMesh};
use crate::mesher::{GmshRodMesher, MESHER_SCRIPT, StepInRodFrame};
use crate::python_env::{pipeline_script, python};
use crate::rod::facets::{MAX_FILLET_RADIUS_MM, SurfaceEdges};
use crate::rod::records::HalfModel;
use crate::rod::smooth::{SmoothSurface, geometry_check};
use crate::rod::solve::RodSolution;
use crate::rod::{BoreSpec, RodOptions};
use anyhow::{Context, Result};
use std::path::Path;

use super::*;

/// What every mode shares: the rod-frame surface, its bores, the material, the singular edges
/// and the options of the rod analysis.
pub(super) struct Setup {
    pub(super) surface: RodFrameSurface,
    /// The half model's surface, when the rod is mirror-symmetric ([`half_surface`]): what gmsh
    /// meshes instead of `surface`.
    pub(super) half: Option<HalfSurface>,
    /// The exact geometry in the rod frame, for a STEP design.
    pub(super) step: Option<StepInRodFrame>,
    pub(super) bores: BoreSpec,
    pub(super) material: Material,
    /// The surface's edges: kinks, faceted small fillets, sharp edges ([`Setup::edges`]).
    pub(super) edges: Option<SurfaceEdges>,
    /// The caller keeps the factorised K of the final mesh (buckling on it).
    pub(super) keep_system: bool,
    pub(super) singular_edges: Vec<[[f64; 3]; 2]>,
    pub(super) rod: RodOptions,
    /// `<file>: FEM`, the context of every error.
    pub(super) context: String,
}

pub(super) const FRAME: &str =
    "rod frame, mm: origin at the crank pin A, x along A→B, z along the pin axis";

impl Setup {
    /// Everything but the surface's edges, which [`Setup::set_edges`] adds (a given mesh works
    /// them out while K is factorised, [`fem_user_mesh`]). `for_gmsh`: the surface is what gmsh
    /// will mesh (simplified); else a given mesh is solved and the surface only tells the sharp
    /// re-entrant edges. With a pressure trace the F_y case carries the largest pin force across
    /// the rod over the engine's cycle ([`FemLoads::transverse_n`]).
    pub(super) fn without_edges(
        design: &LoadedDesign,
        loads: &FemLoads,
        config: &StudyConfig,
        for_gmsh: bool,
        keep_system: bool,
    ) -> Result<Self> {
        let context = format!("{}: FEM", design.file.display());
        if let Some(gap) = design.loose_gap_m {
            anyhow::bail!(
                "{context}: the file holds bodies that do not touch (the nearest two at least \
                 {:.3} mm apart): a body that touches nothing carries no load and has no static \
                 solution; join them in CAD (rod and cap meet at the joint face) or remove the \
                 loose body",
                gap * 1e3
            );
        }
        let surface = rod_frame_surface(design, for_gmsh);
        let half = if for_gmsh && design.format.step().is_none() {
            half_surface(&surface, config.fem.symmetry)
        } else {
            None
        };
        let rod = RodOptions {
            mirror_plane_z_m: half.as_ref().map(|h| h.plane_z_mm * 1e-3),
            fixed_band_m: Some(config.fem.fixed_band_mm * 1e-3),
            singular_band_m: Some(config.fem.singular_band_mm * 1e-3),
            fy_force_n: loads.transverse_n,
            exact_geometry: design.format.step().is_some(),
            // the STL route keeps the last solve's system: the geometry check reuses its symbolic
            // analysis
            keep_system: keep_system || (for_gmsh && design.format.step().is_none()),
            ..RodOptions::default()
        };
        let step = design.format.step().map(|report| {
            let f = &design.frame;
            let to_metres = report.metres_per_unit;
            StepInRodFrame {
                step: design.file.clone(),
                origin: (f.origin / to_metres).into(),
                axes: [f.x.into(), f.y.into(), f.z.into()],
                scale: to_metres * 1e3,
            }
        });
        // a partial bore (a big end without its cap) is loaded or fixed on the arc that exists
        let mut bores = surface.bores();
        [bores.loaded_arc_deg, bores.fixed_arc_deg] = loads.bore_arcs_deg;
        bores.bore_load = config.fem.bore_load;
        bores.clearance_a_m = config.fem.clearance_a_mm.map(|c| c * 1e-3);
        bores.clearance_b_m = config.fem.clearance_b_mm.map(|c| c * 1e-3);
        bores.pins = config.fem.pins;
        bores.pin_inner_ratio = config.fem.pin_inner_ratio;
        Ok(Setup {
            step,
            bores,
            surface,
            half,
            material: Material::from(&config.fem),
            edges: None,
            keep_system,
            singular_edges: Vec::new(),
            rod,
            context,
        })
    }

    /// [`Setup::without_edges`] with the surface's edges ([`Setup::set_edges`]).
    pub(super) fn new(
        design: &LoadedDesign,
        loads: &FemLoads,
        config: &StudyConfig,
        for_gmsh: bool,
        keep_system: bool,
    ) -> Result<Self> {
        let mut setup = Self::without_edges(design, loads, config, for_gmsh, keep_system)?;
        let edges = setup.surface_edges();
        setup.set_edges(edges);
        Ok(setup)
    }

    /// The surface's edges classified, and its sharp re-entrant edges (segments, m).
    pub(super) fn surface_edges(&self) -> (SurfaceEdges, Vec<[[f64; 3]; 2]>) {
        let edges = SurfaceEdges::new(
            &self.surface.vertices,
            &self.surface.triangles,
            FEATURE_ANGLE_DEG,
            MAX_FILLET_RADIUS_MM,
        );
        let singular = edges
            .sharp_reentrant(&self.surface.vertices)
            .into_iter()
            .map(|s| s.map(|p| p.map(|v| v * 1e-3)))
            .collect();
        (edges, singular)
    }

    /// Sets the edges of [`Setup::surface_edges`] and what the rod analysis takes of them.
    pub(super) fn set_edges(&mut self, (edges, singular): (SurfaceEdges, Vec<[[f64; 3]; 2]>)) {
        self.rod.singular_edges_m = singular.clone();
        self.rod.fillet_kink_edges = edges.fillet_kinks();
        self.singular_edges = singular;
        self.edges = Some(edges);
    }

    /// The surface's edges ([`Setup::set_edges`] has set them: every constructor but
    /// [`Setup::without_edges`] does).
    pub(super) fn edges(&self) -> &SurfaceEdges {
        self.edges
            .as_ref()
            .expect("the surface's edges are set before they are used")
    }

    /// The gmsh adapter on this surface (writes `work_dir/rod_frame.stl`), or on the exact
    /// geometry of a STEP design (curved tet10).
    pub(super) fn mesher(&self, work_dir: &Path) -> Result<GmshRodMesher> {
        let python = python().with_context(|| self.context.clone())?;
        let (stl_bytes, digest) = match &self.half {
            Some(h) => (&h.stl_bytes, &h.digest),
            None => (&self.surface.stl_bytes, &self.surface.digest),
        };
        let mesher = GmshRodMesher::new(
            &python,
            &pipeline_script(MESHER_SCRIPT),
            stl_bytes,
            digest,
            work_dir,
            &self.context[..self.context.len() - ": FEM".len()],
        )
        .with_context(|| self.context.clone())?;
        Ok(match &self.step {
            Some(step) => mesher.with_step(step.clone()),
            None => mesher,
        })
    }

    /// What the meshes are made from, for `mesh.source`.
    pub(super) fn source(&self) -> &'static str {
        if self.step.is_some() {
            "gmsh from the STEP (curved tet10 on the exact geometry)"
        } else {
            "gmsh from the STL (straight-sided tet10)"
        }
    }

    /// The record and the outcome of a solution on `mesh`.
    pub(super) fn outcome(
        self,
        force_n: f64,
        config: &StudyConfig,
        summary: MeshSummary,
        mesh: TetMesh,
        solution: RodSolution,
    ) -> FemOutcome {
        let criterion = verdict(&solution.result, config, self.surface.centre_distance_mm);
        FemOutcome {
            record: DesignFem {
                force_n,
                mesh: summary,
                fem: solution.result.clone(),
                criterion,
                buckling_load_factor: None,
                buckling_load_factor_contact: None,
            },
            mesh: StageMesh {
                mesh,
                bores: self.bores,
                singular_edges_m: self.singular_edges,
                fixed_band_m: config.fem.fixed_band_mm * 1e-3,
                singular_band_m: config.fem.singular_band_mm * 1e-3,
                half_model: solution.result.half_model.clone(),
            },
            solution,
            buckling_run: None,
            contact: None,
        }
    }

    /// Splits each case's estimated error into its discretisation part (as estimated so far) and
    /// its geometry part, and folds the two into `estimated_error_rel` (their sum: a bound). The
    /// geometry part of a STEP design is 0 (the exact geometry, curved elements); of an STL, the
    /// change of the judged peak when the same mesh is curved onto the smooth surface through the
    /// STL's vertices ([`crate::rod::smooth`]).
    ///
    /// With `buckling_n`, the buckling analysis under that compression runs beside the geometry
    /// check, on the kept factorisation, and is returned.
    pub(super) fn add_geometry_error(
        &self,
        mesh: &TetMesh,
        solution: &mut RodSolution,
        force_n: f64,
        buckling_n: Option<f64>,
    ) -> Option<BucklingRun> {
        // the first solve's symbolic analysis serves the second; its factor is freed first unless
        // the caller keeps it
        let symbolic = solution
            .system
            .as_ref()
            .map(|s| s.factor.symbolic().clone());
        let system = solution.system.clone();
        if !self.keep_system {
            solution.system = None;
        }
        let buckle = || {
            buckling_n.map(|n| BucklingRun {
                compression_n: n,
                result: rod_buckling_with(mesh, &self.material, &self.bores, n, system.as_deref())
                    .map_err(Into::into),
            })
        };
        let r = &mut solution.result;
        let peaks: Vec<f64> = r
            .cases
            .iter()
            .map(|c| c.max_von_mises_away_from_fixed_mpa)
            .collect();
        // per case: the geometry part (None: could not be estimated) and the smooth peak
        let (smooth, buckled): (Vec<(Option<f64>, Option<f64>)>, _) = if self.step.is_some() {
            (vec![(Some(0.0), None); peaks.len()], buckle())
        } else {
            let surface = SmoothSurface::new(
                &self.surface.vertices,
                &self.surface.triangles,
                self.edges(),
                2.0,
            );
            // the mesh solved, curved: a half model's half, solved as the half and mirrored;
            // else the whole
            let half = r.half_model.as_ref();
            let rod = RodOptions {
                keep_system: false,
                reuse_symbolic: symbolic,
                mirror_plane_z_m: half.map(HalfModel::plane_z_m),
                ..self.rod.clone()
            };
            let (checked, buckled) = rayon::join(
                || {
                    let half_mesh = half.map(|h| h.half_of(mesh)).transpose()?;
                    let solved = half_mesh.as_ref().unwrap_or(mesh);
                    geometry_check(solved, &surface, &self.material, &self.bores, force_n, &rod)
                },
                buckle,
            );
            let smooth = match checked {
                Ok(check) => {
                    r.geometry_check = Some(check.record());
                    check
                        .peaks_mpa
                        .iter()
                        .zip(&peaks)
                        .map(|(p, peak)| (Some((p - peak).abs() / peak), Some(*p)))
                        .collect()
                }
                Err(e) => {
                    r.warnings.push(format!(
                        "the geometry error (what the STL's facets do to the judged peak) is unknown: the mesh curved onto the smooth surface through the STL's vertices could not be solved ({e}); the error bars are the discretisation's alone"
                    ));
                    vec![(None, None); peaks.len()]
                }
            };
            (smooth, buckled)
        };
        for (case, (g, p)) in r.cases.iter_mut().zip(smooth) {
            case.set_error_bar(case.estimated_discretisation_error_rel, g);
            case.smooth_surface_peak_mpa = p;
        }
        buckled
    }

    pub(super) fn surface_triangles(&self) -> [usize; 2] {
        [self.surface.triangles_export, self.surface.triangles.len()]
    }
}

/// The half model's surface: the rod-frame surface's half z ≥ c as the binary STL gmsh meshes,
/// open at the cut (gmsh closes it with a plane surface on the cut's classified curves,
/// `pipeline/meshing/cap.py`'s `cap_open_cut`; the cap of [`crate::geometry::half_solid::half_above`] is what
/// shows the half to be a closed solid of half the volume).
pub(super) struct HalfSurface {
    pub(super) stl_bytes: Vec<u8>,
    /// SHA-256 of the STL bytes (keys the classified-surface cache).
    pub(super) digest: String,
    /// The symmetry plane z = c, mm (rod frame).
    pub(super) plane_z_mm: f64,
}

/// Largest distance of a vertex's mirror image from the rod-frame surface for the rod to count as
/// mirror-symmetric about its mid-plane across the pin axis, mm (the five designs' exports: 0.017–0.024
/// mm, their tessellations' chordal error). Also the largest move of a vertex onto the plane when
/// the surface is halved.
pub const MIRROR_TOLERANCE_MM: f64 = 0.05;

/// The half of `surface` (rod frame, mm) when the rod is mirror-symmetric about the plane halving
/// its thickness ([`crate::geometry::mirror_symmetry`]) and `symmetry` allows; `None` otherwise,
/// or when the halved surface is not a valid closed solid of half the volume (then the whole rod
/// is meshed, as without symmetry).
pub(super) fn half_surface(surface: &RodFrameSurface, symmetry: Symmetry) -> Option<HalfSurface> {
    use crate::geometry::primitives::{binary_stl, to_soup};
    if symmetry == Symmetry::Off {
        return None;
    }
    let mesh = crate::geometry::IndexedMesh {
        vertices: surface
            .vertices
            .iter()
            .map(|v| nalgebra::Vector3::from(*v))
            .collect(),
        triangles: surface.triangles.clone(),
    };
    let fit = crate::geometry::mirror_symmetry::mirror_fit_z(&mesh)?;
    if !fit.is_symmetric(MIRROR_TOLERANCE_MM) {
        return None;
    }
    let half = crate::geometry::half_solid::half_above(&mesh, fit.z, MIRROR_TOLERANCE_MM).ok()?;
    let half = crate::geometry::validate::validate(half).ok()?;
    let ratio = crate::geometry::mass_properties::signed_volume(&half.mesh)
        / crate::geometry::mass_properties::signed_volume(&mesh);
    if !half.warnings.is_empty() || (ratio - 0.5).abs() > 1e-3 {
        return None;
    }
    // gmsh gets the half open at the cut and builds the cap itself, as one plane surface on the
    // cut's classified curves (`pipeline/meshing/cap.py`, `cap_open_cut`): the cap's triangles would be
    // classified into patches whose cuts meet the cut's edge, where the peaks of a bending rod lie
    let open = crate::geometry::IndexedMesh {
        vertices: half.mesh.vertices.clone(),
        triangles: half
            .mesh
            .triangles
            .iter()
            .filter(|t| t.iter().any(|&i| half.mesh.vertices[i as usize].z > fit.z))
            .copied()
            .collect(),
    };
    let stl_bytes = binary_stl(&to_soup(&open));
    Some(HalfSurface {
        digest: super::super::rod_surface::sha256_hex(&stl_bytes),
        stl_bytes,
        plane_z_mm: fit.z,
    })
}

/// DOFs of a uniform gmsh tet10 mesh per (volume / size³): 35.6 on design 1 at 5 mm (111,150 DOFs,
/// 3.90e5 mm³), 39 on design 5 (99,285, 3.18e5 mm³); the guard below takes 30, an estimate
/// from below.
pub(super) const UNIFORM_MESH_DOFS_PER_CELL: f64 = 30.0;

/// The largest uniform mesh stage 3 starts: far beyond a rod's useful meshes (design 1 at 2 mm
/// has about 1.7 M DOFs, at 1 mm about 14 M), and far below a rod read in the wrong units (a
/// centimetre file read as millimetres makes its 5 mm mesh 1000 times larger, 1.1e8 DOFs).
pub const UNIFORM_MESH_MAX_DOFS: f64 = 2e7;

impl Setup {
    /// Refuses, before gmsh starts, a uniform mesh of `size_mm` that would be far beyond what can
    /// be solved: a size meant for another part, or a design read in the wrong units (a
    /// millimetre rod read as metres is 1e9 times its volume).
    /// `knob` names the setting that chose the size.
    pub(super) fn check_uniform_size(
        &self,
        design: &LoadedDesign,
        size_mm: f64,
        knob: &str,
    ) -> Result<()> {
        let v = self.surface.volume_mm3();
        let dofs = UNIFORM_MESH_DOFS_PER_CELL * v / size_mm.powi(3);
        if dofs > UNIFORM_MESH_MAX_DOFS {
            anyhow::bail!(
                "{}: a uniform {size_mm} mm mesh of this part ({v:.3e} mm³, {:.1} mm between the \
                 pins) would have about {dofs:.1e} DOFs, beyond the {UNIFORM_MESH_MAX_DOFS:.0e} \
                 stage 3 starts: check the units (sidecar `units`, now {}), or give a larger {knob}",
                self.context,
                self.surface.centre_distance_mm,
                design.settings.units.symbol()
            );
        }
        Ok(())
    }
}
