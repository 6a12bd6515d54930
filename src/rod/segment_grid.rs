//! Line segments looked up by position: a uniform grid of cubic cells, each listing the segments
//! whose bounding box meets it. The facet floor ([`super::facets::FacetScale`]) and the ceiling at
//! small fillets ([`super::small_fillets::SmallFillets`]) both ask for the kink edges near a point.

use std::collections::HashMap;

use crate::fem::stress::point_segment_distance;

/// Segments in a grid of cells of side `cell`.
#[derive(Clone, Debug, Default)]
pub struct SegmentGrid {
    cell: f64,
    grid: HashMap<[i64; 3], Vec<u32>>,
    segments: Vec<[[f64; 3]; 2]>,
}

impl SegmentGrid {
    /// An empty grid whose cells have side `cell` (> 0): [`Self::nearby`] reaches one cell.
    pub fn new(cell: f64) -> Self {
        SegmentGrid {
            cell,
            ..SegmentGrid::default()
        }
    }

    fn key(&self, p: [f64; 3]) -> [i64; 3] {
        p.map(|v| (v / self.cell).floor() as i64)
    }

    /// Adds segment `s`; returns its index (0, 1, … in the order added).
    pub fn push(&mut self, s: [[f64; 3]; 2]) -> usize {
        let id = self.segments.len();
        self.segments.push(s);
        let lo = self.key(std::array::from_fn(|j| s[0][j].min(s[1][j])));
        let hi = self.key(std::array::from_fn(|j| s[0][j].max(s[1][j])));
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    self.grid.entry([x, y, z]).or_default().push(id as u32);
                }
            }
        }
        id
    }

    /// Number of segments.
    pub fn len(&self) -> usize {
        self.segments.len()
    }

    /// True when no segment was added.
    pub fn is_empty(&self) -> bool {
        self.segments.is_empty()
    }

    /// The segments within one cell of `p`, each with its distance from `p`: every segment listed
    /// in the 27 cells around `p`'s whose distance is at most the cell side (a long segment may
    /// come more than once).
    pub fn nearby(&self, p: [f64; 3]) -> impl Iterator<Item = (usize, f64)> + '_ {
        let k = self.key(p);
        (-1..=1)
            .flat_map(move |dx| (-1..=1).flat_map(move |dy| (-1..=1).map(move |dz| (dx, dy, dz))))
            .filter_map(move |(dx, dy, dz)| self.grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]))
            .flatten()
            .filter_map(move |&i| {
                let d = point_segment_distance(p, self.segments[i as usize]);
                (d <= self.cell).then_some((i as usize, d))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against a brute-force search over segments scattered through several cells: the same
    /// segments within one cell side, with their distances.
    #[test]
    fn nearby_finds_every_segment_within_one_cell() {
        let mut g = SegmentGrid::new(2.0);
        let mut all = Vec::new();
        for i in 0..40 {
            let t = i as f64;
            let s = [
                [(0.7 * t).sin() * 6.0, (0.3 * t).cos() * 5.0, 0.25 * t - 4.0],
                [
                    (0.7 * t).sin() * 6.0 + 1.5,
                    (0.3 * t).cos() * 5.0 - 2.5,
                    0.25 * t - 3.0,
                ],
            ];
            assert_eq!(g.push(s), i);
            all.push(s);
        }
        assert_eq!(g.len(), 40);
        for p in [
            [0.0, 0.0, 0.0],
            [3.0, -2.0, 1.0],
            [-5.5, 4.0, 5.0],
            [20.0, 0.0, 0.0],
        ] {
            let mut found: Vec<usize> = g.nearby(p).map(|(i, _)| i).collect();
            found.sort_unstable();
            found.dedup();
            let expected: Vec<usize> = (0..all.len())
                .filter(|&i| point_segment_distance(p, all[i]) <= 2.0)
                .collect();
            assert_eq!(found, expected, "at {p:?}");
            for (i, d) in g.nearby(p) {
                assert_eq!(d, point_segment_distance(p, all[i]));
            }
        }
        assert!(SegmentGrid::new(1.0).nearby([0.0; 3]).next().is_none());
    }
}
