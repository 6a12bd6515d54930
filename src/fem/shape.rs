//! Shape functions of the 10-node tetrahedron and of its 6-node triangular faces.
//!
//! Quadratic Lagrange elements on simplices in area/volume coordinates (Zienkiewicz, Taylor & Zhu,
//! "The Finite Element Method: Its Basis and Fundamentals", 7th ed., §6.5; Hughes, "The Finite
//! Element Method", §3.7). With volume coordinates L0 = 1 − ξ − η − ζ, L1 = ξ, L2 = η, L3 = ζ:
//! corner nodes N_i = L_i (2 L_i − 1), midside nodes N_ab = 4 L_a L_b.
//!
//! **Node order (the one order used everywhere in rodstudy, VTK's = meshio's):** corners 0–3, then
//! the midside nodes of edges 01, 12, 02, 03, 13, 23 ([`TET10_EDGES`]). gmsh swaps the last two (its
//! node 8 is on edge 23, node 9 on edge 13); Abaqus/CalculiX C3D10 and Nastran CTETRA use VTK's
//! order. Foreign orders are converted once, where a foreign format is read (meshio, in
//! `pipeline/mesh_rod.py`).

/// Corner pairs of the tetra10 edges, in the order of the midside nodes 4..=9.
pub const TET10_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [0, 2], [0, 3], [1, 3], [2, 3]];

/// Natural coordinates (ξ, η, ζ) of the ten nodes.
pub const TET10_NODE_XI: [[f64; 3]; 10] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.5, 0.0, 0.0],
    [0.5, 0.5, 0.0],
    [0.0, 0.5, 0.0],
    [0.0, 0.0, 0.5],
    [0.5, 0.0, 0.5],
    [0.0, 0.5, 0.5],
];

/// The four faces as 6-node triangles (corners c0 c1 c2, then midside nodes of c0c1, c1c2, c2c0),
/// local node numbers, ordered so that (c1 − c0) × (c2 − c0) points out of a positively oriented
/// element (det J > 0). Face k is opposite corner 3, 2, 0, 1 respectively.
pub const TET10_FACES: [[usize; 6]; 4] = [
    [0, 2, 1, 6, 5, 4],
    [0, 1, 3, 4, 8, 7],
    [1, 2, 3, 5, 9, 8],
    [0, 3, 2, 7, 9, 6],
];

/// Gradients of the volume coordinates L0..L3 with respect to (ξ, η, ζ).
const DL: [[f64; 3]; 4] = [
    [-1.0, -1.0, -1.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];

fn volume_coords(xi: [f64; 3]) -> [f64; 4] {
    [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]]
}

/// Tetra10 shape functions at natural coordinates `xi`.
pub fn tet10_shape(xi: [f64; 3]) -> [f64; 10] {
    let l = volume_coords(xi);
    let mut n = [0.0; 10];
    for i in 0..4 {
        n[i] = l[i] * (2.0 * l[i] - 1.0);
    }
    for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
        n[4 + k] = 4.0 * l[*a] * l[*b];
    }
    n
}

/// Derivatives dN_a/dξ_j of the tetra10 shape functions at `xi`.
pub fn tet10_grad(xi: [f64; 3]) -> [[f64; 3]; 10] {
    let l = volume_coords(xi);
    let mut g = [[0.0; 3]; 10];
    for i in 0..4 {
        for j in 0..3 {
            g[i][j] = (4.0 * l[i] - 1.0) * DL[i][j];
        }
    }
    for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
        for j in 0..3 {
            g[4 + k][j] = 4.0 * (l[*b] * DL[*a][j] + l[*a] * DL[*b][j]);
        }
    }
    g
}

/// Corner pairs of the 6-node triangle edges, in the order of its midside nodes 3..=5.
pub const TRI6_EDGES: [[usize; 2]; 3] = [[0, 1], [1, 2], [2, 0]];

/// 6-node triangle shape functions at area coordinates (s, t) (M0 = 1 − s − t, M1 = s, M2 = t).
pub fn tri6_shape(st: [f64; 2]) -> [f64; 6] {
    let m = [1.0 - st[0] - st[1], st[0], st[1]];
    let mut n = [0.0; 6];
    for i in 0..3 {
        n[i] = m[i] * (2.0 * m[i] - 1.0);
    }
    for (k, [a, b]) in TRI6_EDGES.iter().enumerate() {
        n[3 + k] = 4.0 * m[*a] * m[*b];
    }
    n
}

/// Derivatives dN_a/d(s, t) of the 6-node triangle shape functions.
pub fn tri6_grad(st: [f64; 2]) -> [[f64; 2]; 6] {
    const DM: [[f64; 2]; 3] = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
    let m = [1.0 - st[0] - st[1], st[0], st[1]];
    let mut g = [[0.0; 2]; 6];
    for i in 0..3 {
        for j in 0..2 {
            g[i][j] = (4.0 * m[i] - 1.0) * DM[i][j];
        }
    }
    for (k, [a, b]) in TRI6_EDGES.iter().enumerate() {
        for j in 0..2 {
            g[3 + k][j] = 4.0 * (m[*b] * DM[*a][j] + m[*a] * DM[*b][j]);
        }
    }
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kronecker_and_partition_of_unity() {
        for (a, xi) in TET10_NODE_XI.iter().enumerate() {
            let n = tet10_shape(*xi);
            for (b, v) in n.iter().enumerate() {
                assert!((v - if a == b { 1.0 } else { 0.0 }).abs() < 1e-15);
            }
        }
        let xi = [0.21, 0.17, 0.33];
        let g = tet10_grad(xi);
        for j in 0..3 {
            let s: f64 = g.iter().map(|r| r[j]).sum();
            assert!(s.abs() < 1e-14);
            // finite-difference check
            let h = 1e-6;
            let mut p = xi;
            p[j] += h;
            let mut m = xi;
            m[j] -= h;
            let (np, nm) = (tet10_shape(p), tet10_shape(m));
            for a in 0..10 {
                assert!(((np[a] - nm[a]) / (2.0 * h) - g[a][j]).abs() < 1e-8);
            }
        }
        let st = [0.3, 0.25];
        let g = tri6_grad(st);
        for j in 0..2 {
            let h = 1e-6;
            let mut p = st;
            p[j] += h;
            let mut m = st;
            m[j] -= h;
            let (np, nm) = (tri6_shape(p), tri6_shape(m));
            for a in 0..6 {
                assert!(((np[a] - nm[a]) / (2.0 * h) - g[a][j]).abs() < 1e-8);
            }
        }
    }

    #[test]
    fn faces_are_consistent_with_edges() {
        for f in TET10_FACES {
            for (k, [a, b]) in TRI6_EDGES.iter().enumerate() {
                let (ca, cb) = (f[*a], f[*b]);
                let mid = f[3 + k];
                let e = TET10_EDGES[mid - 4];
                assert!(e == [ca, cb] || e == [cb, ca], "face {f:?}");
            }
        }
    }
}
