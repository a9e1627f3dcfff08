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
pub mod params;
mod plastic;
mod roughconductor;
mod roughconductor_lanes;
mod roughplastic;

pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub use diffuse::Diffuse;
pub use mirror::Mirror;
pub use nori_microfacet::NoriMicrofacet;
pub use plastic::Plastic;
pub use roughconductor::RoughConductor;
pub use roughplastic::RoughPlastic;

use crate::math::{Rgb, V3x8};
use crate::rng::LANES;
use glam::{Vec2, Vec3};
use params::Params;

/// Eight lanes' `BsdfSample`s, one array per field (`Bsdf::sample_lanes`): an array of
/// `Option<BsdfSample>` kept the loops that write and read it from running in vector lanes.
#[derive(Default)]
#[repr(C, align(32))]
pub struct BsdfSamples {
    /// Each lane's sampled direction.
    pub wo: V3x8,
    /// Each lane's eval / pdf (or a delta lobe's throughput).
    pub weight: V3x8,
    /// Each lane's density of `wo` (a delta lobe's discrete probability).
    pub pdf: [f32; LANES],
    /// Whether the lane has a sample (the rest of a lane without one is unspecified).
    pub ok: [bool; LANES],
    /// Whether the lane's sample came from a delta lobe.
    pub delta: [bool; LANES],
}

impl BsdfSamples {
    /// Stores lane i's sample, if `live`.
    #[inline(always)]
    pub fn set(&mut self, i: usize, s: Option<BsdfSample>, live: bool) {
        let (ok, wo, weight, pdf, delta) = match s {
            Some(s) => (live, s.wo, s.weight, s.pdf, s.delta),
            None => (false, Vec3::Z, Rgb::ZERO, 0.0, false),
        };
        (self.ok[i], self.pdf[i], self.delta[i]) = (ok, pdf, delta);
        self.wo.set(i, wo);
        self.weight.set(i, weight);
    }
}

/// A direction drawn from a BSDF, with its weight and density.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// The sampled direction, in the local shading frame.
    pub wo: Vec3,
    /// eval(wi, wo) / pdf; for delta lobes, the lobe's throughput.
    pub weight: Rgb,
    /// Solid-angle density of `wo`; for delta lobes the discrete probability of the lobe.
    pub pdf: f32,
    /// Whether the sample came from a Dirac delta lobe (its pdf is then a discrete probability).
    pub delta: bool,
}

/// A material model, one file each; `registry!` below lists them. In the local shading frame
/// (z = shading normal), one-sided: `Material` mirrors the configuration for two-sided use.
/// Plain data (`Copy`): the lane kernel copies a batch's BSDFs next to its working arrays,
/// where the compiler can see that no store of the kernel's changes them.
pub trait Bsdf: Sized + Copy {
    /// Every lobe is a Dirac delta: `eval` and `pdf` are 0, `sample` gives the lobes.
    const DELTA: bool;
    /// Some lobe is a Dirac delta (every lobe for a `DELTA` BSDF; the coating of `plastic`).
    /// Light sampling cannot produce its directions, so the light strategy adds BSDF samples
    /// for them.
    const DELTA_LOBE: bool = Self::DELTA;
    /// Whether `twosided` may wrap it (not for a BSDF that gives both sides a meaning).
    const TWO_SIDED: bool = true;
    /// Reads Mitsuba's (or Nori's) parameters of its `<bsdf>` element.
    fn from_params<P: Params>(p: &mut P) -> Result<Self, P::Error>;
    /// f(wi, wo) |cos(wo)|. Zero for delta BSDFs, which keep this default; a BSDF with a
    /// density that kept it would fail its chi-square and weight checks.
    fn eval(&self, _wi: Vec3, _wo: Vec3) -> Rgb {
        Rgb::ZERO
    }
    /// Solid-angle density of `sample`'s directions; zero for delta BSDFs (the default).
    fn pdf(&self, _wi: Vec3, _wo: Vec3) -> f32 {
        0.0
    }
    /// `(eval, pdf)`, with the work they share done once where a BSDF can.
    fn eval_pdf(&self, wi: Vec3, wo: Vec3) -> (Rgb, f32) {
        (self.eval(wi, wo), self.pdf(wi, wo))
    }
    /// A direction with weight eval / pdf: `u1` picks a lobe, `u2` the direction within it.
    fn sample(&self, wi: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample>;

    // How the lane kernel (`integrator::lanes`) evaluates and samples eight hits at once.
    // The defaults call the methods above lane by lane, so every BSDF with a density runs
    // in lanes as it is; a BSDF overrides them only to share work between the light and the
    // BSDF sample of a hit, or to sample in vector lanes. Each override must give bitwise
    // what the methods above give (the lane tests compare every sample with `li`'s).

    /// The roughness (alpha_u, alpha_v) of a glossy reflection lobe, for the chi-square
    /// tests, which bin narrow lobes in a window fitted to them; None by default.
    fn glossy_lobe(&self) -> Option<(f32, f32)> {
        None
    }

    /// Whether the lane kernel shades this BSDF (every one with a density, by default); a
    /// BSDF whose lane methods cover only some of its parameters says which, and the rest
    /// shade lane by lane with `Direct::li_hit`.
    fn lane_covered(&self) -> bool {
        !Self::DELTA
    }
    /// A value the hit's two samples share, computed once per hit from wi (the rough
    /// conductor's Smith Lambda(wi)); 0 by default.
    #[inline(always)]
    fn lane_shared(&self, _wi: Vec3) -> f32 {
        0.0
    }
    /// `eval_pdf` given `lane_shared(wi)`.
    #[inline(always)]
    fn eval_pdf_shared(&self, wi: Vec3, wo: Vec3, _shared: f32) -> (Rgb, f32) {
        self.eval_pdf(wi, wo)
    }
    /// `sample` of every lane in `live`, lane i with its BSDF `b(i)`, wi, `lane_shared` and
    /// the numbers `u` (lobe, then the direction's two); lanes outside `live` hold garbage
    /// and get none.
    #[inline(always)]
    fn sample_lanes<'b>(
        b: impl Fn(usize) -> &'b Self + Copy,
        wi: &V3x8,
        _shared: &[f32; LANES],
        u: &[[f32; LANES]; 3],
        live: u32,
    ) -> BsdfSamples
    where
        Self: 'b,
    {
        sample_each(b, wi, u, live)
    }
}

/// `Bsdf::sample_lanes` lane by lane: `sample` of each lane in `live`.
#[inline(always)]
pub(crate) fn sample_each<'b, B: Bsdf + 'b>(
    b: impl Fn(usize) -> &'b B,
    wi: &V3x8,
    u: &[[f32; LANES]; 3],
    live: u32,
) -> BsdfSamples {
    // Every lane is sampled, garbage included, and then masked: a branch around the call
    // kept the loop from running in vector lanes.
    let mut out = BsdfSamples::default();
    let [u_lobe, u_x, u_y] = u;
    for i in 0..LANES {
        let s = b(i).sample(wi.get(i), u_lobe[i], Vec2::new(u_x[i], u_y[i]));
        out.set(i, s, live >> i & 1 != 0);
    }
    out
}

/// A generic operation on the BSDF a `BsdfKind` holds (`BsdfKind::visit`): how the lane
/// kernel gets from the closed set to code compiled for one BSDF type.
pub trait BsdfVisitor {
    /// What the operation returns.
    type Out;
    /// Runs the operation on `b`, compiled for its type.
    fn visit<B: Bsdf + Registered>(self, b: &B) -> Self::Out;
}

/// A registered BSDF type: which `BsdfKind` variant holds it.
pub trait Registered: Sized {
    /// The BSDF `kind` holds, if it is of this type.
    fn view(kind: &BsdfKind) -> Option<&Self>;
}

/// The registration: one line per BSDF, `Variant(Type) = "scene type name"`. It makes the
/// closed set `BsdfKind` (enum dispatch keeps the hot path free of virtual calls), its
/// dispatch, the parser's table and `REGISTERED`, the list every per-BSDF test loops over.
macro_rules! registry {
    ($($variant:ident($ty:ty) = $name:literal;)*) => {
        /// Closed set of materials, one variant per registered BSDF. Plain data, as large
        /// as its largest variant (rough plastic's table): a scene holds one per material
        /// and the estimator reads them in place.
        #[derive(Clone, Debug, PartialEq)]
        #[allow(clippy::large_enum_variant)]
        pub enum BsdfKind {
            $(#[doc = concat!("The `", $name, "` BSDF.")] $variant($ty),)*
        }

        /// The scene type names of the registered BSDFs.
        pub const REGISTERED: &[&str] = &[$($name,)*];

        $(impl Registered for $ty {
            #[inline(always)]
            fn view(kind: &BsdfKind) -> Option<&Self> {
                match kind {
                    BsdfKind::$variant(b) => Some(b),
                    #[allow(unreachable_patterns)]
                    _ => None,
                }
            }
        })*

        impl BsdfKind {
            /// The BSDF of scene type `ty` from its parameters; None for a type not registered.
            pub fn parse<P: Params>(ty: &str, p: &mut P) -> Option<Result<Self, P::Error>> {
                match ty {
                    $($name => Some(<$ty as Bsdf>::from_params(p).map(BsdfKind::$variant)),)*
                    _ => None,
                }
            }

            /// Whether every lobe of the BSDF it holds is a Dirac delta.
            pub fn is_delta(&self) -> bool {
                match self {
                    $(BsdfKind::$variant(_) => <$ty as Bsdf>::DELTA,)*
                }
            }

            /// `Bsdf::glossy_lobe` of the BSDF it holds.
            pub fn glossy_lobe(&self) -> Option<(f32, f32)> {
                match self {
                    $(BsdfKind::$variant(b) => Bsdf::glossy_lobe(b),)*
                }
            }

            /// `Bsdf::lane_covered` of the BSDF it holds.
            pub fn lane_covered(&self) -> bool {
                match self {
                    $(BsdfKind::$variant(b) => Bsdf::lane_covered(b),)*
                }
            }

            /// Whether some lobe of the BSDF it holds is a Dirac delta.
            pub fn has_delta_lobe(&self) -> bool {
                match self {
                    $(BsdfKind::$variant(_) => <$ty as Bsdf>::DELTA_LOBE,)*
                }
            }

            /// `v.visit` of the BSDF it holds.
            #[inline(always)]
            pub fn visit<V: BsdfVisitor>(&self, v: V) -> V::Out {
                match self {
                    $(BsdfKind::$variant(b) => v.visit(b),)*
                }
            }

            /// Its position in the registration: equal for two materials of the same type.
            pub fn index(&self) -> usize {
                let mut i = 0usize;
                $(
                    if let BsdfKind::$variant(_) = self {
                        return i;
                    }
                    i += 1;
                )*
                unreachable!("{i} registered BSDFs")
            }

            /// Its scene type name.
            pub fn type_name(&self) -> &'static str {
                match self {
                    $(BsdfKind::$variant(_) => $name,)*
                }
            }

            /// Whether `twosided` may wrap it.
            pub fn two_sided_ok(&self) -> bool {
                match self {
                    $(BsdfKind::$variant(_) => <$ty as Bsdf>::TWO_SIDED,)*
                }
            }

            #[inline]
            fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
                match self {
                    $(BsdfKind::$variant(b) => Bsdf::eval(b, wi, wo),)*
                }
            }

            #[inline]
            fn pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
                match self {
                    $(BsdfKind::$variant(b) => Bsdf::pdf(b, wi, wo),)*
                }
            }

            #[inline]
            fn eval_pdf(&self, wi: Vec3, wo: Vec3) -> (Rgb, f32) {
                match self {
                    $(BsdfKind::$variant(b) => Bsdf::eval_pdf(b, wi, wo),)*
                }
            }

            #[inline]
            fn sample(&self, wi: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
                match self {
                    $(BsdfKind::$variant(b) => Bsdf::sample(b, wi, u1, u2),)*
                }
            }
        }
    };
}

registry! {
    Diffuse(Diffuse) = "diffuse";
    Conductor(Conductor) = "conductor";
    RoughConductor(RoughConductor) = "roughconductor";
    Dielectric(Dielectric) = "dielectric";
    NoriMicrofacet(NoriMicrofacet) = "microfacet";
    Mirror(Mirror) = "mirror";
    Plastic(Plastic) = "plastic";
    RoughPlastic(RoughPlastic) = "roughplastic";
}

/// A material: a BSDF and whether it is used on both sides of the surface.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// The BSDF.
    pub kind: BsdfKind,
    /// Whether the BSDF is used on both sides (Mitsuba's `twosided`); otherwise the back side is black.
    pub two_sided: bool,
}

impl Material {
    /// Two-sided materials mirror the configuration into the upper hemisphere.
    #[inline]
    fn orient(&self, wi: Vec3, wo: Vec3) -> (Vec3, Vec3) {
        let (wi, flip) = Self::side(self.two_sided, wi);
        (wi, Self::mirror(flip, wo))
    }

    /// wi as a material of this sidedness hands it to its BSDF (mirrored into the upper
    /// hemisphere for a two-sided one seen from below), and whether it was mirrored.
    #[inline(always)]
    pub(crate) fn side(two_sided: bool, wi: Vec3) -> (Vec3, bool) {
        let flip = two_sided && wi.z < 0.0;
        (Self::mirror(flip, wi), flip)
    }

    /// v mirrored in the surface if `flip`.
    #[inline(always)]
    pub(crate) fn mirror(flip: bool, v: Vec3) -> Vec3 {
        if flip {
            Vec3::new(v.x, v.y, -v.z)
        } else {
            v
        }
    }

    /// True if every lobe is a Dirac delta (light sampling is then useless).
    pub fn is_delta(&self) -> bool {
        self.kind.is_delta()
    }

    /// True if some lobe is a Dirac delta (then light sampling misses its paths).
    pub fn has_delta_lobe(&self) -> bool {
        self.kind.has_delta_lobe()
    }

    /// f(wi, wo) cos(wo), in the local shading frame.
    #[inline]
    pub fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        let (wi, wo) = self.orient(wi, wo);
        self.kind.eval(wi, wo)
    }

    /// The solid-angle density with which `sample` draws `wo` given `wi`.
    #[inline]
    pub fn pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        let (wi, wo) = self.orient(wi, wo);
        self.kind.pdf(wi, wo)
    }

    /// `(eval, pdf)` with the work they share done once.
    #[inline]
    pub fn eval_pdf(&self, wi: Vec3, wo: Vec3) -> (Rgb, f32) {
        let (wi, wo) = self.orient(wi, wo);
        self.kind.eval_pdf(wi, wo)
    }

    /// `u1` picks a lobe, `u2` the direction within it: separate numbers for separate decisions.
    #[inline]
    pub fn sample(&self, wi: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        let (wi_up, flip) = Self::side(self.two_sided, wi);
        let mut s = self.kind.sample(wi_up, u1, u2)?;
        s.wo = Self::mirror(flip, s.wo);
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
        // eval_pdf is its own function (the estimator's): the same pair as eval and pdf.
        let (f_joint, pdf_joint) = m.eval_pdf(wi, s.wo);
        let f = m.eval(wi, s.wo);
        assert!(
            (pdf_joint - pdf).abs() <= 1e-6 * pdf
                && (f_joint - f).abs().max_element() <= 1e-6 * f.max_element(),
            "wi {wi} wo {}: eval_pdf ({f_joint}, {pdf_joint}) vs ({f}, {pdf})",
            s.wo
        );
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

    /// The diffuse Fresnel reflectance F_dr(eta) = 2 int_0^1 F(mu, eta) mu dmu of the f32
    /// Fresnel term, by Simpson's rule on 20k intervals in f64 (against which the fits of
    /// `fresnel_diffuse_reflectance` are tested).
    pub fn diffuse_fresnel_by_quadrature(eta: f32) -> f64 {
        let n = 20_000;
        let f = |mu: f64| super::fresnel::fresnel_dielectric(mu as f32, eta).0 as f64 * mu;
        let h = 1.0 / n as f64;
        let inner: f64 = (1..n)
            .map(|i| f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 })
            .sum();
        2.0 * (f(0.0) + f(1.0) + inner) * h / 3.0
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

#[cfg(test)]
mod tests {
    use super::params::Defaults;
    use super::*;
    use crate::rng::Rng;
    use crate::sampling::warps::square_to_uniform_sphere;

    /// A delta BSDF has no density: eval and pdf are 0 for every pair of directions, so that
    /// light samples and MIS weights never see its lobes; its samples say they are delta.
    #[test]
    fn delta_bsdfs_have_no_density() {
        let mut rng = Rng::new(11, 2);
        for ty in REGISTERED {
            let kind = BsdfKind::parse(ty, &mut Defaults).unwrap().unwrap();
            if !kind.is_delta() {
                continue;
            }
            let m = Material {
                kind,
                two_sided: false,
            };
            for _ in 0..1000 {
                let wi = square_to_uniform_sphere(rng.next_2d());
                let wo = square_to_uniform_sphere(rng.next_2d());
                assert_eq!(m.eval(wi, wo), Rgb::ZERO, "{ty}");
                assert_eq!(m.pdf(wi, wo), 0.0, "{ty}");
                assert_eq!(m.eval_pdf(wi, wo), (Rgb::ZERO, 0.0), "{ty}");
                if let Some(s) = m.sample(wi, rng.next_f32(), rng.next_2d()) {
                    assert!(s.delta, "{ty}");
                }
            }
        }
    }
}
