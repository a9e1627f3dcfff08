//! Eight f32 lanes for the BVH's node test: one AVX register where the build has AVX (all
//! eight children in one instruction per step), else two SSE halves through glam. Each lane
//! does the same IEEE operation either way, with glam's operand order for min and max, so
//! the traversal's answers do not depend on the build.

#[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
mod imp {
    //! SAFETY (every `unsafe` below): the module exists only when the whole build has AVX,
    //! which is all these intrinsics require; the loads and stores also take exactly eight
    //! f32 behind a reference.
    use std::arch::x86_64::*;

    #[derive(Clone, Copy)]
    pub struct F8(__m256);

    impl F8 {
        #[inline(always)]
        pub fn splat(x: f32) -> F8 {
            F8(unsafe { _mm256_set1_ps(x) })
        }
        #[inline(always)]
        pub fn load(x: &[f32; 8]) -> F8 {
            F8(unsafe { _mm256_loadu_ps(x.as_ptr()) })
        }
        #[inline(always)]
        pub fn store(self, out: &mut [f32; 8]) {
            unsafe { _mm256_storeu_ps(out.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        pub fn sub(self, o: F8) -> F8 {
            F8(unsafe { _mm256_sub_ps(self.0, o.0) })
        }
        #[inline(always)]
        pub fn mul(self, o: F8) -> F8 {
            F8(unsafe { _mm256_mul_ps(self.0, o.0) })
        }
        #[inline(always)]
        pub fn max(self, o: F8) -> F8 {
            F8(unsafe { _mm256_max_ps(self.0, o.0) })
        }
        #[inline(always)]
        pub fn min(self, o: F8) -> F8 {
            F8(unsafe { _mm256_min_ps(self.0, o.0) })
        }
        /// Bit i set where lane i of `self` <= lane i of `o` (false for NaN, as SSE's cmple).
        #[inline(always)]
        pub fn le_mask(self, o: F8) -> u32 {
            unsafe { _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OS>(self.0, o.0)) as u32 }
        }
    }
}

#[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
mod imp {
    use glam::Vec4;

    #[derive(Clone, Copy)]
    pub struct F8([Vec4; 2]);

    impl F8 {
        #[inline(always)]
        pub fn splat(x: f32) -> F8 {
            F8([Vec4::splat(x); 2])
        }
        #[inline(always)]
        pub fn load(x: &[f32; 8]) -> F8 {
            F8([Vec4::from_slice(&x[..4]), Vec4::from_slice(&x[4..])])
        }
        #[inline(always)]
        pub fn store(self, out: &mut [f32; 8]) {
            self.0[0].write_to_slice(&mut out[..4]);
            self.0[1].write_to_slice(&mut out[4..]);
        }
        #[inline(always)]
        fn zip(self, o: F8, f: impl Fn(Vec4, Vec4) -> Vec4) -> F8 {
            F8([f(self.0[0], o.0[0]), f(self.0[1], o.0[1])])
        }
        #[inline(always)]
        pub fn sub(self, o: F8) -> F8 {
            self.zip(o, |a, b| a - b)
        }
        #[inline(always)]
        pub fn mul(self, o: F8) -> F8 {
            self.zip(o, |a, b| a * b)
        }
        #[inline(always)]
        pub fn max(self, o: F8) -> F8 {
            self.zip(o, Vec4::max)
        }
        #[inline(always)]
        pub fn min(self, o: F8) -> F8 {
            self.zip(o, Vec4::min)
        }
        #[inline(always)]
        pub fn le_mask(self, o: F8) -> u32 {
            self.0[0].cmple(o.0[0]).bitmask() | self.0[1].cmple(o.0[1]).bitmask() << 4
        }
    }
}

pub use imp::F8;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_match_scalar_ops() {
        let a = [1.0, -2.0, 3.5, f32::INFINITY, 0.0, -0.0, 7.0, f32::NAN];
        let b = [2.0, -3.0, 3.5, 1.0, -0.0, 0.0, f32::NEG_INFINITY, 1.0];
        let (fa, fb) = (F8::load(&a), F8::load(&b));
        let mut out = [0.0; 8];
        fa.sub(fb).store(&mut out);
        assert!((0..8).all(|i| out[i].to_bits() == (a[i] - b[i]).to_bits()));
        fa.mul(fb).store(&mut out);
        assert!((0..8).all(|i| out[i].to_bits() == (a[i] * b[i]).to_bits()));
        // SSE semantics: the second operand wins when either is NaN or both are zeros.
        fa.max(fb).store(&mut out);
        let sse_max = |x: f32, y: f32| if x > y { x } else { y };
        assert!((0..8).all(|i| out[i].to_bits() == sse_max(a[i], b[i]).to_bits()));
        fa.min(fb).store(&mut out);
        let sse_min = |x: f32, y: f32| if x < y { x } else { y };
        assert!((0..8).all(|i| out[i].to_bits() == sse_min(a[i], b[i]).to_bits()));
        let le = (0..8).filter(|&i| a[i] <= b[i]).fold(0, |m, i| m | 1 << i);
        assert_eq!(fa.le_mask(fb), le);
        assert_eq!(F8::splat(2.0).le_mask(F8::load(&a)), 0b0100_1100);
    }
}
