//! Gauss–Kronrod 7–15 quadrature (the `qk15` rule of QUADPACK: Piessens, de Doncker-Kapenga,
//! Überhuber & Kahaner, 1983).

/// Kronrod nodes on [−1, 1] (non-negative half; `XGK[1]`, `XGK[3]`, `XGK[5]`, `XGK[7]` are the
/// 7-point Gauss nodes).
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
/// Kronrod weights.
const WGK: [f64; 8] = [
    0.022_935_322_010_529_225,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_18,
    0.140_653_259_715_525_92,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_83,
];
/// Gauss weights of the nodes `XGK[1]`, `XGK[3]`, `XGK[5]`, `XGK[7]`.
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// `∫_a^b f` by the 15-point Kronrod rule; returns `(K15, |K15 − G7|)`. The difference
/// estimates the error of G7; the K15 value itself is far more accurate for smooth `f`.
pub fn gk15(mut f: impl FnMut(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let fc = f(c);
    let mut k = WGK[7] * fc;
    let mut g = WG[3] * fc;
    for j in 0..7 {
        let dx = h * XGK[j];
        let s = f(c - dx) + f(c + dx);
        k += WGK[j] * s;
        if j % 2 == 1 {
            g += WG[j / 2] * s;
        }
    }
    (k * h, ((k - g) * h).abs())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_two() {
        let k: f64 = 2.0 * WGK[..7].iter().sum::<f64>() + WGK[7];
        let g: f64 = 2.0 * WG[..3].iter().sum::<f64>() + WG[3];
        assert!((k - 2.0).abs() < 1e-15 && (g - 2.0).abs() < 1e-15);
    }

    #[test]
    fn exact_for_polynomials() {
        // K15 exact to degree 22, G7 to degree 13
        for p in 0..=22 {
            let (k, e) = gk15(|x| x.powi(p), 0.0, 1.0);
            assert!((k - 1.0 / (p as f64 + 1.0)).abs() < 1e-15, "degree {p}");
            if p <= 13 {
                assert!(e < 1e-15, "G7 degree {p}");
            }
        }
        let (k, _) = gk15(f64::exp, 0.0, 1.0);
        assert!((k - (1f64.exp() - 1.0)).abs() < 1e-15);
    }
}
