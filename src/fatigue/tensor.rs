//! Small operations on symmetric stress tensors stored as `[xx, yy, zz, xy, yz, zx]` (the order of
//! the FEM kernel, [`crate::fem::material`]) and on 3-vectors.

pub(crate) use crate::fem::boundary::{cross, dot, norm};

/// σ · n.
pub fn traction(s: &[f64; 6], n: [f64; 3]) -> [f64; 3] {
    [
        s[0] * n[0] + s[3] * n[1] + s[5] * n[2],
        s[3] * n[0] + s[1] * n[1] + s[4] * n[2],
        s[5] * n[0] + s[4] * n[1] + s[2] * n[2],
    ]
}

/// a · σ · b.
pub fn quadratic_form(s: &[f64; 6], a: [f64; 3], b: [f64; 3]) -> f64 {
    dot(a, traction(s, b))
}

/// `a` + `f` · `b`, component-wise.
pub fn axpy(a: &[f64; 6], f: f64, b: &[f64; 6]) -> [f64; 6] {
    std::array::from_fn(|c| a[c] + f * b[c])
}

/// The unit vector of `a` (`a` itself when it is zero).
pub fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = norm(a);
    if l > 0.0 { a.map(|v| v / l) } else { a }
}

/// Two unit vectors completing the unit `n` to a right-handed orthonormal basis (t1, t2, n).
pub fn tangent_basis(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    // start from the axis least aligned with n
    let k = (0..3)
        .min_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
        .expect("three axes");
    let mut e = [0.0; 3];
    e[k] = 1.0;
    let t1 = unit(cross(e, n));
    let t2 = cross(n, t1);
    (t1, t2)
}

/// In-plane components (s11, s22, s12) of `s` in the tangent basis (`t1`, `t2`).
pub fn in_plane(s: &[f64; 6], t1: [f64; 3], t2: [f64; 3]) -> [f64; 3] {
    [
        quadratic_form(s, t1, t1),
        quadratic_form(s, t2, t2),
        quadratic_form(s, t1, t2),
    ]
}

/// Plane-stress von Mises of in-plane components (s11, s22, s12).
pub fn von_mises_plane(p: [f64; 3]) -> f64 {
    (p[0] * p[0] + p[1] * p[1] - p[0] * p[1] + 3.0 * p[2] * p[2]).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_orthonormal_and_right_handed() {
        for n in [
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            unit([0.3, -0.8, 0.52]),
            unit([-1.0, -1.0, 1e-9]),
        ] {
            let (a, b) = tangent_basis(n);
            assert!((norm(a) - 1.0).abs() < 1e-14 && (norm(b) - 1.0).abs() < 1e-14);
            assert!(dot(a, b).abs() < 1e-14 && dot(a, n).abs() < 1e-14);
            let c = cross(a, b);
            assert!((0..3).all(|i| (c[i] - n[i]).abs() < 1e-14));
        }
    }

    #[test]
    fn traction_and_forms() {
        let s = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        assert_eq!(traction(&s, [1.0, 0.0, 0.0]), [1.0, 4.0, 6.0]);
        assert_eq!(quadratic_form(&s, [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]), 5.0);
        assert_eq!(
            in_plane(&s, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            [1.0, 2.0, 4.0]
        );
        // uniaxial: von Mises = |σ|; pure shear: √3 τ
        assert_eq!(von_mises_plane([-7.0, 0.0, 0.0]), 7.0);
        assert!((von_mises_plane([0.0, 0.0, 2.0]) - 2.0 * 3f64.sqrt()).abs() < 1e-15);
    }
}
