//! Direct-lighting estimators at one receiver point built from the (possibly wrong)
//! samplers: light sampling, BSDF sampling, and MIS of one sample of each with the balance
//! heuristic, in the study's structure. Gallery scenes have no occluders between receiver
//! and lights, so light samples skip the shadow ray; BSDF samples trace the scene to find
//! the light they hit.

use super::lights::Lights;
use super::receiver::Bsdf;
use super::Bug;
use crate::geometry::Ray;
use crate::math::Frame;
use crate::rng::Rng;
use crate::scene::Scene;
use crate::stats::Welford;
use glam::Vec3;

pub struct Setup<'a> {
    pub scene: &'a Scene,
    pub x: Vec3,
    pub frame: Frame,
    /// Direction to the viewer in the local frame.
    pub wi: Vec3,
    pub lights: Lights<'a>,
    pub bsdf: Bsdf,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Strategy {
    Light,
    Bsdf,
    Mis,
}

/// The emitted radiance found along world direction `d` from the receiver, if a light's
/// front faces it.
fn emitted(scene: &Scene, x: Vec3, n: Vec3, d: Vec3) -> f32 {
    let hit = scene.intersect(&Ray::new(x + n * 1e-4, d));
    hit.and_then(|h| {
        let (_, e) = scene.emitter_at(&h.sp)?;
        Some(e.le(&h.sp, -d).x)
    })
    .unwrap_or(0.0)
}

impl Setup<'_> {
    fn light_only(&self, rng: &mut Rng) -> f32 {
        let Some(ls) = self.lights.sample(self.x, rng) else {
            return 0.0;
        };
        let f = self.bsdf.eval(self.wi, self.frame.to_local(ls.wi));
        f * ls.le / ls.pdf
    }

    fn bsdf_only(&self, rng: &mut Rng) -> f32 {
        let Some(s) = self.bsdf.sample(self.wi, rng.next_f32(), rng.next_2d()) else {
            return 0.0;
        };
        let d = self.frame.to_world(s.wo);
        s.weight * emitted(self.scene, self.x, self.frame.n, d)
    }

    fn mis(&self, rng: &mut Rng) -> f32 {
        let balance = |a: f32, b: f32| if a > 0.0 { a / (a + b) } else { 0.0 };
        // Both samples are drawn first, as in the study, so the mixed-direction bug can
        // reach for the other sample's pdf.
        let ls = self.lights.sample(self.x, rng);
        let bs = self.bsdf.sample(self.wi, rng.next_f32(), rng.next_2d());
        let mixed = self.bug() == Bug::MisMixedDirections;
        let mut l = 0.0;
        if let Some(ls) = ls {
            let wo = self.frame.to_local(ls.wi);
            let p_bsdf = match (mixed, bs) {
                (true, Some(b)) => b.pdf,
                (true, None) => 0.0,
                (false, _) => self.bsdf.pdf(self.wi, wo),
            };
            let f = self.bsdf.eval(self.wi, wo);
            l += f * ls.le * balance(ls.pdf, p_bsdf) / ls.pdf;
        }
        if let Some(b) = bs {
            let d = self.frame.to_world(b.wo);
            let le = emitted(self.scene, self.x, self.frame.n, d);
            if le > 0.0 {
                let p_light = match (mixed, ls) {
                    (true, Some(s)) => s.pdf,
                    (true, None) => 0.0,
                    (false, _) => self.lights.pdf(self.x, d) as f32,
                };
                l += b.weight * le * balance(b.pdf, p_light);
            }
        }
        l
    }

    fn bug(&self) -> Bug {
        self.lights.bug
    }

    /// `n` estimates with strategy `s` from the stream `(seed, stream)`.
    pub fn run(&self, s: Strategy, n: u64, seed: u64, stream: u64) -> Welford {
        let mut rng = Rng::new(seed, stream);
        let mut w = Welford::new();
        for _ in 0..n {
            let v = match s {
                Strategy::Light => self.light_only(&mut rng),
                Strategy::Bsdf => self.bsdf_only(&mut rng),
                Strategy::Mis => self.mis(&mut rng),
            };
            w.push(v as f64);
        }
        w
    }
}
