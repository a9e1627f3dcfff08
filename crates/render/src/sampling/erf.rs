//! Error function and its inverse, for Beckmann's exact Smith term and visible-normal sampling.
//! Computed in f32, as Mitsuba 3 does: the sampler inverts a CDF built from `erfc` to about the
//! resolution of its f32 uniform number (see `microfacet::SlopeInversion`), and the chi-square
//! tests of the sampled densities cannot see errors of a few 1e-7.

use super::elementary::{exp, horner, ln};

/// Complementary error function, relative error below 2.5e-7 for |x| <= 9 (0 beyond ~9.3,
/// where exp(-x^2) leaves f32's normal range). The renderer calls `erfc_from_exp`; this and
/// `erf` are the plain forms (the Gaussian pixel filter uses `erf`).
pub fn erfc(x: f32) -> f32 {
    erfc_from_exp(x, exp(-x * x))
}

/// erfc(x) given `e` = exp(-x^2). Callers that need exp(-x^2) anyway (the Beckmann Smith term,
/// the slope inversion's Halley steps) pay for one exp instead of two.
///
/// erfc(|x|) = exp(-x^2) t Q(t) with t = 1 / (1 + |x| / 2) in (0, 1]. Q is a degree-12
/// polynomial in s = 2t - 1, a relative-error-weighted Chebyshev fit to erfcx(z) / t
/// (erfcx(z) = exp(z^2) erfc(z), from mpmath at 40 digits) constrained to be exact at z = 0,
/// so that erf is continuous and odd through 0. Fitted for f64 (1.41e-9), it is below f32's
/// rounding here; a degree-10 fit would do as well in f32. The relative bound matters:
/// Beckmann tails live in erfc's tail. Evaluated by Estrin's scheme in fused multiply-adds,
/// a shorter dependency chain than Horner's on the Halley steps' critical path.
#[inline(always)]
pub fn erfc_from_exp(x: f32, e: f32) -> f32 {
    const C: [f32; 13] = [
        0.510_791_36,
        0.343_580_34,
        0.139_736_06,
        0.018_221_367,
        -0.010_755_407,
        -0.003_241_774_2,
        0.001_545_272_2,
        0.000_426_861_86,
        -0.000_330_425_94,
        -3.281_964_7e-5,
        6.971_882e-5,
        -1.365_704_7e-6,
        -9.172_661e-6,
    ];
    let t = 1.0 / (1.0 + 0.5 * x.abs());
    let s = 2.0 * t - 1.0;
    // Pairs of terms, then pairs of pairs, then the two halves.
    let (s2, s4) = (s * s, (s * s) * (s * s));
    let pair = |i: usize| C[i + 1].mul_add(s, C[i]);
    let quad = |i: usize| pair(i + 2).mul_add(s2, pair(i));
    let lo = quad(4).mul_add(s4, quad(0));
    let hi = C[12].mul_add(s4, quad(8));
    let r = e * t * hi.mul_add(s4 * s4, lo);
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

pub fn erf(x: f32) -> f32 {
    1.0 - erfc(x)
}

/// Inverse of erf on (-1, 1): Giles' 2010 single-precision approximation, relative error
/// ~4e-7 (`erfinv_inverts_erf`). Both of its branches are evaluated and one is selected, so
/// that it runs in vector lanes.
#[inline(always)]
pub fn erfinv(y: f32) -> f32 {
    // The largest f32 below 1: erfinv(+-1) is infinite.
    let y = y.clamp(-0.999_999_94, 0.999_999_94);
    let w = -ln((1.0 - y) * (1.0 + y));
    let centre = [
        2.810_226_4e-8,
        3.432_739_4e-7,
        -3.523_387_7e-6,
        -4.391_506_5e-6,
        0.000_218_580_87,
        -0.001_253_725,
        -0.004_177_681_6,
        0.246_640_73,
        1.501_409_4,
    ];
    let tail = [
        -0.000_200_214_26,
        0.000_100_950_56,
        0.001_349_343_2,
        -0.003_673_428_4,
        0.005_739_507_7,
        -0.007_622_461_3,
        0.009_438_870_5,
        1.001_674,
        2.832_976_8,
    ];
    let p_centre = horner(w - 2.5, &centre);
    let p_tail = horner(w.sqrt() - 3.0, &tail);
    let p = if w < 5.0 { p_centre } else { p_tail };
    p * y
}

#[cfg(test)]
mod tests {
    use super::*;

    /// erf by composite Simpson on 2/sqrt(pi) exp(-t^2) in f64: an independent reference.
    fn erf_quad(x: f64) -> f64 {
        let n = 2000;
        let h = x / n as f64;
        let f = |t: f64| (-t * t).exp();
        let mut s = f(0.0) + f(x);
        for i in 1..n {
            s += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        s * h / 3.0 * 2.0 / std::f64::consts::PI.sqrt()
    }

    #[test]
    fn erf_matches_quadrature_and_known_values() {
        assert!((erf(1.0) as f64 - 0.842_700_792_949_714_9).abs() < 2e-7);
        assert!((erf(0.5) as f64 - 0.520_499_877_813_046_5).abs() < 2e-7);
        assert!((erf(2.0) as f64 - 0.995_322_265_018_952_7).abs() < 2e-7);
        for i in -40..=40 {
            let x = i as f32 * 0.1;
            // Two ulps of erf's largest values.
            assert!((erf(x) as f64 - erf_quad(x as f64)).abs() < 2.4e-7, "x={x}");
        }
    }

    /// Relative error against mpmath's erfc (40 digits) from the centre into the tail the
    /// Beckmann code uses (|x| <= 9): the fit's 1.4e-9 plus f32 rounding.
    #[test]
    fn erfc_keeps_relative_precision_in_the_tail() {
        let want = [
            (0.1, 0.887_537_083_981_715),
            (0.5, 0.479_500_122_186_953_5),
            (1.0, 0.157_299_207_050_285_13),
            (2.0, 0.004_677_734_981_047_266),
            (3.0, 2.209_049_699_858_544e-5),
            (5.0, 1.537_459_794_428_035e-12),
            (8.0, 1.122_429_717_298_292_7e-29),
            (9.0, 4.137_031_746_513_81e-37),
        ];
        for (x, erfc_x) in want {
            let rel = (erfc(x) as f64 / erfc_x - 1.0).abs();
            assert!(rel < 2.5e-7, "erfc({x}): relative error {rel:e}");
            // erfc(-x) = 2 - erfc(x), and erf is its complement, to f32 rounding.
            let ulp2 = f32::EPSILON as f64 * 2.0;
            assert!((erfc(-x) as f64 - (2.0 - erfc_x)).abs() <= ulp2 + 2.5e-7 * erfc_x);
            assert!((erf(x) as f64 - (1.0 - erfc_x)).abs() <= ulp2 / 2.0 + 2.5e-7 * erfc_x);
        }
    }

    /// erfinv(y) is the exact inverse of erf at a y' within 4e-7 of y, relative: as close
    /// as f32's own rounding of y allows, give or take a few ulps.
    #[test]
    fn erfinv_inverts_erf() {
        let mut worst: f64 = 0.0;
        for i in -999_999i32..=999_999 {
            if i % 97 != 0 && i.abs() < 999_000 {
                continue;
            }
            let y = i as f32 / 1_000_000.0;
            let x = erfinv(y);
            let back = erf_quad(x as f64);
            worst = worst.max((back - y as f64).abs() / (y as f64).abs().max(1e-3));
        }
        assert!(worst < 4e-7, "worst relative {worst:e}");
        assert_eq!(erfinv(0.0), 0.0);
        assert!(erfinv(1.0).is_finite() && erfinv(-1.0) == -erfinv(1.0));
    }
}
