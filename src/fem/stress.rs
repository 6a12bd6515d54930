//! Stress recovery: the strain of each element evaluated directly at its ten nodes (the
//! "element-nodal, unaveraged" values NX Nastran reports), σ = D ε, and the nodal average of those
//! tensors over the elements sharing a node (component-wise, then von Mises). Peaks with their
//! locations, and the band of nodes near a surface (to exclude the fixed-edge singularity).

use std::collections::HashMap;

use rayon::prelude::*;

use super::boundary::{cross, dot};
use super::element::{ElementCoords, shape_gradients, strain};
use super::error::Result;
use super::material::{Material, von_mises};
use super::mesh::TetMesh;
use super::shape::TET10_NODE_XI;

/// Stresses of one solution, Pa, components `[xx, yy, zz, xy, yz, zx]`.
#[derive(Clone, Debug)]
pub struct StressField {
    /// σ at each element's ten nodes (unaveraged).
    pub element_nodal: Vec<[[f64; 6]; 10]>,
    /// Nodal average of the element-nodal tensors.
    pub averaged: Vec<[f64; 6]>,
}

/// Computes the stress field of the displacements `u` (3 per node, m).
pub fn stress_field(mesh: &TetMesh, material: &Material, u: &[f64]) -> Result<StressField> {
    let element_nodal: Vec<[[f64; 6]; 10]> = (0..mesh.n_elements())
        .into_par_iter()
        .map(|e| {
            let x: ElementCoords = mesh.element_coords(e);
            let ue = mesh.element_displacements(e, u);
            let mut out = [[0.0; 6]; 10];
            for (a, xi) in TET10_NODE_XI.iter().enumerate() {
                let (g, _) = shape_gradients(&x, *xi, e, "node")?;
                out[a] = material.stress(&strain(&g, &ue));
            }
            Ok(out)
        })
        .collect::<Result<_>>()?;
    let mut sum = vec![[0.0; 6]; mesh.n_nodes()];
    let mut count = vec![0u32; mesh.n_nodes()];
    for (el, s) in mesh.elements().iter().zip(&element_nodal) {
        for a in 0..10 {
            for c in 0..6 {
                sum[el[a]][c] += s[a][c];
            }
            count[el[a]] += 1;
        }
    }
    let averaged = sum
        .iter()
        .zip(&count)
        .map(|(s, &n)| s.map(|v| v / f64::from(n)))
        .collect();
    Ok(StressField {
        element_nodal,
        averaged,
    })
}

impl StressField {
    /// Von Mises stress of the nodally averaged tensors, per node, Pa.
    pub fn von_mises_averaged(&self) -> Vec<f64> {
        self.averaged.iter().map(von_mises).collect()
    }

    /// Largest unaveraged von Mises stress over each element's nodes, Pa.
    pub fn von_mises_element_max(&self) -> Vec<f64> {
        self.element_nodal
            .iter()
            .map(|s| s.iter().map(von_mises).fold(0.0, f64::max))
            .collect()
    }
}

/// A maximum and where it sits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Peak {
    /// The value (Pa for stresses, m for displacements).
    pub value: f64,
    /// Node.
    pub node: usize,
    /// Element (for element-nodal values).
    pub element: Option<usize>,
    /// Node coordinates, m.
    pub location_m: [f64; 3],
}

/// Largest unaveraged (element-nodal) von Mises stress over the nodes where `mask` is true (all when
/// `None`). Ties go to the first element.
pub fn peak_unaveraged(mesh: &TetMesh, field: &StressField, mask: Option<&[bool]>) -> Peak {
    let mut best = Peak {
        value: f64::NEG_INFINITY,
        node: 0,
        element: None,
        location_m: [0.0; 3],
    };
    for (e, (el, s)) in mesh.elements().iter().zip(&field.element_nodal).enumerate() {
        for a in 0..10 {
            if mask.is_some_and(|m| !m[el[a]]) {
                continue;
            }
            let v = von_mises(&s[a]);
            if v > best.value {
                best = Peak {
                    value: v,
                    node: el[a],
                    element: Some(e),
                    location_m: mesh.nodes()[el[a]],
                };
            }
        }
    }
    best
}

/// Largest value of a nodal quantity over the nodes where `mask` is true (all when `None`).
pub fn peak_nodal(mesh: &TetMesh, values: &[f64], mask: Option<&[bool]>) -> Peak {
    let mut best = Peak {
        value: f64::NEG_INFINITY,
        node: 0,
        element: None,
        location_m: [0.0; 3],
    };
    for (n, &v) in values.iter().enumerate() {
        if mask.is_some_and(|m| !m[n]) {
            continue;
        }
        if v > best.value {
            best = Peak {
                value: v,
                node: n,
                element: None,
                location_m: mesh.nodes()[n],
            };
        }
    }
    best
}

/// Displacement magnitude per node, m.
pub fn displacement_magnitudes(u: &[f64]) -> Vec<f64> {
    u.chunks_exact(3)
        .map(|d| (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt())
        .collect()
}

/// Per node: true when its distance to the surface made of the corner triangles of `faces` is at
/// least `band` (m).
pub fn nodes_away_from(mesh: &TetMesh, faces: &[[usize; 6]], band: f64) -> Vec<bool> {
    let corners = |i: usize| {
        let f = &faces[i];
        [mesh.nodes()[f[0]], mesh.nodes()[f[1]], mesh.nodes()[f[2]]]
    };
    nodes_away_from_shapes(
        mesh,
        faces.len(),
        band,
        |i| corners(i).to_vec(),
        |p, i| point_triangle_distance(p, corners(i)),
    )
}

/// Per node: true when it is at least `band` (m) from each of `n` shapes, given the points that
/// bound shape i (its bounding box is theirs) and the distance from a point to it. Shapes are
/// binned on a grid of spacing `band`, so each node tests only the shapes in its cell.
fn nodes_away_from_shapes(
    mesh: &TetMesh,
    n: usize,
    band: f64,
    points: impl Fn(usize) -> Vec<[f64; 3]>,
    distance: impl Fn([f64; 3], usize) -> f64 + Sync,
) -> Vec<bool> {
    if n == 0 || band.is_nan() || band <= 0.0 {
        return vec![true; mesh.n_nodes()];
    }
    let cell = |p: [f64; 3]| p.map(|v| (v / band).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for i in 0..n {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for q in points(i) {
            for j in 0..3 {
                lo[j] = lo[j].min(q[j] - band);
                hi[j] = hi[j].max(q[j] + band);
            }
        }
        let (a, b) = (cell(lo), cell(hi));
        for x in a[0]..=b[0] {
            for y in a[1]..=b[1] {
                for z in a[2]..=b[2] {
                    grid.entry([x, y, z]).or_default().push(i);
                }
            }
        }
    }
    mesh.nodes()
        .par_iter()
        .map(|p| {
            grid.get(&cell(*p))
                .is_none_or(|list| list.iter().all(|&i| distance(*p, i) >= band))
        })
        .collect()
}

/// Distance from `p` to the triangle `t` (Ericson, "Real-Time Collision Detection", §5.1.5).
pub fn point_triangle_distance(p: [f64; 3], t: [[f64; 3]; 3]) -> f64 {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let [a, b, c] = t;
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    let q = |v: [f64; 3], s: f64, w: [f64; 3]| [v[0] + s * w[0], v[1] + s * w[1], v[2] + s * w[2]];
    let dist = |x: [f64; 3]| {
        let d = sub(p, x);
        dot(d, d).sqrt()
    };
    if d1 <= 0.0 && d2 <= 0.0 {
        return dist(a);
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return dist(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return dist(q(a, d1 / (d1 - d3), ab));
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return dist(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return dist(q(a, d2 / (d2 - d6), ac));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return dist(q(b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), sub(c, b)));
    }
    let n = cross(ab, ac);
    dot(ap, n).abs() / dot(n, n).sqrt()
}

/// Per node: true when its distance to every segment of `segments` is at least `band` (m).
pub fn nodes_away_from_segments(
    mesh: &TetMesh,
    segments: &[[[f64; 3]; 2]],
    band: f64,
) -> Vec<bool> {
    nodes_away_from_shapes(
        mesh,
        segments.len(),
        band,
        |i| segments[i].to_vec(),
        |p, i| point_segment_distance(p, segments[i]),
    )
}

/// Distance from `p` to the segment `s`.
pub fn point_segment_distance(p: [f64; 3], s: [[f64; 3]; 2]) -> f64 {
    let d: [f64; 3] = std::array::from_fn(|j| s[1][j] - s[0][j]);
    let w: [f64; 3] = std::array::from_fn(|j| p[j] - s[0][j]);
    let dd = dot(d, d);
    let t = if dd > 0.0 {
        (dot(w, d) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q: [f64; 3] = std::array::from_fn(|j| w[j] - t * d[j]);
    dot(q, q).sqrt()
}
