//! A structured tetra10 mesh of a thick ring (an annulus extruded along z), for verification:
//! the annulus a ≤ r ≤ b is divided into n_θ sectors and n_r rings (sizes growing geometrically
//! outwards by `grading` from the first ring to the last), each quad split into two triangles,
//! the prisms into three tetrahedra by the global-index rule of [`super::structured`]. Every
//! node, midside nodes included, is placed by the polar map (r, θ, z) ↦ (r cos θ, r sin θ, z)
//! from its parameter-space position, so the element edges along θ are arcs of the circles and
//! the inner and outer walls are exact cylinders at the nodes.

use std::collections::HashMap;

use super::TetMesh;
use super::structured::signed_volume;
use crate::fem::error::{FemError, Result};
use crate::fem::shape::TET10_EDGES;

/// Parameters of [`ring_tet10`], metres.
#[derive(Clone, Copy, Debug)]
pub struct Ring {
    /// Inner radius a.
    pub inner_radius: f64,
    /// Outer radius b.
    pub outer_radius: f64,
    /// Thickness along z (from z = 0).
    pub thickness: f64,
    /// Sectors around.
    pub n_theta: usize,
    /// Rings from a to b.
    pub n_radial: usize,
    /// Layers along z.
    pub n_z: usize,
    /// Ratio of the outermost ring's radial size to the innermost's.
    pub grading: f64,
}

/// The ring of `p`.
pub fn ring_tet10(p: &Ring) -> Result<TetMesh> {
    let (a, b) = (p.inner_radius, p.outer_radius);
    if !(a > 0.0 && b > a && p.thickness > 0.0 && p.grading > 0.0)
        || p.n_theta < 3
        || p.n_radial < 1
        || p.n_z < 1
    {
        return Err(FemError::InvalidInput(format!("invalid ring {p:?}")));
    }
    // radii: sizes s_i = s_0 q^i, q^(n−1) = grading
    let nr = p.n_radial;
    let q = if nr > 1 {
        p.grading.powf(1.0 / (nr - 1) as f64)
    } else {
        1.0
    };
    let weights: Vec<f64> = (0..nr).map(|i| q.powi(i as i32)).collect();
    let total: f64 = weights.iter().sum();
    let mut radii = vec![a];
    for w in &weights {
        radii.push(radii.last().unwrap() + (b - a) * w / total);
    }
    radii[nr] = b;
    let nt = p.n_theta;
    let dth = 2.0 * std::f64::consts::PI / nt as f64;
    // parameter-space corner nodes (r, θ, z); θ index wraps
    let id2 = |i: usize, k: usize| i + (nr + 1) * (k % nt);
    let n2 = (nr + 1) * nt;
    let mut param: Vec<[f64; 3]> = Vec::with_capacity(n2 * (p.n_z + 1));
    for l in 0..=p.n_z {
        let z = p.thickness * l as f64 / p.n_z as f64;
        for k in 0..nt {
            for r in &radii {
                param.push([*r, k as f64 * dth, z]);
            }
        }
    }
    let mut tris = Vec::with_capacity(2 * nr * nt);
    for k in 0..nt {
        for i in 0..nr {
            let (p0, p1, p2, p3) = (id2(i, k), id2(i + 1, k), id2(i + 1, k + 1), id2(i, k + 1));
            tris.push([p0, p1, p2]);
            tris.push([p0, p2, p3]);
        }
    }
    let mut tets = Vec::with_capacity(3 * tris.len() * p.n_z);
    for t in &tris {
        let mut v = *t;
        v.sort_unstable();
        let [x, y, w] = v;
        for l in 0..p.n_z {
            let (lo, hi) = (l * n2, (l + 1) * n2);
            tets.push([x + lo, y + lo, w + lo, w + hi]);
            tets.push([x + lo, y + lo, y + hi, w + hi]);
            tets.push([x + lo, x + hi, y + hi, w + hi]);
        }
    }
    let polar = |s: [f64; 3]| [s[0] * s[1].cos(), s[0] * s[1].sin(), s[2]];
    let mut nodes: Vec<[f64; 3]> = param.iter().map(|s| polar(*s)).collect();
    let mut mid: HashMap<(usize, usize), usize> = HashMap::new();
    let mut elements = Vec::with_capacity(tets.len());
    for t in &tets {
        let mut c = *t;
        if signed_volume(&nodes, &c) < 0.0 {
            c.swap(1, 2);
        }
        let mut el = [0usize; 10];
        el[..4].copy_from_slice(&c);
        for (k, [ea, eb]) in TET10_EDGES.iter().enumerate() {
            let (u, v) = (c[*ea].min(c[*eb]), c[*ea].max(c[*eb]));
            let id = *mid.entry((u, v)).or_insert_with(|| {
                let (su, mut sv) = (param[u], param[v]);
                // across the seam θ = 0 = 2π
                if (sv[1] - su[1]).abs() > std::f64::consts::PI {
                    sv[1] += if sv[1] < su[1] { 2.0 } else { -2.0 } * std::f64::consts::PI;
                }
                nodes.push(polar(std::array::from_fn(|j| 0.5 * (su[j] + sv[j]))));
                nodes.len() - 1
            });
            el[4 + k] = id;
        }
        elements.push(el);
    }
    TetMesh::new(nodes, elements)
}
