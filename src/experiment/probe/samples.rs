//! The individual sample values of one pixel, drawn exactly as `render` draws them (same
//! seeding, camera ray and estimator), for statistics a mean and variance cannot give.

use crate::counts::Counts;
use crate::integrator::Direct;
use crate::rng::Rng;

/// What a pixel's samples give besides their channel-0 values.
#[derive(Clone, Copy, Debug, Default)]
pub struct Drawn {
    pub non_finite: u64,
    /// What the samples did (rays, evaluations), all of them.
    pub counts: Counts,
    /// Per-channel mean and sample variance (of one sample), for the image-mean columns.
    pub mean: [f64; 3],
    pub variance: [f64; 3],
}

/// Appends the channel-0 value of samples 0..n of pixel (x, y) to `out` (cleared first) and
/// counts the non-finite ones. Those are stored as 0, as `render` does, so the mean of `out`
/// is the renderer's pixel mean. The loop does not allocate once `out` has capacity.
pub fn pixel_samples(
    direct: &Direct,
    x: u32,
    y: u32,
    seed: u64,
    n: u32,
    out: &mut Vec<f64>,
) -> Drawn {
    let cam = &direct.scene.camera;
    let pixel = y as u64 * cam.width as u64 + x as u64;
    out.clear();
    out.reserve(n as usize);
    let mut d = Drawn::default();
    // Welford per channel: exact enough where the variance is 1e-15 of the mean squared.
    let mut m2 = [0.0f64; 3];
    for s in 0..n {
        let mut rng = Rng::for_sample(seed, pixel, s as u64);
        let ray = cam.generate_ray(x, y, &mut rng);
        let v = direct.li_counted(&ray, &mut rng, &mut d.counts);
        let v = if v.is_finite() {
            v
        } else {
            d.non_finite += 1;
            crate::math::Rgb::ZERO
        };
        out.push(v.x as f64);
        let k = (s + 1) as f64;
        for c in 0..3 {
            let x = v[c] as f64;
            let delta = x - d.mean[c];
            d.mean[c] += delta / k;
            m2[c] += delta * (x - d.mean[c]);
        }
    }
    if n > 1 {
        d.variance = m2.map(|m| m / (n - 1) as f64);
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::Strategy;
    use crate::render::{render, RenderSettings};
    use crate::scene::{fixtures, Scene};

    /// Same samples as the renderer: the means agree to rounding (Welford vs shifted sums).
    #[test]
    fn extreme_samples_reproduce_the_renderer() {
        let scene = Scene::build(fixtures::furnace(0.5, true, 3)).unwrap();
        let s = Strategy::from_desc(&scene.desc.integrator);
        let settings = RenderSettings {
            spp: 64,
            seed: 9,
            first_sample: 0,
            threads: Some(1),
            progress: None,
            sampling: Default::default(),
        };
        let img = render(&scene, s, &settings);
        let direct = Direct::new(&scene, s);
        let mut buf = Vec::new();
        for (x, y) in [(0, 0), (2, 1)] {
            assert_eq!(pixel_samples(&direct, x, y, 9, 64, &mut buf).non_finite, 0);
            let mean = buf.iter().sum::<f64>() / 64.0;
            let r = img.mean.get(x, y)[0];
            assert!((mean - r).abs() <= 1e-12 * r, "{mean} vs {r}");
        }
    }
}
