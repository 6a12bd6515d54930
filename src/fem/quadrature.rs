//! Quadrature rules on the reference tetrahedron {ξ, η, ζ ≥ 0, ξ + η + ζ ≤ 1} (volume 1/6) and the
//! reference triangle {s, t ≥ 0, s + t ≤ 1} (area 1/2). Weights include the reference measure.
//!
//! * [`TET4`]: 4 points, degree 2 (Zienkiewicz & Taylor, Table 6.4; Hughes Table 3.I.2): exact for
//!   the stiffness of a straight-sided tetra10 (B is linear, BᵀDB quadratic, det J constant).
//! * [`TET14`]: 14 points, degree 5, all weights positive (the symmetric rule with two 4-point orbits
//!   and one 6-point orbit, e.g. Walkington 2000, "Quadrature on simplices of arbitrary dimension";
//!   of the same family as Keast 1986, "Moderate-degree tetrahedral quadrature formulas", CMAME 55;
//!   coefficients here re-derived from the degree-5 moment equations and checked by a test). Used for
//!   curved elements: det J·∂N/∂x (cofactor times ∂N/∂ξ) is then of degree 3, so the internal force
//!   of a constant stress is integrated exactly and the patch test passes on curved meshes too.
//! * [`TRI6`]: 6 points, degree 4 (Dunavant 1985, "High degree efficient symmetrical Gaussian
//!   quadrature rules for the triangle", IJNME 21), for surface loads of 6-node faces.

/// A quadrature rule: points (natural coordinates) and weights.
#[derive(Clone, Copy, Debug)]
pub struct Rule<const D: usize> {
    /// Short name for reports.
    pub name: &'static str,
    /// Polynomial degree integrated exactly.
    pub degree: u32,
    /// Points.
    pub points: &'static [[f64; D]],
    /// Weights (sum = reference measure).
    pub weights: &'static [f64],
}

/// Tetrahedron rule.
pub type TetRule = Rule<3>;
/// Triangle rule.
pub type TriRule = Rule<2>;

const T4A: f64 = 0.585_410_196_624_968_5;
const T4B: f64 = 0.138_196_601_125_010_5;

/// 4-point degree-2 tetrahedron rule.
pub const TET4: TetRule = Rule {
    name: "tet4 (degree 2)",
    degree: 2,
    points: &[
        [T4B, T4B, T4B],
        [T4A, T4B, T4B],
        [T4B, T4A, T4B],
        [T4B, T4B, T4A],
    ],
    weights: &[1.0 / 24.0; 4],
};

const A1: f64 = 0.092_735_250_310_895_97;
const W1: f64 = 0.012_248_840_519_394_968;
const A2: f64 = 0.310_885_919_263_301_17;
const W2: f64 = 0.018_781_320_953_005_23;
const B3: f64 = 0.045_503_704_125_629_56;
const W3: f64 = 0.007_091_003_462_844_316;
const C1: f64 = 1.0 - 3.0 * A1;
const C2: f64 = 1.0 - 3.0 * A2;
const C3: f64 = 0.5 - B3;

/// 14-point degree-5 tetrahedron rule with positive weights.
pub const TET14: TetRule = Rule {
    name: "tet14 (degree 5)",
    degree: 5,
    points: &[
        [A1, A1, A1],
        [C1, A1, A1],
        [A1, C1, A1],
        [A1, A1, C1],
        [A2, A2, A2],
        [C2, A2, A2],
        [A2, C2, A2],
        [A2, A2, C2],
        [B3, C3, C3],
        [C3, B3, C3],
        [C3, C3, B3],
        [B3, B3, C3],
        [B3, C3, B3],
        [C3, B3, B3],
    ],
    weights: &[W1, W1, W1, W1, W2, W2, W2, W2, W3, W3, W3, W3, W3, W3],
};

const TA: f64 = 0.445_948_490_915_964_45;
const TWA: f64 = 0.111_690_794_839_004_9;
const TB: f64 = 0.091_576_213_509_771_9;
const TWB: f64 = 0.054_975_871_827_661_78;

/// 6-point degree-4 triangle rule.
pub const TRI6: TriRule = Rule {
    name: "tri6 (degree 4)",
    degree: 4,
    points: &[
        [TA, TA],
        [1.0 - 2.0 * TA, TA],
        [TA, 1.0 - 2.0 * TA],
        [TB, TB],
        [1.0 - 2.0 * TB, TB],
        [TB, 1.0 - 2.0 * TB],
    ],
    weights: &[TWA, TWA, TWA, TWB, TWB, TWB],
};

#[cfg(test)]
mod tests {
    use super::*;

    fn fact(n: u32) -> f64 {
        (1..=n).map(f64::from).product()
    }

    /// ∫ ξ^a η^b ζ^c over the reference tet = a! b! c! / (a + b + c + 3)!.
    #[test]
    fn tet_rules_exact_to_their_degree() {
        for rule in [TET4, TET14] {
            for a in 0..=rule.degree {
                for b in 0..=rule.degree - a {
                    for c in 0..=rule.degree - a - b {
                        let exact = fact(a) * fact(b) * fact(c) / fact(a + b + c + 3);
                        let q: f64 = rule
                            .points
                            .iter()
                            .zip(rule.weights)
                            .map(|(p, w)| {
                                w * p[0].powi(a as i32) * p[1].powi(b as i32) * p[2].powi(c as i32)
                            })
                            .sum();
                        assert!(
                            (q - exact).abs() < 1e-15,
                            "{} x^{a} y^{b} z^{c}: {q} vs {exact}",
                            rule.name
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn tri_rule_exact_to_degree_4() {
        for a in 0..=4 {
            for b in 0..=4 - a {
                let exact = fact(a) * fact(b) / fact(a + b + 2);
                let q: f64 = TRI6
                    .points
                    .iter()
                    .zip(TRI6.weights)
                    .map(|(p, w)| w * p[0].powi(a as i32) * p[1].powi(b as i32))
                    .sum();
                assert!((q - exact).abs() < 1e-15, "s^{a} t^{b}: {q} vs {exact}");
            }
        }
    }
}
