//! An elastic pin: the pin's own compliance added to the rigid cylinder's gap.
//!
//! The pin is a second linear-elastic body whose outer surface is the bore wall itself, node for
//! node (small sliding: the pressure acts on both surfaces at the same points), extruded radially
//! inwards to the radius r_i = `inner_ratio` · R in layers that grow geometrically from the wall
//! (the first half the wall faces' mean shortest edge thick, ×1.5 per layer, at most 12). Each prism of a wall face between two
//! levels is split into three tetrahedra by the smallest-index rule (the diagonal of each side
//! quad from its lower-index bottom corner to its higher-index top corner), so that neighbouring
//! prisms agree; the tetrahedra are quadratic (tet10), their midside nodes on the wall's radial
//! rays or at the diagonals' midpoints. Held ([`PinHold`]): its core (every node at r_i: a solid
//! pin around a rigid core, the pin's own compliance under the pressure without its bending), or
//! its two end faces (a pin held by the piston's bosses or the crank's webs right at the bore's
//! faces: the pin also bends and shears between them). A face of the bore whose wall nodes the
//! body holds along the axis (a symmetry plane, plane strain) holds the pin's nodes there along
//! the axis too, and is not an end the pin is held by.
//!
//! With the pin's translation w moving its held nodes, the weighted gap of the rigid cylinder
//! ([`super::cylinder`], [`super::solve`]) gains the pin's deflection under the contact pressure:
//!
//! G = D g₀ + C u − B w + S_p λ,  S_p = C_p K_p⁻¹ C_pᵀ,
//!
//! C_p the rows of C read at the pin's surface nodes (the pin, pushed towards its axis by the
//! pressure, opens the gap as the body does when pushed outwards). The condensed problem keeps its
//! form with the compliance S + S_p: the columns of S_p are added to the body's on the wall's rows
//! ([`super::system::ContactSystem`]), computed as the body's are ([`super::compliance`]) with the
//! pin's own factor. The nodal deflection δ = e·K_p⁻¹ Cᵀλ enters the gaps the check and the
//! outputs report.

use std::collections::HashMap;

use super::cylinder::{Cylinder, PinElasticity, PinHold, PinMotion};
use super::factorised::Factorised;
use super::weights::Wall;
use crate::fem::assembly::DofMap;
use crate::fem::boundary::dot;
use crate::fem::element::QuadratureChoice;
use crate::fem::error::{FemError, Result};
use crate::fem::mesh::TetMesh;
use crate::fem::shape::TET10_EDGES;

/// Growth of the layers' thickness from the wall inwards.
const GROWTH: f64 = 1.5;
/// The most layers through the pin's wall.
const MAX_LAYERS: usize = 12;

/// A pin's compliance on its wall's rows, factorised once (the body's
/// [`super::system::ContactSystem`] keeps the columns it asks for).
pub struct ElasticPin {
    mesh: TetMesh,
    wall: Wall,
    dofs: DofMap,
    fact: Factorised,
}

/// A node of the pin: a wall node `a` at level `l` (0 the wall, 2 N the inner radius; odd levels
/// the radial midsides), or the midpoint of a side quad's diagonal from (a, l) to (b, l + 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Key {
    Level(usize, usize),
    Diagonal(usize, usize, usize),
}

impl ElasticPin {
    /// The pin of `cyl` on `wall` (the body's `body`, whose prescribed DOFs are `prescribed`).
    pub fn new(
        body: &TetMesh,
        cyl: &Cylinder,
        wall: &Wall,
        prescribed: &[(usize, f64)],
        elasticity: &PinElasticity,
        quadrature: QuadratureChoice,
    ) -> Result<ElasticPin> {
        elasticity.material.validate()?;
        let ratio = elasticity.inner_ratio;
        if !(ratio > 0.0 && ratio < 1.0) {
            return Err(FemError::InvalidInput(format!(
                "elastic pin: the inner radius ratio must lie in (0, 1), got {ratio}"
            )));
        }
        let (mesh, sources, levels) = extrude(body, wall, ratio)?;
        let faces: Vec<[usize; 6]> = wall.faces.iter().map(|f| f.0).collect();
        let pin_cyl = Cylinder {
            faces,
            motion: PinMotion::Fixed,
            elastic: None,
            ..cyl.clone()
        };
        let pin_wall = Wall::new(&mesh, &pin_cyl, 0, 0)?;
        debug_assert_eq!(pin_wall.nodes, (0..wall.len()).collect::<Vec<_>>());
        let held = held_dofs(body, wall, prescribed, elasticity.hold, &sources, &levels)?;
        let dofs = DofMap::new(mesh.n_dofs(), &held)?;
        let fact = Factorised::new(
            &mesh,
            &elasticity.material,
            quadrature,
            &dofs,
            std::slice::from_ref(&pin_wall),
        )?;
        Ok(ElasticPin {
            mesh,
            wall: pin_wall,
            dofs,
            fact,
        })
    }

    /// The pin's mesh (its outer surface nodes first, in the wall's order).
    pub fn mesh(&self) -> &TetMesh {
        &self.mesh
    }

    /// The columns S_p[:, j] (over the wall's rows) of the wall's rows `js`.
    pub fn columns(&self, js: &[usize]) -> Vec<Vec<f64>> {
        self.fact.compliance.columns(&self.fact.factor, js)
    }

    /// The pin surface's displacement towards its axis at each wall node under the wall
    /// pressures `lambda`, δ_a = e_a · K_p⁻¹ Cᵀλ (m).
    pub fn deflection(&self, lambda: &[f64]) -> Vec<f64> {
        let mut f = vec![0.0; self.mesh.n_dofs()];
        self.wall.add_forces(lambda, &mut f);
        let mut b = self.fact.dirichlet_rhs.clone();
        for (d, v) in f.iter().enumerate() {
            if let Some(q) = self.dofs.eq(d) {
                b[q] += v;
            }
        }
        self.fact.solve(&mut b);
        (0..self.wall.len())
            .map(|a| {
                let u: [f64; 3] =
                    std::array::from_fn(|j| self.dofs.eq(3 * a + j).map_or(0.0, |q| b[q]));
                dot(self.wall.e[a], u)
            })
            .collect()
    }
}

/// The pin's mesh extruded from `wall` inwards to `ratio` × its radius: the mesh (the wall's
/// nodes first, in order), each node's wall nodes (one on a radial ray, two on a diagonal) and
/// its level (0 the wall, the largest the inner radius).
fn extrude(
    body: &TetMesh,
    wall: &Wall,
    ratio: f64,
) -> Result<(TetMesh, Vec<Vec<usize>>, Vec<usize>)> {
    let m = wall.len();
    let x = |a: usize| body.nodes()[wall.nodes[a]];
    let r0: Vec<f64> = (0..m)
        .map(|a| {
            let v: [f64; 3] = std::array::from_fn(|j| x(a)[j] - wall.centre[j]);
            let along = dot(v, wall.axis);
            let r: [f64; 3] = std::array::from_fn(|j| v[j] - along * wall.axis[j]);
            dot(r, r).sqrt()
        })
        .collect();
    let radius = r0.iter().sum::<f64>() / m as f64;
    let inner = ratio * radius;
    // the wall faces' mean shortest corner-to-corner edge
    let h = wall
        .faces
        .iter()
        .map(|(f, _, _)| {
            [(0, 1), (1, 2), (2, 0)]
                .map(|(i, j)| {
                    let d: [f64; 3] = std::array::from_fn(|k| x(f[i])[k] - x(f[j])[k]);
                    dot(d, d).sqrt()
                })
                .into_iter()
                .fold(f64::INFINITY, f64::min)
        })
        .sum::<f64>()
        / wall.faces.len() as f64;
    let depth = radius - inner;
    let t0 = 0.5 * h;
    let mut layers = 1;
    while layers < MAX_LAYERS && t0 * (GROWTH.powi(layers as i32) - 1.0) / (GROWTH - 1.0) < depth {
        layers += 1;
    }
    let layers = layers.max(2);
    // s(k): the fraction of the way to the inner radius at corner level k
    let mut s = vec![0.0; layers + 1];
    let total: f64 = (0..layers).map(|k| GROWTH.powi(k as i32)).sum();
    for k in 0..layers {
        s[k + 1] = s[k] + GROWTH.powi(k as i32) / total;
    }
    let frac = |l: usize| {
        if l.is_multiple_of(2) {
            s[l / 2]
        } else {
            0.5 * (s[l / 2] + s[l / 2 + 1])
        }
    };
    let at = |a: usize, l: usize| -> [f64; 3] {
        let d = frac(l) * (r0[a] - inner);
        std::array::from_fn(|j| x(a)[j] - d * wall.e[a][j])
    };
    // the wall's midside node of each corner pair
    let mut midside: HashMap<(usize, usize), usize> = HashMap::new();
    for (f, _, _) in &wall.faces {
        for (k, (i, j)) in [(0, 1), (1, 2), (2, 0)].into_iter().enumerate() {
            midside.insert((f[i].min(f[j]), f[i].max(f[j])), f[3 + k]);
        }
    }
    let mut ids: HashMap<Key, usize> = HashMap::new();
    let mut nodes: Vec<[f64; 3]> = Vec::new();
    let mut sources: Vec<Vec<usize>> = Vec::new();
    let mut levels: Vec<usize> = Vec::new();
    for a in 0..m {
        ids.insert(Key::Level(a, 0), a);
        nodes.push(x(a));
        sources.push(vec![a]);
        levels.push(0);
    }
    let mut node = |key: Key, nodes: &mut Vec<[f64; 3]>| -> usize {
        *ids.entry(key).or_insert_with(|| {
            let (p, src, lev) = match key {
                Key::Level(a, l) => (at(a, l), vec![a], l),
                Key::Diagonal(a, b, l) => {
                    let (p, q) = (at(a, l), at(b, l + 2));
                    (
                        std::array::from_fn(|j| 0.5 * (p[j] + q[j])),
                        vec![a, b],
                        l + 1,
                    )
                }
            };
            nodes.push(p);
            sources.push(src);
            levels.push(lev);
            nodes.len() - 1
        })
    };
    let mut elements: Vec<[usize; 10]> = Vec::new();
    for (f, _, _) in &wall.faces {
        let mut v = [f[0], f[1], f[2]];
        v.sort_unstable();
        for k in 0..layers {
            let (lb, lt) = (2 * k, 2 * k + 2);
            let b = v.map(|a| (a, lb));
            let t = v.map(|a| (a, lt));
            for tet in [
                [b[0], b[1], b[2], t[2]],
                [b[0], b[1], t[1], t[2]],
                [b[0], t[0], t[1], t[2]],
            ] {
                let mut c = tet;
                let p = c.map(|(a, l)| at(a, l));
                let d = |i: usize| -> [f64; 3] { std::array::from_fn(|j| p[i][j] - p[0][j]) };
                let vol = dot(d(1), crate::fem::boundary::cross(d(2), d(3)));
                if vol < 0.0 {
                    c.swap(1, 2);
                }
                let mut el = [0usize; 10];
                for (i, &(a, l)) in c.iter().enumerate() {
                    el[i] = node(Key::Level(a, l), &mut nodes);
                }
                for (e, [i, j]) in TET10_EDGES.iter().enumerate() {
                    let ((a1, l1), (a2, l2)) = (c[*i], c[*j]);
                    let key = if a1 == a2 {
                        Key::Level(a1, (l1 + l2) / 2)
                    } else if l1 == l2 {
                        Key::Level(midside[&(a1.min(a2), a1.max(a2))], l1)
                    } else {
                        // the diagonal runs from the lower-index corner's bottom
                        let (lo, hi) = if l1 < l2 { (a1, a2) } else { (a2, a1) };
                        Key::Diagonal(lo, hi, l1.min(l2))
                    };
                    el[4 + e] = node(key, &mut nodes);
                }
                elements.push(el);
            }
        }
    }
    let mesh = TetMesh::new(nodes, elements).map_err(|e| {
        FemError::InvalidMesh(format!(
            "elastic pin: the mesh extruded from the bore wall is not valid ({e}); use rigid \
                 pins (`[fem] pins = \"rigid\"`) for this bore"
        ))
    })?;
    Ok((mesh, sources, levels))
}

/// The pin's held DOFs: its core or its end faces, and along the axis where the body holds the
/// wall nodes the pin's node lies over.
fn held_dofs(
    body: &TetMesh,
    wall: &Wall,
    prescribed: &[(usize, f64)],
    hold: PinHold,
    sources: &[Vec<usize>],
    levels: &[usize],
) -> Result<Vec<(usize, f64)>> {
    let held_body: std::collections::HashSet<usize> = prescribed.iter().map(|p| p.0).collect();
    // the axis along a coordinate direction: that DOF of a wall node held by the body
    let axial = (0..3).find(|&j| wall.axis[j].abs() > 1.0 - 1e-12);
    let held_along = |a: usize| axial.is_some_and(|j| held_body.contains(&(3 * wall.nodes[a] + j)));
    let along = |a: usize| {
        dot(
            std::array::from_fn(|j| body.nodes()[wall.nodes[a]][j] - wall.centre[j]),
            wall.axis,
        )
    };
    let m = wall.len();
    let (lo, hi) = (0..m).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), a| {
        (lo.min(along(a)), hi.max(along(a)))
    });
    let tol = 1e-6 * (hi - lo).max(f64::MIN_POSITIVE);
    let inner = levels.iter().copied().max().unwrap_or(0);
    // an end of the bore whose wall nodes the body holds along the axis is a symmetry plane
    let end_is_plane = |end: f64| {
        (0..m)
            .filter(|&a| (along(a) - end).abs() <= tol)
            .all(held_along)
    };
    let ends: Vec<f64> = [lo, hi]
        .into_iter()
        .filter(|&end| !end_is_plane(end))
        .collect();
    let mut out = Vec::new();
    for (p, (src, &level)) in sources.iter().zip(levels).enumerate() {
        let fully = match hold {
            PinHold::Core => level == inner,
            PinHold::Ends => {
                let z = src.iter().map(|&a| along(a)).sum::<f64>() / src.len() as f64;
                src.iter()
                    .all(|&a| ends.iter().any(|e| (along(a) - e).abs() <= tol))
                    && ends.iter().any(|e| (z - e).abs() <= tol)
            }
        };
        if fully {
            out.extend((0..3).map(|j| (3 * p + j, 0.0)));
        } else if let Some(j) = axial
            && src.iter().all(|&a| held_along(a))
        {
            out.push((3 * p + j, 0.0));
        }
    }
    if !out.iter().any(|&(d, _)| axial.is_none_or(|j| d % 3 != j)) {
        return Err(FemError::InvalidInput(
            "elastic pin: nothing holds it (held at its ends, but the body holds both of the \
             bore's faces along the axis: hold it at its core)"
                .into(),
        ));
    }
    Ok(out)
}
