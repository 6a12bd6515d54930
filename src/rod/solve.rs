//! The static load cases of the rod ([`super::cases`]): bore B fixed (all DOFs of its nodes), the
//! pin force of each case on bore A ([`super::pin_load`]), all cases from one factorisation
//! (SPEC "Stage 3 — FEM", thesis §5.3).
//!
//! Reported per case: max von Mises element-nodal unaveraged (as NX reports), nodally averaged, and
//! nodally averaged over the judged region ([`super::judged`]: outside the bands around the fixed
//! bore and the sharp edges, the convergent measure), each with its location; max displacement;
//! the load resultant check and the reaction balance; the error estimates.

use std::sync::Arc;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::bores::{BoreSpec, BoreSurface, find_bores};
use super::cases::STATIC_CASES;
use super::contact_cases::{ContactCase, contact_solutions};
use super::judged::{
    Bands, DEFAULT_FIXED_BAND_M, DEFAULT_SINGULAR_BAND_M, edge_band_warning, judged_nodes,
    singularity_floor,
};
use super::pin_load::{BoreLoad, pin_load};
use super::records::{FemResult, LoadCaseResult, LoadCases};
use crate::fem::boundary::{boundary_faces, norm};
use crate::fem::element::QuadratureChoice;
use crate::fem::error::{FemError, Result};
use crate::fem::estimate::{ErrorEstimate, estimate_error};
use crate::fem::load::SurfaceLoad;
use crate::fem::material::Material;
use crate::fem::mesh::TetMesh;
use crate::fem::recovery::recover_stress_cases;
use crate::fem::statics::{
    FactorisedSystem, StaticProblem, StaticSolution, solve_static, solve_static_reusing,
};
use crate::fem::stress::{
    StressField, displacement_magnitudes, peak_nodal, peak_unaveraged, stress_field,
};

/// Options of [`solve_rod`].
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct RodOptions {
    /// Element quadrature (default: 4-point for straight, 14-point for curved elements).
    pub quadrature: QuadratureChoice,
    /// Width of the band around the fixed bore excluded from the "away from fixed" measure, m.
    /// `None`: [`DEFAULT_FIXED_BAND_M`], a fixed physical distance (not a number of elements, so
    /// that refinement does not move the band towards the singular edge).
    pub fixed_band_m: Option<f64>,
    /// Sharp re-entrant edges of the geometry (segments, m): stress singularities, left out of
    /// the judged peak like the fixed bore ([`super::facets::reentrant_edges`]).
    #[serde(default)]
    pub singular_edges_m: Vec<[[f64; 3]; 2]>,
    /// Band around the singular edges left out of the judged peak, m (`None`:
    /// [`DEFAULT_SINGULAR_BAND_M`]).
    #[serde(default)]
    pub singular_band_m: Option<f64>,
    /// The magnitude of the F_y case when it differs from the F_x case's (`None`: both are
    /// `force_n`, the thesis' setting). The engine study sets it to the largest pin force across
    /// the rod over the cycle.
    #[serde(default)]
    pub fy_force_n: Option<f64>,
    /// Keep the factorised K in [`RodSolution::system`] for the buckling case on the same mesh
    /// (its supports are stage 3's), which then neither assembles nor factorises K again.
    #[serde(skip)]
    pub keep_system: bool,
    /// Edges of the geometry at or above the feature angle taken for kinks of faceted small
    /// fillets (refined like any curved surface, not excluded; [`super::facets::SurfaceEdges`]),
    /// for the record.
    #[serde(default)]
    pub fillet_kink_edges: usize,
    /// The symbolic analysis of another solve of K's pattern (the same mesh with its boundary moved:
    /// the geometry check of [`super::smooth`]), reused where it fits.
    #[serde(skip)]
    pub reuse_symbolic: Option<crate::fem::solver::SymbolicFactor>,
    /// The mesh given to [`solve_rod_on`] is the half z ≥ c of a mirror-symmetric rod, with its
    /// face on the plane z = c (m, rod frame); `None`: the whole rod.
    #[serde(default)]
    pub mirror_plane_z_m: Option<f64>,
    /// The mesh is of an exact geometry (a STEP's B-rep): a sharp edge is sharp in the part, not
    /// a fillet an export cut into few facets (what the warnings of the edge band say).
    #[serde(default)]
    pub exact_geometry: bool,
}

/// Full fields of a rod analysis (for post-processing beyond the figures); the per-case fields in
/// the order of `result.cases`.
#[derive(Clone, Debug)]
pub struct RodSolution {
    /// The figures.
    pub result: FemResult,
    /// Displacements (3 per node, m), per case.
    pub displacements: Vec<Vec<f64>>,
    /// Stresses, per case.
    pub stresses: Vec<StressField>,
    /// Loaded bore A.
    pub loaded: BoreSurface,
    /// Fixed bore B.
    pub fixed: BoreSurface,
    /// The judged nodes: outside the bands around the fixed bore and the singular edges
    /// ([`super::judged`]).
    pub away_from_fixed: Vec<bool>,
    /// Per node, the smallest element size adaptive refinement may ask for near a singularity, m
    /// ([`super::judged::singularity_floor`]).
    pub singularity_floor_m: Vec<f64>,
    /// Error estimates, per case.
    pub estimates: Vec<ErrorEstimate>,
    /// The buckling mode of the F_x case, when buckling was computed
    /// ([`super::buckling::rod_buckling`]; set by the caller, `None` from [`solve_rod_fields`]).
    pub buckling: Option<crate::fem::buckling::BucklingMode>,
    /// The factorised K of the static cases, when [`RodOptions::keep_system`] asked for it.
    pub system: Option<Arc<FactorisedSystem>>,
    /// A half model's solution ([`super::half_model::solve_rod_on`]): for each node of the whole,
    /// the node of the half it is or is the image of (the first `half_model.nodes` are the half's
    /// own).
    pub mirror_source: Option<Vec<usize>>,
    /// With contact: per case, the contact pressure and gap at each node (empty otherwise).
    pub contact_fields: Vec<ContactFields>,
}

/// The nodal fields of one case's contact ([`super::contact_cases::ContactCase`]).
#[derive(Clone, Debug)]
pub struct ContactFields {
    /// Contact pressure (face-smoothed; 0 off the bore walls), Pa.
    pub pressure_pa: Vec<f64>,
    /// Gap between a bore wall and its pin (0 off the bore walls), m.
    pub gap_m: Vec<f64>,
}

/// Analyses a rod: see the module documentation. `force_n` > 0 is the pin force of the cases
/// ([`super::cases::LoadCase::force_n`]: of every case but F_y when [`RodOptions::fy_force_n`] is
/// set).
pub fn solve_rod(
    mesh: &TetMesh,
    material: &Material,
    bores: &BoreSpec,
    force_n: f64,
    options: &RodOptions,
) -> Result<FemResult> {
    Ok(solve_rod_fields(mesh, material, bores, force_n, options)?.result)
}

/// [`solve_rod`] returning the fields too.
pub fn solve_rod_fields(
    mesh: &TetMesh,
    material: &Material,
    bores: &BoreSpec,
    force_n: f64,
    options: &RodOptions,
) -> Result<RodSolution> {
    rod_fields(
        solve_rod_static(mesh, material, bores, force_n, options)?,
        options,
    )
}

/// The first half of [`solve_rod_fields`]: the bores, the pin loads and the static solution of
/// the cases. What it does not read of `options` (the fixed band, the singular edges and their
/// band, the fillet-kink count) [`rod_fields`] reads, so that a caller can work those out while K
/// is factorised (on one thread, [`crate::fem::solver`]).
pub struct RodStatic<'a> {
    pub(super) mesh: &'a TetMesh,
    pub(super) material: Material,
    pub(super) bores: BoreSpec,
    pub(super) t_all: Instant,
    pub(super) loaded: BoreSurface,
    pub(super) fixed: BoreSurface,
    /// Per case of [`STATIC_CASES`]: its unit direction and force, N.
    pub(super) cases: Vec<([f64; 3], f64)>,
    pub(super) loads: Vec<SurfaceLoad>,
    pub(super) sol: StaticSolution,
    pub(super) system: Option<Arc<FactorisedSystem>>,
    /// With contact ([`BoreLoad::Contact`]): each case's contact ([`super::contact_cases`]).
    pub(super) contact: Vec<ContactCase>,
}

/// The bores, loads and static solution of the cases ([`RodStatic`]).
pub fn solve_rod_static<'a>(
    mesh: &'a TetMesh,
    material: &Material,
    bores: &BoreSpec,
    force_n: f64,
    options: &RodOptions,
) -> Result<RodStatic<'a>> {
    static_cases(mesh, material, bores, force_n, options, 1.0, &[])
}

/// [`solve_rod_static`] with the pin loads scaled by `load_share` (½ on a half model) and the
/// DOFs `held` fixed besides bore B's (u_z on a half model's symmetry plane).
pub(super) fn static_cases<'a>(
    mesh: &'a TetMesh,
    material: &Material,
    bores: &BoreSpec,
    force_n: f64,
    options: &RodOptions,
    load_share: f64,
    held: &[usize],
) -> Result<RodStatic<'a>> {
    let t_all = Instant::now();
    material.validate()?;
    let (loaded, fixed, axis, ex) = bores_and_direction(mesh, bores)?;
    let cases = STATIC_CASES
        .iter()
        .map(|c| {
            let f = c.force_n(force_n, options.fy_force_n);
            if !(f.is_finite() && f > 0.0) {
                return Err(FemError::InvalidInput(format!(
                    "force must be > 0 N, got {f}"
                )));
            }
            Ok((c.unit_direction(axis, ex), f))
        })
        .collect::<Result<Vec<_>>>()?;
    check_one_piece(mesh, &fixed.nodes)?;
    if bores.bore_load == BoreLoad::Contact {
        let (sol, loads, contact) = contact_solutions(
            mesh,
            material,
            bores,
            options.quadrature,
            &cases,
            (&loaded, &fixed, axis),
            load_share,
            held,
        )?;
        return Ok(RodStatic {
            mesh,
            material: *material,
            bores: bores.clone(),
            t_all,
            loaded,
            fixed,
            cases,
            loads,
            sol,
            system: None,
            contact,
        });
    }
    let loads = cases
        .iter()
        .map(|(d, f)| {
            pin_load(
                mesh,
                &loaded.faces,
                bores.loaded_centre_m,
                axis,
                d.map(|v| v * f * load_share),
                bores.bore_load,
            )
        })
        .collect::<Result<Vec<_>>>()?;

    let mut prescribed: Vec<(usize, f64)> = fixed
        .nodes
        .iter()
        .flat_map(|&n| (0..3).map(move |j| (3 * n + j, 0.0)))
        .collect();
    let fixed_already: std::collections::HashSet<usize> =
        prescribed.iter().map(|(d, _)| *d).collect();
    prescribed.extend(
        held.iter()
            .filter(|d| !fixed_already.contains(d))
            .map(|&d| (d, 0.0)),
    );
    let problem = StaticProblem {
        mesh,
        material: *material,
        prescribed,
        loads: loads.iter().map(|l| l.forces.clone()).collect(),
        quadrature: options.quadrature,
    };
    let (sol, system) = if options.keep_system || options.reuse_symbolic.is_some() {
        let (sol, system) = solve_static_reusing(&problem, options.reuse_symbolic.as_ref())?;
        (sol, options.keep_system.then(|| Arc::new(system)))
    } else {
        (solve_static(&problem)?, None)
    };
    Ok(RodStatic {
        mesh,
        material: *material,
        bores: bores.clone(),
        t_all,
        loaded,
        fixed,
        cases,
        loads,
        sol,
        system,
        contact: Vec::new(),
    })
}

/// The second half of [`solve_rod_fields`]: stresses, recovery, error estimates and peaks of the
/// cases of `st`, the peaks judged away from the fixed bore and from the singular edges of
/// `options` ([`super::judged`]).
pub fn rod_fields(st: RodStatic<'_>, options: &RodOptions) -> Result<RodSolution> {
    let RodStatic {
        mesh,
        material,
        bores,
        t_all,
        loaded,
        fixed,
        cases,
        loads,
        sol,
        system,
        contact,
    } = st;
    let (material, bores) = (&material, &bores);
    let t_stress = Instant::now();
    let bands = Bands {
        fixed_faces: &fixed.faces,
        fixed_band_m: options.fixed_band_m.unwrap_or(DEFAULT_FIXED_BAND_M),
        singular_edges_m: &options.singular_edges_m,
        singular_band_m: options.singular_band_m.unwrap_or(DEFAULT_SINGULAR_BAND_M),
    };
    let nodes = judged_nodes(mesh, &bands);
    let away = nodes.judged;
    let chase_floor = singularity_floor(mesh, &bands);
    let any_in_edge_band = nodes.in_edge_band.iter().any(|b| *b);
    let mut warnings = Vec::new();
    let mut results = Vec::new();
    let mut fields = Vec::new();
    let mut estimates = Vec::new();
    // all cases' recovery at once: the patches' normal matrices are factorised once
    let displacements: Vec<&[f64]> = sol.displacements.iter().map(|u| u.as_slice()).collect();
    let recovered = recover_stress_cases(mesh, material, &displacements)?;
    for (c, ((def, (dir, force_n)), load)) in
        STATIC_CASES.iter().zip(&cases).zip(&loads).enumerate()
    {
        let name = def.name;
        let u = &sol.displacements[c];
        let field = stress_field(mesh, material, u)?;
        let estimate = estimate_error(mesh, material, u, &field, &recovered[c], &away)?;
        let vm_avg = field.von_mises_averaged();
        let un = peak_unaveraged(mesh, &field, None);
        let av = peak_nodal(mesh, &vm_avg, None);
        let away_av = peak_nodal(mesh, &vm_avg, Some(&away));
        let away_un = peak_unaveraged(mesh, &field, Some(&away));
        let umag = displacement_magnitudes(u);
        let dmax = peak_nodal(mesh, &umag, None);
        let mut reaction = [0.0; 3];
        for (d, r) in sol.reactions[c].iter().enumerate() {
            reaction[d % 3] += r;
        }
        let bal = norm(std::array::from_fn(|j| reaction[j] + load.resultant_n[j])) / *force_n;
        if bal > 1e-6 {
            return Err(FemError::Check(format!(
                "case {name}: reactions {reaction:?} N do not balance the load {:?} N (relative {bal:.2e})",
                load.resultant_n
            )));
        }
        let mm = |p: [f64; 3]| p.map(|v| v * 1e3);
        if any_in_edge_band {
            let hidden = peak_nodal(mesh, &vm_avg, Some(&nodes.in_edge_band));
            if hidden.value > away_av.value {
                warnings.push(edge_band_warning(
                    def.label,
                    &hidden,
                    away_av.value,
                    bands.singular_edges_m,
                    bands.singular_band_m,
                    options.exact_geometry,
                ));
            }
        }
        let mut case = LoadCaseResult {
            name: name.to_string(),
            direction: *dir,
            force_n: *force_n,
            max_von_mises_unaveraged_mpa: un.value * 1e-6,
            max_von_mises_unaveraged_at_mm: mm(un.location_m),
            max_von_mises_unaveraged_element: un.element.unwrap_or(0),
            max_von_mises_averaged_mpa: av.value * 1e-6,
            max_von_mises_averaged_at_mm: mm(av.location_m),
            max_von_mises_away_from_fixed_mpa: away_av.value * 1e-6,
            max_von_mises_away_from_fixed_at_mm: mm(away_av.location_m),
            max_von_mises_unaveraged_away_from_fixed_mpa: away_un.value * 1e-6,
            max_displacement_mm: dmax.value * 1e3,
            max_displacement_at_mm: mm(dmax.location_m),
            applied_resultant_n: load.resultant_n,
            resultant_error_rel: load.resultant_error_rel,
            reaction_n: reaction,
            reaction_balance_rel: bal,
            solve_residual_rel: sol.residual_rel[c],
            estimated_error_rel: 0.0,
            estimated_discretisation_error_rel: 0.0,
            estimated_geometry_error_rel: None,
            smooth_surface_peak_mpa: None,
            error_estimate: estimate.summary,
            adaptive: Vec::new(),
            vtu: None,
            picture: None,
            estimated_load_model_error_rel: None,
            load_models: None,
            contact: contact.get(c).map(|cc| cc.record.clone()),
        };
        case.set_error_bar(estimate.summary.single_mesh_estimate(), None);
        results.push(case);
        fields.push(field);
        estimates.push(estimate);
    }
    let mut timings = sol.timings;
    timings.stress_s = t_stress.elapsed().as_secs_f64();
    let result = FemResult {
        cases: LoadCases(results),
        nodes: mesh.n_nodes(),
        elements: mesh.n_elements(),
        dofs: sol.stats.dofs,
        equations: sol.stats.equations,
        nnz_k: sol.stats.nnz_k,
        nnz_l: sol.stats.nnz_l,
        curved_elements: sol.stats.curved_elements,
        quadrature: options.quadrature,
        material: *material,
        mean_edge_mm: mesh.mean_edge_length() * 1e3,
        fixed_band_mm: bands.fixed_band_m * 1e3,
        singular_edges: options.singular_edges_m.len(),
        singular_band_mm: bands.singular_band_m * 1e3,
        fillet_kink_edges: options.fillet_kink_edges,
        warnings,
        geometry_check: None,
        half_model: None,
        bore_load: bores.bore_load,
        loaded_bore: (&loaded).into(),
        fixed_bore: (&fixed).into(),
        timings,
        total_s: t_all.elapsed().as_secs_f64(),
    };
    Ok(RodSolution {
        result,
        displacements: sol.displacements,
        stresses: fields,
        loaded,
        fixed,
        away_from_fixed: away,
        singularity_floor_m: chase_floor,
        estimates,
        buckling: None,
        system,
        mirror_source: None,
        contact_fields: contact
            .into_iter()
            .map(|c| ContactFields {
                pressure_pa: c.pressure_pa,
                gap_m: c.gap_m,
            })
            .collect(),
    })
}

/// The F_x case of [`solve_rod`] as supports and nodal forces: bore B fixed (all DOFs of its
/// nodes), the pin load (uniform or cosine, [`BoreSpec::bore_load`]) of resultant `force_n` along
/// A→B (perpendicular to the pin axis)
/// on bore A. Pushing A towards the fixed B, this case compresses the rod.
#[derive(Clone, Debug)]
pub struct RodFxCase {
    /// Unit direction of the load, A→B.
    pub direction: [f64; 3],
    /// The fixed DOFs (3 · node + component).
    pub fixed_dofs: Vec<usize>,
    /// Nodal forces, 3 per node, N.
    pub load: Vec<f64>,
    /// Loaded bore A.
    pub loaded: BoreSurface,
    /// Fixed bore B.
    pub fixed: BoreSurface,
}

/// The bores of a rod mesh (loaded A, fixed B), the unit pin axis, and the F_x direction: along
/// A→B, perpendicular to the pin axis. Shared by the static cases and [`rod_fx_case`].
pub(super) fn bores_and_direction(
    mesh: &TetMesh,
    bores: &BoreSpec,
) -> Result<(BoreSurface, BoreSurface, [f64; 3], [f64; 3])> {
    let axis = bores.unit_axis()?;
    let boundary = boundary_faces(mesh)?;
    let (loaded, fixed) = find_bores(mesh, &boundary, bores)?;
    let ab: [f64; 3] = std::array::from_fn(|j| bores.fixed_centre_m[j] - bores.loaded_centre_m[j]);
    let along = crate::fem::boundary::dot(ab, axis);
    let abp: [f64; 3] = std::array::from_fn(|j| ab[j] - along * axis[j]);
    let l = norm(abp);
    if l.is_nan() || l <= 0.0 {
        return Err(FemError::InvalidInput(
            "the pin centres lie on one pin axis".into(),
        ));
    }
    Ok((loaded, fixed, axis, abp.map(|v| v / l)))
}

/// The F_x case of [`solve_rod_fields`] (the same bores, direction and nodal forces), for an
/// analysis of that load other than the static one (buckling).
pub fn rod_fx_case(mesh: &TetMesh, bores: &BoreSpec, force_n: f64) -> Result<RodFxCase> {
    if !(force_n.is_finite() && force_n > 0.0) {
        return Err(FemError::InvalidInput(format!(
            "force must be > 0 N, got {force_n}"
        )));
    }
    let (loaded, fixed, axis, ex) = bores_and_direction(mesh, bores)?;
    let load = pin_load(
        mesh,
        &loaded.faces,
        bores.loaded_centre_m,
        axis,
        ex.map(|v| v * force_n),
        bores.bore_load,
    )?;
    let fixed_dofs = fixed
        .nodes
        .iter()
        .flat_map(|&n| (0..3).map(move |j| 3 * n + j))
        .collect();
    Ok(RodFxCase {
        direction: ex,
        fixed_dofs,
        load: load.forces,
        loaded,
        fixed,
    })
}

/// A rod's mesh must be one piece ([`crate::fem::mesh::pieces`]): a piece apart from the one that
/// holds the fixed bore has no support (K singular), so it is refused by where it is and how
/// large it is, not reported later as a failed pivot.
fn check_one_piece(mesh: &TetMesh, fixed_nodes: &[usize]) -> Result<()> {
    let (pieces, labels) = crate::fem::mesh::pieces::pieces(mesh);
    if pieces.len() < 2 {
        return Ok(());
    }
    let held = fixed_nodes.first().map_or(0, |&n| labels[n]);
    let stray: Vec<String> = pieces
        .iter()
        .enumerate()
        .filter(|(k, _)| *k != held)
        .take(3)
        .map(|(_, p)| {
            let c = p.centroid_m.map(|v| v * 1e3);
            format!(
                "{:.4e} mm³ ({} elements) around ({:.1}, {:.1}, {:.1}) mm",
                p.volume_m3 * 1e9,
                p.elements,
                c[0],
                c[1],
                c[2]
            )
        })
        .collect();
    Err(FemError::InvalidInput(format!(
        "the mesh is {} separate pieces, and only the one of {:.4e} mm³ holds the fixed bore: {} \
         {} not connected to it (a separate body in the file, or a part that only touches the \
         rod without sharing its surface) and would float; remove it, or join it to the rod",
        pieces.len(),
        pieces[held].volume_m3 * 1e9,
        stray.join("; "),
        if pieces.len() == 2 { "is" } else { "are" }
    )))
}

#[cfg(test)]
mod tests {

    use super::{RodOptions, check_one_piece};
    use crate::fem::TetMesh;
    use crate::fem::mesh::structured::box_tet10;

    /// A half model solved with half the pin loads and u_z = 0 on its plane, mirrored, is the
    /// whole model's solution: against the direct solve of the mirrored mesh (the same mesh, the
    /// same loads) the displacements, peaks, reactions and estimates agree to round-off.
    #[test]
    fn a_half_model_mirrored_is_the_whole_model() {
        use crate::fem::Material;
        use crate::fem::mesh::structured::{TwoEyePlate, two_eye_plate};
        use crate::rod::BoreSpec;
        // the upper half of a 40 mm plate, z ∈ [0, 20] mm, two layers
        let p = TwoEyePlate {
            thickness: 0.02,
            n_z: 2,
            ..TwoEyePlate::default()
        };
        let half = two_eye_plate(&p)
            .unwrap()
            .map_nodes(|_, q| [q[0], q[1], q[2] + 0.01])
            .unwrap();
        let (material, bores) = (Material::STEEL, BoreSpec::default());
        let options = RodOptions {
            mirror_plane_z_m: Some(0.0),
            fy_force_n: Some(3000.0),
            ..RodOptions::default()
        };
        let (whole, mirrored) = crate::rod::half_model::solve_rod_on(
            half.clone(),
            &material,
            &bores,
            10_000.0,
            &options,
        )
        .unwrap();
        let direct = super::solve_rod_fields(
            &whole,
            &material,
            &bores,
            10_000.0,
            &RodOptions {
                mirror_plane_z_m: None,
                ..options.clone()
            },
        )
        .unwrap();
        let (lo, hi) = whole.bounding_box();
        assert_eq!((lo[2], hi[2]), (-0.02, 0.02));
        let hm = mirrored.result.half_model.as_ref().unwrap();
        assert_eq!((hm.nodes, hm.elements), (half.n_nodes(), half.n_elements()));
        assert_eq!(whole.n_elements(), 2 * half.n_elements());
        assert_eq!(mirrored.result.dofs, 3 * half.n_nodes());
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1e-300);
        for c in 0..2 {
            let (a, b) = (&mirrored.displacements[c], &direct.displacements[c]);
            let umax = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = a
                .iter()
                .zip(b)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(diff < 1e-9 * umax, "case {c}: {diff:e} of {umax:e}");
        }
        for (m, d) in mirrored.result.cases.iter().zip(direct.result.cases.iter()) {
            assert!(
                rel(
                    m.max_von_mises_away_from_fixed_mpa,
                    d.max_von_mises_away_from_fixed_mpa
                ) < 1e-9
            );
            assert!(
                rel(
                    m.max_von_mises_unaveraged_mpa,
                    d.max_von_mises_unaveraged_mpa
                ) < 1e-9
            );
            assert!(rel(m.max_displacement_mm, d.max_displacement_mm) < 1e-9);
            assert!(rel(m.estimated_error_rel, d.estimated_error_rel) < 1e-6);
            assert_eq!(m.force_n, d.force_n);
            for j in 0..3 {
                assert!(
                    (m.reaction_n[j] - d.reaction_n[j]).abs() < 1e-6 * d.force_n,
                    "{:?} {:?}",
                    m.reaction_n,
                    d.reaction_n
                );
                assert!(
                    (m.applied_resultant_n[j] - d.applied_resultant_n[j]).abs() < 1e-9 * d.force_n
                );
            }
            assert!(m.reaction_balance_rel < 1e-6);
        }
        assert_eq!(
            format!("{:?}", mirrored.result.loaded_bore),
            format!("{:?}", direct.result.loaded_bore)
        );
    }

    #[test]
    fn a_piece_apart_from_the_fixed_bores_is_refused_by_where_it_is() {
        let a = box_tet10(0.1, 0.02, 0.02, 4, 1, 1).unwrap();
        assert!(check_one_piece(&a, &[0]).is_ok());
        let b = box_tet10(0.01, 0.01, 0.01, 1, 1, 1).unwrap();
        let mut nodes = a.nodes().to_vec();
        let n0 = nodes.len();
        nodes.extend(b.nodes().iter().map(|p| [p[0] + 0.2, p[1], p[2]]));
        let mut elements = a.elements().to_vec();
        elements.extend(b.elements().iter().map(|el| el.map(|i| i + n0)));
        let two = TetMesh::new(nodes, elements).unwrap();
        let e = check_one_piece(&two, &[0]).unwrap_err().to_string();
        assert!(
            e.contains("2 separate pieces")
                && e.contains("4.0000e4 mm³")
                && e.contains("1.0000e3 mm³")
                && e.contains("around (205.0, 5.0, 5.0) mm"),
            "{e}"
        );
    }
}
