//! Closed triangle meshes with known mass properties, for tests and benchmarks, and the
//! transformations and STL encodings the tests apply to them.
//!
//! Every generator returns an outward-oriented (counter-clockwise seen from outside), welded
//! mesh. The exact properties of the tessellated solids are stated where they have a closed form.

use super::stl_file::RawTriangle;
use super::weld::IndexedMesh;
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::TAU;

/// Axis-aligned box with the given edge lengths, centred at `centre` (12 triangles).
pub fn cuboid(size: Vector3<f64>, centre: Vector3<f64>) -> IndexedMesh {
    voxel_solid([1, 1, 1], size, centre - size / 2.0, |_, _, _| true)
}

/// Hollow circular cylinder (a tube) along z, centred at the origin, tessellated with
/// `segments` flat facets around: 8·segments triangles.
///
/// The tessellated solid is a prism over a regular polygon annulus: its exact volume is
/// h·(n/2)·sin(2π/n)·(R² − r²), and its polar moment J = (n ρ⁴/12) sin(2π/n)(2 + cos(2π/n)) per
/// polygon of circumradius ρ (see [`polygon_prism_properties`]).
pub fn hollow_cylinder(outer: f64, inner: f64, height: f64, segments: usize) -> IndexedMesh {
    let n = segments as u32;
    let mut vertices = Vec::with_capacity(4 * segments);
    for radius in [outer, inner] {
        for z in [-height / 2.0, height / 2.0] {
            for i in 0..segments {
                let a = TAU * i as f64 / segments as f64;
                vertices.push(Vector3::new(radius * a.cos(), radius * a.sin(), z));
            }
        }
    }
    // Ring indices: outer bottom, outer top, inner bottom, inner top.
    let (ob, ot, ib, it) = (0, n, 2 * n, 3 * n);
    let mut triangles = Vec::with_capacity(8 * segments);
    for i in 0..n {
        let j = (i + 1) % n;
        triangles.extend([
            [ob + i, ob + j, ot + j],
            [ob + i, ot + j, ot + i],
            [ib + i, it + j, ib + j],
            [ib + i, it + i, it + j],
            [it + i, ot + i, ot + j],
            [it + i, ot + j, it + j],
            [ib + i, ob + j, ob + i],
            [ib + i, ib + j, ob + j],
        ]);
    }
    IndexedMesh {
        vertices,
        triangles,
    }
}

/// Exact volume, I_zz and I_xx (per unit density, about the centroid) of [`hollow_cylinder`]'s
/// tessellated solid: a prism of height h over the annulus between two regular n-gons.
pub fn polygon_prism_properties(
    outer: f64,
    inner: f64,
    height: f64,
    segments: usize,
) -> (f64, f64, f64) {
    let n = segments as f64;
    let (s, c) = ((TAU / n).sin(), (TAU / n).cos());
    let area = n / 2.0 * s * (outer.powi(2) - inner.powi(2));
    let polar = n / 12.0 * s * (2.0 + c) * (outer.powi(4) - inner.powi(4));
    let volume = area * height;
    // A regular polygon's in-plane second moments are isotropic: I_x = I_y = J/2.
    let i_zz = polar * height;
    let i_xx = polar / 2.0 * height + area * height.powi(3) / 12.0;
    (volume, i_zz, i_xx)
}

/// Torus about z with major radius `major` and tube radius `minor`, 2·n·m triangles.
/// The smooth torus has V = 2π² R r² and I_zz = m (R² + 3r²/4).
pub fn torus(major: f64, minor: f64, n: usize, m: usize) -> IndexedMesh {
    let mut vertices = Vec::with_capacity(n * m);
    for i in 0..n {
        let u = TAU * i as f64 / n as f64;
        for j in 0..m {
            let v = TAU * j as f64 / m as f64;
            let rho = major + minor * v.cos();
            vertices.push(Vector3::new(rho * u.cos(), rho * u.sin(), minor * v.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let mut triangles = Vec::with_capacity(2 * n * m);
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.extend([[a, b, c], [a, c, d]]);
        }
    }
    IndexedMesh {
        vertices,
        triangles,
    }
}

/// The boundary of a union of grid cells: `cells` counts per axis, each cell of size `cell`,
/// the grid's lowest corner at `origin`, `filled(i, j, k)` says which cells are solid.
/// Two filled cells must not touch along an edge only (that surface would be non-manifold).
pub fn voxel_solid(
    cells: [usize; 3],
    cell: Vector3<f64>,
    origin: Vector3<f64>,
    filled: impl Fn(usize, usize, usize) -> bool,
) -> IndexedMesh {
    let [nx, ny, nz] = cells;
    let solid = |i: isize, j: isize, k: isize| {
        i >= 0
            && j >= 0
            && k >= 0
            && (i as usize) < nx
            && (j as usize) < ny
            && (k as usize) < nz
            && filled(i as usize, j as usize, k as usize)
    };
    let grid_id = |i: usize, j: usize, k: usize| ((i * (ny + 1) + j) * (nz + 1) + k) as u32;
    let mut quads = Vec::new();
    for i in 0..nx {
        for j in 0..ny {
            for k in 0..nz {
                if !filled(i, j, k) {
                    continue;
                }
                let (si, sj, sk) = (i as isize, j as isize, k as isize);
                let g = |di, dj, dk| grid_id(i + di, j + dj, k + dk);
                // Corners listed counter-clockwise seen from outside each face.
                if !solid(si + 1, sj, sk) {
                    quads.push([g(1, 0, 0), g(1, 1, 0), g(1, 1, 1), g(1, 0, 1)]);
                }
                if !solid(si - 1, sj, sk) {
                    quads.push([g(0, 0, 0), g(0, 0, 1), g(0, 1, 1), g(0, 1, 0)]);
                }
                if !solid(si, sj + 1, sk) {
                    quads.push([g(0, 1, 0), g(0, 1, 1), g(1, 1, 1), g(1, 1, 0)]);
                }
                if !solid(si, sj - 1, sk) {
                    quads.push([g(0, 0, 0), g(1, 0, 0), g(1, 0, 1), g(0, 0, 1)]);
                }
                if !solid(si, sj, sk + 1) {
                    quads.push([g(0, 0, 1), g(1, 0, 1), g(1, 1, 1), g(0, 1, 1)]);
                }
                if !solid(si, sj, sk - 1) {
                    quads.push([g(0, 0, 0), g(0, 1, 0), g(1, 1, 0), g(1, 0, 0)]);
                }
            }
        }
    }
    // Keep only the grid points the faces use, numbered in order of first use.
    let mut remap = vec![u32::MAX; (nx + 1) * (ny + 1) * (nz + 1)];
    let mut vertices = Vec::new();
    let mut triangles = Vec::with_capacity(2 * quads.len());
    for quad in quads {
        let [a, b, c, d] = quad.map(|g| {
            if remap[g as usize] == u32::MAX {
                let nk = nz + 1;
                let (i, rest) = (g as usize / ((ny + 1) * nk), g as usize % ((ny + 1) * nk));
                let (j, k) = (rest / nk, rest % nk);
                let p = Vector3::new(i as f64, j as f64, k as f64).component_mul(&cell);
                vertices.push(origin + p);
                remap[g as usize] = (vertices.len() - 1) as u32;
            }
            remap[g as usize]
        });
        triangles.extend([[a, b, c], [a, c, d]]);
    }
    IndexedMesh {
        vertices,
        triangles,
    }
}

/// A rod-like compound solid on a 5 mm grid (in metres): a square big-end eye with a 40 mm
/// square bore at the origin, an I-beam shank (flanges and a thin web) and a small-end eye with a
/// 20 mm square bore at (0.18, 0, 0); 40 mm thick. Returns the mesh and its filled cell centres
/// (each a 5 mm cube), the independent reference for its mass properties.
pub fn voxel_rod() -> (IndexedMesh, Vec<Vector3<f64>>, f64) {
    let h = 0.005;
    let cells = [54, 16, 8];
    let origin = Vector3::new(-0.045, -0.04, -0.02);
    let centre = |i: usize, j: usize, k: usize| {
        origin + Vector3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5) * h
    };
    let filled = move |i, j, k| {
        let c = centre(i, j, k);
        let (x, y, z) = (c.x, c.y.abs(), c.z.abs());
        let big_end = x.abs() < 0.04 && y < 0.04 && !(x.abs() < 0.02 && y < 0.02);
        let small_end =
            (x - 0.18).abs() < 0.025 && y < 0.025 && !((x - 0.18).abs() < 0.01 && y < 0.01);
        let shank =
            (0.04..0.155).contains(&x) && ((0.01..0.02).contains(&y) || (y < 0.01 && z < 0.005));
        big_end || small_end || shank
    };
    let mesh = voxel_solid(cells, Vector3::repeat(h), origin, filled);
    let mut centres = Vec::new();
    for i in 0..cells[0] {
        for j in 0..cells[1] {
            for k in 0..cells[2] {
                if filled(i, j, k) {
                    centres.push(centre(i, j, k));
                }
            }
        }
    }
    (mesh, centres, h)
}

/// The mesh rotated by `rotation` and then shifted by `shift`.
pub fn transformed(
    mesh: &IndexedMesh,
    rotation: &Matrix3<f64>,
    shift: Vector3<f64>,
) -> IndexedMesh {
    IndexedMesh {
        vertices: mesh.vertices.iter().map(|v| rotation * v + shift).collect(),
        triangles: mesh.triangles.clone(),
    }
}

/// The mesh with every triangle's orientation reversed (inward-facing).
pub fn flipped(mesh: &IndexedMesh) -> IndexedMesh {
    IndexedMesh {
        vertices: mesh.vertices.clone(),
        triangles: mesh.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect(),
    }
}

/// The triangles as an STL would store them (single precision).
pub fn to_soup(mesh: &IndexedMesh) -> Vec<RawTriangle> {
    (0..mesh.triangles.len())
        .map(|t| {
            mesh.corners(t)
                .map(|v| [v.x as f32, v.y as f32, v.z as f32])
        })
        .collect()
}

/// Binary STL bytes of a soup (written by `stl_io`, facet normals computed).
pub fn binary_stl(soup: &[RawTriangle]) -> Vec<u8> {
    let triangles: Vec<stl_io::Triangle> = soup
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| Vector3::from(v.map(f64::from)));
            let n = (b - a)
                .cross(&(c - a))
                .try_normalize(0.0)
                .unwrap_or_default();
            stl_io::Triangle {
                normal: stl_io::Normal::new([n.x as f32, n.y as f32, n.z as f32]),
                vertices: t.map(stl_io::Vertex::new),
            }
        })
        .collect();
    let mut out = Vec::with_capacity(84 + 50 * soup.len());
    stl_io::write_stl(&mut out, triangles.iter()).expect("writing to memory cannot fail");
    out
}

/// ASCII STL text of a soup, with the exact shortest round-trip decimal of each coordinate.
pub fn ascii_stl(name: &str, soup: &[RawTriangle]) -> String {
    let mut out = format!("solid {name}\n");
    for t in soup {
        out.push_str("  facet normal 0 0 0\n    outer loop\n");
        for v in t {
            out.push_str(&format!("      vertex {:?} {:?} {:?}\n", v[0], v[1], v[2]));
        }
        out.push_str("    endloop\n  endfacet\n");
    }
    out.push_str(&format!("endsolid {name}\n"));
    out
}
