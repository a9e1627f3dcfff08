//! Hashed random permutations and uniform numbers: the randomisations of the stratified
//! sampler, each a pure function of its arguments.

use crate::rng::mix64;

/// Element `i` of a random permutation of `0..n` chosen by `seed` (Kensler 2013, "Correlated
/// Multi-Jittered Sampling", section 3): a bijective hash on the next power of two, walked
/// until it lands below `n`. For a fixed seed, `i -> permute(i, n, seed)` is a permutation
/// of `0..n`; `i < n` is required.
pub fn permute(mut i: u32, n: u32, seed: u32) -> u32 {
    debug_assert!(i < n);
    let p = seed;
    let mut w = n - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    loop {
        i ^= p;
        i = i.wrapping_mul(0xe170893d);
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929eb3f);
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | p >> 27);
        i = i.wrapping_mul(0x6935fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dcb303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e501cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860a3df);
        i &= w;
        i ^= i >> 5;
        if i < n {
            break;
        }
    }
    ((i as u64 + p as u64) % n as u64) as u32
}

/// A uniform number in [0, 1) with 53 random bits, from a 64-bit key.
#[inline]
pub fn uniform_f64(key: u64) -> f64 {
    (mix64(key) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// The largest f32 below 1.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// `x` in f32, kept below 1 (a value just under 1 in f64 rounds up to 1 in f32).
#[inline]
pub fn below_one(x: f64) -> f32 {
    (x as f32).min(ONE_MINUS_EPSILON)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permute_is_a_permutation_for_every_size() {
        for n in (1..=70).chain([127, 128, 129, 1000, 4096, 4097]) {
            for seed in [0, 1, 0xdead_beef, u32::MAX] {
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let j = permute(i, n, seed) as usize;
                    assert!(!seen[j], "n = {n}, seed = {seed}: {j} twice");
                    seen[j] = true;
                }
            }
        }
    }

    #[test]
    fn permute_depends_on_the_seed() {
        let n = 64;
        let a: Vec<u32> = (0..n).map(|i| permute(i, n, 1)).collect();
        let b: Vec<u32> = (0..n).map(|i| permute(i, n, 2)).collect();
        assert_ne!(a, b);
        // Not the identity either.
        assert!((0..n).any(|i| a[i as usize] != i));
    }

    #[test]
    fn uniform_numbers_lie_in_the_unit_interval() {
        let mut sum = 0.0;
        for k in 0..10_000u64 {
            let u = uniform_f64(k);
            assert!((0.0..1.0).contains(&u));
            sum += u;
        }
        // Mean of 10^4 uniforms: sd 0.0029; 5 sd.
        assert!((sum / 1e4 - 0.5).abs() < 0.015);
        assert_eq!(below_one(1.0 - 1e-12), ONE_MINUS_EPSILON);
    }
}
