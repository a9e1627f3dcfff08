//! Counter-based seeding plus PCG32 streams.
//!
//! Every (seed, pixel, sample) triple gets its own generator, so an image does not depend on
//! how pixels are split among threads: the determinism the harness promises. A pixel's
//! samples share one PCG stream (its increment, hashed from the pixel) and each starts at a
//! hashed state in it, as pbrt-v4's PCG sampler places them: one hash per sample, where a
//! stream per sample took two hashes and a warm-up step (the render loop's largest
//! per-sample cost outside traversal, about a tenth of Cornell render time).

/// Mixes 64 bits so that nearby inputs give unrelated outputs (SplitMix64 finaliser).
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// PCG32 (XSH RR), O'Neill 2014.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    inc: u64,
}

const PCG_MULT: u64 = 6_364_136_223_846_793_005;

impl Rng {
    /// A generator for one stream; `stream` selects among 2^63 independent sequences.
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut rng = Rng {
            state: 0,
            inc: (stream << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    /// The generator for one camera sample of one pixel.
    #[inline]
    pub fn for_sample(seed: u64, pixel: u64, sample: u64) -> Self {
        Rng::for_pixel_sample(Rng::pixel_key(seed, pixel), sample)
    }

    /// The part of `for_sample`'s seeding shared by all samples of a pixel.
    #[inline]
    pub fn pixel_key(seed: u64, pixel: u64) -> u64 {
        mix64(seed ^ mix64(pixel))
    }

    /// `for_sample(seed, pixel, sample)` from `pixel_key(seed, pixel)`.
    #[inline]
    pub fn for_pixel_sample(pixel_key: u64, sample: u64) -> Self {
        Rng::in_pixel_stream(Rng::pixel_stream(pixel_key), pixel_key, sample)
    }

    /// The increment of a pixel's stream.
    #[inline]
    pub fn pixel_stream(pixel_key: u64) -> u64 {
        (mix64(pixel_key ^ 0x5851_F42D_4C95_7F2D) << 1) | 1
    }

    /// `for_pixel_sample` given the pixel's stream. The start is hashed, not advanced to:
    /// two samples' sequences overlap only if their starts fall within a few hundred steps of
    /// each other in a 2^64 cycle (at 10^6 samples per pixel, odds about 10^-5).
    #[inline]
    pub fn in_pixel_stream(inc: u64, pixel_key: u64, sample: u64) -> Self {
        Rng {
            state: mix64(pixel_key ^ sample),
            inc,
        }
    }

    /// The generator at `state` of the stream `inc` (odd), for the lane samplers that step
    /// many of them together.
    #[inline(always)]
    pub(crate) fn from_parts(state: u64, inc: u64) -> Self {
        Rng { state, inc }
    }

    #[inline(always)]
    pub(crate) fn state(&self) -> u64 {
        self.state
    }

    /// The next 32 random bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(PCG_MULT).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in [0, 1), never 1: 24 random mantissa bits.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Uniform in [0, 1) with 53 random bits, for statistics code.
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        let hi = (self.next_u32() as u64) << 21;
        let lo = (self.next_u32() >> 11) as u64;
        (hi | lo) as f64 * (1.0 / 9_007_199_254_740_992.0)
    }

    /// Two uniform numbers in [0, 1).
    #[inline]
    pub fn next_2d(&mut self) -> glam::Vec2 {
        glam::Vec2::new(self.next_f32(), self.next_f32())
    }
}

/// Samples drawn side by side: camera samples are started this many at a time.
pub const LANES: usize = 8;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_key_same_stream() {
        let mut a = Rng::for_sample(7, 123, 4);
        let mut b = Rng::for_sample(7, 123, 4);
        for _ in 0..100 {
            assert_eq!(a.next_u32(), b.next_u32());
        }
    }

    #[test]
    fn pixel_key_seeding_is_for_sample() {
        for (seed, pixel, s) in [(0, 0, 0), (7, 123, 4), (u64::MAX, 1 << 40, 99)] {
            let mut a = Rng::for_sample(seed, pixel, s);
            let mut b = Rng::for_pixel_sample(Rng::pixel_key(seed, pixel), s);
            assert!((0..8).all(|_| a.next_u32() == b.next_u32()));
        }
    }

    #[test]
    fn neighbouring_keys_differ() {
        let mut a = Rng::for_sample(7, 123, 4);
        let mut b = Rng::for_sample(7, 123, 5);
        let same = (0..64).filter(|_| a.next_u32() == b.next_u32()).count();
        assert!(same < 2);
    }

    #[test]
    fn floats_in_unit_interval_with_correct_mean() {
        let mut r = Rng::new(1, 2);
        let n = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let x = r.next_f32();
            assert!((0.0..1.0).contains(&x));
            sum += x as f64;
        }
        // Mean of U(0,1) has sd 1/sqrt(12 n) ~ 6.5e-4; 5 sd is a 6e-7 false-alarm rate.
        assert!((sum / n as f64 - 0.5).abs() < 5.0 * (1.0 / (12.0 * n as f64)).sqrt());
    }
}
