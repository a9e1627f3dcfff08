//! exp, ln and atan in plain f64 arithmetic, for the Beckmann microfacet code.
//!
//! libm's versions are calls, so a loop over eight lanes that used them could not become
//! vector code, and their branches mispredicted on the slope inversion's path. These use
//! only additions, multiplications, one division at most, bit operations and selects, so
//! they inline and vectorise. exp and ln are accurate to about an ulp (the unit tests
//! bound them against std's); atan is a starting-guess quality approximation.

// fdlibm's split of ln 2: k * LN2_HI is exact for |k| < 2^11.
const LN2_HI: f64 = 0.693_147_180_369_123_8;
const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;

/// e^x, relative error below 4e-16; 0 below -708 (where e^x is subnormal or 0) and
/// +inf above 709.78.
#[inline(always)]
pub fn exp(x: f64) -> f64 {
    let xc = x.clamp(-708.0, 709.0);
    let k = (xc * std::f64::consts::LOG2_E).round_ties_even();
    let r = (xc - k * LN2_HI) - k * LN2_LO;
    // |r| <= ln(2) / 2: Taylor to degree 13 leaves 4e-18, by Estrin's scheme.
    let r2 = r * r;
    let r4 = r2 * r2;
    let r8 = r4 * r4;
    // 1 / n!, n = 2..=13.
    const C: [f64; 12] = [
        0.5,
        0.166_666_666_666_666_66,
        0.041_666_666_666_666_664,
        0.008_333_333_333_333_333,
        0.001_388_888_888_888_889,
        1.984_126_984_126_984e-4,
        2.480_158_730_158_73e-5,
        2.755_731_922_398_589_3e-6,
        2.755_731_922_398_589e-7,
        2.505_210_838_544_172e-8,
        2.087_675_698_786_81e-9,
        1.605_904_383_682_161_3e-10,
    ];
    let p01 = 1.0 + r;
    let p23 = C[0] + C[1] * r;
    let p45 = C[2] + C[3] * r;
    let p67 = C[4] + C[5] * r;
    let p89 = C[6] + C[7] * r;
    let p1011 = C[8] + C[9] * r;
    let p1213 = C[10] + C[11] * r;
    let p = (p01 + p23 * r2) + (p45 + p67 * r2) * r4 + ((p89 + p1011 * r2) + p1213 * r4) * r8;
    let scale = f64::from_bits(((k as i64 + 1023) << 52) as u64);
    let y = p * scale;
    if x < -708.0 {
        0.0
    } else if x > 709.78 {
        f64::INFINITY
    } else {
        y
    }
}

/// Natural logarithm of a positive normal x (fdlibm's method and coefficients), -inf at 0.
#[inline(always)]
pub fn ln(x: f64) -> f64 {
    const LG: [f64; 7] = [
        0.666_666_666_666_673_5,
        0.399_999_999_994_094_2,
        0.285_714_287_436_623_9,
        0.222_221_984_321_497_84,
        0.181_835_721_616_180_5,
        0.153_138_376_992_093_73,
        0.147_981_986_051_165_86,
    ];
    let bits = x.to_bits();
    // Mantissa m in [sqrt(1/2), sqrt(2)) and exponent k with x = m 2^k: the mantissa bits
    // are offset so that the exponent rolls over at sqrt(2), not at 2.
    let shifted = bits.wrapping_add(0x3ff0_0000_0000_0000 - 0x3fe6_a09e_0000_0000);
    let k = ((shifted >> 52) as i64 - 0x3ff) as f64;
    let m = f64::from_bits((shifted & 0x000f_ffff_ffff_ffff) + 0x3fe6_a09e_0000_0000);
    let f = m - 1.0;
    let s = f / (2.0 + f);
    let z = s * s;
    let w = z * z;
    let t1 = w * (LG[1] + w * (LG[3] + w * LG[5]));
    let t2 = z * (LG[0] + w * (LG[2] + w * (LG[4] + w * LG[6])));
    let r = t2 + t1;
    let hfsq = 0.5 * f * f;
    let y = k * LN2_HI - ((hfsq - (s * (hfsq + r) + k * LN2_LO)) - f);
    if x == 0.0 {
        f64::NEG_INFINITY
    } else {
        y
    }
}

/// arctan of t >= 0 (including +inf), absolute error below 2e-7: Cephes' atanf reduction to
/// |t| <= tan(pi / 8) with one division, then its degree-4 polynomial in t^2.
#[inline(always)]
pub fn atan(t: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
    let (base, num, den) = if t > 2.414_213_562_373_095 {
        (FRAC_PI_2, -1.0, t)
    } else if t > 0.414_213_562_373_095_1 {
        (FRAC_PI_4, t - 1.0, t + 1.0)
    } else {
        (0.0, t, 1.0)
    };
    let x = num / den;
    let z = x * x;
    let p =
        (((8.053_744_5e-2 * z - 1.387_768_5e-1) * z + 1.997_771_1e-1) * z - 3.333_294_9e-1) * z * x
            + x;
    base + p
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative error in units of the last place of the true value (std's, itself within
    /// an ulp of the correctly rounded one).
    fn ulps(got: f64, want: f64) -> f64 {
        ((got - want) / want).abs() / f64::EPSILON
    }

    #[test]
    fn exp_matches_std_to_two_ulps_over_its_range() {
        let mut worst: f64 = 0.0;
        for i in 0..=200_000 {
            let x = -708.0 + 1417.0 * i as f64 / 200_000.0;
            let x = x.min(709.7);
            worst = worst.max(ulps(exp(x), x.exp()));
        }
        // Small arguments, where the reduction does nothing.
        for i in -1000..=1000 {
            let x = i as f64 * 1e-6;
            worst = worst.max(ulps(exp(x), x.exp()));
        }
        assert!(worst <= 2.0, "worst {worst} ulp");
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(-708.5), 0.0);
        assert_eq!(exp(-1e300), 0.0);
        assert_eq!(exp(f64::NEG_INFINITY), 0.0);
        assert_eq!(exp(710.0), f64::INFINITY);
    }

    #[test]
    fn ln_matches_std_to_two_ulps() {
        let mut worst: f64 = 0.0;
        let mut x = f64::MIN_POSITIVE;
        while x < 1e300 {
            for m in [1.0, 1.1, 1.3, 1.414, 1.4143, 1.7, 1.99] {
                let v = x * m;
                let want = v.ln();
                if want != 0.0 {
                    worst = worst.max(ulps(ln(v), want));
                }
            }
            x *= 3.7;
        }
        for i in 1..20_000 {
            let v = 0.5 + i as f64 / 10_000.0;
            if v != 1.0 {
                worst = worst.max(ulps(ln(v), v.ln()));
            }
        }
        assert!(worst <= 2.0, "worst {worst} ulp");
        assert_eq!(ln(1.0), 0.0);
        assert_eq!(ln(0.0), f64::NEG_INFINITY);
    }

    #[test]
    fn atan_is_within_2e7_of_std() {
        for i in 0..=100_000 {
            let t = (i as f64 / 5_000.0).powi(3);
            assert!((atan(t) - t.atan()).abs() < 2e-7, "t={t}");
        }
        assert!((atan(f64::INFINITY) - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert_eq!(atan(0.0), 0.0);
    }
}
