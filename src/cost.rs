//! The linear cost model: a render's seconds as a non-negative sum of what it did, one
//! coefficient per term (a constant per render, a cost per pixel, and one per counted ray or
//! evaluation, `counts::Counts`). Fitted per machine by `directlab bench` on its timed renders
//! and per experiment on its own runs; reports plot error against the modelled cost beside
//! error against the measured time, and state how far each run's time is from its model.
//!
//! The counters are the same on every machine and code path, so the modelled cost compares
//! estimators where a clock compares implementations: a sampler that draws its numbers
//! slowly shows as runs slower than their counts predict, not as a worse estimator.

use crate::counts::Counts;
use crate::emitter::LightSampling;
use crate::rng::LANES;
use crate::scene::desc::StrategyKind;
use crate::stats::nnls::nnls;

/// The terms of the model, in coefficient order: per render, per pixel, per counter (in
/// `Counts::values` order), the extra cost of a light sample and a light-density
/// evaluation in solid angle (spherical triangles and cones: trigonometry in f64), a cost per
/// camera sample for each estimator that is not two-sample MIS (how it runs its techniques:
/// light or BSDF sampling alone skip the step MIS shares between them; one-sample MIS runs
/// both steps over each group of lanes), and a cost per batch of `LANES` camera samples of a
/// pixel: below `LANES` spp a batch runs with lanes idle, which no count of work shows.
pub const TERMS: [&str; 17] = [
    "render",
    "pixel",
    "camera_ray",
    "light_sample",
    "shadow_ray",
    "bsdf_sample",
    "bsdf_ray",
    "bsdf_rejected",
    "bsdf_eval",
    "light_pdf_eval",
    "choice_eval",
    "solid_angle_light_sample",
    "solid_angle_light_pdf_eval",
    "light_only_camera_sample",
    "bsdf_only_camera_sample",
    "one_sample_camera_sample",
    "lane_batch",
];

/// `v` per camera sample of the render that counted `c` (0 for a render without any).
pub fn per_camera_sample(c: &Counts, v: u64) -> f64 {
    v as f64 / c.camera_rays.max(1) as f64
}

/// What one render did: its size, its counts, its estimator and how it drew light points.
#[derive(Clone, Copy, Debug)]
pub struct Work {
    pub pixels: u64,
    pub counts: Counts,
    pub kind: StrategyKind,
    pub light_sampling: LightSampling,
}

impl Work {
    /// The model's terms for this render (`TERMS` order).
    pub fn terms(&self) -> [f64; TERMS.len()] {
        let c = self.counts.values().map(|v| v as f64);
        let sa = f64::from(u8::from(self.light_sampling == LightSampling::SolidAngle));
        let kind = |k| f64::from(u8::from(self.kind == k)) * c[0];
        // Every pixel takes the same spp, so camera rays / pixels is it.
        let spp = self.counts.camera_rays / self.pixels.max(1);
        let batches = self.pixels * spp.div_ceil(LANES as u64);
        [
            1.0,
            self.pixels as f64,
            c[0],
            c[1],
            c[2],
            c[3],
            c[4],
            c[5],
            c[6],
            c[7],
            c[8],
            sa * c[1],
            sa * c[7],
            kind(StrategyKind::Light),
            kind(StrategyKind::Bsdf),
            kind(StrategyKind::MisOneSample),
            batches as f64,
        ]
    }
}

/// Seconds per unit of each term (`TERMS` order), fitted on `runs` renders.
#[derive(Clone, Debug, PartialEq)]
pub struct CostModel {
    pub seconds_per: [f64; TERMS.len()],
    pub runs: usize,
}

impl CostModel {
    /// The model that best predicts each run's seconds in relative terms (least squares of
    /// predicted / measured - 1, coefficients non-negative). None without a run of positive
    /// time.
    pub fn fit(runs: &[(Work, f64)]) -> Option<CostModel> {
        let runs: Vec<&(Work, f64)> = runs
            .iter()
            .filter(|(_, s)| *s > 0.0 && s.is_finite())
            .collect();
        if runs.is_empty() {
            return None;
        }
        // Dividing each equation by its seconds makes the residual relative: a 2 s run and
        // a 20 ms run count alike.
        let a: Vec<Vec<f64>> = runs
            .iter()
            .map(|(w, s)| w.terms().iter().map(|t| t / s).collect())
            .collect();
        let b = vec![1.0; runs.len()];
        let x = nnls(&a, &b);
        Some(CostModel {
            seconds_per: std::array::from_fn(|i| x[i]),
            runs: runs.len(),
        })
    }

    /// Modelled seconds of `w`.
    pub fn predict(&self, w: &Work) -> f64 {
        w.terms()
            .iter()
            .zip(&self.seconds_per)
            .map(|(t, c)| t * c)
            .sum()
    }

    /// How far the model is from a run's measured `seconds`: predicted / measured - 1.
    pub fn error(&self, w: &Work, seconds: f64) -> f64 {
        self.predict(w) / seconds - 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn work(spp: u64, shadow: u64, sa: bool) -> Work {
        work_of(spp, shadow, sa, StrategyKind::Mis)
    }

    fn work_of(spp: u64, shadow: u64, sa: bool, kind: StrategyKind) -> Work {
        let pixels = 100;
        let n = pixels * spp;
        Work {
            pixels,
            counts: Counts {
                camera_rays: n,
                light_samples: n,
                shadow_rays: shadow * n / 2,
                light_pdf_evals: n / 3,
                ..Counts::default()
            },
            kind,
            light_sampling: if sa {
                LightSampling::SolidAngle
            } else {
                LightSampling::Area
            },
        }
    }

    #[test]
    fn terms_follow_the_counters_and_the_light_sampling() {
        let w = work(4, 2, true);
        let t = w.terms();
        assert_eq!(&t[..5], &[1.0, 100.0, 400.0, 400.0, 400.0]);
        assert_eq!(t[9], 133.0);
        assert_eq!((t[11], t[12]), (400.0, 133.0));
        assert_eq!(&t[13..16], &[0.0; 3]);
        // 4 spp on 100 pixels: one batch of eight lanes per pixel; 9 spp would be two.
        assert_eq!(t[16], 100.0);
        assert_eq!(work(9, 2, true).terms()[16], 200.0);
        let t = work(4, 2, false).terms();
        assert_eq!((t[11], t[12]), (0.0, 0.0));
        let t = work_of(4, 2, false, StrategyKind::MisOneSample).terms();
        assert_eq!(&t[13..16], &[0.0, 0.0, 400.0]);
        let t = work_of(4, 2, false, StrategyKind::Light).terms();
        assert_eq!(&t[13..16], &[400.0, 0.0, 0.0]);
    }

    #[test]
    fn recovers_known_costs_and_predicts_a_held_out_configuration() {
        // Seconds = 5 ms per render + 40 ns per camera ray + 15 ns per shadow ray + 200 ns
        // more per solid-angle light sample, by construction.
        let truth = |w: &Work| {
            let c = w.counts;
            let sa = if w.light_sampling == LightSampling::SolidAngle {
                c.light_samples as f64
            } else {
                0.0
            };
            5e-3 + 40e-9 * c.camera_rays as f64 + 15e-9 * c.shadow_rays as f64 + 200e-9 * sa
        };
        let runs: Vec<(Work, f64)> = [1, 4, 16, 64, 256]
            .iter()
            .flat_map(|&spp| [work(spp, 2, false), work(spp, 0, false), work(spp, 2, true)])
            .map(|w| (w, truth(&w)))
            .collect();
        let m = CostModel::fit(&runs).unwrap();
        assert_eq!(m.runs, 15);
        assert!(m.seconds_per.iter().all(|&c| c >= 0.0), "{m:?}");
        for (w, s) in &runs {
            assert!(m.error(w, *s).abs() < 1e-6, "{w:?}: {}", m.error(w, *s));
        }
        // Four shadow rays per sample and solid angle at 1000 spp were never timed.
        let held = work(1000, 4, true);
        assert!((m.error(&held, truth(&held))).abs() < 1e-6);
        // A run twice as slow as its counts say: the model predicts half its time.
        assert!((m.error(&held, 2.0 * truth(&held)) + 0.5).abs() < 1e-6);
        assert!(CostModel::fit(&[(held, 0.0)]).is_none());
    }
}
