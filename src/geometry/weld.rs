//! Welding a triangle soup into an indexed mesh: vertices equal in value become one.
//!
//! Equality is by value of the stored single-precision coordinates, so `-0.0` and `0.0` are the
//! same vertex (unlike `stl_io`'s bit-equality welding). Coordinates are widened to f64 exactly.

use super::stl_file::RawTriangle;
use nalgebra::Vector3;
use rayon::prelude::*;

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
        self.vertices.par_iter_mut().for_each(|v| *v *= factor);
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
    #[inline]
    pub fn corners(&self, t: usize) -> [Vector3<f64>; 3] {
        // Spelled out: `array::map` is not always inlined, and this is called per triangle.
        let [a, b, c] = self.triangles[t];
        [
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        ]
    }
}

/// Merges vertices with equal coordinates (by value) and returns the indexed mesh.
///
/// Vertices are numbered in the order of their first use (triangle by triangle, corner by
/// corner), as by inserting each corner into one hash map in turn. The map is an open-addressing
/// table of 8-byte slots (a hash fragment and a vertex number; the key itself is read from the
/// soup at the vertex's first corner), sized from Euler's formula for a closed surface
/// (V ≈ T/2), and the slot of the corner a few places ahead is prefetched, so that the table's
/// cache misses overlap. With several threads the soup is cut into consecutive parts welded
/// side by side; the later parts' vertices are then looked up in the first part's table in
/// their order of first use, which gives exactly the numbering of a single pass.
pub fn weld(soup: &[RawTriangle]) -> IndexedMesh {
    let parts = rayon::current_num_threads().min(soup.len().div_ceil(MIN_PART));
    weld_in_parts(soup, parts)
}

/// [`weld`] with the soup cut into `parts` (at least one) consecutive parts.
fn weld_in_parts(soup: &[RawTriangle], parts: usize) -> IndexedMesh {
    let corners: &[[f32; 3]] = soup.as_flattened();
    assert!(
        corners.len() < u32::MAX as usize,
        "too many triangles to index with u32"
    );
    let parts = parts.max(1);
    let per = soup.len().div_ceil(parts).max(1);
    let mut triangles = vec![[0u32; 3]; soup.len()];
    // Each part on its own: its table and its vertices' first corners (numbered within the
    // part); the first part's table is sized for the whole mesh, as the others merge into it.
    let mut welded: Vec<(VertexTable, Vec<u32>)> = triangles
        .par_chunks_mut(per)
        .enumerate()
        .map(|(k, out)| {
            let own = &corners[3 * k * per..3 * (k * per + out.len())];
            let mut table = VertexTable::new(if k == 0 { soup.len() } else { out.len() });
            let mut firsts = Vec::with_capacity(out.len() / 2 + 16);
            let out = out.as_flattened_mut();
            for (c, v) in own.iter().enumerate() {
                if let Some(ahead) = own.get(c + AHEAD) {
                    table.prefetch(hash(key(ahead)));
                }
                let k = key(v);
                out[c] = table.vertex(own, &mut firsts, k, hash(k), c as u32);
            }
            (table, firsts)
        })
        .collect();
    let later = welded.split_off(1.min(welded.len()));
    let (mut table, mut firsts) = welded
        .pop()
        .unwrap_or_else(|| (VertexTable::new(0), Vec::new()));
    // The later parts' vertices in order: found in (or added to) the first part's table.
    let mut renumber = Vec::with_capacity(later.len());
    for (k, (part_table, part_firsts)) in later.into_iter().enumerate() {
        drop(part_table);
        let offset = (3 * (k + 1) * per) as u32;
        let global = |c: u32| c + offset;
        let map = (0..part_firsts.len())
            .map(|l| {
                if let Some(&ahead) = part_firsts.get(l + AHEAD) {
                    table.prefetch(hash(key(&corners[global(ahead) as usize])));
                }
                let c = global(part_firsts[l]);
                let k = key(&corners[c as usize]);
                table.vertex(corners, &mut firsts, k, hash(k), c)
            })
            .collect::<Vec<u32>>();
        renumber.push(map);
    }
    drop(table);
    if !renumber.is_empty() {
        triangles[per..]
            .par_chunks_mut(per)
            .zip(&renumber)
            .for_each(|(tris, map)| {
                for t in tris.as_flattened_mut() {
                    *t = map[*t as usize];
                }
            });
    }
    let vertices = firsts
        .par_iter()
        .map(|&c| {
            let [x, y, z] = corners[c as usize];
            Vector3::new(f64::from(x), f64::from(y), f64::from(z))
        })
        .collect();
    IndexedMesh {
        vertices,
        triangles,
    }
}

/// Fewest triangles worth a part of their own in [`weld`].
const MIN_PART: usize = 65_536;

/// How many corners ahead [`weld`] prefetches the table slot.
const AHEAD: usize = 16;

/// The coordinates' bit patterns, `-0.0` made `+0.0` (adding +0.0 does that), so that equal
/// bit patterns mean equal values.
#[inline]
fn key(&[x, y, z]: &[f32; 3]) -> [u32; 3] {
    [
        (x + 0.0).to_bits(),
        (y + 0.0).to_bits(),
        (z + 0.0).to_bits(),
    ]
}

/// A well-mixed 64-bit hash of a key (a folded 128-bit multiplication, as in foldhash): the
/// low bits choose the slot, the high 32 are kept in it to skip most key comparisons.
fn hash([x, y, z]: [u32; 3]) -> u64 {
    let a = (u64::from(x) | (u64::from(y) << 32)) ^ 0x243f_6a88_85a3_08d3;
    let b = u64::from(z) ^ 0x1319_8a2e_0370_7344;
    let p = u128::from(a) * u128::from(b);
    (p as u64) ^ ((p >> 64) as u64)
}

/// An empty slot (no vertex number reaches `u32::MAX`).
const EMPTY: u64 = u64::MAX;

/// Open addressing with linear probing; each slot is `hash >> 32 << 32 | vertex`.
struct VertexTable {
    slots: Vec<u64>,
    mask: usize,
}

impl VertexTable {
    /// A table for the vertices of about `triangles` triangles of a closed surface (V ≈ T/2,
    /// so at most half full); it doubles if more come.
    fn new(triangles: usize) -> Self {
        let size = triangles.next_power_of_two().max(16);
        VertexTable {
            slots: vec![EMPTY; size],
            mask: size - 1,
        }
    }

    fn prefetch(&self, h: u64) {
        let slot = &self.slots[h as usize & self.mask];
        #[cfg(target_arch = "x86_64")]
        // SAFETY: a prefetch is only a hint; it neither reads nor writes memory as the program
        // sees it, and `slot` is a valid reference anyway.
        unsafe {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            _mm_prefetch::<_MM_HINT_T0>((slot as *const u64).cast());
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = slot;
    }

    /// The vertex with key `k` (hash `h`); if new, it is numbered `firsts.len()` and its first
    /// corner, `corner`, is appended to `firsts`. `firsts` are indices into `corners`.
    fn vertex(
        &mut self,
        corners: &[[f32; 3]],
        firsts: &mut Vec<u32>,
        k: [u32; 3],
        h: u64,
        corner: u32,
    ) -> u32 {
        let fragment = h >> 32;
        let mut i = h as usize & self.mask;
        loop {
            let slot = self.slots[i];
            if slot == EMPTY {
                let vertex = firsts.len() as u32;
                self.slots[i] = fragment << 32 | u64::from(vertex);
                firsts.push(corner);
                if 2 * firsts.len() > self.slots.len() {
                    self.grow(corners, firsts);
                }
                return vertex;
            }
            if slot >> 32 == fragment {
                let vertex = slot as u32;
                if key(&corners[firsts[vertex as usize] as usize]) == k {
                    return vertex;
                }
            }
            i = (i + 1) & self.mask;
        }
    }

    #[cold]
    fn grow(&mut self, corners: &[[f32; 3]], firsts: &[u32]) {
        let size = 2 * self.slots.len();
        self.slots = vec![EMPTY; size];
        self.mask = size - 1;
        for (vertex, &c) in firsts.iter().enumerate() {
            let h = hash(key(&corners[c as usize]));
            let mut i = h as usize & self.mask;
            while self.slots[i] != EMPTY {
                i = (i + 1) & self.mask;
            }
            self.slots[i] = h >> 32 << 32 | vertex as u64;
        }
    }
}

/// Relative welding tolerance of [`weld_within`]: a share of the bounding-box diagonal, far below
/// any real feature of a part (1e-9 of a 600 mm rod is 0.6 nm).
pub const NEAR_WELD_REL: f64 = 1e-9;

/// Single-precision units in the last place of the largest coordinate that [`weld_within`] also
/// merges: an exporter's own rounding of a coordinate it computed twice.
pub const NEAR_WELD_ULPS: f64 = 4.0;

/// What [`weld_within`] did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NearWeld {
    /// Vertices merged into a neighbour closer than the tolerance.
    pub vertices_merged: usize,
    /// Triangles dropped because two of their corners became one vertex (slivers thinner than
    /// the tolerance).
    pub triangles_dropped: usize,
    /// The tolerance used, in the mesh's units.
    pub tolerance: f64,
}

/// The welding tolerance of a mesh: [`NEAR_WELD_REL`] of its bounding-box diagonal, or
/// [`NEAR_WELD_ULPS`] single-precision ulps of its largest coordinate, whichever is larger.
pub fn near_weld_tolerance(mesh: &IndexedMesh) -> f64 {
    let (lo, hi) = mesh.bounding_box();
    let diagonal = (hi - lo).norm();
    let largest = lo.abs().max().max(hi.abs().max());
    let ulp = largest * f64::from(f32::EPSILON);
    (NEAR_WELD_REL * diagonal).max(NEAR_WELD_ULPS * ulp)
}

/// Merges vertices closer than `tolerance` to each other (a SolidWorks export writes one vertex
/// as `0.0` in one facet and `6.9e-15` in its neighbour, so equality by value leaves the surface
/// open along those edges).
///
/// Vertices are hashed into a grid of cells of the tolerance's size; each vertex is compared with
/// the vertices of its own and the 26 neighbouring cells, and joined (union–find) to every one
/// within the tolerance. Each group becomes its lowest-numbered vertex, so the numbering of the
/// vertices that stay follows the original order, and a mesh with nothing to merge comes back
/// unchanged. Triangles with two corners in one group are dropped.
pub fn weld_within(mesh: &IndexedMesh, tolerance: f64) -> (IndexedMesh, NearWeld) {
    use std::collections::HashMap;
    let n = mesh.vertices.len();
    let cell = |v: &Vector3<f64>| {
        [
            (v.x / tolerance).floor() as i64,
            (v.y / tolerance).floor() as i64,
            (v.z / tolerance).floor() as i64,
        ]
    };
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::with_capacity(n);
    for (i, v) in mesh.vertices.iter().enumerate() {
        grid.entry(cell(v)).or_default().push(i as u32);
    }
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    for (i, v) in mesh.vertices.iter().enumerate() {
        let c = cell(v);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(others) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                        continue;
                    };
                    for &j in others {
                        if j as usize > i && (mesh.vertices[j as usize] - v).norm() <= tolerance {
                            let (a, b) = (root(&mut parent, i as u32), root(&mut parent, j));
                            if a != b {
                                parent[a.max(b) as usize] = a.min(b);
                            }
                        }
                    }
                }
            }
        }
    }
    let mut number = vec![u32::MAX; n];
    let mut vertices = Vec::with_capacity(n);
    for i in 0..n as u32 {
        let r = root(&mut parent, i);
        if r == i {
            number[i as usize] = vertices.len() as u32;
            vertices.push(mesh.vertices[i as usize]);
        }
    }
    let mut triangles = Vec::with_capacity(mesh.triangles.len());
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|v| number[root(&mut parent, v) as usize]);
        if a != b && b != c && a != c {
            triangles.push([a, b, c]);
        }
    }
    let report = NearWeld {
        vertices_merged: n - vertices.len(),
        triangles_dropped: mesh.triangles.len() - triangles.len(),
        tolerance,
    };
    (
        IndexedMesh {
            vertices,
            triangles,
        },
        report,
    )
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

    /// The plain algorithm: one hash map, corners inserted in order.
    fn reference_weld(soup: &[RawTriangle]) -> IndexedMesh {
        let mut index_of = std::collections::HashMap::new();
        let mut vertices = Vec::new();
        let triangles = soup
            .iter()
            .map(|tri| {
                tri.map(|v| {
                    *index_of.entry(key(&v)).or_insert_with(|| {
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

    /// A torus soup in a scrambled triangle order, some zeros negative.
    fn scrambled_soup() -> Vec<RawTriangle> {
        let mut soup = crate::geometry::primitives::to_soup(&crate::geometry::primitives::torus(
            1.0, 0.3, 60, 40,
        ));
        let mut state = 7u64;
        for i in (1..soup.len()).rev() {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            soup.swap(i, (state >> 33) as usize % (i + 1));
        }
        for (t, tri) in soup.iter_mut().enumerate() {
            for v in tri.iter_mut().flatten() {
                if *v == 0.0 && t % 3 == 0 {
                    *v = -0.0;
                }
            }
        }
        soup
    }

    #[test]
    fn parts_give_the_numbering_of_one_pass() {
        let soup = scrambled_soup();
        let expected = reference_weld(&soup);
        assert!(expected.vertices.len() < soup.len());
        for parts in 1..=5 {
            assert!(weld_in_parts(&soup, parts) == expected, "{parts} parts");
        }
        assert!(weld(&soup) == expected);
    }

    #[test]
    fn a_soup_sharing_nothing_grows_the_tables() {
        // Every corner its own vertex: three times as many vertices as the table was sized for.
        let soup: Vec<RawTriangle> = (0..5000)
            .map(|t| {
                let x = t as f32;
                [[x, 0.0, 0.0], [x, 1.0, 0.0], [x, 0.0, 1.0]]
            })
            .collect();
        let expected = reference_weld(&soup);
        assert_eq!(expected.vertices.len(), 15_000);
        for parts in [1, 2, 3] {
            assert!(weld_in_parts(&soup, parts) == expected, "{parts} parts");
        }
    }

    #[test]
    fn empty_soup_gives_an_empty_mesh() {
        let mesh = weld(&[]);
        assert!(mesh.vertices.is_empty() && mesh.triangles.is_empty());
    }

    #[test]
    fn widening_is_exact() {
        let soup = [[[0.1f32, 0.2, 0.3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]];
        assert_eq!(weld(&soup).vertices[0].x, f64::from(0.1f32));
    }
    #[test]
    fn near_duplicates_weld_within_the_tolerance_and_nothing_else() {
        // two triangles sharing an edge whose second copy is 6.9e-15 off (a SolidWorks export)
        let mesh = IndexedMesh {
            vertices: vec![
                Vector3::new(0.0, 0.0, 0.0),
                Vector3::new(1.0, 0.0, 0.0),
                Vector3::new(0.0, 1.0, 0.0),
                Vector3::new(1.0, 6.9e-15, 0.0),
                Vector3::new(0.0, 1.0, -5.4e-14),
                Vector3::new(1.0, 1.0, 0.0),
            ],
            triangles: vec![[0, 1, 2], [3, 5, 4]],
        };
        let tol = near_weld_tolerance(&mesh);
        // 4 ulps of 1.0 in f32 (4.8e-7) dominate 1e-9 of the diagonal here
        assert!((tol - 4.0 * f64::from(f32::EPSILON)).abs() < 1e-20, "{tol}");
        let (welded, report) = weld_within(&mesh, tol);
        assert_eq!(report.vertices_merged, 2);
        assert_eq!(report.triangles_dropped, 0);
        assert_eq!(welded.vertices.len(), 4);
        assert_eq!(welded.triangles, vec![[0, 1, 2], [1, 3, 2]]);
        // a real gap (1e-3) stays open
        let mut gap = mesh.clone();
        gap.vertices[3].y = 1e-3;
        let (_, report) = weld_within(&gap, tol);
        assert_eq!(report.vertices_merged, 1);
        // nothing to merge: the same mesh back
        let (same, report) = weld_within(&welded, tol);
        assert_eq!((same, report.vertices_merged), (welded, 0));
    }
}
