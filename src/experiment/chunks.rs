//! Long reference renders in fixed chunks of samples, merged per pixel in f64, with a
//! checkpoint after each chunk so that a killed run resumes where it stopped.
//!
//! The chunks are fixed by the sample count alone ([`CHUNK_SPP`] samples each, the last one
//! shorter), each renders its own range of the per-pixel sample streams
//! (`RenderSettings::first_sample`), and they are merged in chunk order by Chan et al.'s
//! pairwise formula: the result is bitwise the same whether the run was interrupted or not,
//! and for any thread count. A reference of at most one chunk is the plain render.

use crate::film::Image;
use crate::integrator::Strategy;
use crate::render::{render, RenderOutput, RenderSettings};
use crate::scene::Scene;
use std::path::{Path, PathBuf};

/// Samples per pixel of one chunk.
pub const CHUNK_SPP: u32 = 1024;

/// Per-pixel, per-channel count, mean and sum of squared deviations (M2), in f64.
#[derive(Clone, Debug, PartialEq)]
pub struct Accum {
    pub width: u32,
    pub height: u32,
    pub n: u64,
    pub mean: Vec<[f64; 3]>,
    pub m2: Vec<[f64; 3]>,
    pub seconds: f64,
    pub non_finite_samples: u64,
}

impl Accum {
    /// The statistics of one render (its variance image is the variance of the mean).
    pub fn of(out: &RenderOutput) -> Self {
        let n = out.spp as f64;
        Accum {
            width: out.mean.width,
            height: out.mean.height,
            n: out.spp as u64,
            mean: out.mean.data.clone(),
            m2: out
                .variance
                .data
                .iter()
                .map(|v| v.map(|v| v * n * (n - 1.0)))
                .collect(),
            seconds: out.seconds,
            non_finite_samples: out.non_finite_samples,
        }
    }

    /// Chan, Golub and LeVeque's pairwise update: `self` followed by `other`.
    pub fn merge(&mut self, other: &Accum) {
        assert_eq!((self.width, self.height), (other.width, other.height));
        let (na, nb) = (self.n as f64, other.n as f64);
        let n = na + nb;
        for ((ma, m2a), (mb, m2b)) in self
            .mean
            .iter_mut()
            .zip(&mut self.m2)
            .zip(other.mean.iter().zip(&other.m2))
        {
            for c in 0..3 {
                let delta = mb[c] - ma[c];
                ma[c] += delta * nb / n;
                m2a[c] += m2b[c] + delta * delta * na * nb / n;
            }
        }
        self.n += other.n;
        self.seconds += other.seconds;
        self.non_finite_samples += other.non_finite_samples;
    }

    /// Mean and variance-of-the-mean images.
    pub fn images(&self) -> (Image, Image) {
        let n = self.n as f64;
        let mean = Image {
            width: self.width,
            height: self.height,
            data: self.mean.clone(),
        };
        let variance = Image {
            width: self.width,
            height: self.height,
            data: self
                .m2
                .iter()
                .map(|m| m.map(|m| if n > 1.0 { m / (n - 1.0) / n } else { 0.0 }))
                .collect(),
        };
        (mean, variance)
    }
}

const MAGIC: &[u8; 8] = b"DLCHUNK1";

/// The checkpoint file of the reference stored under `key`.
pub fn checkpoint_path(dir: &Path, key: &str) -> PathBuf {
    dir.join(format!("reference-{key}.partial"))
}

impl Accum {
    /// Appends the film size, counts and the f64 statistics, little-endian.
    pub fn encode(&self, b: &mut Vec<u8>) {
        for v in [self.width as u64, self.height as u64, self.n] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(&self.seconds.to_le_bytes());
        b.extend_from_slice(&self.non_finite_samples.to_le_bytes());
        for p in self.mean.iter().chain(&self.m2) {
            for v in p {
                b.extend_from_slice(&v.to_le_bytes());
            }
        }
    }

    /// Reads what [`Accum::encode`] wrote from `r`; None if it is cut short or the film is
    /// implausibly large for the bytes there.
    pub fn decode(r: &mut Reader) -> Option<Accum> {
        let (w, h, n) = (r.u64()?, r.u64()?, r.u64()?);
        let seconds = f64::from_bits(r.u64()?);
        let non_finite_samples = r.u64()?;
        let pixels = w.checked_mul(h)? as usize;
        if pixels.checked_mul(48)? > r.left() {
            return None;
        }
        let mut read = || -> Option<Vec<[f64; 3]>> {
            (0..pixels)
                .map(|_| Some([r.f64()?, r.f64()?, r.f64()?]))
                .collect()
        };
        let mean = read()?;
        let m2 = read()?;
        Some(Accum {
            width: u32::try_from(w).ok()?,
            height: u32::try_from(h).ok()?,
            n,
            mean,
            m2,
            seconds,
            non_finite_samples,
        })
    }
}

impl Accum {
    /// Checks what no render can produce: a mean that is not finite (non-finite samples are
    /// counted and left out), a negative or non-finite sum of squares, a negative time. Names
    /// the first bad pixel.
    pub fn check_values(&self) -> Result<(), String> {
        if !(self.seconds.is_finite() && self.seconds >= 0.0) {
            return Err(format!("its time {} s is not a duration", self.seconds));
        }
        let w = self.width.max(1) as usize;
        for (i, (m, m2)) in self.mean.iter().zip(&self.m2).enumerate() {
            let ok =
                m.iter().all(|v| v.is_finite()) && m2.iter().all(|v| v.is_finite() && *v >= 0.0);
            if !ok {
                return Err(format!(
                    "pixel ({}, {}) holds mean {m:?} and sum of squares {m2:?}; a render gives \
                     finite means and non-negative sums",
                    i % w,
                    i / w
                ));
            }
        }
        Ok(())
    }
}

/// A cursor over little-endian bytes.
pub struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    pub fn new(b: &'a [u8]) -> Self {
        Reader { b, at: 0 }
    }

    pub fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let s = self.b.get(self.at..self.at.checked_add(n)?)?;
        self.at += n;
        Some(s)
    }

    pub fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }

    pub fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }

    pub fn f64(&mut self) -> Option<f64> {
        self.u64().map(f64::from_bits)
    }

    /// A u32-length-prefixed byte string.
    pub fn bytes(&mut self) -> Option<&'a [u8]> {
        let n = self.u32()? as usize;
        self.take(n)
    }

    /// Bytes not read yet.
    pub fn left(&self) -> usize {
        self.b.len() - self.at
    }
}

/// Appends a u32-length-prefixed byte string.
pub fn put_bytes(b: &mut Vec<u8>, s: &[u8]) {
    b.extend_from_slice(&(s.len() as u32).to_le_bytes());
    b.extend_from_slice(s);
}

/// Writes `acc` after `chunks` chunks (atomically: a checkpoint is whole or absent). A
/// finished reference keeps its statistics in the same format (`cache::stats_path`).
pub fn save(path: &Path, key: &str, chunks: u32, acc: &Accum) -> Result<(), String> {
    let mut b = Vec::with_capacity(64 + acc.mean.len() * 48);
    b.extend_from_slice(MAGIC);
    put_bytes(&mut b, key.as_bytes());
    b.extend_from_slice(&(chunks as u64).to_le_bytes());
    acc.encode(&mut b);
    crate::output::write_atomic(path, |tmp| {
        std::fs::write(tmp, &b).map_err(|e| format!("{}: {e}", path.display()))
    })
}

/// The checkpoint at `path` if it is one of `key` for a `width` x `height` film; anything
/// else (absent, another key, truncated) is None and the render starts over.
fn load(path: &Path, key: &str, width: u32, height: u32) -> Option<(u32, Accum)> {
    let b = std::fs::read(path).ok()?;
    let mut r = Reader::new(&b);
    if r.take(8)? != MAGIC || r.bytes()? != key.as_bytes() {
        return None;
    }
    let chunks = r.u64()?;
    let acc = Accum::decode(&mut r)?;
    if (acc.width, acc.height) != (width, height) || r.left() != 0 {
        return None;
    }
    Some((u32::try_from(chunks).ok()?, acc))
}

/// The fixed chunks of a reference of `spp` samples per pixel: (first sample, spp) each, in
/// merge order. A plain run and every shard of a cluster run cut the same chunks.
pub fn chunk_ranges(spp: u32) -> Vec<(u64, u32)> {
    (0..spp.div_ceil(CHUNK_SPP) as u64)
        .map(|k| {
            let first = k * CHUNK_SPP as u64;
            (first, (spp as u64 - first).min(CHUNK_SPP as u64) as u32)
        })
        .collect()
}

/// Renders one chunk: samples `first .. first + spp` of every pixel's stream.
pub fn render_chunk(
    scene: &Scene,
    strategy: Strategy,
    seed: u64,
    (first, spp): (u64, u32),
    threads: Option<usize>,
    progress: bool,
) -> Accum {
    Accum::of(&render(
        scene,
        strategy,
        &RenderSettings {
            spp,
            seed,
            first_sample: first,
            threads,
            progress: crate::progress::tiles(progress),
            // References draw independent samples: their chunks merge as independent
            // estimates whatever the sweep's samplers.
            sampling: Default::default(),
        },
    ))
}

/// What a chunked reference render needs.
pub struct ChunkedRender<'a> {
    pub scene: &'a Scene,
    pub strategy: Strategy,
    pub spp: u32,
    pub seed: u64,
    pub threads: Option<usize>,
    pub progress: bool,
    /// Names the checkpoint; a checkpoint of another key is ignored.
    pub key: &'a str,
}

/// Renders `spp` samples per pixel in chunks, resuming from the checkpoint in `dir` if one
/// is there, and removes the checkpoint when done.
pub fn render_chunked(dir: &Path, r: &ChunkedRender) -> Result<Accum, String> {
    let (w, h) = (r.scene.camera.width, r.scene.camera.height);
    let ranges = chunk_ranges(r.spp);
    let chunks = ranges.len() as u32;
    let path = checkpoint_path(dir, r.key);
    let (mut done, mut acc) = match load(&path, r.key, w, h) {
        Some((k, acc)) if k < chunks => {
            eprintln!(
                "resuming the reference from its checkpoint: {k} of {chunks} chunks of {CHUNK_SPP} spp done"
            );
            (k, Some(acc))
        }
        _ => (0, None),
    };
    for &range in &ranges[done as usize..] {
        let chunk = render_chunk(r.scene, r.strategy, r.seed, range, r.threads, r.progress);
        match &mut acc {
            Some(a) => a.merge(&chunk),
            None => acc = Some(chunk),
        }
        done += 1;
        if done < chunks {
            save(&path, r.key, done, acc.as_ref().expect("set above"))?;
        }
    }
    let _ = std::fs::remove_file(&path);
    Ok(acc.expect("at least one chunk: spp >= 1"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::fixtures;

    fn scratch(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("directlab-chunks-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// Chan's merge of two halves equals the one-pass statistics of the whole, to rounding.
    #[test]
    fn merge_matches_one_pass_statistics() {
        let xs: Vec<f64> = (0..37)
            .map(|i| ((i * 7919) % 101) as f64 * 0.37 + 1e3)
            .collect();
        let acc_of = |x: &[f64]| {
            let n = x.len() as f64;
            let m = x.iter().sum::<f64>() / n;
            let m2 = x.iter().map(|v| (v - m) * (v - m)).sum::<f64>();
            Accum {
                width: 1,
                height: 1,
                n: x.len() as u64,
                mean: vec![[m; 3]],
                m2: vec![[m2; 3]],
                seconds: 1.0,
                non_finite_samples: 1,
            }
        };
        let mut a = acc_of(&xs[..13]);
        a.merge(&acc_of(&xs[13..]));
        let whole = acc_of(&xs);
        assert_eq!(a.n, 37);
        assert!((a.mean[0][0] - whole.mean[0][0]).abs() < 1e-12 * whole.mean[0][0]);
        assert!((a.m2[0][1] - whole.m2[0][1]).abs() < 1e-9 * whole.m2[0][1]);
        assert_eq!((a.seconds, a.non_finite_samples), (2.0, 2));
    }

    /// A run stopped after its first chunk (its checkpoint left as a kill would leave it)
    /// resumes from it and ends bitwise where an uninterrupted run ends; a checkpoint of
    /// another key is ignored; none is left behind.
    #[test]
    fn resumed_render_is_bitwise_the_uninterrupted_one() {
        use glam::Vec3;
        let tri = [
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::new(1.0, -1.0, 1.0),
        ];
        let scene = Scene::build(fixtures::triangle_over_floor(
            tri,
            2.0,
            0.5,
            Vec3::ZERO,
            0.5,
        ))
        .unwrap();
        let strategy = Strategy::combinations()[1];
        let spp = CHUNK_SPP + 40;
        let req = |key| ChunkedRender {
            scene: &scene,
            strategy,
            spp,
            seed: 3,
            threads: Some(2),
            progress: false,
            key,
        };
        let dir = scratch("resume");
        let whole = render_chunked(&dir, &req("k")).unwrap();
        assert_eq!(whole.n, spp as u64);
        assert!(whole.m2[0][0] > 0.0, "the pixel must vary: {whole:?}");
        assert!(!checkpoint_path(&dir, "k").exists());

        // The state after chunk 1, saved as the run would have saved it.
        let first = Accum::of(&render(
            &scene,
            strategy,
            &RenderSettings {
                spp: CHUNK_SPP,
                seed: 3,
                first_sample: 0,
                threads: Some(1),
                progress: None,
                sampling: Default::default(),
            },
        ));
        // Marked by its time, so that the resumed run shows it started from the checkpoint.
        let marked = Accum {
            seconds: 1e6,
            ..first.clone()
        };
        save(&checkpoint_path(&dir, "k"), "k", 1, &marked).unwrap();
        let resumed = render_chunked(&dir, &req("k")).unwrap();
        assert!(
            resumed.seconds >= 1e6,
            "the checkpoint was not resumed from"
        );
        assert_eq!(resumed.mean, whole.mean);
        assert_eq!(resumed.m2, whole.m2);
        assert!(!checkpoint_path(&dir, "k").exists());

        // Another key's checkpoint, and a truncated one, are not resumed from.
        save(&checkpoint_path(&dir, "other"), "other", 1, &first).unwrap();
        std::fs::rename(checkpoint_path(&dir, "other"), checkpoint_path(&dir, "k")).unwrap();
        assert!(load(&checkpoint_path(&dir, "k"), "k", 1, 1).is_none());
        save(&checkpoint_path(&dir, "k"), "k", 1, &first).unwrap();
        let b = std::fs::read(checkpoint_path(&dir, "k")).unwrap();
        std::fs::write(checkpoint_path(&dir, "k"), &b[..b.len() - 8]).unwrap();
        let (w, h) = (scene.camera.width, scene.camera.height);
        assert!(load(&checkpoint_path(&dir, "k"), "k", w, h).is_none());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
