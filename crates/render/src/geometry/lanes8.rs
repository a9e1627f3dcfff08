//! Eight f32 lanes for the BVH's node test and the eight-ray triangle test: one AVX register
//! where the build has AVX (all eight lanes in one instruction per step), else two SSE halves
//! through glam. Each lane does the same IEEE operation either way, with glam's operand order
//! for min and max, so the traversal's answers do not depend on the build, and a lane of the
//! eight-ray triangle test computes bitwise what glam's four-lane test computes for it.

#[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
mod imp {
    //! SAFETY (every `unsafe` below): the module exists only when the whole build has AVX,
    //! which is all these intrinsics require; the loads and stores also take exactly eight
    //! f32 behind a reference.
    use std::arch::x86_64::*;

    #[derive(Clone, Copy)]
    pub struct F8(__m256);

    /// Eight lane masks (all ones or all zeros per lane).
    #[derive(Clone, Copy)]
    pub struct M8(__m256);

    macro_rules! binop {
        ($name:ident, $intr:ident) => {
            #[inline(always)]
            pub fn $name(self, o: F8) -> F8 {
                F8(unsafe { $intr(self.0, o.0) })
            }
        };
    }
    macro_rules! cmp {
        ($name:ident, $pred:ident) => {
            #[inline(always)]
            pub fn $name(self, o: F8) -> M8 {
                M8(unsafe { _mm256_cmp_ps::<$pred>(self.0, o.0) })
            }
        };
    }

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
        binop!(add, _mm256_add_ps);
        binop!(sub, _mm256_sub_ps);
        binop!(mul, _mm256_mul_ps);
        binop!(div, _mm256_div_ps);
        binop!(max, _mm256_max_ps);
        binop!(min, _mm256_min_ps);
        /// Clears the sign bit, as glam's abs.
        #[inline(always)]
        pub fn abs(self) -> F8 {
            F8(unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0) })
        }
        /// Flips the sign bit, as scalar negation.
        #[inline(always)]
        pub fn neg(self) -> F8 {
            F8(unsafe { _mm256_xor_ps(_mm256_set1_ps(-0.0), self.0) })
        }
        /// Bit i set where lane i's sign bit is (-0.0 and negative NaNs included).
        #[inline(always)]
        pub fn sign_mask(self) -> u32 {
            unsafe { _mm256_movemask_ps(self.0) as u32 }
        }
        // Ordered predicates, false for NaN, as SSE's cmplt/cmple/cmpgt/cmpeq; cmpneq is
        // unordered (true for NaN), as SSE's.
        cmp!(lt, _CMP_LT_OS);
        cmp!(le, _CMP_LE_OS);
        cmp!(gt, _CMP_GT_OS);
        cmp!(eq, _CMP_EQ_OQ);
        cmp!(ne, _CMP_NEQ_UQ);
        /// Bit i set where lane i of `self` <= lane i of `o` (false for NaN, as SSE's cmple).
        #[inline(always)]
        pub fn le_mask(self, o: F8) -> u32 {
            self.le(o).bitmask()
        }
        /// `a` where the mask is set, else `b`.
        #[inline(always)]
        pub fn select(m: M8, a: F8, b: F8) -> F8 {
            F8(unsafe { _mm256_blendv_ps(b.0, a.0, m.0) })
        }
    }

    impl M8 {
        /// Lane i set where bit i of `bits` is.
        #[inline(always)]
        pub fn from_bits(bits: u32) -> M8 {
            unsafe {
                let lanes = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
                let b = _mm256_and_si256(_mm256_set1_epi32(bits as i32), lanes);
                M8(_mm256_castsi256_ps(_mm256_cmpeq_epi32(b, lanes)))
            }
        }
        #[inline(always)]
        pub fn bitmask(self) -> u32 {
            unsafe { _mm256_movemask_ps(self.0) as u32 }
        }
        #[inline(always)]
        pub fn and(self, o: M8) -> M8 {
            M8(unsafe { _mm256_and_ps(self.0, o.0) })
        }
        #[inline(always)]
        pub fn or(self, o: M8) -> M8 {
            M8(unsafe { _mm256_or_ps(self.0, o.0) })
        }
        /// `self` and not `o`.
        #[inline(always)]
        pub fn and_not(self, o: M8) -> M8 {
            M8(unsafe { _mm256_andnot_ps(o.0, self.0) })
        }
    }
}

#[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
mod imp {
    use glam::{BVec4A, Vec4};

    #[derive(Clone, Copy)]
    pub struct F8([Vec4; 2]);

    #[derive(Clone, Copy)]
    pub struct M8([BVec4A; 2]);

    macro_rules! binop {
        ($name:ident, $f:expr) => {
            #[inline(always)]
            pub fn $name(self, o: F8) -> F8 {
                let f = $f;
                F8([f(self.0[0], o.0[0]), f(self.0[1], o.0[1])])
            }
        };
    }
    macro_rules! cmp {
        ($name:ident, $f:ident) => {
            #[inline(always)]
            pub fn $name(self, o: F8) -> M8 {
                M8([self.0[0].$f(o.0[0]), self.0[1].$f(o.0[1])])
            }
        };
    }

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
        binop!(add, |a: Vec4, b: Vec4| a + b);
        binop!(sub, |a: Vec4, b: Vec4| a - b);
        binop!(mul, |a: Vec4, b: Vec4| a * b);
        binop!(div, |a: Vec4, b: Vec4| a / b);
        binop!(max, Vec4::max);
        binop!(min, Vec4::min);
        #[inline(always)]
        pub fn abs(self) -> F8 {
            F8([self.0[0].abs(), self.0[1].abs()])
        }
        #[inline(always)]
        pub fn neg(self) -> F8 {
            F8([-self.0[0], -self.0[1]])
        }
        #[inline(always)]
        pub fn sign_mask(self) -> u32 {
            self.0[0].is_negative_bitmask() | self.0[1].is_negative_bitmask() << 4
        }
        cmp!(lt, cmplt);
        cmp!(le, cmple);
        cmp!(gt, cmpgt);
        cmp!(eq, cmpeq);
        cmp!(ne, cmpne);
        #[inline(always)]
        pub fn le_mask(self, o: F8) -> u32 {
            self.le(o).bitmask()
        }
        #[inline(always)]
        pub fn select(m: M8, a: F8, b: F8) -> F8 {
            F8([
                Vec4::select(m.0[0], a.0[0], b.0[0]),
                Vec4::select(m.0[1], a.0[1], b.0[1]),
            ])
        }
    }

    impl M8 {
        #[inline(always)]
        pub fn from_bits(bits: u32) -> M8 {
            let b = |i: u32| bits >> i & 1 != 0;
            M8([
                BVec4A::new(b(0), b(1), b(2), b(3)),
                BVec4A::new(b(4), b(5), b(6), b(7)),
            ])
        }
        #[inline(always)]
        pub fn bitmask(self) -> u32 {
            self.0[0].bitmask() | self.0[1].bitmask() << 4
        }
        #[inline(always)]
        pub fn and(self, o: M8) -> M8 {
            M8([self.0[0] & o.0[0], self.0[1] & o.0[1]])
        }
        #[inline(always)]
        pub fn or(self, o: M8) -> M8 {
            M8([self.0[0] | o.0[0], self.0[1] | o.0[1]])
        }
        #[inline(always)]
        pub fn and_not(self, o: M8) -> M8 {
            M8([self.0[0] & !o.0[0], self.0[1] & !o.0[1]])
        }
    }
}

pub use imp::{F8, M8};

/// `table[idx[i]]` in each lane i, for indices below 8: a table of up to eight entries held
/// in a register and read by one permute (AVX2), where a lookup per lane takes a load and a
/// store, and AVX-512 gathers of the same entries measured slower than those (see README).
/// The bits move unchanged.
#[inline(always)]
pub fn lookup8(table: &[f32; 8], idx: &[u32; 8]) -> [f32; 8] {
    debug_assert!(idx.iter().all(|&i| i < 8));
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    {
        use std::arch::x86_64::*;
        let mut out = [0.0; 8];
        // SAFETY: the build has AVX2, all these intrinsics require; the unaligned loads and
        // the store take exactly eight 32-bit values behind a reference.
        unsafe {
            let t = _mm256_loadu_ps(table.as_ptr());
            let i = _mm256_loadu_si256(idx.as_ptr().cast());
            _mm256_storeu_ps(out.as_mut_ptr(), _mm256_permutevar8x32_ps(t, i));
        }
        out
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    {
        std::array::from_fn(|k| table[idx[k] as usize & 7])
    }
}

impl F8 {
    #[inline(always)]
    pub fn to_array(self) -> [f32; 8] {
        let mut out = [0.0; 8];
        self.store(&mut out);
        out
    }
}

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

    /// `lookup8` reads the indexed entry in every lane, bits unchanged (NaN payloads and
    /// signed zeros too), for every index in every lane.
    #[test]
    fn lookup8_reads_the_indexed_entries() {
        let table = [
            1.5,
            -0.0,
            f32::from_bits(0x7fc0_1234),
            f32::INFINITY,
            f32::from_bits(7),
            -2.25,
            f32::MAX,
            0.0,
        ];
        for shift in 0..8u32 {
            let idx: [u32; 8] = std::array::from_fn(|k| (k as u32 * 3 + shift) % 8);
            let got = lookup8(&table, &idx);
            assert!((0..8).all(|k| got[k].to_bits() == table[idx[k] as usize].to_bits()));
        }
        assert!(lookup8(&table, &[5; 8]).iter().all(|x| *x == -2.25));
    }

    /// Each lane of the eight-lane ops is bitwise glam's four-lane op on it.
    #[test]
    fn lanes_match_glam() {
        use glam::Vec4;
        let a = [1.0, -2.0, 3.5, f32::INFINITY, 0.0, -0.0, 7.0, f32::NAN];
        let b = [2.0, -3.0, 3.5, 1.0, -0.0, 0.0, f32::NEG_INFINITY, 1.0];
        let (fa, fb) = (F8::load(&a), F8::load(&b));
        let halves = |x: [f32; 8]| [Vec4::from_slice(&x[..4]), Vec4::from_slice(&x[4..])];
        let (ga, gb) = (halves(a), halves(b));
        let same = |got: F8, want: [Vec4; 2]| {
            let got = got.to_array();
            let want: Vec<f32> = want.iter().flat_map(|v| v.to_array()).collect();
            (0..8).all(|i| got[i].to_bits() == want[i].to_bits())
        };
        let map = |f: fn(Vec4, Vec4) -> Vec4| [f(ga[0], gb[0]), f(ga[1], gb[1])];
        assert!(same(fa.add(fb), map(|x, y| x + y)));
        assert!(same(fa.div(fb), map(|x, y| x / y)));
        assert!(same(fa.max(fb), map(Vec4::max)));
        assert!(same(fa.min(fb), map(Vec4::min)));
        assert!(same(fa.abs(), [ga[0].abs(), ga[1].abs()]));
        assert!(same(fa.neg(), [-ga[0], -ga[1]]));
        let signs = ga[0].is_negative_bitmask() | ga[1].is_negative_bitmask() << 4;
        assert_eq!(fa.sign_mask(), signs);
        assert_eq!(F8::load(&b).sign_mask(), 0b0101_0010, "-3, -0 and -inf");
        let bits = |f: fn(Vec4, Vec4) -> u32| f(ga[0], gb[0]) | f(ga[1], gb[1]) << 4;
        assert_eq!(fa.lt(fb).bitmask(), bits(|x, y| x.cmplt(y).bitmask()));
        assert_eq!(fa.le(fb).bitmask(), bits(|x, y| x.cmple(y).bitmask()));
        assert_eq!(fa.gt(fb).bitmask(), bits(|x, y| x.cmpgt(y).bitmask()));
        assert_eq!(fa.eq(fb).bitmask(), bits(|x, y| x.cmpeq(y).bitmask()));
        assert_eq!(fa.ne(fb).bitmask(), bits(|x, y| x.cmpne(y).bitmask()));
        for m in [0, 1, 0b1010_0110, 0x80, 0xff] {
            let mask = M8::from_bits(m);
            assert_eq!(mask.bitmask(), m);
            let sel = F8::select(mask, fa, fb).to_array();
            assert!((0..8).all(|i| {
                let want = if m >> i & 1 != 0 { a[i] } else { b[i] };
                sel[i].to_bits() == want.to_bits()
            }));
            let other = M8::from_bits(0b0110_0011);
            assert_eq!(mask.and(other).bitmask(), m & 0b0110_0011);
            assert_eq!(mask.or(other).bitmask(), m | 0b0110_0011);
            assert_eq!(mask.and_not(other).bitmask(), m & !0b0110_0011 & 0xff);
        }
    }
}
