//! Welch's t-test between two noisy images, per pixel or per tile (Jung, Hanika and
//! Dachsbacher 2020): finds a bias of one render against another with no reference.
//!
//! Each side gives, per pixel and channel, a mean, the variance of that mean and the count of
//! independent samples behind it: either one render's per-pixel variance and its spp (for
//! independent samples only), or several seeds' images (the seeds are the samples, which is
//! right for correlated samplers too). Averaging pixels into tiles raises the power against
//! smooth biases. The family of tests is judged at a Sidak-corrected level.

use super::ttest::{sidak, welch, Group};

/// One side of the comparison on a `width` x `height` film, three channels.
#[derive(Clone, Debug)]
pub struct Side {
    pub width: usize,
    pub height: usize,
    /// Per pixel, per channel: the mean.
    pub mean: Vec<[f64; 3]>,
    /// Per pixel, per channel: the variance of the mean.
    pub var_mean: Vec<[f64; 3]>,
    /// Independent samples behind each mean.
    pub n: u64,
    /// Per seed images, kept so tiles average each seed before taking a variance (which is
    /// right whatever the correlation between pixels); empty for a render with variances.
    pub seeds: Vec<Vec<[f64; 3]>>,
}

impl Side {
    /// Several seeds' images of one configuration (at least two).
    pub fn from_seeds(width: usize, height: usize, seeds: Vec<Vec<[f64; 3]>>) -> Side {
        let n = seeds.len();
        assert!(n >= 2, "a variance needs two seeds");
        let (mean, var_mean) = moments(&seeds, width * height);
        Side {
            width,
            height,
            mean,
            var_mean,
            n: n as u64,
            seeds,
        }
    }

    /// The side averaged over `k` x `k` tiles (the last row and column of tiles may be
    /// smaller).
    pub fn tiled(&self, k: usize) -> Side {
        let k = k.max(1);
        let (tw, th) = (self.width.div_ceil(k), self.height.div_ceil(k));
        let average = |img: &[[f64; 3]], square: bool| -> Vec<[f64; 3]> {
            let mut out = vec![[0.0; 3]; tw * th];
            let mut count = vec![0.0; tw * th];
            for y in 0..self.height {
                for x in 0..self.width {
                    let t = (y / k) * tw + x / k;
                    for c in 0..3 {
                        out[t][c] += img[y * self.width + x][c];
                    }
                    count[t] += 1.0;
                }
            }
            for (o, n) in out.iter_mut().zip(count) {
                // The mean of n pixels; its variance (independent pixels) is sum / n^2.
                let d = if square { n * n } else { n };
                o.iter_mut().for_each(|v| *v /= d);
            }
            out
        };
        if self.seeds.is_empty() {
            Side {
                width: tw,
                height: th,
                mean: average(&self.mean, false),
                var_mean: average(&self.var_mean, true),
                n: self.n,
                seeds: Vec::new(),
            }
        } else {
            let seeds: Vec<Vec<[f64; 3]>> = self.seeds.iter().map(|s| average(s, false)).collect();
            Side::from_seeds(tw, th, seeds)
        }
    }
}

/// Per pixel and channel, the mean of the seeds and the variance of that mean.
fn moments(seeds: &[Vec<[f64; 3]>], pixels: usize) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let n = seeds.len() as f64;
    let mut mean = vec![[0.0; 3]; pixels];
    for s in seeds {
        for (m, p) in mean.iter_mut().zip(s) {
            for c in 0..3 {
                m[c] += p[c] / n;
            }
        }
    }
    let mut var = vec![[0.0; 3]; pixels];
    for s in seeds {
        for ((v, m), p) in var.iter_mut().zip(&mean).zip(s) {
            for c in 0..3 {
                v[c] += (p[c] - m[c]).powi(2) / (n - 1.0) / n;
            }
        }
    }
    (mean, var)
}

/// The tests of two sides on the same grid.
#[derive(Clone, Debug)]
pub struct WelchMap {
    pub width: usize,
    pub height: usize,
    /// Per unit (pixel or tile), per channel: the two-sided p-value; NaN where the unit is
    /// excluded (a non-finite value on either side).
    pub p: Vec<[f64; 3]>,
    /// Per unit, per channel: (mean A - mean B).
    pub diff: Vec<[f64; 3]>,
    /// Per unit, per channel: mean B (for relative differences).
    pub mean_b: Vec<[f64; 3]>,
    /// Units with a non-finite input on either side (their channels are not tested).
    pub nonfinite: usize,
    /// Unit channels constant on both sides (zero variance: a light seen directly, a black
    /// pixel) and equal: no evidence either way, so not tested (unequal constants are p 0).
    pub constant: usize,
    /// Per unit: a tested channel had one side constant (zero variance) and the other not.
    /// Its variance is then unknown, not zero: at low counts a heavy-tailed side (BSDF
    /// sampling of a small light) often shows no hit at all, so such a unit's p-value alone
    /// is no evidence of bias.
    pub one_sided: Vec<bool>,
}

impl WelchMap {
    /// Welch's test per unit and channel. The sides must share their grid.
    pub fn new(a: &Side, b: &Side) -> WelchMap {
        assert_eq!((a.width, a.height), (b.width, b.height), "different grids");
        let mut p = Vec::with_capacity(a.mean.len());
        let mut diff = Vec::with_capacity(a.mean.len());
        let (mut nonfinite, mut constant) = (0, 0);
        let mut one_sided = Vec::with_capacity(a.mean.len());
        for i in 0..a.mean.len() {
            let (mut bad, mut one) = (false, false);
            let mut pi = [f64::NAN; 3];
            let mut di = [f64::NAN; 3];
            for c in 0..3 {
                let (ma, va, mb, vb) = (
                    a.mean[i][c],
                    a.var_mean[i][c],
                    b.mean[i][c],
                    b.var_mean[i][c],
                );
                if !(ma.is_finite() && va.is_finite() && mb.is_finite() && vb.is_finite()) {
                    bad = true;
                    continue;
                }
                di[c] = ma - mb;
                if va == 0.0 && vb == 0.0 && ma == mb {
                    constant += 1;
                    continue;
                }
                one |= (va == 0.0) != (vb == 0.0);
                // Groups of n samples whose mean has variance v: sample variance v n.
                let ga = Group {
                    mean: ma,
                    variance: va * a.n as f64,
                    n: a.n,
                };
                let gb = Group {
                    mean: mb,
                    variance: vb * b.n as f64,
                    n: b.n,
                };
                pi[c] = welch(ga, gb).p_value;
            }
            nonfinite += bad as usize;
            one_sided.push(one);
            p.push(pi);
            diff.push(di);
        }
        WelchMap {
            width: a.width,
            height: a.height,
            p,
            diff,
            mean_b: b.mean.clone(),
            nonfinite,
            constant,
            one_sided,
        }
    }

    /// The p-values of every unit and channel that was tested.
    pub fn p_values(&self) -> Vec<f64> {
        self.p
            .iter()
            .flatten()
            .copied()
            .filter(|p| !p.is_nan())
            .collect()
    }

    /// Units excluded (a channel with a non-finite input).
    pub fn excluded(&self) -> usize {
        self.nonfinite
    }

    /// The per-test level that keeps the whole map at `alpha` (Sidak over every test).
    pub fn level(&self, alpha: f64) -> f64 {
        sidak(alpha, self.p_values().len().max(1))
    }

    /// Per unit, the smallest p-value of its tested channels (NaN when none was tested).
    pub fn min_p(&self) -> Vec<f64> {
        self.p
            .iter()
            .map(|p| {
                let tested = p.iter().copied().filter(|x| !x.is_nan());
                tested.fold(f64::NAN, |m, x| if m.is_nan() { x } else { m.min(x) })
            })
            .collect()
    }

    /// Connected regions (4-neighbours) of units significant at `level`, largest first:
    /// (units, bounding box [x0, y0, x1, y1] in units, mean relative difference A / B - 1).
    pub fn regions(&self, level: f64) -> Vec<Region> {
        let sig: Vec<bool> = self.min_p().iter().map(|p| *p < level).collect();
        let mut seen = vec![false; sig.len()];
        let mut out = Vec::new();
        for start in 0..sig.len() {
            if !sig[start] || seen[start] {
                continue;
            }
            let mut stack = vec![start];
            seen[start] = true;
            let mut r = Region {
                units: 0,
                bbox: [usize::MAX, usize::MAX, 0, 0],
                rel_diff: 0.0,
                one_sided: true,
            };
            let (mut sum_d, mut sum_b) = (0.0, 0.0);
            while let Some(i) = stack.pop() {
                let (x, y) = (i % self.width, i / self.width);
                r.units += 1;
                r.one_sided &= self.one_sided[i];
                r.bbox = [
                    r.bbox[0].min(x),
                    r.bbox[1].min(y),
                    r.bbox[2].max(x),
                    r.bbox[3].max(y),
                ];
                sum_d += self.diff[i].iter().sum::<f64>();
                sum_b += self.mean_b[i].iter().sum::<f64>();
                let mut push = |j: usize| {
                    if sig[j] && !seen[j] {
                        seen[j] = true;
                        stack.push(j);
                    }
                };
                if x > 0 {
                    push(i - 1);
                }
                if x + 1 < self.width {
                    push(i + 1);
                }
                if y > 0 {
                    push(i - self.width);
                }
                if y + 1 < self.height {
                    push(i + self.width);
                }
            }
            r.rel_diff = if sum_b != 0.0 {
                sum_d / sum_b
            } else {
                f64::NAN
            };
            out.push(r);
        }
        out.sort_by_key(|r| std::cmp::Reverse(r.units));
        out
    }
}

/// A connected region of significant units.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    pub units: usize,
    /// [x0, y0, x1, y1], inclusive, in units (pixels or tiles).
    pub bbox: [usize; 4],
    /// Sum over the region of (A - B) over the sum of B (NaN where B sums to 0).
    pub rel_diff: f64,
    /// Every unit of the region is one-sided (see [`WelchMap::one_sided`]).
    pub one_sided: bool,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// `seeds` images of `w` x `h` whose pixels are `value(x, y)` plus unit-variance noise
    /// scaled by `sd`.
    fn images(
        rng: &mut Rng,
        seeds: usize,
        (w, h): (usize, usize),
        value: impl Fn(usize, usize) -> f64,
        sd: f64,
    ) -> Vec<Vec<[f64; 3]>> {
        let mut normal = || {
            let (u1, u2) = (1.0 - rng.next_f64(), rng.next_f64());
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        };
        (0..seeds)
            .map(|_| {
                (0..w * h)
                    .map(|i| {
                        let v = value(i % w, i / w);
                        [v + sd * normal(), v + sd * normal(), v + sd * normal()]
                    })
                    .collect()
            })
            .collect()
    }

    /// Two sides of the same image: p-values uniform (KS against uniform at 0.01 over 3072
    /// tests) and, at the Sidak level, no detection; alpha 0.01.
    #[test]
    fn equal_sides_give_uniform_p_values_and_no_detection() {
        let mut rng = Rng::new(1, 0);
        let size = (32, 32);
        let a = Side::from_seeds(
            32,
            32,
            images(&mut rng, 8, size, |x, _| 1.0 + x as f64, 0.3),
        );
        let b = Side::from_seeds(
            32,
            32,
            images(&mut rng, 6, size, |x, _| 1.0 + x as f64, 0.5),
        );
        let m = WelchMap::new(&a, &b);
        let mut p = m.p_values();
        p.sort_by(f64::total_cmp);
        let d = crate::stats::ks_uniform(&p);
        assert!(
            crate::stats::ks_p_value(d, p.len()) > 0.01,
            "KS distance {d}"
        );
        assert!(m.regions(m.level(0.01)).is_empty());
        assert_eq!(m.excluded(), 0);
    }

    /// A 3 % bias in an 8 x 8 corner, invisible per pixel at this noise, is found by 8 x 8
    /// tiles at the Sidak level, with its relative difference.
    #[test]
    fn tiles_find_a_small_bias_in_a_region() {
        let mut rng = Rng::new(2, 0);
        let size = (32, 32);
        let biased = |x: usize, y: usize| if x < 8 && y < 8 { 1.03 } else { 1.0 };
        let a = Side::from_seeds(32, 32, images(&mut rng, 8, size, biased, 0.1));
        let b = Side::from_seeds(32, 32, images(&mut rng, 8, size, |_, _| 1.0, 0.1));
        let px = WelchMap::new(&a, &b);
        assert!(
            px.regions(px.level(0.01)).len() <= 1,
            "per pixel: barely any power"
        );
        let tiles = WelchMap::new(&a.tiled(8), &b.tiled(8));
        let r = tiles.regions(tiles.level(0.01));
        assert_eq!(r.len(), 1, "{r:?}");
        assert_eq!((r[0].units, r[0].bbox), (1, [0, 0, 0, 0]));
        assert!((r[0].rel_diff - 0.03).abs() < 0.01, "{}", r[0].rel_diff);
    }

    /// A render's per-pixel variances tile by sum / n^2: the tile test of two renders with
    /// variances equals the test of their seeds' tiles when the pixels are independent.
    #[test]
    fn tiled_variances_match_tiled_seeds_for_independent_pixels() {
        let mut rng = Rng::new(3, 0);
        let s = Side::from_seeds(16, 16, images(&mut rng, 4000, (16, 16), |_, _| 2.0, 1.0));
        let as_render = Side {
            seeds: Vec::new(),
            ..s.clone()
        };
        let (t1, t2) = (s.tiled(4), as_render.tiled(4));
        for (v1, v2) in t1.var_mean.iter().zip(&t2.var_mean) {
            assert!((v1[0] / v2[0] - 1.0).abs() < 0.15, "{v1:?} vs {v2:?}");
        }
    }

    /// Channels constant and equal on both sides carry no evidence: not tested, counted.
    #[test]
    fn equal_constants_are_not_tested() {
        let a = Side::from_seeds(2, 1, vec![vec![[1.0, 0.0, 2.0]; 2]; 3]);
        let mut b = a.clone();
        b.mean[1][2] = 3.0;
        let m = WelchMap::new(&a, &b);
        assert_eq!(m.constant, 5, "five equal constants");
        assert_eq!(
            m.p_values(),
            vec![0.0],
            "unequal constants are certainly different"
        );
    }

    #[test]
    fn non_finite_inputs_are_excluded_not_tested() {
        let mut rng = Rng::new(4, 0);
        let mut seeds = images(&mut rng, 3, (4, 4), |_, _| 1.0, 0.1);
        seeds[1][5][2] = f64::NAN;
        let a = Side::from_seeds(4, 4, seeds);
        let b = Side::from_seeds(4, 4, images(&mut rng, 3, (4, 4), |_, _| 1.0, 0.1));
        let m = WelchMap::new(&a, &b);
        assert_eq!(m.excluded(), 1);
        assert_eq!(m.p_values().len(), 16 * 3 - 1);
        assert!(m.p[5][2].is_nan() && !m.min_p()[5].is_nan());
    }

    /// A side that never saw a rare contribution (all seeds 0) against one that did: the
    /// tile is significant but one-sided, and so is its region; a shift where both sides
    /// vary is not.
    #[test]
    fn a_side_of_equal_seeds_makes_its_region_one_sided() {
        let mut rng = Rng::new(5, 0);
        let rare = Side::from_seeds(4, 4, images(&mut rng, 4, (4, 4), |_, _| 5.0, 0.5));
        let zero = Side::from_seeds(4, 4, vec![vec![[0.0; 3]; 16]; 4]);
        let m = WelchMap::new(&rare, &zero);
        assert!(m.one_sided.iter().all(|x| *x));
        let r = m.regions(m.level(0.01));
        assert!(
            r.len() == 1 && r[0].one_sided && r[0].rel_diff.is_nan(),
            "{r:?}"
        );
        let shifted = Side::from_seeds(4, 4, images(&mut rng, 4, (4, 4), |_, _| 3.0, 0.5));
        let m = WelchMap::new(&rare, &shifted);
        let r = m.regions(m.level(0.01));
        assert!(!m.one_sided.iter().any(|x| *x));
        assert!(!r.is_empty() && !r[0].one_sided, "{r:?}");
    }
}
