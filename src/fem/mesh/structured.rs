//! Structured 10-node tetrahedral meshes generated in Rust, for verification without gmsh:
//! a box split into hexahedra, each into six tetrahedra ([`box_tet10`]); and a rod-like plate with
//! two bores ([`two_eye_plate`]), a 2D O-grid/rectangle triangulation extruded along z, each prism
//! split into three tetrahedra by the global-index rule (conforming by construction: on the quad face
//! over a 2D edge p < q the diagonal always runs from p at the lower layer to q at the upper one).

use std::collections::HashMap;

use super::TetMesh;
use crate::fem::error::Result;
use crate::fem::shape::TET10_EDGES;

/// Adds midside nodes (straight, at edge midpoints, shared between elements) to linear tetrahedra
/// and orients every element positively.
pub fn tet4_to_tet10(mut nodes: Vec<[f64; 3]>, tets: &[[usize; 4]]) -> Result<TetMesh> {
    let mut edge_node: HashMap<(usize, usize), usize> = HashMap::new();
    let mut elements = Vec::with_capacity(tets.len());
    for t in tets {
        let mut c = *t;
        if signed_volume(&nodes, &c) < 0.0 {
            c.swap(1, 2);
        }
        let mut el = [0usize; 10];
        el[..4].copy_from_slice(&c);
        for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
            let (p, q) = (c[*a].min(c[*b]), c[*a].max(c[*b]));
            let id = *edge_node.entry((p, q)).or_insert_with(|| {
                let m = std::array::from_fn(|j| 0.5 * (nodes[p][j] + nodes[q][j]));
                nodes.push(m);
                nodes.len() - 1
            });
            el[4 + k] = id;
        }
        elements.push(el);
    }
    TetMesh::new(nodes, elements)
}

/// Six times the signed volume of the tetrahedron on corners `c` of `nodes` (the triple product
/// of its edges from corner 0; positive for corners 1-2-3 anticlockwise seen from corner 4).
pub(crate) fn signed_volume(nodes: &[[f64; 3]], c: &[usize; 4]) -> f64 {
    let d = |i: usize| std::array::from_fn::<f64, 3, _>(|j| nodes[c[i]][j] - nodes[c[0]][j]);
    let (a, b, e) = (d(1), d(2), d(3));
    a[0] * (b[1] * e[2] - b[2] * e[1]) - a[1] * (b[0] * e[2] - b[2] * e[0])
        + a[2] * (b[0] * e[1] - b[1] * e[0])
}

/// Box [0, lx] × [0, ly] × [0, lz] (m) with nx × ny × nz hexahedra, each split into six tetrahedra
/// around its main diagonal (Kuhn/Freudenthal split, conforming on a structured grid), straight-sided
/// tetra10 (nx·ny·nz·6 elements).
pub fn box_tet10(lx: f64, ly: f64, lz: f64, nx: usize, ny: usize, nz: usize) -> Result<TetMesh> {
    let id = |i: usize, j: usize, k: usize| i + (nx + 1) * (j + (ny + 1) * k);
    let mut nodes = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                nodes.push([
                    lx * i as f64 / nx as f64,
                    ly * j as f64 / ny as f64,
                    lz * k as f64 / nz as f64,
                ]);
            }
        }
    }
    const PERMS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut tets = Vec::with_capacity(6 * nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                for p in PERMS {
                    let mut v = [i, j, k];
                    let mut t = [id(i, j, k); 4];
                    for (s, axis) in p.iter().enumerate() {
                        v[*axis] += 1;
                        t[s + 1] = id(v[0], v[1], v[2]);
                    }
                    tets.push(t);
                }
            }
        }
    }
    tet4_to_tet10(nodes, &tets)
}

/// Parameters of [`two_eye_plate`]: a rod-like block with two through bores along z, in metres.
#[derive(Clone, Copy, Debug)]
pub struct TwoEyePlate {
    /// Distance between the bore centres A = (0, 0, 0) and B = (length, 0, 0).
    pub length: f64,
    /// Bore radius at A.
    pub bore_a_radius: f64,
    /// Bore radius at B.
    pub bore_b_radius: f64,
    /// Half-width S: the outline is [−S, length + S] × [−S, S].
    pub half_width: f64,
    /// Thickness along z (centred on z = 0).
    pub thickness: f64,
    /// Divisions along each side of the squares around the bores (4× that around a bore).
    pub n_side: usize,
    /// Divisions from a bore to its square.
    pub n_radial: usize,
    /// Divisions along x of the part between the squares.
    pub n_shank: usize,
    /// Layers along z.
    pub n_z: usize,
    /// Place the midside nodes of bore-wall edges on the cylinder (curved elements).
    pub curved: bool,
}

impl Default for TwoEyePlate {
    /// The rodstudy interface: bores of 50 and 25 mm diameter, 180 mm apart, 40 mm thick.
    fn default() -> Self {
        TwoEyePlate {
            length: 0.18,
            bore_a_radius: 0.025,
            bore_b_radius: 0.0125,
            half_width: 0.045,
            thickness: 0.04,
            n_side: 4,
            n_radial: 3,
            n_shank: 6,
            n_z: 4,
            curved: false,
        }
    }
}

/// The plate of `p` meshed with tetra10: O-grids around both bores, a structured block between them.
pub fn two_eye_plate(p: &TwoEyePlate) -> Result<TetMesh> {
    let s = p.half_width;
    let mut pts2: Vec<[f64; 2]> = Vec::new();
    let mut index: HashMap<(i64, i64), usize> = HashMap::new();
    // merges coincident points (shared by the blocks)
    let mut node = |pts2: &mut Vec<[f64; 2]>, x: f64, y: f64| -> usize {
        let key = ((x * 1e9).round() as i64, (y * 1e9).round() as i64);
        *index.entry(key).or_insert_with(|| {
            pts2.push([x, y]);
            pts2.len() - 1
        })
    };
    let mut tris: Vec<[usize; 3]> = Vec::new();
    let mut quad = |q: [usize; 4], pts: &[[f64; 2]]| {
        let d = |a: usize, b: usize| (pts[a][0] - pts[b][0]).hypot(pts[a][1] - pts[b][1]);
        if d(q[0], q[2]) <= d(q[1], q[3]) {
            tris.push([q[0], q[1], q[2]]);
            tris.push([q[0], q[2], q[3]]);
        } else {
            tris.push([q[0], q[1], q[3]]);
            tris.push([q[1], q[2], q[3]]);
        }
    };
    let n = p.n_side;
    for (cx, r) in [(0.0, p.bore_a_radius), (p.length, p.bore_b_radius)] {
        // perimeter of the square, counter-clockwise from (S, −S)
        let perim: Vec<[f64; 2]> = (0..4 * n)
            .map(|k| {
                let (side, t) = (k / n, (k % n) as f64 / n as f64);
                let u = -s + 2.0 * s * t;
                match side {
                    0 => [s, u],
                    1 => [-u, s],
                    2 => [-s, -u],
                    _ => [u, -s],
                }
            })
            .collect();
        let mut grid = vec![vec![0usize; p.n_radial + 1]; 4 * n];
        for (q, row) in perim.iter().zip(grid.iter_mut()) {
            let th = q[1].atan2(q[0]);
            let c = [r * th.cos(), r * th.sin()];
            for (i, id) in row.iter_mut().enumerate() {
                let f = i as f64 / p.n_radial as f64;
                let (x, y) = (c[0] + f * (q[0] - c[0]), c[1] + f * (q[1] - c[1]));
                *id = node(&mut pts2, cx + x, y);
            }
        }
        for k in 0..4 * n {
            let k1 = (k + 1) % (4 * n);
            for i in 0..p.n_radial {
                quad(
                    [grid[k][i], grid[k1][i], grid[k1][i + 1], grid[k][i + 1]],
                    &pts2,
                );
            }
        }
    }
    // the block between the squares
    let (x0, x1) = (s, p.length - s);
    let mut g = vec![vec![0usize; n + 1]; p.n_shank + 1];
    for (i, row) in g.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = node(
                &mut pts2,
                x0 + (x1 - x0) * i as f64 / p.n_shank as f64,
                -s + 2.0 * s * j as f64 / n as f64,
            );
        }
    }
    for i in 0..p.n_shank {
        for j in 0..n {
            quad([g[i][j], g[i + 1][j], g[i + 1][j + 1], g[i][j + 1]], &pts2);
        }
    }
    // extrude
    let n2 = pts2.len();
    let mut nodes = Vec::with_capacity(n2 * (p.n_z + 1));
    for k in 0..=p.n_z {
        let z = -0.5 * p.thickness + p.thickness * k as f64 / p.n_z as f64;
        nodes.extend(pts2.iter().map(|q| [q[0], q[1], z]));
    }
    let mut tets = Vec::with_capacity(3 * tris.len() * p.n_z);
    for t in &tris {
        let mut v = *t;
        v.sort_unstable();
        let [a, b, c] = v;
        for k in 0..p.n_z {
            let (lo, hi) = (k * n2, (k + 1) * n2);
            tets.push([a + lo, b + lo, c + lo, c + hi]);
            tets.push([a + lo, b + lo, b + hi, c + hi]);
            tets.push([a + lo, a + hi, b + hi, c + hi]);
        }
    }
    let mesh = tet4_to_tet10(nodes, &tets)?;
    if !p.curved {
        return Ok(mesh);
    }
    // midside nodes of edges lying on a bore wall: onto the cylinder
    let mut moved = mesh.nodes().to_vec();
    let on = |q: [f64; 3], cx: f64, r: f64| ((q[0] - cx).hypot(q[1]) - r).abs() <= 1e-9 * r;
    for el in mesh.elements() {
        for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
            let (qa, qb) = (mesh.nodes()[el[*a]], mesh.nodes()[el[*b]]);
            for (cx, r) in [(0.0, p.bore_a_radius), (p.length, p.bore_b_radius)] {
                if on(qa, cx, r) && on(qb, cx, r) {
                    let m = &mut moved[el[4 + k]];
                    let rm = (m[0] - cx).hypot(m[1]);
                    m[0] = cx + (m[0] - cx) * r / rm;
                    m[1] *= r / rm;
                }
            }
        }
    }
    mesh.map_nodes(|i, _| moved[i])
}
