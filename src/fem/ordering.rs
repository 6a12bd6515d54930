//! Fill-reducing ordering of the stiffness matrix by nested dissection (George 1973), with METIS's
//! multilevel `METIS_NodeND` (Karypis & Kumar 1998) on the graph of the mesh's corner nodes.
//!
//! A tet10 mesh is a three-dimensional graph: minimum degree (AMD, faer's default) leaves a factor
//! whose fill grows faster than nested dissection's O(n^{4/3}) entries and O(n²) flops (George &
//! Liu 1981, ch. 8). The separators come from the corners alone (the tet4 graph, about a seventh of
//! the nodes and a fifth of their neighbours, so METIS is cheap); a midside node follows the earlier
//! of its edge's two corners, so an edge from a subdomain to a separator is eliminated with the
//! subdomain and only the separator's own edges enlarge it. A node's equations follow one another.

use metis_sys as m;

use super::assembly::DofMap;
use super::constraints::Reduction;
use super::error::{FemError, Result};
use super::mesh::TetMesh;
use super::shape::TET10_EDGES;

/// The nested-dissection order of the equations of `dofs` on `mesh`: `fwd[new] = old`.
pub fn nested_dissection(mesh: &TetMesh, dofs: &DofMap) -> Result<Vec<usize>> {
    let order = node_order(mesh.n_nodes(), mesh.elements())?;
    Ok(order
        .iter()
        .flat_map(|&v| (0..3).filter_map(move |c| dofs.eq(3 * v + c)))
        .collect())
}

/// The nested-dissection order of the equations of a [`Reduction`] (u = T q + g) on tetrahedra
/// given by their node lists (4 corners, then for a tet10 the midside nodes in
/// [`TET10_EDGES`] order): `fwd[new] = old`. An equation enters T's rows of several nodes' DOFs
/// where a constraint ties them (a local-axes node, an `*EQUATION`, a reference node); it is
/// placed with the latest of those nodes, so that eliminating it never joins nodes not yet
/// eliminated. Without ties this is [`nested_dissection`]'s order.
pub fn nested_dissection_reduced<E: AsRef<[usize]>>(
    n_nodes: usize,
    elements: &[E],
    reduction: &Reduction,
) -> Result<Vec<usize>> {
    let order = node_order(n_nodes, elements)?;
    const NONE: usize = usize::MAX;
    let mut key = vec![NONE; reduction.n_eq()];
    for (pos, &v) in order.iter().enumerate() {
        for c in 0..3 {
            for &(q, _) in reduction.row(3 * v + c) {
                // `order` ascends in pos: the last node seen is the latest
                key[q] = pos;
            }
        }
    }
    let mut fwd: Vec<usize> = (0..reduction.n_eq()).collect();
    fwd.sort_by_key(|&q| (key[q], q));
    Ok(fwd)
}

/// The nodes of tetrahedra (corners first, midside nodes in [`TET10_EDGES`] order) in
/// nested-dissection order: the corners by METIS on the corner graph, each midside node just
/// after the earlier of its edge's corners, nodes in no element last.
fn node_order<E: AsRef<[usize]>>(n_nodes: usize, elements: &[E]) -> Result<Vec<usize>> {
    // Corner nodes, numbered 0..n_corners.
    const NONE: usize = usize::MAX;
    let mut corner = vec![NONE; n_nodes];
    let mut corners = Vec::new();
    for el in elements {
        for &v in &el.as_ref()[..4] {
            if corner[v] == NONE {
                corner[v] = corners.len();
                corners.push(v);
            }
        }
    }
    let nc = corners.len();
    // The corner graph: each element's six edges, both directions, duplicates removed.
    let mut adj: Vec<Vec<u32>> = vec![Vec::new(); nc];
    for el in elements {
        let el = el.as_ref();
        for [a, b] in TET10_EDGES {
            let (ca, cb) = (corner[el[a]], corner[el[b]]);
            adj[ca].push(cb as u32);
            adj[cb].push(ca as u32);
        }
    }
    let too_big = || {
        FemError::Solver(format!(
            "{n_nodes} nodes exceed METIS's 32-bit indices: mesh coarser (a larger element size)"
        ))
    };
    let mut xadj: Vec<m::idx_t> = Vec::with_capacity(nc + 1);
    let mut adjncy: Vec<m::idx_t> = Vec::new();
    xadj.push(0);
    for list in &mut adj {
        list.sort_unstable();
        list.dedup();
        adjncy.extend(list.iter().map(|&v| v as m::idx_t));
        xadj.push(m::idx_t::try_from(adjncy.len()).map_err(|_| too_big())?);
    }
    drop(adj);
    let rank = metis_node_nd(xadj, adjncy)?;
    // Each node's key: a corner its own rank, a midside node the earlier of its corners' ranks
    // (placed just after that corner).
    let mut key = vec![(NONE, 0u8); n_nodes];
    for (c, &v) in corners.iter().enumerate() {
        key[v] = (rank[c], 0);
    }
    for el in elements {
        let el = el.as_ref();
        for (k, [a, b]) in TET10_EDGES
            .iter()
            .enumerate()
            .take(el.len().saturating_sub(4))
        {
            let r = rank[corner[el[*a]]].min(rank[corner[el[*b]]]);
            key[el[4 + k]] = (r, 1);
        }
    }
    let mut order: Vec<usize> = (0..n_nodes).collect();
    order.sort_unstable_by_key(|&v| (key[v], v));
    Ok(order)
}

/// METIS_NodeND on a graph in CSR form (0-based, no self-loops): each vertex's rank in the
/// fill-reducing order.
fn metis_node_nd(mut xadj: Vec<m::idx_t>, mut adjncy: Vec<m::idx_t>) -> Result<Vec<usize>> {
    let n = xadj.len() - 1;
    if n == 0 {
        return Ok(Vec::new());
    }
    let mut nvtxs = m::idx_t::try_from(n).map_err(|_| {
        FemError::Solver(format!(
            "{n} corner nodes exceed METIS's 32-bit indices: mesh coarser (a larger element size)"
        ))
    })?;
    let mut options = [0 as m::idx_t; m::METIS_NOPTIONS as usize];
    let mut perm = vec![0 as m::idx_t; n];
    let mut iperm = vec![0 as m::idx_t; n];
    // METIS's random generator (GKlib's `mt`) is one global, not per thread: calls from two
    // threads (the study analyses designs side by side, the tests run in parallel) would race on
    // it and draw each other's numbers, so that an ordering, and with it the last bits of every
    // result, would depend on timing. One call at a time; each reseeds it (SetupCtrl), so the
    // ordering of a graph is always the same.
    static METIS: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one_at_a_time = METIS
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    // SAFETY: the arrays have the sizes METIS_NodeND documents (xadj n + 1, adjncy xadj[n],
    // options METIS_NOPTIONS, perm and iperm n); METIS keeps no pointer after it returns.
    let status = unsafe {
        m::METIS_SetDefaultOptions(options.as_mut_ptr());
        options[m::moptions_et_METIS_OPTION_NUMBERING as usize] = 0;
        m::METIS_NodeND(
            &mut nvtxs,
            xadj.as_mut_ptr(),
            adjncy.as_mut_ptr(),
            std::ptr::null_mut(),
            options.as_mut_ptr(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    if status != m::rstatus_et_METIS_OK {
        return Err(FemError::Solver(format!(
            "the fill-reducing ordering failed (METIS_NodeND status {status}: out of memory, or a mesh \
             graph METIS refuses); mesh coarser or check the mesh's connectivity"
        )));
    }
    // METIS: row i of the permuted matrix is row perm[i] of the original; iperm is its inverse.
    Ok(iperm.iter().map(|&r| r as usize).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::assembly::assemble;
    use crate::fem::element::QuadratureChoice;
    use crate::fem::material::Material;
    use crate::fem::mesh::structured::box_tet10;
    use crate::fem::solver::{CholeskyFactor, SymbolicFactor};

    /// A box clamped on its x = 0 face, its equations and stiffness.
    fn clamped_box(n: usize) -> (TetMesh, DofMap, crate::fem::assembly::Assembled) {
        let mesh = box_tet10(2.0, 1.0, 1.0, 2 * n, n, n).unwrap();
        let prescribed: Vec<(usize, f64)> = (0..mesh.n_nodes())
            .filter(|&v| mesh.nodes()[v][0] == 0.0)
            .flat_map(|v| (0..3).map(move |c| (3 * v + c, 0.0)))
            .collect();
        let dofs = DofMap::new(mesh.n_dofs(), &prescribed).unwrap();
        let asm = assemble(&mesh, &Material::STEEL, QuadratureChoice::Auto, &dofs).unwrap();
        (mesh, dofs, asm)
    }

    #[test]
    fn the_order_is_a_permutation_of_the_free_equations_with_a_nodes_equations_together() {
        let (mesh, dofs, _) = clamped_box(3);
        let fwd = nested_dissection(&mesh, &dofs).unwrap();
        assert_eq!(fwd.len(), dofs.n_eq());
        let mut seen = vec![false; dofs.n_eq()];
        for &q in &fwd {
            assert!(!seen[q], "equation {q} twice");
            seen[q] = true;
        }
        // equations are numbered in DOF order, so a node's three free equations are q, q+1, q+2
        for w in fwd.chunks(3) {
            assert_eq!(w, [w[0], w[0] + 1, w[0] + 2]);
        }
    }

    #[test]
    fn the_reduced_order_without_ties_is_the_kernels_order() {
        use crate::fem::constraints::{Constraint, Reduction};
        let (mesh, dofs, _) = clamped_box(3);
        let constraints: Vec<Constraint> = (0..mesh.n_dofs())
            .filter(|&d| dofs.eq(d).is_none())
            .map(|d| Constraint {
                terms: vec![(d, 1.0)],
                value: 0.0,
                label: format!("DOF {d}"),
            })
            .collect();
        let reduction = Reduction::new(mesh.n_dofs(), &constraints).unwrap();
        assert_eq!(reduction.n_eq(), dofs.n_eq());
        // each order as the sequence of the DOFs its equations stand for
        let mut dof_of_eq = vec![0; dofs.n_eq()];
        let mut dof_of_q = vec![0; reduction.n_eq()];
        for d in 0..mesh.n_dofs() {
            if let Some(q) = dofs.eq(d) {
                dof_of_eq[q] = d;
                assert_eq!(reduction.row(d).len(), 1);
                dof_of_q[reduction.row(d)[0].0] = d;
            }
        }
        let kernel: Vec<usize> = nested_dissection(&mesh, &dofs)
            .unwrap()
            .iter()
            .map(|&q| dof_of_eq[q])
            .collect();
        let reduced: Vec<usize> =
            nested_dissection_reduced(mesh.n_nodes(), mesh.elements(), &reduction)
                .unwrap()
                .iter()
                .map(|&q| dof_of_q[q])
                .collect();
        assert_eq!(kernel, reduced);
    }

    #[test]
    fn nested_dissection_fills_less_than_minimum_degree_and_solves_the_same_system() {
        // 16 × 8 × 8 cells: 3D enough that nested dissection's separators pay off
        let (mesh, dofs, asm) = clamped_box(8);
        let fwd = nested_dissection(&mesh, &dofs).unwrap();
        let nd = SymbolicFactor::analyse(&asm.k, Some(&fwd)).unwrap();
        let amd = SymbolicFactor::analyse(&asm.k, None).unwrap();
        assert!(
            (nd.nnz_l() as f64) < 0.9 * amd.nnz_l() as f64,
            "nested dissection {} entries, minimum degree {}",
            nd.nnz_l(),
            amd.nnz_l()
        );
        // a load on every free equation: the same displacements from both factors
        let mut b: Vec<f64> = (0..dofs.n_eq())
            .map(|q| ((q % 7) as f64 - 3.0) * 1e3)
            .collect();
        let mut x = b.clone();
        CholeskyFactor::factorise(&nd, &asm.k)
            .unwrap()
            .solve_in_place(&mut x, 1);
        CholeskyFactor::factorise(&amd, &asm.k)
            .unwrap()
            .solve_in_place(&mut b, 1);
        let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = x
            .iter()
            .zip(&b)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        assert!(diff < 1e-10 * scale, "max difference {diff:e} of {scale:e}");
    }
}
