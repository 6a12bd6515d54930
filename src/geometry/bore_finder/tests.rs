//! Tests of the bore finder on synthetic plates with holes (full, partial, rotated, refused).

use super::*;
use crate::geometry::primitives::{to_soup, transformed};
use crate::geometry::validate::validate;
use crate::geometry::weld::weld;
use nalgebra::Matrix3;
use nalgebra::{Rotation3, Vector2};
use std::collections::HashMap;
use std::f64::consts::{PI, TAU};

/// A hole of a test plate: centre x (mm), radius, and whether it is cut in half at its
/// centre plane (a big end without its cap, open towards −x).
pub struct Hole {
    pub x: f64,
    pub r: f64,
    pub half: bool,
}

/// Plane triangulation of a bar of half-width `s` (mm) along x with the given holes (left to
/// right, each in a square tile of half-size `s`, tiles joined by rectangles), extruded over
/// z ∈ [−h/2, h/2], `n` segments per full turn (a multiple of 8); welded as the STL stores
/// it, validated, in metres.
pub fn plate(holes: &[Hole], s: f64, h: f64, n: usize) -> IndexedMesh {
    assert!(n.is_multiple_of(8));
    let mut tris: Vec<[Vector2<f64>; 3]> = Vec::new();
    // right and left edge chains of each tile (bottom to top)
    type Chain = Vec<Vector2<f64>>;
    let mut chains: Vec<(Chain, Chain)> = Vec::new();
    for hole in holes {
        let c = Vector2::new(hole.x, 0.0);
        let ks: Vec<i64> = if hole.half {
            (-(n as i64) / 4..=n as i64 / 4).collect()
        } else {
            (0..=n as i64).collect()
        };
        let at = |k: i64| {
            let th = TAU * k.rem_euclid(n as i64) as f64 / n as f64;
            let d = Vector2::new(th.cos(), th.sin());
            let t = s / d.x.abs().max(d.y.abs());
            // exact square coordinates at the corners and the edge middles
            let k8 = k.rem_euclid(n as i64);
            let sq = if (8 * k8) % n as i64 == 0 {
                let (x, y) = [
                    (s, 0.0),
                    (s, s),
                    (0.0, s),
                    (-s, s),
                    (-s, 0.0),
                    (-s, -s),
                    (0.0, -s),
                    (s, -s),
                ][(8 * k8 / n as i64) as usize];
                Vector2::new(x, y)
            } else {
                Vector2::new((d.x * t).clamp(-s, s), (d.y * t).clamp(-s, s))
            };
            (c + d * hole.r, c + sq)
        };
        let pts: Vec<_> = ks.iter().map(|&k| at(k)).collect();
        for w in pts.windows(2) {
            let ((c0, s0), (c1, s1)) = (w[0], w[1]);
            tris.push([c0, c1, s1]);
            tris.push([c0, s1, s0]);
        }
        let mut right: Vec<_> = pts
            .iter()
            .map(|p| p.1)
            .filter(|p| (p.x - (c.x + s)).abs() < 1e-12)
            .collect();
        let mut left: Vec<_> = pts
            .iter()
            .map(|p| p.1)
            .filter(|p| (p.x - (c.x - s)).abs() < 1e-12)
            .collect();
        right.sort_by(|a, b| a.y.total_cmp(&b.y));
        right.dedup();
        left.sort_by(|a, b| a.y.total_cmp(&b.y));
        left.dedup();
        chains.push((left, right));
    }
    // rectangles between consecutive tiles: zip the right chain of one and the left of the next
    for k in 0..holes.len().saturating_sub(1) {
        let (l, r) = (&chains[k].1, &chains[k + 1].0);
        let (mut i, mut j) = (0, 0);
        while i + 1 < l.len() || j + 1 < r.len() {
            if j + 1 >= r.len() || (i + 1 < l.len() && l[i + 1].y <= r[j + 1].y) {
                tris.push([l[i], r[j], l[i + 1]]);
                i += 1;
            } else {
                tris.push([l[i], r[j], r[j + 1]]);
                j += 1;
            }
        }
    }
    // index the plane points, orient counter-clockwise, find the boundary edges
    let mut ids: HashMap<(u64, u64), u32> = HashMap::new();
    let mut pts: Vec<Vector2<f64>> = Vec::new();
    let mut id = |p: Vector2<f64>| {
        *ids.entry((p.x.to_bits(), p.y.to_bits()))
            .or_insert_with(|| {
                pts.push(p);
                (pts.len() - 1) as u32
            })
    };
    let mut plane: Vec<[u32; 3]> = Vec::new();
    for [a, b, c] in tris {
        let cross = (b - a).perp(&(c - a));
        if cross.abs() < 1e-12 {
            continue;
        }
        let t = [id(a), id(b), id(c)];
        plane.push(if cross > 0.0 { t } else { [t[0], t[2], t[1]] });
    }
    let mut edge_count: HashMap<(u32, u32), i32> = HashMap::new();
    for t in &plane {
        for (i, j) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            *edge_count.entry((i.min(j), i.max(j))).or_default() += 1;
        }
    }
    let np = pts.len() as u32;
    let mut mesh = IndexedMesh {
        vertices: pts
            .iter()
            .map(|p| Vector3::new(p.x, p.y, -h / 2.0))
            .chain(pts.iter().map(|p| Vector3::new(p.x, p.y, h / 2.0)))
            .collect(),
        triangles: Vec::new(),
    };
    for t in &plane {
        mesh.triangles.push([t[0] + np, t[1] + np, t[2] + np]);
        mesh.triangles.push([t[0], t[2], t[1]]);
        for (i, j) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            if edge_count[&(i.min(j), i.max(j))] == 1 {
                // interior on the left of i→j: the wall faces right
                mesh.triangles.push([i, j, j + np]);
                mesh.triangles.push([i, j + np, i + np]);
            }
        }
    }
    mesh
}

/// The plate as a design file would give it: float32 in mm, welded, validated, metres.
pub fn as_read(mesh_mm: &IndexedMesh) -> IndexedMesh {
    validate(weld(&to_soup(mesh_mm)))
        .expect("a valid test plate")
        .mesh
        .scaled(1e-3)
}

fn rod(holes: &[Hole]) -> IndexedMesh {
    plate(holes, 40.0, 30.0, 96)
}

fn close(a: [f64; 3], b: Vector3<f64>, tol: f64) -> bool {
    (Vector3::from(a) - b).norm() <= tol
}

#[test]
fn one_hole_is_one_bore_and_refused_as_pins() {
    let m = as_read(&rod(&[Hole {
        x: 0.0,
        r: 20.0,
        half: false,
    }]));
    let bores = find_bores(&m);
    assert_eq!(bores.len(), 1, "{bores:#?}");
    assert!(bores[0].full && bores[0].arc_deg == 360.0);
    assert!(
        (bores[0].radius - 0.020).abs() < 1e-8,
        "{}",
        bores[0].radius
    );
    assert!((bores[0].length - 0.030).abs() < 1e-8);
    let e = find_pins(&m, None, Units::Mm).unwrap_err();
    assert!(matches!(e, PinSearchError::OnlyOne(_)), "{e}");
    assert!(e.to_string().contains("only one bore"), "{e}");
}

#[test]
fn two_holes_any_pose() {
    let base = rod(&[
        Hole {
            x: 0.0,
            r: 24.0,
            half: false,
        },
        Hole {
            x: 180.0,
            r: 12.0,
            half: false,
        },
    ]);
    // as drawn; then pins along y, shifted by 1 m
    let turn = Rotation3::from_axis_angle(&Vector3::x_axis(), -PI / 2.0).into_inner();
    let poses = [
        (Matrix3::identity(), Vector3::zeros()),
        (turn, Vector3::new(1000.0, -1000.0, 1000.0)),
    ];
    for (rot, shift) in poses {
        let m = as_read(&transformed(&base, &rot, shift));
        let f = find_pins(&m, None, Units::Mm).unwrap();
        let a = (rot * Vector3::zeros() + shift) * 1e-3;
        let b = (rot * Vector3::new(180.0, 0.0, 0.0) + shift) * 1e-3;
        assert!(
            close(f.crank.centre, a, 1e-5),
            "{:?} vs {a}",
            f.crank.centre
        );
        assert!(
            close(f.piston.centre, b, 1e-5),
            "{:?} vs {b}",
            f.piston.centre
        );
        assert!((f.crank.radius - 0.024).abs() < 1e-8);
        assert!((f.piston.radius - 0.012).abs() < 1e-8);
        assert!(close(
            f.axis,
            rot * Vector3::z() * (rot * Vector3::z()).sum().signum(),
            1e-9
        ));
        assert!((f.centre_distance - 0.18).abs() < 1e-8);
        assert!(f.crank.full && f.piston.full);
    }
}

#[test]
fn capless_big_end_is_an_arc_of_180_degrees() {
    let m = as_read(&rod(&[
        Hole {
            x: 0.0,
            r: 24.0,
            half: true,
        },
        Hole {
            x: 180.0,
            r: 12.0,
            half: false,
        },
    ]));
    let f = find_pins(&m, None, Units::Mm).unwrap();
    assert!(!f.crank.full);
    assert!(
        (f.crank.arc_deg - 180.0).abs() < 1e-6,
        "{}",
        f.crank.arc_deg
    );
    assert!(
        close(f.crank.centre, Vector3::zeros(), 1e-5),
        "{:?}",
        f.crank.centre
    );
    assert!((f.crank.radius - 0.024).abs() < 1e-8);
    // opening towards −x
    assert!(close(f.crank.opening.unwrap(), -Vector3::x(), 1e-9));
    assert!(close(f.piston.centre, Vector3::new(0.18, 0.0, 0.0), 1e-5));
}

#[test]
fn equal_radii_are_refused_and_three_holes_give_the_ends() {
    let h = |x, r| Hole { x, r, half: false };
    let m = as_read(&rod(&[h(0.0, 20.0), h(180.0, 20.1)]));
    let e = find_pins(&m, None, Units::Mm).unwrap_err();
    assert!(
        e.to_string()
            .contains("cannot tell the crank end from the piston end"),
        "{e}"
    );
    // three holes in line: the pins are the two at the ends of the part's long extent
    let m = as_read(&rod(&[h(0.0, 24.0), h(120.0, 16.0), h(240.0, 12.0)]));
    let f = find_pins(&m, None, Units::Mm).unwrap();
    assert!(close(f.crank.centre, Vector3::zeros(), 1e-5));
    assert!(close(f.piston.centre, Vector3::new(0.24, 0.0, 0.0), 1e-5));
    assert!((f.crank.radius - 0.024).abs() < 1e-8);
    // a small oil hole does not compete
    let m = as_read(&rod(&[h(0.0, 24.0), h(120.0, 2.0), h(240.0, 12.0)]));
    let f = find_pins(&m, None, Units::Mm).unwrap();
    assert!((f.centre_distance - 0.24).abs() < 1e-8);
    // restricted to another axis: nothing
    let e = find_pins(&m, Some(Vector3::y()), Units::Mm).unwrap_err();
    assert!(matches!(e, PinSearchError::NoBore(_)), "{e}");
}

/// The walk from seeds gives each smooth patch as the union–find over the sorted edges does
/// (the second method, `patches::smooth_patches`), on a plate with a full and a half hole.
#[test]
fn the_walk_from_a_seed_gives_its_smooth_patch() {
    let m = as_read(&rod(&[
        Hole {
            x: 0.0,
            r: 20.0,
            half: true,
        },
        Hole {
            x: 100.0,
            r: 12.0,
            half: false,
        },
    ]));
    let normals: Vec<Vector3<f64>> = (0..m.triangles.len())
        .map(|t| {
            let [a, b, c] = m.corners(t);
            (b - a).cross(&(c - a)).normalize()
        })
        .collect();
    let (patches, _) = super::patches::smooth_patches(&m, &normals);
    assert!(patches.len() > 3, "{}", patches.len());
    for patch in &patches {
        let middle = patch[patch.len() / 2];
        assert_eq!(&smooth_patches_through(&m, &[middle]), patch);
    }
    let two = [patches[0][0], patches[1][0]];
    let mut both: Vec<u32> = patches[0].iter().chain(&patches[1]).copied().collect();
    both.sort_unstable();
    assert_eq!(smooth_patches_through(&m, &two), both);
}
