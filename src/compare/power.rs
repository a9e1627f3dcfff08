//! `directlab compare-power`: how small a bias `compare` finds. Renders a configuration
//! twice per trial (independent seeds), scales side B by 1 + b in a square region, and
//! counts how often the test says "biased" at each spp and bias; b = 0 gives the false
//! alarm rate. A table with Wilson 95 % intervals on every rate, and `power.csv`.

use super::{sides, test, Outcome};
use crate::render_cmd::RenderArgs;
use crate::stats::welch_map::Side;
use std::fmt::Write;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct PowerArgs {
    /// The configuration: a scene and `directlab render`'s options as one string, without
    /// --spp ("scenes/cbox/cbox.xml -D res=64 --strategy mis").
    pub render: String,
    /// Samples per pixel of each seed's render (comma-separated).
    #[arg(long, value_delimiter = ',', default_values_t = [16u32, 64, 256],
          value_parser = crate::limits::parse_spp)]
    pub spp: Vec<u32>,
    /// Relative biases put into side B's region (comma-separated; 0 is always added, for the
    /// false alarm rate).
    #[arg(long, value_delimiter = ',', default_values_t = [0.005, 0.01, 0.03])]
    pub bias: Vec<f64>,
    /// The biased region: a centred square whose side is this fraction of the film's.
    #[arg(long, default_value_t = 0.25)]
    pub region: f64,
    /// Trials per spp (each a pair of independent sides).
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u64).range(1..=10000))]
    pub trials: u64,
    /// Seeds per side (the samples of the test).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u64).range(2..=1000))]
    pub seeds: u64,
    /// Each side is one render of --seeds x spp samples with its per-pixel variance (the
    /// samples are the test's samples: far more power, for the independent sampler only).
    #[arg(long)]
    pub per_pixel_variance: bool,
    /// Tile side in pixels.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u64).range(1..=4096))]
    pub tile: u64,
    /// Significance level of each comparison.
    #[arg(long, default_value_t = 0.01)]
    pub alpha: f64,
    /// Where the table goes.
    #[arg(long, default_value = "reports/compare-power")]
    pub out: PathBuf,
}

/// Wilson's 95 % interval of a proportion k / n.
pub fn wilson(k: u64, n: u64) -> (f64, f64) {
    let (k, n, z) = (k as f64, n as f64, 1.959_964);
    let p = k / n;
    let centre = (p + z * z / (2.0 * n)) / (1.0 + z * z / n);
    let half = z / (1.0 + z * z / n) * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt();
    ((centre - half).max(0.0), (centre + half).min(1.0))
}

/// `seeds` renders of `a` at `spp`, seeds `first..`; or, `single`, one render of
/// `seeds * spp` samples with its per-pixel variance.
fn render_side(
    a: &RenderArgs,
    spp: u32,
    first: u64,
    seeds: u64,
    single: bool,
) -> Result<Side, String> {
    let mut a = a.clone();
    if !single {
        a.spp = Some(spp);
        return Ok(sides::render_seeds(&a, first, seeds, None)?.0);
    }
    let n = spp as u64 * seeds;
    // Held to render's own bound on --spp.
    a.spp = Some(crate::limits::parse_spp(&n.to_string())?);
    let (out, stats, _) = crate::render_cmd::render_args(&a, Some(first), false)?;
    if stats.sampler != "independent" {
        return Err(format!(
            "--per-pixel-variance: the {} sampler's samples in a pixel are correlated, so \
             one render's variance is not the mean's; give seeds instead",
            stats.sampler
        ));
    }
    Ok(Side {
        width: out.mean.width as usize,
        height: out.mean.height as usize,
        mean: out.mean.data,
        var_mean: out.variance.data,
        n,
        seeds: Vec::new(),
    })
}

/// `s` with its pixels in the centred square of side `frac` scaled by `1 + b` (each seed's,
/// or the mean and its variance, by (1 + b)^2, of a render with variances).
fn biased(s: &Side, b: f64, frac: f64) -> Side {
    let side = |n: usize| ((n as f64 * frac).round() as usize).clamp(1, n);
    let (rw, rh) = (side(s.width), side(s.height));
    let (x0, y0) = ((s.width - rw) / 2, (s.height - rh) / 2);
    let scale = |img: &mut Vec<[f64; 3]>, f: f64| {
        for y in y0..y0 + rh {
            for p in &mut img[y * s.width + x0..y * s.width + x0 + rw] {
                p.iter_mut().for_each(|c| *c *= f);
            }
        }
    };
    if s.seeds.is_empty() {
        let mut out = s.clone();
        scale(&mut out.mean, 1.0 + b);
        scale(&mut out.var_mean, (1.0 + b) * (1.0 + b));
        return out;
    }
    let seeds = s
        .seeds
        .iter()
        .map(|img| {
            let mut img = img.clone();
            scale(&mut img, 1.0 + b);
            img
        })
        .collect();
    Side::from_seeds(s.width, s.height, seeds)
}

/// The command: renders, tests, writes `index.md`/`index.html` and `power.csv`.
pub fn command(a: &PowerArgs) -> Result<(), String> {
    if !(a.alpha > 0.0 && a.alpha < 1.0) {
        return Err(format!("--alpha {}: expected a level in (0, 1)", a.alpha));
    }
    if !(a.region > 0.0 && a.region <= 1.0) {
        return Err(format!(
            "--region {}: expected a fraction in (0, 1]",
            a.region
        ));
    }
    if let Some(b) = a.bias.iter().find(|b| !(b.is_finite() && **b > -1.0)) {
        return Err(format!("--bias {b}: expected a relative bias above -1"));
    }
    // Parsed once, before any render (it may not set --spp: that is ours).
    let config = sides::render_line(&a.render, "the configuration", true)?;
    let mut biases = vec![0.0];
    biases.extend(a.bias.iter().copied().filter(|b| *b != 0.0));
    let k = a.tile as usize;
    let mut csv = String::from("spp,bias,trials,detected,inconclusive,rate,ci95_low,ci95_high\n");
    let mut table = String::from("| spp |");
    for b in &biases {
        let _ = write!(table, " bias {:.1} % |", 100.0 * b);
    }
    table.push_str("\n|---|");
    table.push_str(&"---|".repeat(biases.len()));
    table.push('\n');
    let start = std::time::Instant::now();
    for (si, &spp) in a.spp.iter().enumerate() {
        let mut detected = vec![(0u64, 0u64); biases.len()];
        for t in 0..a.trials {
            // Every render of the whole command has its own seeds.
            let first = ((si as u64 * a.trials + t) * 2) * a.seeds;
            let single = a.per_pixel_variance;
            let sa = render_side(&config, spp, first, a.seeds, single)?;
            let sb = render_side(&config, spp, first + a.seeds, a.seeds, single)?;
            for (d, &b) in detected.iter_mut().zip(&biases) {
                match test(&sa, &biased(&sb, b, a.region), k, a.alpha).outcome {
                    Outcome::Biased => d.0 += 1,
                    Outcome::Inconclusive => d.1 += 1,
                    Outcome::Agree => {}
                }
            }
        }
        let _ = write!(table, "| {spp} |");
        for (&(hit, inconclusive), &b) in detected.iter().zip(&biases) {
            let (lo, hi) = wilson(hit, a.trials);
            let rate = hit as f64 / a.trials as f64;
            let _ = write!(table, " {hit}/{} [{lo:.2}, {hi:.2}] |", a.trials);
            let _ = writeln!(
                csv,
                "{spp},{b},{},{hit},{inconclusive},{rate:.4},{lo:.4},{hi:.4}",
                a.trials
            );
        }
        table.push('\n');
    }
    let md = format!(
        "# compare: power against known biases\n\n{}; {} trials per spp, each two sides of {} \
         {}; side B scaled by 1 + bias in a centred square of {:.0} % of the \
         film's side; {k}x{k} tiles, alpha {} per comparison (Sidak over its tiles). A cell \
         is the count of trials `compare` called biased, with its Wilson 95 % interval; the \
         0 % column is the false alarm rate (at most alpha, within its interval, when the \
         test is calibrated). {:.1} s in all.\n\n{table}\nData: `power.csv`.\n",
        a.render,
        a.trials,
        a.seeds,
        match a.per_pixel_variance {
            true => "x spp samples in one render with its per-pixel variance",
            false => "seeds (independent)",
        },
        100.0 * a.region,
        a.alpha,
        start.elapsed().as_secs_f64()
    );
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    let path = a.out.join("power.csv");
    crate::output::write_atomic(&path, |tmp| {
        std::fs::write(tmp, &csv).map_err(|e| format!("{}: {e}", path.display()))
    })?;
    crate::report::write_report(&a.out, &md, None, Default::default())?;
    print!("{table}");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Wilson's interval against values computed by hand: 0/10 is [0, 0.278], 5/10
    /// [0.237, 0.763], 10/10 [0.722, 1].
    #[test]
    fn wilson_intervals() {
        for ((k, n), (lo, hi)) in [
            ((0, 10), (0.0, 0.2775)),
            ((5, 10), (0.2366, 0.7634)),
            ((10, 10), (0.7225, 1.0)),
        ] {
            let (a, b) = wilson(k, n);
            assert!(
                (a - lo).abs() < 1e-3 && (b - hi).abs() < 1e-3,
                "{k}/{n}: {a} {b}"
            );
        }
    }

    /// The region is centred, of the asked side, and scaled by exactly 1 + b.
    #[test]
    fn the_bias_goes_into_the_centred_square_only() {
        let s = Side::from_seeds(8, 4, vec![vec![[1.0; 3]; 32]; 2]);
        let b = biased(&s, 0.5, 0.5);
        let changed: Vec<usize> = (0..32).filter(|&i| b.mean[i][0] != 1.0).collect();
        assert_eq!(changed, vec![10, 11, 12, 13, 18, 19, 20, 21]);
        assert!(changed.iter().all(|&i| b.mean[i] == [1.5; 3]));
        let render = Side {
            seeds: Vec::new(),
            var_mean: vec![[2.0; 3]; 32],
            ..s
        };
        let b = biased(&render, 0.5, 0.5);
        assert!(b.mean[10] == [1.5; 3] && b.var_mean[10] == [4.5; 3] && b.var_mean[9] == [2.0; 3]);
    }
}
