//! The local fatigue factor of the rod over the cycle: the FKM local-stress assessment
//! ([`crate::fatigue::assess_node`]) at every surface node, and the Findley critical plane
//! ([`crate::fatigue::findley`]) at the nodes it ranks worst.
//!
//! **Stresses and gradients over the cycle.** The cycle's stress is the superposition
//! σ(t) = Σ_k c_k(t) σ_k of the unit load cases ([`super::UnitSolutions`], [`super::Terms`]). The
//! depth gradient is linear in the field too, so the gradient of each unit case is computed once
//! per surface node ([`crate::fatigue::depth_gradients`]: the recovered nodal field sampled along
//! the inward normal, a least-squares cubic in depth) and combined per instant with the same
//! coefficients, dσ/dd(t) = Σ_k c_k(t) dσ_k/dd (as [`crate::fatigue::DepthGradient::combine`]).
//! Each surface node's history (nodal stress, depth gradient, outward normal) is then assessed
//! after FKM: amplitude and mean of the two surface stress components, χ* of each from the
//! gradient of the amplitude, n(χ*), K_R, K_V, σ_WK, M_σ and K_AK (overload case F2 by default),
//! degrees of utilisation and their von Mises combination, the safety factor S = j_D / a_BK,sv.
//!
//! **The design's local factor** is the smallest S over the surface nodes the cycle judges (away
//! from the fixed bore and the sharp re-entrant edges: the bands of [`crate::rod::judged`], the
//! same nodes the Goodman factor is taken over). S is a load factor: the factor by which the whole
//! load history could grow until the component fatigue limit with the safety j_D is reached
//! (under F2 the utilisation is linear in the load), the number to set beside the Goodman factor
//! n = 1/(σ_a/S_e + σ_m/S_ut), which is one too.
//!
//! **The multiaxial check.** Findley's parameter max_n (τ_a + k σ_n,max) on the full stress
//! tensor history, at the [`FINDLEY_NODES`] judged nodes of lowest S and at the node of the
//! lowest Goodman factor, with k and the limit from the node's own component fatigue limits in
//! tension σ_WK,1 and shear f_W,τ · σ_WK,1 (so that it carries the same support, roughness and
//! treatment as the FKM factor there, and compares with it): S_F = f_lim / f, a load factor too.
//! Where the principal directions turn over the cycle the FKM reduction to fixed surface axes is
//! approximate and the critical plane is the one to read; the record says where the two disagree.

use rayon::prelude::*;

use super::{Terms, UnitSolutions};
use crate::fatigue::tensor::axpy;
use crate::fatigue::{
    FindleyResult, FindleySettings, GradientOptions, LocalAssessment, LocalSettings, NodeHistory,
    assess_node, depth_gradients, findley, surface_points,
};
use crate::fem::error::{FemError, Result};
use crate::fem::mesh::TetMesh;

/// How many of the lowest local factors the Findley check visits (besides the Goodman node).
pub const FINDLEY_NODES: usize = 20;

/// One surface node's assessment.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceAssessment {
    /// Mesh node.
    pub node: usize,
    /// Outward unit normal.
    pub outward_normal: [f64; 3],
    /// Whether the depth gradient could be formed (else no support credited, n = 1).
    pub has_gradient: bool,
    /// Judged (outside the bands).
    pub judged: bool,
    /// The FKM assessment.
    pub assessment: LocalAssessment,
}

/// Findley's check at one node.
#[derive(Clone, Copy, Debug)]
pub struct FindleyNode {
    /// Mesh node.
    pub node: usize,
    /// The local FKM factor there (`None`: not a surface node).
    pub local_factor: Option<f64>,
    /// The constants used.
    pub settings: FindleySettings,
    /// The critical plane.
    pub result: FindleyResult,
}

/// The local fatigue over the cycle.
#[derive(Clone, Debug)]
pub struct LocalFatigueSolution {
    /// Per mesh node: the local safety factor S (∞ off the surface and where unloaded).
    pub safety_factor: Vec<f64>,
    /// Per mesh node: χ* of the larger surface component σ_1, 1/m (0 off the surface).
    pub chi_star_per_m: Vec<f64>,
    /// Every surface node, in node order.
    pub surface: Vec<SurfaceAssessment>,
    /// Index into `surface` of the judged node of the smallest S.
    pub critical: usize,
    /// The Findley check, lowest S first, the Goodman node last unless among them.
    pub findley: Vec<FindleyNode>,
}

impl LocalFatigueSolution {
    /// The critical node's assessment.
    pub fn critical(&self) -> &SurfaceAssessment {
        &self.surface[self.critical]
    }

    /// The Findley node of the smallest factor.
    pub fn findley_worst(&self) -> Option<&FindleyNode> {
        self.findley
            .iter()
            .min_by(|a, b| a.result.factor.total_cmp(&b.result.factor))
    }
}

/// The node's stress history: σ(t) at node `n` for every instant's `terms`.
fn history(units: &UnitSolutions, n: usize, terms: &[Terms]) -> Vec<[f64; 6]> {
    terms.iter().map(|t| units.stress_at(n, t)).collect()
}

/// The local fatigue of the cycle given by `terms` (one per instant) on the unit solutions
/// `units` of `mesh` (see the module documentation); `goodman_node` is checked by Findley too.
pub fn local_fatigue(
    mesh: &TetMesh,
    units: &UnitSolutions,
    terms: &[Terms],
    goodman_node: usize,
    settings: &LocalSettings,
) -> Result<LocalFatigueSolution> {
    if terms.is_empty() {
        return Err(FemError::InvalidInput("no instant in the cycle".into()));
    }
    settings
        .material
        .validate()
        .map_err(|e| FemError::InvalidInput(format!("local fatigue: {e}")))?;
    let points = surface_points(mesh)?;
    let fields: Vec<&[[f64; 6]]> = units.stresses.iter().map(|f| f.as_slice()).collect();
    let gradients = depth_gradients(mesh, &fields, &points, &GradientOptions::default());
    let surface: Vec<SurfaceAssessment> = points
        .par_iter()
        .zip(gradients.par_iter())
        .map(|(p, g)| {
            let stress = history(units, p.node, terms);
            let depth: Option<Vec<[f64; 6]>> = g.as_ref().map(|g| {
                terms
                    .iter()
                    .map(|t| {
                        let mut d = [0.0; 6];
                        for (k, c) in t {
                            d = axpy(&d, *c, &g.fields[*k].d_stress_d_depth);
                        }
                        d
                    })
                    .collect()
            });
            let assessment = assess_node(
                settings,
                &NodeHistory {
                    stress: &stress,
                    depth_gradient: depth.as_deref(),
                    outward_normal: p.outward_normal,
                },
            );
            SurfaceAssessment {
                node: p.node,
                outward_normal: p.outward_normal,
                has_gradient: g.is_some(),
                judged: units.judged[p.node],
                assessment,
            }
        })
        .collect();
    let mut ranked: Vec<usize> = (0..surface.len()).filter(|&i| surface[i].judged).collect();
    if ranked.is_empty() {
        return Err(FemError::InvalidInput(
            "local fatigue: no surface node lies outside the bands around the fixed bore and the sharp edges".into(),
        ));
    }
    // stable: ties keep node order
    ranked.sort_by(|&a, &b| {
        surface[a]
            .assessment
            .safety_factor
            .total_cmp(&surface[b].assessment.safety_factor)
    });
    let critical = ranked[0];
    let n_nodes = mesh.n_nodes();
    let mut safety_factor = vec![f64::INFINITY; n_nodes];
    let mut chi_star_per_m = vec![0.0; n_nodes];
    for s in &surface {
        safety_factor[s.node] = s.assessment.safety_factor;
        chi_star_per_m[s.node] = s.assessment.sigma1.strength.chi_star_sigma_per_m;
    }
    // Findley at the lowest S and at the Goodman node
    let mut visit: Vec<(usize, Option<&SurfaceAssessment>)> = ranked
        .iter()
        .take(FINDLEY_NODES)
        .map(|&i| (surface[i].node, Some(&surface[i])))
        .collect();
    if !visit.iter().any(|(n, _)| *n == goodman_node) {
        let at = surface
            .binary_search_by_key(&goodman_node, |s| s.node)
            .ok()
            .map(|i| &surface[i]);
        visit.push((goodman_node, at));
    }
    let f_w_tau = settings.material.constants().f_w_tau;
    let findley = visit
        .par_iter()
        .map(|&(node, at)| {
            // the node's own component limits, or the material's (no support) off the surface
            let sigma_w = at.map_or_else(
                || {
                    crate::fatigue::local_strength(&settings.material, &settings.surface, 0.0, 0.0)
                        .sigma_wk_pa
                },
                |s| s.assessment.sigma1.strength.sigma_wk_pa,
            );
            let fs = FindleySettings::from_fatigue_limits(sigma_w, f_w_tau * sigma_w);
            FindleyNode {
                node,
                local_factor: at.map(|s| s.assessment.safety_factor),
                settings: fs,
                result: findley(&history(units, node, terms), &fs),
            }
        })
        .collect();
    Ok(LocalFatigueSolution {
        safety_factor,
        chi_star_per_m,
        surface,
        critical,
        findley,
    })
}
