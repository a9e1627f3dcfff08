//! exp, ln and atan in plain f32 arithmetic, for the Beckmann microfacet code.
//!
//! libm's versions are calls, so a loop over eight lanes that used them could not become
//! vector code, and their branches mispredicted on the slope inversion's path. These use
//! only additions, (fused) multiplications, one division at most, bit operations and selects,
//! so they inline and vectorise, eight lanes to a 256-bit register. exp and ln are Cephes'
//! expf and logf, accurate to about an ulp (the unit tests bound them against std's f64
//! functions); atan is Cephes' atanf. `small_int_bits`, exp's float-to-integer step, also
//! serves the other lane loops that need one (`warps`, the lane kernel's alias draw).

// Cephes' split of ln 2: k * LN2_HI is exact for |k| < 2^9.
const LN2_HI: f32 = 0.693_359_4;
const LN2_LO: f32 = -2.121_944_4e-4;

/// 1.5 * 2^23: adding it to an integer-valued f32 k with |k| < 2^22 is exact and leaves k,
/// in two's complement, in the sum's low mantissa bits.
const INT_BIAS: f32 = 12_582_912.0;

/// The low bits of an integer-valued f32 k, |k| < 2^22, as `k as i32` has them. Rust's
/// `as` saturates (NaN to 0, out of range to the ends), which LLVM cannot vectorise: it
/// makes every lane a scalar conversion, two compares and two conditional moves, about 60
/// instructions per eight lanes where this is an addition and a move.
#[inline(always)]
pub(crate) fn small_int_bits(k: f32) -> u32 {
    (k + INT_BIAS).to_bits()
}

/// c[0] x^(n-1) + ... + c[n-1] by Horner's rule in fused multiply-adds: one rounding per
/// step instead of two, and half the instructions and latency where the CPU has FMA (every
/// x86-64-v3 one). `mul_add` rounds once, exactly as IEEE specifies, in hardware or in
/// software, so results do not depend on the build's target.
#[inline(always)]
pub(crate) fn horner(x: f32, c: &[f32]) -> f32 {
    c[1..].iter().fold(c[0], |p, &c| p.mul_add(x, c))
}

/// e^x, relative error below 2 ulp on [-87.3, 88]; 0 below (where e^x is subnormal or 0)
/// and +inf above. e^x is finite up to 88.72, but there 2^k would need k = 128, beyond one
/// exponent field; every caller's argument is at most 0 (Beckmann's exponents, erfc's).
#[inline(always)]
pub fn exp(x: f32) -> f32 {
    let xc = x.clamp(-87.3, 88.0);
    let k = (xc * std::f32::consts::LOG2_E).round_ties_even();
    let r = (xc - k * LN2_HI) - k * LN2_LO;
    // |r| <= ln(2) / 2: Cephes' polynomial, degree 7 in all.
    let r2 = r * r;
    let p = horner(
        r,
        &[
            1.987_569_1e-4,
            1.398_199_9e-3,
            8.333_452e-3,
            4.166_579_6e-2,
            1.666_666_5e-1,
            5e-1,
        ],
    );
    let y = p.mul_add(r2, r) + 1.0;
    // 2^k: k + 127 in [1, 254] (x is clamped) shifted into the exponent field; the bias's
    // own bits shift out. (A NaN x gives a NaN y, whatever the scale.)
    let scale = f32::from_bits(small_int_bits(k + 127.0) << 23);
    let y = y * scale;
    if x < -87.3 {
        0.0
    } else if x > 88.0 {
        f32::INFINITY
    } else {
        y
    }
}

/// Natural logarithm of a positive normal x (Cephes' logf polynomial), -inf at 0.
#[inline(always)]
pub fn ln(x: f32) -> f32 {
    let bits = x.to_bits();
    // Mantissa m in [sqrt(1/2), sqrt(2)) and exponent k with x = m 2^k: the mantissa bits
    // are offset so that the exponent rolls over at sqrt(2), not at 2.
    let shifted = bits.wrapping_add(0x3f80_0000 - 0x3f35_04f3);
    let k = ((shifted >> 23) as i32 - 0x7f) as f32;
    let m = f32::from_bits((shifted & 0x007f_ffff) + 0x3f35_04f3);
    let f = m - 1.0;
    let z = f * f;
    let p = horner(
        f,
        &[
            7.037_683_6e-2,
            -1.151_461e-1,
            1.167_699_9e-1,
            -1.242_014_1e-1,
            1.424_932_3e-1,
            -1.666_805_8e-1,
            2.000_071_4e-1,
            -2.499_999_4e-1,
            3.333_333e-1,
        ],
    ) * f
        * z;
    let y = (p + k * LN2_LO - 0.5 * z + f) + k * LN2_HI;
    if x == 0.0 {
        f32::NEG_INFINITY
    } else {
        y
    }
}

/// arctan of t >= 0 (including +inf), absolute error below 2e-7: Cephes' atanf reduction to
/// |t| <= tan(pi / 8) with one division, then its degree-4 polynomial in t^2.
#[inline(always)]
pub fn atan(t: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4};
    let (base, num, den) = if t > 2.414_213_5 {
        (FRAC_PI_2, -1.0, t)
    } else if t > 0.414_213_57 {
        (FRAC_PI_4, t - 1.0, t + 1.0)
    } else {
        (0.0, t, 1.0)
    };
    let x = num / den;
    let z = x * x;
    let p = horner(
        z,
        &[
            8.053_744_5e-2,
            -1.387_768_5e-1,
            1.997_771_1e-1,
            -3.333_295e-1,
        ],
    ) * z
        * x
        + x;
    base + p
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative error in units of f32's last place, against std's f64 function.
    fn ulps(got: f32, want: f64) -> f64 {
        ((got as f64 - want) / want).abs() / f32::EPSILON as f64
    }

    /// `small_int_bits` is `k as i32`'s bits for every integer k with |k| < 2^22 (the
    /// 22-bit mask keeps what the bias leaves in the mantissa), and 2^k in `exp` is the
    /// power of two over the whole clamped range.
    #[test]
    fn small_int_bits_is_the_integer() {
        let mask = (1u32 << 22) - 1;
        for k in (-(1i32 << 22) + 1..1 << 22).step_by(997).chain(-300..300) {
            let got = small_int_bits(k as f32) & mask;
            assert_eq!(got, k as u32 & mask, "{k}");
        }
        for k in -126..=127 {
            let scale = f32::from_bits(small_int_bits(k as f32 + 127.0) << 23);
            assert_eq!(scale, 2f32.powi(k), "2^{k}");
        }
    }

    /// `horner` at every length up to 16 against Horner's rule in f64: each coefficient
    /// counted once at its power (a dropped or doubled term is off by far more than
    /// rounding), with positive terms so that the bound is relative.
    #[test]
    fn horner_is_the_polynomial_at_every_length() {
        let mut rng = crate::rng::Rng::new(5, 1);
        for n in 1..=16 {
            for _ in 0..200 {
                let c: Vec<f32> = (0..n).map(|_| 0.1 + rng.next_f32()).collect();
                let x = 2.0 * rng.next_f32();
                let want = c.iter().fold(0.0f64, |p, &c| p * x as f64 + c as f64);
                let got = horner(x, &c);
                let err = ((got as f64 - want) / want).abs();
                assert!(
                    err < 4.0 * n as f64 * f32::EPSILON as f64,
                    "n {n}, x {x}: {got} against {want}"
                );
            }
        }
    }

    #[test]
    fn exp_matches_std_to_two_ulps_over_its_range() {
        let mut worst: f64 = 0.0;
        for i in 0..=200_000 {
            let x = (-87.3 + 175.3 * i as f64 / 200_000.0) as f32;
            let x = x.clamp(-87.3, 88.0);
            worst = worst.max(ulps(exp(x), (x as f64).exp()));
        }
        // The ends of the range, and just past them.
        for x in [-87.3f32, -87.2, 88.0] {
            assert!(
                ulps(exp(x), (x as f64).exp()) <= 2.0,
                "exp({x}) = {}",
                exp(x)
            );
        }
        assert_eq!(exp(-87.31), 0.0);
        assert_eq!(exp(88.01), f32::INFINITY);
        // Small arguments, where the reduction does nothing.
        for i in -1000..=1000 {
            let x = i as f32 * 1e-6;
            worst = worst.max(ulps(exp(x), (x as f64).exp()));
        }
        assert!(worst <= 2.0, "worst {worst} ulp");
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(-87.5), 0.0);
        assert_eq!(exp(-1e30), 0.0);
        assert_eq!(exp(f32::NEG_INFINITY), 0.0);
        assert_eq!(exp(89.0), f32::INFINITY);
    }

    #[test]
    fn ln_matches_std_to_two_ulps() {
        let mut worst: f64 = 0.0;
        let mut x = f32::MIN_POSITIVE;
        while x < 1e37 {
            for m in [1.0, 1.1, 1.3, 1.414, 1.4143, 1.7, 1.99] {
                let v = x * m;
                let want = (v as f64).ln();
                if want.abs() > 1e-3 {
                    worst = worst.max(ulps(ln(v), want));
                }
            }
            x *= 3.7;
        }
        // Near 1 ln is small and an absolute bound is the meaningful one.
        for i in 1..20_000 {
            let v = 0.5 + i as f32 / 10_000.0;
            let want = (v as f64).ln();
            let err = (ln(v) as f64 - want).abs();
            assert!(
                err <= 2.0 * f32::EPSILON as f64 * want.abs().max(1e-3),
                "ln({v})"
            );
        }
        assert!(worst <= 2.0, "worst {worst} ulp");
        assert_eq!(ln(1.0), 0.0);
        assert_eq!(ln(0.0), f32::NEG_INFINITY);
    }

    #[test]
    fn atan_is_within_2e7_of_std() {
        for i in 0..=100_000 {
            let t = (i as f32 / 5_000.0).powi(3);
            assert!((atan(t) as f64 - (t as f64).atan()).abs() < 2e-7, "t={t}");
        }
        assert!((atan(f32::INFINITY) - std::f32::consts::FRAC_PI_2).abs() < 1e-7);
        assert_eq!(atan(0.0), 0.0);
    }
}
