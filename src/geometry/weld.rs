//! Welding a triangle soup into an indexed mesh: vertices equal in value become one.
//!
//! Equality is by value of the stored single-precision coordinates, so `-0.0` and `0.0` are the
//! same vertex (unlike `stl_io`'s bit-equality welding). Coordinates are widened to f64 exactly.

use super::stl_file::RawTriangle;
use foldhash::{HashMap, HashMapExt};
use nalgebra::Vector3;

/// A triangle mesh with shared vertices; units are those of the file it came from until
/// [`IndexedMesh::scaled`] converts them.
#[derive(Debug, Clone, PartialEq)]
pub struct IndexedMesh {
    pub vertices: Vec<Vector3<f64>>,
    /// Vertex indices of each triangle, counter-clockwise seen from outside once validated.
    pub triangles: Vec<[u32; 3]>,
}

impl IndexedMesh {
    /// The same mesh with every coordinate multiplied by `factor` (e.g. 1e-3 for mm → m).
    pub fn scaled(mut self, factor: f64) -> Self {
        for v in &mut self.vertices {
            *v *= factor;
        }
        self
    }

    /// Axis-aligned bounding box `(min, max)`.
    pub fn bounding_box(&self) -> (Vector3<f64>, Vector3<f64>) {
        let lo = Vector3::repeat(f64::INFINITY);
        let hi = Vector3::repeat(f64::NEG_INFINITY);
        self.vertices
            .iter()
            .fold((lo, hi), |(lo, hi), v| (lo.inf(v), hi.sup(v)))
    }

    /// The three corners of triangle `t`.
    pub fn corners(&self, t: usize) -> [Vector3<f64>; 3] {
        self.triangles[t].map(|i| self.vertices[i as usize])
    }
}

/// Merges vertices with equal coordinates (by value) and returns the indexed mesh.
pub fn weld(soup: &[RawTriangle]) -> IndexedMesh {
    let mut index_of: HashMap<[u32; 3], u32> = HashMap::with_capacity(soup.len() / 2 + 16);
    let mut vertices = Vec::with_capacity(soup.len() / 2 + 16);
    let triangles = soup
        .iter()
        .map(|tri| {
            tri.map(|v| {
                // Adding +0.0 turns -0.0 into +0.0, so the bit patterns compare by value.
                let key = v.map(|c| (c + 0.0).to_bits());
                *index_of.entry(key).or_insert_with(|| {
                    vertices.push(Vector3::from(v.map(f64::from)));
                    (vertices.len() - 1) as u32
                })
            })
        })
        .collect();
    IndexedMesh {
        vertices,
        triangles,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negative_zero_welds_with_zero() {
        let soup = [
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            [[-0.0, 0.0, -0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
        ];
        let mesh = weld(&soup);
        assert_eq!(mesh.vertices.len(), 3);
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 1]]);
    }

    #[test]
    fn widening_is_exact() {
        let soup = [[[0.1f32, 0.2, 0.3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]];
        assert_eq!(weld(&soup).vertices[0].x, f64::from(0.1f32));
    }
}
