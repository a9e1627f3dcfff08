//! What each pixel's estimate is made of (`render --aov`): the emission the camera sees, the
//! light-sampled and the BSDF-sampled parts (the three add up to the image), the mean MIS
//! weight of each technique's samples that carry light, and the per-pixel second moment of
//! the estimate.
//!
//! The estimator is the scalar one (`Direct::li_recorded`, the definition the lane kernel is
//! tested bitwise against) with a recorder; each sample is the sampler's sample of the
//! render, so the parts belong to the render of the same settings.

use crate::counts::Counts;
use crate::film::Image;
use crate::integrator::{Direct, Record, Strategy};
use crate::math::Rgb;
use crate::render::RenderSettings;
use crate::rng::LANES;
use crate::sampler::{LanesVisitor, SamplerConfig, SamplerLanes};
use crate::scene::Scene;
use rayon::prelude::*;

/// The images of `render --aov`, each a per-pixel mean over the samples.
pub struct Aov {
    /// Emission seen directly by the camera.
    pub emitted: Image,
    /// The light technique's terms (weighted, as added to the estimate).
    pub light: Image,
    /// The BSDF technique's terms.
    pub bsdf: Image,
    /// The mean MIS weight of the light samples that carry light (0 where none does), in
    /// every channel.
    pub weight_light: Image,
    /// The same for BSDF samples.
    pub weight_bsdf: Image,
    /// The mean of the squared estimate, per channel.
    pub second_moment: Image,
}

impl Aov {
    /// The images with their file stems, in a fixed order.
    pub fn images(&self) -> [(&'static str, &Image); 6] {
        [
            ("emitted", &self.emitted),
            ("light", &self.light),
            ("bsdf", &self.bsdf),
            ("weight-light", &self.weight_light),
            ("weight-bsdf", &self.weight_bsdf),
            ("second-moment", &self.second_moment),
        ]
    }
}

/// One sample's or one pixel's sums.
#[derive(Clone, Copy, Default)]
struct Sums {
    emitted: [f64; 3],
    light: [f64; 3],
    bsdf: [f64; 3],
    square: [f64; 3],
    /// Sum and count of the MIS weights of light-carrying samples: light, BSDF.
    weights: [(f64, u64); 2],
}

fn add(a: &mut [f64; 3], v: Rgb) {
    for (a, v) in a.iter_mut().zip(v.to_array()) {
        *a += v as f64;
    }
}

impl Record for Sums {
    fn emitted(&mut self, le: Rgb) {
        add(&mut self.emitted, le);
    }

    fn term(&mut self, light: bool, value: Rgb, mis_weight: f32) {
        add(
            if light {
                &mut self.light
            } else {
                &mut self.bsdf
            },
            value,
        );
        let w = &mut self.weights[usize::from(!light)];
        w.0 += mis_weight as f64;
        w.1 += 1;
    }
}

impl Sums {
    fn merge(&mut self, o: &Sums) {
        for (a, b) in [
            (&mut self.emitted, o.emitted),
            (&mut self.light, o.light),
            (&mut self.bsdf, o.bsdf),
            (&mut self.square, o.square),
        ] {
            a.iter_mut().zip(b).for_each(|(a, b)| *a += b);
        }
        for (a, b) in self.weights.iter_mut().zip(o.weights) {
            (a.0, a.1) = (a.0 + b.0, a.1 + b.1);
        }
    }
}

/// One pixel's samples, drawn by the sampler `L`.
struct Pixel<'a> {
    direct: &'a Direct<'a>,
    cfg: &'a SamplerConfig,
    settings: &'a RenderSettings,
    x: u32,
    y: u32,
}

impl LanesVisitor for Pixel<'_> {
    type Output = Sums;
    fn visit<L: SamplerLanes>(self) -> Sums {
        let (settings, cam) = (self.settings, &self.direct.scene.camera);
        let key = L::pixel(self.cfg, self.x, self.y);
        let mut pixel = Sums::default();
        let mut c = Counts::default();
        for s0 in (0..settings.spp).step_by(LANES) {
            let lanes = L::start(key, settings.first_sample + s0 as u64);
            for i in 0..(settings.spp - s0).min(LANES as u32) as usize {
                let mut one = lanes.lane(i);
                let ray = cam.generate_ray(self.x, self.y, &mut one);
                let mut sample = Sums::default();
                let v = self.direct.li_recorded(&ray, &mut one, &mut c, &mut sample);
                // As the render does, a non-finite sample counts as 0 (in every part).
                if v.is_finite() {
                    add(&mut sample.square, v * v);
                    pixel.merge(&sample);
                }
            }
        }
        pixel
    }
}

/// The parts of `scene`'s render with `strategy` and `settings` (see the module comment).
pub fn render_aov(scene: &Scene, strategy: Strategy, settings: &RenderSettings) -> Aov {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let cfg = settings
        .sampler_config((w, h))
        .expect("sampler settings checked by the caller");
    let direct = Direct::new(scene, strategy);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(settings.threads.unwrap_or(0))
        .build()
        .expect("thread pool");
    let rows: Vec<Vec<Sums>> = pool.install(|| {
        (0..h)
            .into_par_iter()
            .map(|y| {
                (0..w)
                    .map(|x| {
                        settings.sampling.kind.visit(Pixel {
                            direct: &direct,
                            cfg: &cfg,
                            settings,
                            x,
                            y,
                        })
                    })
                    .collect()
            })
            .collect()
    });
    let n = settings.spp.max(1) as f64;
    let image = |f: &dyn Fn(&Sums) -> [f64; 3]| Image {
        width: w,
        height: h,
        data: rows.iter().flatten().map(f).collect(),
    };
    let weight = |s: &Sums, k: usize| {
        let (sum, count) = s.weights[k];
        [if count > 0 { sum / count as f64 } else { 0.0 }; 3]
    };
    Aov {
        emitted: image(&|s| s.emitted.map(|v| v / n)),
        light: image(&|s| s.light.map(|v| v / n)),
        bsdf: image(&|s| s.bsdf.map(|v| v / n)),
        weight_light: image(&|s| weight(s, 0)),
        weight_bsdf: image(&|s| weight(s, 1)),
        second_moment: image(&|s| s.square.map(|v| v / n)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emitter::EmitterSelection;
    use crate::render::render;
    use crate::scene::desc::{Heuristic, StrategyKind};

    fn cbox() -> Scene {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cbox/cbox.xml");
        let defines = [("res".to_string(), "24".to_string())];
        crate::scene::open_with(std::path::Path::new(path), &defines, None).expect("cbox")
    }

    /// The parts add up to the render's image (to f32 rounding of the terms); the second
    /// moment is at least the squared mean; MIS weights lie in [0, 1] and, where both
    /// techniques carry light under the balance heuristic, neither is 0 or 1 everywhere.
    /// Light sampling alone puts everything in the light part with weight 1.
    #[test]
    fn parts_add_up_to_the_image_and_weights_are_weights() {
        let scene = cbox();
        let settings = RenderSettings::new(16, 7);
        for (kind, heuristic) in [
            (StrategyKind::Mis, Heuristic::Balance),
            (StrategyKind::Mis, Heuristic::Power),
            (StrategyKind::MisOneSample, Heuristic::Balance),
            (StrategyKind::Light, Heuristic::Balance),
        ] {
            let strategy = Strategy {
                kind,
                heuristic,
                emitter_samples: 1,
                bsdf_samples: 1,
                selection: EmitterSelection::Uniform,
                light_sampling: crate::emitter::LightSampling::Area,
                hide_emitters: false,
            };
            let image = render(&scene, strategy, &settings).mean;
            let aov = render_aov(&scene, strategy, &settings);
            for i in 0..image.data.len() {
                for c in 0..3 {
                    let sum = aov.emitted.data[i][c] + aov.light.data[i][c] + aov.bsdf.data[i][c];
                    let m = image.data[i][c];
                    assert!(
                        (sum - m).abs() <= 1e-5 * m.abs().max(1e-3),
                        "{kind:?} pixel {i}: parts {sum} vs image {m}"
                    );
                    assert!(aov.second_moment.data[i][c] >= m * m * (1.0 - 1e-5));
                }
                for w in [&aov.weight_light, &aov.weight_bsdf] {
                    assert!((0.0..=1.0 + 1e-6).contains(&w.data[i][0]), "{kind:?}");
                }
            }
            let (wl, wb) = (&aov.weight_light.data, &aov.weight_bsdf.data);
            if kind == StrategyKind::Light {
                assert!(aov.bsdf.data.iter().all(|p| p == &[0.0; 3]));
                assert!(wl.iter().all(|w| w[0] == 0.0 || w[0] == 1.0));
                assert!(wl.iter().any(|w| w[0] == 1.0));
            } else {
                // A small light: its own samples weigh near 1, BSDF samples near 0.
                let mixed = |w: &Vec<[f64; 3]>| w.iter().any(|w| w[0] > 0.0 && w[0] < 1.0);
                assert!(mixed(wl) && mixed(wb), "{kind:?}");
                let lit: Vec<usize> = (0..wl.len()).filter(|&i| wb[i][0] > 0.0).collect();
                let light_heavier = lit.iter().filter(|&&i| wl[i][0] > wb[i][0]).count();
                assert!(light_heavier * 10 > lit.len() * 9, "{kind:?}");
            }
        }
    }
}
