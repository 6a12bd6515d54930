//! Smooth patches of a surface: its triangles joined across manifold edges whose dihedral angle
//! is below [`SMOOTH_ANGLE_DEG`], all at once (sorted edges, union–find) or only those holding
//! some seed triangles (a walk from them).

use super::bore::SMOOTH_ANGLE_DEG;
use crate::geometry::weld::IndexedMesh;
use nalgebra::Vector3;

/// Smooth patches: triangle groups joined across manifold edges with small dihedral angles;
/// and each triangle's neighbours across its manifold edges (`u32::MAX`: none).
pub(super) fn smooth_patches(
    mesh: &IndexedMesh,
    normals: &[Vector3<f64>],
) -> (Vec<Vec<u32>>, Vec<[u32; 3]>) {
    let n = mesh.triangles.len();
    // the edge uses (higher vertex, triangle) filed under their lower vertex by a counting sort,
    // then sorted within each vertex's handful: the order of a sort of (edge, triangle)
    let mut start = vec![0u32; mesh.vertices.len() + 1];
    for &[a, b, c] in &mesh.triangles {
        for (i, j) in [(a, b), (b, c), (c, a)] {
            start[i.min(j) as usize + 1] += 1;
        }
    }
    for v in 0..mesh.vertices.len() {
        start[v + 1] += start[v];
    }
    let mut next = start.clone();
    let mut uses: Vec<(u32, u32)> = vec![(0, 0); 3 * n];
    for (t, &[a, b, c]) in mesh.triangles.iter().enumerate() {
        for (i, j) in [(a, b), (b, c), (c, a)] {
            let slot = &mut next[i.min(j) as usize];
            uses[*slot as usize] = (i.max(j), t as u32);
            *slot += 1;
        }
    }
    for v in 0..mesh.vertices.len() {
        uses[start[v] as usize..start[v + 1] as usize].sort_unstable();
    }
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    let cos_max = SMOOTH_ANGLE_DEG.to_radians().cos();
    let mut neighbours = vec![[u32::MAX; 3]; n];
    let mut link = |a: u32, b: u32| {
        if let Some(slot) = neighbours[a as usize].iter_mut().find(|x| **x == u32::MAX) {
            *slot = b;
        }
    };
    for v in 0..mesh.vertices.len() {
        let around = &uses[start[v] as usize..start[v + 1] as usize];
        for group in around.chunk_by(|x, y| x.0 == y.0) {
            if let [(_, s), (_, t)] = *group {
                link(s, t);
                link(t, s);
            }
            if let [(_, s), (_, t)] = *group
                && normals[s as usize].dot(&normals[t as usize]) >= cos_max
            {
                let (ra, rb) = (root(&mut parent, s), root(&mut parent, t));
                if ra != rb {
                    parent[ra.max(rb) as usize] = ra.min(rb);
                }
            }
        }
    }
    let mut index = vec![u32::MAX; n];
    let mut patches: Vec<Vec<u32>> = Vec::new();
    for t in 0..n as u32 {
        let r = root(&mut parent, t) as usize;
        if index[r] == u32::MAX {
            index[r] = patches.len() as u32;
            patches.push(Vec::new());
        }
        patches[index[r] as usize].push(t);
    }
    (patches, neighbours)
}

/// The triangles of the smooth patches that hold `seeds`, in increasing order: the patches of
/// [`smooth_patches`] (joined across manifold edges, two uses, whose dihedral angle is below
/// [`SMOOTH_ANGLE_DEG`]), found by walking from the seeds, so that the rest of the surface costs
/// one pass to list each vertex's triangles.
pub fn smooth_patches_through(mesh: &IndexedMesh, seeds: &[u32]) -> Vec<u32> {
    let n = mesh.triangles.len();
    let mut start = vec![0u32; mesh.vertices.len() + 1];
    for &v in mesh.triangles.iter().flatten() {
        start[v as usize + 1] += 1;
    }
    for v in 0..mesh.vertices.len() {
        start[v + 1] += start[v];
    }
    let mut next = start.clone();
    let mut around = vec![0u32; 3 * n];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            around[next[v as usize] as usize] = t as u32;
            next[v as usize] += 1;
        }
    }
    // the unit normal as `find_bores` forms it
    let normal = |t: u32| {
        let [a, b, c] = mesh.corners(t as usize);
        let n = (b - a).cross(&(c - a));
        let twice = n.norm();
        if twice > 0.0 {
            n / twice
        } else {
            Vector3::zeros()
        }
    };
    let cos_max = SMOOTH_ANGLE_DEG.to_radians().cos();
    // every triangle seen is queued once and walked from: the patches are the triangles seen
    let mut seen = vec![false; n];
    let mut queue: Vec<u32> = Vec::new();
    for &s in seeds {
        if !seen[s as usize] {
            seen[s as usize] = true;
            queue.push(s);
        }
    }
    while let Some(t) = queue.pop() {
        let [a, b, c] = mesh.triangles[t as usize];
        let nt = normal(t);
        for (i, j) in [(a, b), (b, c), (c, a)] {
            let users = &around[start[i as usize] as usize..start[i as usize + 1] as usize];
            let mut other = users
                .iter()
                .filter(|&&u| u != t && mesh.triangles[u as usize].contains(&j));
            // a manifold edge: exactly one other triangle uses it
            let (Some(&u), None) = (other.next(), other.next()) else {
                continue;
            };
            if !seen[u as usize] && normal(u).dot(&nt) >= cos_max {
                seen[u as usize] = true;
                queue.push(u);
            }
        }
    }
    (0..n as u32).filter(|&t| seen[t as usize]).collect()
}
