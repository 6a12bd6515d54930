//! The Turbo colour map (A. Mikhailov, Google AI Blog, 2019) as 8-bit sRGB, evaluated with the
//! degree-5 polynomial approximation published with it.

/// Turbo colour map at `t` ∈ [0, 1] (clamped; NaN maps to 0), 8-bit sRGB.
///
/// Source: A. Mikhailov, "Turbo, An Improved Rainbow Colormap for Visualization", Google AI Blog,
/// 2019; this is the polynomial approximation published with it (R. Du, GLSL `TurboColormap`, gist
/// mikhailov-work/0d177465a8151eb6ede1768d51d476c7), whose coefficients are used unchanged, the
/// result clamped to [0, 1] per channel and rounded. Endpoints: `colour_map(0) = [35, 23, 27]`
/// (near black), `colour_map(1) = [144, 13, 0]` (dark red). On [0.1, 1] the hue falls monotonically
/// from blue (≈ 225°) through cyan, green, yellow and orange to red; the lightness rises from dark
/// blue to the yellow-green middle and falls again to dark red.
pub fn colour_map(t: f64) -> [u8; 3] {
    const R4: [f64; 4] = [0.13572138, 4.61539260, -42.66032258, 132.13108234];
    const G4: [f64; 4] = [0.09140261, 2.19418839, 4.84296658, -14.18503333];
    const B4: [f64; 4] = [0.10667330, 12.64194608, -60.58204836, 110.36276771];
    const R2: [f64; 2] = [-152.94239396, 59.28637943];
    const G2: [f64; 2] = [4.27729857, 2.82956604];
    const B2: [f64; 2] = [-89.90310912, 27.34824973];
    let x = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let v4 = [1.0, x, x * x, x * x * x];
    let v2 = [x.powi(4), x.powi(5)];
    let ch = |c4: [f64; 4], c2: [f64; 2]| {
        let v = c4[0] * v4[0]
            + c4[1] * v4[1]
            + c4[2] * v4[2]
            + c4[3] * v4[3]
            + c2[0] * v2[0]
            + c2[1] * v2[1];
        (v.clamp(0.0, 1.0) * 255.0).round() as u8
    };
    [ch(R4, R2), ch(G4, G2), ch(B4, B2)]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hue(c: [u8; 3]) -> f64 {
        let [r, g, b] = c.map(|v| f64::from(v) / 255.0);
        let (mx, mn) = (r.max(g).max(b), r.min(g).min(b));
        let d = mx - mn;
        let h = if d == 0.0 {
            0.0
        } else if mx == r {
            60.0 * ((g - b) / d).rem_euclid(6.0)
        } else if mx == g {
            60.0 * ((b - r) / d + 2.0)
        } else {
            60.0 * ((r - g) / d + 4.0)
        };
        // red that has wrapped past 0 (magenta side) counts as just below 360 − treat > 300 as < 0
        if h > 300.0 { h - 360.0 } else { h }
    }

    #[test]
    fn colour_map_endpoints_and_monotone_hue() {
        assert_eq!(colour_map(0.0), [35, 23, 27]);
        assert_eq!(colour_map(1.0), [144, 13, 0]);
        assert_eq!(colour_map(-3.0), colour_map(0.0));
        assert_eq!(colour_map(7.0), colour_map(1.0));
        assert_eq!(colour_map(f64::NAN), colour_map(0.0));
        let (a, b, c) = (colour_map(0.0), colour_map(0.5), colour_map(1.0));
        assert!(a != b && b != c && a != c);
        // blue, then green, then red dominate
        let m = colour_map(0.15);
        assert!(m[2] > m[0] && m[2] > m[1], "{m:?}");
        let m = colour_map(0.5);
        assert!(m[1] > m[0] && m[1] > m[2], "{m:?}");
        let m = colour_map(0.9);
        assert!(m[0] > m[1] && m[0] > m[2], "{m:?}");
        // hue non-increasing on [0.1, 1], from blue to red
        let hues: Vec<f64> = (10..=100)
            .map(|k| hue(colour_map(k as f64 / 100.0)))
            .collect();
        assert!(hues[0] > 200.0 && hues[0] < 250.0, "{}", hues[0]);
        assert!(*hues.last().unwrap() < 15.0);
        for w in hues.windows(2) {
            assert!(w[1] <= w[0] + 1.0, "hue rises: {:?}", w);
        }
    }
}
