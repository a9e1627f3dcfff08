//! The error-spectrum ensemble (Celarek, Jakob, Wimmer and Lehtinen 2019): the radially
//! averaged power spectrum of a render's error image, averaged over seeds. MSE says how
//! much error there is; the spectrum says how it is spread over the screen: white for
//! independent pixels, rising with frequency (blue noise) when neighbouring pixels'
//! errors cancel, which a viewer sees as finer grain at the same MSE.
//!
//! The error of seed i is its deviation from the mean of the seeds, scaled by
//! sqrt(n / (n - 1)) so that its expected power is the estimator's: no reference is needed
//! and the reference's own noise does not enter.

use super::slope::quantile;
use rustfft::num_complex::Complex;
use rustfft::FftPlanner;

/// Frequencies below this many cycles per pixel (a quarter of Nyquist's 0.5) are "low" in
/// [`Spectrum::low_share`].
pub const LOW: f64 = 0.125;

/// A radially averaged power spectrum, normalised by the MSE, with 95 % bootstrap intervals
/// over the seeds (heavy-tailed errors, a few fireflies, make the spectrum of a few dozen
/// seeds wander far from its expectation, smoothly across neighbouring bins).
#[derive(Clone, Debug)]
pub struct Spectrum {
    /// Bin centres in cycles per pixel, up to 0.5.
    pub freq: Vec<f64>,
    /// Mean power per bin divided by the MSE: 1 everywhere for white noise. (Power is
    /// |DFT|^2 / pixels, whose mean over all frequencies is the MSE, by Parseval.)
    pub power: Vec<f64>,
    /// Per bin, the 95 % bootstrap interval of `power` over seeds.
    pub interval: Vec<(f64, f64)>,
    /// Mean squared error per pixel.
    pub mse: f64,
    /// The share of the error's energy at frequencies below [`LOW`], and its interval.
    pub low_share: f64,
    pub low_interval: (f64, f64),
    /// Seeds averaged.
    pub seeds: usize,
}

/// Bootstrap draws for the intervals.
const DRAWS: usize = 400;

/// The 2D power spectrum |DFT|^2 / (w h) of a `w` x `h` real image, row-major.
fn power_2d(img: &[f64], w: usize, h: usize, planner: &mut FftPlanner<f64>) -> Vec<f64> {
    let mut data: Vec<Complex<f64>> = img.iter().map(|&v| Complex::new(v, 0.0)).collect();
    let rows = planner.plan_fft_forward(w);
    rows.process(&mut data);
    let cols = planner.plan_fft_forward(h);
    let mut col = vec![Complex::new(0.0, 0.0); h];
    for x in 0..w {
        for y in 0..h {
            col[y] = data[y * w + x];
        }
        cols.process(&mut col);
        for y in 0..h {
            data[y * w + x] = col[y];
        }
    }
    let n = (w * h) as f64;
    data.iter().map(|c| c.norm_sqr() / n).collect()
}

/// Radial frequency of DFT index (kx, ky) in cycles per pixel.
fn radius(kx: usize, ky: usize, w: usize, h: usize) -> f64 {
    let f = |k: usize, n: usize| {
        let k = if 2 * k >= n {
            k as f64 - n as f64
        } else {
            k as f64
        };
        k / n as f64
    };
    f(kx, w).hypot(f(ky, h))
}

/// White noise's share of energy below [`LOW`] on a `w` x `h` film: the share of its
/// frequencies that are below it.
pub fn white_low_share(w: usize, h: usize) -> f64 {
    let low = (0..w * h)
        .filter(|&i| radius(i % w, i / w, w, h) < LOW)
        .count();
    low as f64 / (w * h) as f64
}

/// One seed's radial profile: summed power per bin, all power, power below [`LOW`].
struct Profile {
    bins: Vec<f64>,
    total: f64,
    low: f64,
}

/// The error-spectrum ensemble of `seeds` images of `w` x `h` (one value per pixel, e.g. the
/// mean of the channels), at least two.
pub fn error_spectrum(seeds: &[Vec<f64>], w: usize, h: usize) -> Spectrum {
    let n = seeds.len();
    assert!(n >= 2, "an error spectrum needs two seeds");
    let px = w * h;
    let mut mean = vec![0.0; px];
    for s in seeds {
        assert_eq!(s.len(), px, "seed images of one size");
        mean.iter_mut().zip(s).for_each(|(m, v)| *m += v / n as f64);
    }
    let scale = n as f64 / (n as f64 - 1.0);
    let bins = (w.min(h) / 2).max(1);
    let width = 0.5 / bins as f64;
    let bin_of: Vec<(Option<usize>, bool)> = (0..px)
        .map(|i| {
            let r = radius(i % w, i / w, w, h);
            let b = (r / width) as usize;
            ((b < bins).then_some(b), r < LOW)
        })
        .collect();
    let mut count = vec![0usize; bins];
    bin_of
        .iter()
        .filter_map(|b| b.0)
        .for_each(|b| count[b] += 1);
    let mut planner = FftPlanner::new();
    let profiles: Vec<Profile> = seeds
        .iter()
        .map(|s| {
            let e: Vec<f64> = s.iter().zip(&mean).map(|(v, m)| v - m).collect();
            let mut p = Profile {
                bins: vec![0.0; bins],
                total: 0.0,
                low: 0.0,
            };
            for (pw, (b, low)) in power_2d(&e, w, h, &mut planner).iter().zip(&bin_of) {
                let pw = pw * scale;
                p.total += pw;
                if *low {
                    p.low += pw;
                }
                if let Some(b) = b {
                    p.bins[*b] += pw;
                }
            }
            p
        })
        .collect();
    // The statistics of a set of seeds (indices into `profiles`, repeats allowed).
    let stats = |pick: &mut dyn Iterator<Item = usize>| -> (Vec<f64>, f64, f64) {
        let (mut b, mut total, mut low) = (vec![0.0; bins], 0.0, 0.0);
        for i in pick {
            let p = &profiles[i];
            b.iter_mut().zip(&p.bins).for_each(|(a, v)| *a += v);
            total += p.total;
            low += p.low;
        }
        let mse_px = total / px as f64;
        let norm: Vec<f64> = (0..bins)
            .map(|k| match count[k] > 0 && total > 0.0 {
                true => b[k] / count[k] as f64 / mse_px,
                false => f64::NAN,
            })
            .collect();
        (norm, if total > 0.0 { low / total } else { 0.0 }, total)
    };
    let (power, low_share, total) = stats(&mut (0..n));
    let mut rng = crate::rng::Rng::new(0x5bec, n as u64);
    let mut draws_bins: Vec<Vec<f64>> = vec![Vec::with_capacity(DRAWS); bins];
    let mut draws_low = Vec::with_capacity(DRAWS);
    for _ in 0..DRAWS {
        let mut pick = (0..n).map(|_| ((rng.next_f32() as f64 * n as f64) as usize).min(n - 1));
        let (p, low, _) = stats(&mut pick);
        draws_bins.iter_mut().zip(p).for_each(|(d, v)| d.push(v));
        draws_low.push(low);
    }
    let interval = |d: &mut Vec<f64>| -> (f64, f64) {
        d.retain(|v| v.is_finite());
        if d.is_empty() {
            return (f64::NAN, f64::NAN);
        }
        d.sort_by(f64::total_cmp);
        (quantile(d, 0.025), quantile(d, 0.975))
    };
    let keep: Vec<usize> = (0..bins).filter(|&k| count[k] > 0).collect();
    Spectrum {
        freq: keep.iter().map(|&k| (k as f64 + 0.5) * width).collect(),
        power: keep.iter().map(|&k| power[k]).collect(),
        interval: keep.iter().map(|&k| interval(&mut draws_bins[k])).collect(),
        mse: total / n as f64 / px as f64,
        low_share,
        low_interval: interval(&mut draws_low),
        seeds: n,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn noise(rng: &mut Rng, px: usize) -> Vec<f64> {
        // Uniform on [-1, 1): variance 1/3.
        (0..px).map(|_| 2.0 * rng.next_f32() as f64 - 1.0).collect()
    }

    /// Parseval: the MSE is the noise's variance (deviations scaled by n / (n - 1)); white
    /// noise has a flat spectrum (1 after dividing by the MSE), each bin's interval holding it,
    /// and a low-frequency share equal to the share of frequencies that are low.
    #[test]
    fn white_noise_is_flat_at_its_variance() {
        let (w, h) = (48, 32);
        let mut rng = Rng::new(1, 0);
        let seeds: Vec<Vec<f64>> = (0..64).map(|_| noise(&mut rng, w * h)).collect();
        let s = error_spectrum(&seeds, w, h);
        assert!((s.mse / (1.0 / 3.0) - 1.0).abs() < 0.03, "mse {}", s.mse);
        for ((f, p), (lo, hi)) in s.freq.iter().zip(&s.power).zip(&s.interval) {
            assert!((p - 1.0).abs() < 0.25, "{f}: {p}");
            assert!(lo <= p && p <= hi && hi - lo < 1.0, "{f}: {lo}..{hi}");
        }
        assert!(s.low_interval.0 <= s.low_share && s.low_share <= s.low_interval.1);
        let expected = white_low_share(w, h);
        assert!(
            (s.low_share / expected - 1.0).abs() < 0.2,
            "{}",
            s.low_share
        );
    }

    /// Differences of neighbours (blue noise: e_x = u_x - u_{x-1}) put the error at high
    /// frequencies, the running means of neighbours (e_x = u_x + u_{x-1}) at low ones; both
    /// have the same MSE. A constant offset per seed is all at frequency 0.
    #[test]
    fn correlated_errors_move_energy_between_frequencies() {
        let (w, h) = (32, 32);
        let mut rng = Rng::new(2, 0);
        let mut blue = Vec::new();
        let mut red = Vec::new();
        let mut offset = Vec::new();
        for _ in 0..32 {
            let u = noise(&mut rng, w * h);
            let shifted = |i: usize| u[(i / w) * w + (i % w + w - 1) % w];
            blue.push((0..w * h).map(|i| u[i] - shifted(i)).collect::<Vec<_>>());
            red.push((0..w * h).map(|i| u[i] + shifted(i)).collect::<Vec<_>>());
            offset.push(vec![2.0 * rng.next_f32() as f64 - 1.0; w * h]);
        }
        let (b, r, o) = (
            error_spectrum(&blue, w, h),
            error_spectrum(&red, w, h),
            error_spectrum(&offset, w, h),
        );
        assert!((b.mse / r.mse - 1.0).abs() < 0.1, "{} {}", b.mse, r.mse);
        assert!(
            b.low_share < 0.5 * r.low_share,
            "{} {}",
            b.low_share,
            r.low_share
        );
        assert!(b.power[0] < b.power[b.power.len() - 1]);
        assert!(r.power[0] > r.power[r.power.len() - 1]);
        assert!((o.low_share - 1.0).abs() < 1e-9 && o.power[1..].iter().all(|p| *p < 1e-20));
    }
}
