//! HDR images for a self-contained HTML page opened from disk (no fetch, no modules): RGBE
//! pixels (Ward's shared exponent: 8-bit mantissas, about 0.4 % of the largest channel),
//! zlib-compressed and base64-encoded into the page, which inflates them with the browser's
//! `DecompressionStream('deflate')` and tone-maps them on a canvas at any exposure. Films
//! larger than a pixel budget are box-averaged by an integer factor first (still HDR), so an
//! experiment's page stays a few MB.

use crate::film::Image;
use std::io::Write;

/// Ward's RGBE of one linear RGB pixel (negative and non-finite values as 0).
pub fn rgbe(p: [f64; 3]) -> [u8; 4] {
    let c = p.map(|v| if v.is_finite() && v > 0.0 { v } else { 0.0 });
    let m = c[0].max(c[1]).max(c[2]);
    if m < 1e-32 {
        return [0; 4];
    }
    // m = f 2^e with f in [0.5, 1).
    let e = m.log2().floor() as i32 + 1;
    let scale = 256.0 / 2f64.powi(e);
    let q = |v: f64| (v * scale).min(255.0) as u8;
    [q(c[0]), q(c[1]), q(c[2]), (e + 128).clamp(0, 255) as u8]
}

/// The inverse, as the page computes it (mantissa + 0.5, the middle of its step).
pub fn from_rgbe(b: [u8; 4]) -> [f64; 3] {
    if b[3] == 0 {
        return [0.0; 3];
    }
    let f = 2f64.powi(b[3] as i32 - 128 - 8);
    [0, 1, 2].map(|i| (b[i] as f64 + 0.5) * f)
}

/// The smallest integer factor that brings `w` x `h` within `max_pixels`.
pub fn factor(w: u32, h: u32, max_pixels: u64) -> u32 {
    let mut k = 1u32;
    while (w / k) as u64 * (h / k) as u64 > max_pixels.max(1) && k < w.min(h) {
        k += 1;
    }
    k
}

/// `img` box-averaged by `k` (pixels past the last whole block are dropped).
pub fn downsample(img: &Image, k: u32) -> Image {
    if k <= 1 {
        return img.clone();
    }
    let (w, h) = (img.width / k, img.height / k);
    let mut out = Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            let mut s = [0.0f64; 3];
            for dy in 0..k {
                for dx in 0..k {
                    let p = img.get(x * k + dx, y * k + dy);
                    for c in 0..3 {
                        s[c] += p[c];
                    }
                }
            }
            out.set(x, y, s.map(|v| v / (k * k) as f64));
        }
    }
    out
}

/// RGBE bytes of `img`, zlib-compressed, in base64.
pub fn encode(img: &Image) -> String {
    let mut raw = Vec::with_capacity(img.data.len() * 4);
    for p in &img.data {
        raw.extend_from_slice(&rgbe(*p));
    }
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
    z.write_all(&raw).expect("writing to memory");
    base64(&z.finish().expect("writing to memory"))
}

/// Standard base64 with padding.
pub fn base64(b: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(b.len().div_ceil(3) * 4);
    for chunk in b.chunks(3) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &x)| n | (x as u32) << (16 - 8 * i));
        for i in 0..4 {
            if i <= chunk.len() {
                s.push(T[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    #[test]
    fn base64_matches_the_rfc_vectors() {
        for (i, o) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(i.as_bytes()), o);
        }
    }

    #[test]
    fn rgbe_keeps_values_to_its_step_over_a_huge_range() {
        let mut r = crate::rng::Rng::new(3, 0);
        for _ in 0..10_000 {
            let scale = 10f64.powf(r.next_f64() * 20.0 - 10.0);
            let p = [r.next_f64(), r.next_f64(), r.next_f64()].map(|v| v * scale);
            let q = from_rgbe(rgbe(p));
            let m = p[0].max(p[1]).max(p[2]);
            for c in 0..3 {
                // Half a mantissa step of the largest channel, which is at least m / 256.
                assert!((q[c] - p[c]).abs() <= m / 256.0, "{p:?} -> {q:?}");
            }
        }
        assert_eq!(rgbe([0.0; 3]), [0; 4]);
        assert_eq!(rgbe([f64::NAN, -1.0, 0.0]), [0; 4]);
        assert_eq!(
            from_rgbe(rgbe([1.0, 0.5, 0.25])),
            [1.0 + 1.0 / 256.0, 0.5 + 1.0 / 256.0, 0.25 + 1.0 / 256.0]
        );
    }

    #[test]
    fn downsampling_averages_blocks_and_fits_the_budget() {
        let mut img = Image::new(5, 4);
        for y in 0..4 {
            for x in 0..5 {
                img.set(x, y, [(x + 10 * y) as f64, 1.0, 0.0]);
            }
        }
        let d = downsample(&img, 2);
        assert_eq!((d.width, d.height), (2, 2));
        assert_eq!(
            d.get(1, 1),
            [(2.0 + 3.0 + 12.0 + 13.0) / 4.0 + 20.0, 1.0, 0.0]
        );
        assert_eq!(factor(768, 512, 150_000), 2);
        assert_eq!(factor(128, 128, 150_000), 1);
        let k = factor(4000, 3000, 1);
        assert_eq!(((4000 / k), (3000 / k)), (1, 1));
        assert!(
            (4000 / (k - 1)) * (3000 / (k - 1)) > 1,
            "the smallest factor"
        );
    }

    #[test]
    fn encoded_images_inflate_back_to_their_rgbe_bytes() {
        let mut img = Image::new(7, 3);
        for (i, p) in img.data.iter_mut().enumerate() {
            *p = [i as f64 * 0.1, 2.0, 1e-3];
        }
        let b64 = encode(&img);
        let bytes = decode_base64(&b64);
        let mut raw = Vec::new();
        flate2::read::ZlibDecoder::new(&bytes[..])
            .read_to_end(&mut raw)
            .unwrap();
        let want: Vec<u8> = img.data.iter().flat_map(|p| rgbe(*p)).collect();
        assert_eq!(raw, want);
    }

    fn decode_base64(s: &str) -> Vec<u8> {
        let val = |c: u8| match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            _ => 63,
        };
        let mut out = Vec::new();
        for chunk in s.as_bytes().chunks(4) {
            let n = chunk
                .iter()
                .take_while(|&&c| c != b'=')
                .enumerate()
                .fold(0u32, |n, (i, &c)| n | (val(c) as u32) << (18 - 6 * i));
            let len = chunk.iter().filter(|&&c| c != b'=').count() - 1;
            for i in 0..len {
                out.push((n >> (16 - 8 * i)) as u8);
            }
        }
        out
    }
}
