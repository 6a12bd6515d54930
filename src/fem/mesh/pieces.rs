//! The connected pieces of a mesh: elements that share a node belong to one piece. A supported
//! body's analysis needs one piece; a second one (a stray body in the file, or a part that only
//! touches it without sharing nodes) has no support and would make K singular, which the
//! factorisation reports only as a failed pivot. Found by union–find over the elements' nodes
//! (Tarjan, "Efficiency of a good but not linear set union algorithm", JACM 1975).

use super::TetMesh;

/// One connected piece of a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    /// Number of elements.
    pub elements: usize,
    /// Volume of the straight-sided elements (corners only), m³.
    pub volume_m3: f64,
    /// Centroid of that volume, m.
    pub centroid_m: [f64; 3],
}

/// The mesh's pieces, largest volume first, and each node's piece (an index into them).
pub fn pieces(mesh: &TetMesh) -> (Vec<Piece>, Vec<usize>) {
    let n = mesh.n_nodes();
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for el in mesh.elements() {
        let a = find(&mut parent, el[0]);
        for &m in &el[1..] {
            let b = find(&mut parent, m);
            if a != b {
                parent[b] = a;
            }
        }
    }
    let mut index = vec![usize::MAX; n];
    let mut out: Vec<Piece> = Vec::new();
    let mut moments: Vec<[f64; 3]> = Vec::new();
    for (e, el) in mesh.elements().iter().enumerate() {
        let root = find(&mut parent, el[0]);
        if index[root] == usize::MAX {
            index[root] = out.len();
            out.push(Piece {
                elements: 0,
                volume_m3: 0.0,
                centroid_m: [0.0; 3],
            });
            moments.push([0.0; 3]);
        }
        let k = index[root];
        let x = mesh.element_coords(e);
        let v = super::structured::signed_volume(mesh.nodes(), &[el[0], el[1], el[2], el[3]]) / 6.0;
        out[k].elements += 1;
        out[k].volume_m3 += v;
        for j in 0..3 {
            moments[k][j] += v * (x[0][j] + x[1][j] + x[2][j] + x[3][j]) / 4.0;
        }
    }
    for (p, m) in out.iter_mut().zip(&moments) {
        p.centroid_m = m.map(|s| s / p.volume_m3);
    }
    // largest first, each node labelled with its piece's new place
    let mut order: Vec<usize> = (0..out.len()).collect();
    order.sort_by(|&i, &j| out[j].volume_m3.total_cmp(&out[i].volume_m3));
    let mut place = vec![0; out.len()];
    for (new, &old) in order.iter().enumerate() {
        place[old] = new;
    }
    let labels = (0..n).map(|i| place[index[find(&mut parent, i)]]).collect();
    let sorted = order.iter().map(|&i| out[i].clone()).collect();
    (sorted, labels)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::mesh::structured::box_tet10;

    #[test]
    fn two_boxes_apart_are_two_pieces_with_their_volumes_and_centroids() {
        let a = box_tet10(2.0, 1.0, 1.0, 2, 1, 1).unwrap();
        let (one, labels) = pieces(&a);
        assert_eq!(one.len(), 1);
        assert!((one[0].volume_m3 - 2.0).abs() < 1e-12);
        assert!(labels.iter().all(|&l| l == 0));
        // the same box, and a unit cube moved 10 m along x
        let b = box_tet10(1.0, 1.0, 1.0, 1, 1, 1).unwrap();
        let mut nodes = a.nodes().to_vec();
        let n0 = nodes.len();
        nodes.extend(b.nodes().iter().map(|p| [p[0] + 10.0, p[1], p[2]]));
        let mut elements = a.elements().to_vec();
        elements.extend(b.elements().iter().map(|el| el.map(|i| i + n0)));
        let two = TetMesh::new(nodes, elements).unwrap();
        let (p, labels) = pieces(&two);
        assert_eq!(p.len(), 2);
        assert!((p[0].volume_m3 - 2.0).abs() < 1e-12 && (p[1].volume_m3 - 1.0).abs() < 1e-12);
        let c = p[1].centroid_m;
        assert!(
            (c[0] - 10.5).abs() < 1e-12 && (c[1] - 0.5).abs() < 1e-12,
            "{c:?}"
        );
        assert!(labels[..n0].iter().all(|&l| l == 0) && labels[n0..].iter().all(|&l| l == 1));
    }
}
