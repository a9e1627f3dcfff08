//! BSDFs in the local shading frame (z = shading normal), with `sample`, `eval` and `pdf`
//! that agree: `sample` returns weight = eval / pdf for the direction it drew.
//!
//! Conventions (as Mitsuba): `wi` is the direction towards the viewer/previous vertex,
//! `wo` the sampled direction towards the light; `eval` includes the |cos| of `wo`.

mod conductor;
mod dielectric;
mod diffuse;
pub mod fresnel;
mod mirror;
mod nori_microfacet;
mod roughconductor;

pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub use diffuse::Diffuse;
pub use mirror::Mirror;
pub use nori_microfacet::NoriMicrofacet;
pub use roughconductor::RoughConductor;

use crate::math::Rgb;
use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub wo: Vec3,
    /// eval(wi, wo) / pdf; for delta lobes, the lobe's throughput.
    pub weight: Rgb,
    /// Solid-angle density of `wo`; for delta lobes the discrete probability of the lobe.
    pub pdf: f32,
    pub delta: bool,
}

/// Closed set of materials; enum dispatch keeps the hot path free of virtual calls.
#[derive(Clone, Debug)]
pub enum BsdfKind {
    Diffuse(Diffuse),
    Conductor(Conductor),
    RoughConductor(RoughConductor),
    Dielectric(Dielectric),
    NoriMicrofacet(NoriMicrofacet),
    Mirror(Mirror),
}

/// A material: a BSDF and whether it is used on both sides of the surface.
#[derive(Clone, Debug)]
pub struct Material {
    pub kind: BsdfKind,
    pub two_sided: bool,
}

impl Material {
    /// Two-sided materials mirror the configuration into the upper hemisphere.
    #[inline]
    fn orient(&self, wi: Vec3, wo: Vec3) -> (Vec3, Vec3) {
        if self.two_sided && wi.z < 0.0 {
            (Vec3::new(wi.x, wi.y, -wi.z), Vec3::new(wo.x, wo.y, -wo.z))
        } else {
            (wi, wo)
        }
    }

    /// True if every lobe is a Dirac delta (light sampling is then useless).
    pub fn is_delta(&self) -> bool {
        match &self.kind {
            BsdfKind::Conductor(_) | BsdfKind::Dielectric(_) | BsdfKind::Mirror(_) => true,
            BsdfKind::Diffuse(_) | BsdfKind::RoughConductor(_) | BsdfKind::NoriMicrofacet(_) => {
                false
            }
        }
    }

    #[inline]
    pub fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        let (wi, wo) = self.orient(wi, wo);
        match &self.kind {
            BsdfKind::Diffuse(b) => b.eval(wi, wo),
            BsdfKind::RoughConductor(b) => b.eval(wi, wo),
            BsdfKind::NoriMicrofacet(b) => b.eval(wi, wo),
            // Delta lobes have no density to evaluate.
            BsdfKind::Conductor(_) | BsdfKind::Dielectric(_) | BsdfKind::Mirror(_) => Rgb::ZERO,
        }
    }

    #[inline]
    pub fn pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        let (wi, wo) = self.orient(wi, wo);
        match &self.kind {
            BsdfKind::Diffuse(b) => b.pdf(wi, wo),
            BsdfKind::RoughConductor(b) => b.pdf(wi, wo),
            BsdfKind::NoriMicrofacet(b) => b.pdf(wi, wo),
            BsdfKind::Conductor(_) | BsdfKind::Dielectric(_) | BsdfKind::Mirror(_) => 0.0,
        }
    }

    /// `(eval, pdf)` with the work they share done once.
    #[inline]
    pub fn eval_pdf(&self, wi: Vec3, wo: Vec3) -> (Rgb, f32) {
        let (wi, wo) = self.orient(wi, wo);
        match &self.kind {
            BsdfKind::Diffuse(b) => (b.eval(wi, wo), b.pdf(wi, wo)),
            BsdfKind::RoughConductor(b) => b.eval_pdf(wi, wo),
            BsdfKind::NoriMicrofacet(b) => (b.eval(wi, wo), b.pdf(wi, wo)),
            BsdfKind::Conductor(_) | BsdfKind::Dielectric(_) | BsdfKind::Mirror(_) => {
                (Rgb::ZERO, 0.0)
            }
        }
    }

    /// `u1` picks a lobe, `u2` the direction within it: separate numbers for separate decisions.
    #[inline]
    pub fn sample(&self, wi: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        let flip = self.two_sided && wi.z < 0.0;
        let wi_up = if flip {
            Vec3::new(wi.x, wi.y, -wi.z)
        } else {
            wi
        };
        let mut s = match &self.kind {
            BsdfKind::Diffuse(b) => b.sample(wi_up, u2)?,
            BsdfKind::Conductor(b) => b.sample(wi_up)?,
            BsdfKind::RoughConductor(b) => b.sample(wi_up, u2)?,
            BsdfKind::Dielectric(b) => b.sample(wi_up, u1)?,
            BsdfKind::NoriMicrofacet(b) => b.sample(wi_up, u1, u2)?,
            BsdfKind::Mirror(b) => b.sample(wi_up)?,
        };
        if flip {
            s.wo.z = -s.wo.z;
        }
        Some(s)
    }
}

#[cfg(test)]
pub(crate) mod testing {
    //! Checks every BSDF must pass: sample/eval/pdf agreement and energy bounds.
    use super::*;
    use crate::rng::Rng;
    use crate::sampling::warps::square_to_uniform_sphere;

    /// For many incident directions and samples: pdf() of the sampled direction equals the
    /// returned pdf, and weight == eval/pdf (non-delta lobes), to 1e-3 relative.
    pub fn check_sample_consistency(m: &Material, n: usize) {
        let mut rng = Rng::new(17, 3);
        for _ in 0..n {
            let wi = square_to_uniform_sphere(rng.next_2d());
            check_one(m, wi, &mut rng);
        }
    }

    /// As `check_sample_consistency` for one incident direction; returns the worst relative
    /// mismatch seen (pdf or weight), for reports.
    pub fn check_sample_consistency_at(m: &Material, wi: Vec3, n: usize) -> f32 {
        let mut rng = Rng::new(19, 4);
        (0..n).fold(0.0, |w, _| w.max(check_one(m, wi, &mut rng)))
    }

    fn check_one(m: &Material, wi: Vec3, rng: &mut Rng) -> f32 {
        let Some(s) = m.sample(wi, rng.next_f32(), rng.next_2d()) else {
            return 0.0;
        };
        assert!(
            s.weight.is_finite() && s.pdf.is_finite() && s.pdf > 0.0,
            "{s:?}"
        );
        assert!(s.weight.min_element() >= 0.0, "{s:?}");
        if s.delta {
            assert!(s.pdf <= 1.0, "{s:?}");
            return 0.0;
        }
        let pdf = m.pdf(wi, s.wo);
        let e_pdf = (pdf - s.pdf).abs() / s.pdf;
        assert!(
            e_pdf <= 1e-3,
            "wi {wi} wo {}: pdf {pdf} vs sampled {}",
            s.wo,
            s.pdf
        );
        let w = m.eval(wi, s.wo) / s.pdf;
        let e_w = (w - s.weight).abs().max_element() / w.max_element().max(1e-3);
        assert!(e_w <= 1e-3, "wi {wi} wo {}: {w} vs {}", s.wo, s.weight);
        e_pdf.max(e_w)
    }

    /// Fraction of `sample` calls that return a direction, and the albedo estimate with it.
    pub fn success_rate(m: &Material, wi: Vec3, n: usize) -> f64 {
        let mut rng = Rng::new(29, 6);
        (0..n)
            .filter(|_| m.sample(wi, rng.next_f32(), rng.next_2d()).is_some())
            .count() as f64
            / n as f64
    }

    /// ∫ eval(wi, wo) dwo and ∫ pdf(wi, wo) dwo by quadrature on `grid` (independent of
    /// the samplers).
    pub fn quadrature(
        m: &Material,
        wi: Vec3,
        grid: &crate::sampling::quadrature::LobeGrid,
    ) -> (Rgb, f64) {
        let [r, g, b, p] = grid.integrate_n(|wo| {
            let e = m.eval(wi, wo).as_dvec3();
            [e.x, e.y, e.z, m.pdf(wi, wo) as f64]
        });
        (Rgb::new(r as f32, g as f32, b as f32), p)
    }

    /// Directional albedo by sampling: E[weight] for a fixed wi. Returns (mean, std error).
    pub fn albedo(m: &Material, wi: Vec3, n: usize) -> (Rgb, Rgb) {
        let mut rng = Rng::new(23, 5);
        let (mut s, mut s2) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
        for _ in 0..n {
            if let Some(x) = m.sample(wi, rng.next_f32(), rng.next_2d()) {
                let w = x.weight.as_dvec3();
                s += w;
                s2 += w * w;
            }
        }
        let mean = s / n as f64;
        let var = (s2 / n as f64 - mean * mean).max(glam::DVec3::ZERO);
        (mean.as_vec3(), (var / n as f64).as_vec3().map(f32::sqrt))
    }
}
