//! Coated materials in the white furnace, seen at one point, for every strategy: plastic
//! (a delta coating, which light sampling reaches only through its BSDF samples for that
//! lobe) and rough plastic (whose whole albedo has a density). z-tests at `ALPHA`, Sidak over
//! strategies and both emitter layouts.

use super::tests::{all_strategies, image_z, settings, z_critical, ALPHA};
use crate::bsdf::{BsdfKind, Material};
use crate::render::render;
use crate::scene::{fixtures, Scene};

/// The cosine of incidence at the furnace's centre pixel with fov 1e-3 degrees: the camera
/// ray meets the far face at 1.5 / sqrt(2.65).
fn cos_i() -> f32 {
    1.5 / 2.65f32.sqrt()
}

/// Every strategy renders `expected` at the furnace's centre for material `kind`.
fn furnace_at_one_point(kind: BsdfKind, expected: f64, spp: u32) {
    let strategies = all_strategies();
    let zc = z_critical(ALPHA, strategies.len() * 2);
    for split in [false, true] {
        let mut desc = fixtures::furnace(0.5, split, 1);
        desc.camera.fov_degrees = 1e-3;
        for shape in &mut desc.shapes {
            shape.bsdf = fixtures::one_sided(kind.clone());
        }
        let scene = Scene::build(desc).unwrap();
        for st in &strategies {
            let out = render(&scene, *st, &settings(spp, 3));
            assert_eq!(out.non_finite_samples, 0);
            let (z, mean) = image_z(&out, expected);
            assert!(
                z.abs() < zc,
                "{} {} split={split}: mean {mean} vs {expected}, z = {z:.2} (critical {zc:.2})",
                kind.type_name(),
                st.label()
            );
        }
    }
}

/// Plastic (a delta coating over a diffuse base) in the white furnace, seen at one point
/// (one pixel, fov 1e-3 degrees, cos_i = 1.5 / sqrt(2.65) on the far face): every strategy
/// must give 1 + s F(cos_i) + (1 - F(cos_i)) d / (eta^2 (1 - F_dr,int)) (1 - F_dr,ext),
/// with F_dr,ext by quadrature. Light sampling reaches the coating's reflection only through
/// its BSDF samples for the delta lobe; without them it misses s F(cos_i) = 0.047.
#[test]
fn plastic_furnace_for_every_strategy() {
    use crate::bsdf::fresnel::fresnel_dielectric;
    use crate::bsdf::Plastic;
    use crate::math::Rgb;
    let (eta, d, s) = (1.5f32, 0.6f32, 0.9f32);
    let plastic = Plastic::new(eta, Rgb::splat(d), Rgb::splat(s), false);
    let cos_i = cos_i();
    let f_i = fresnel_dielectric(cos_i, eta).0 as f64;
    let fdr_int = crate::bsdf::fresnel::fresnel_diffuse_reflectance(1.0 / eta) as f64;
    let eta2 = (eta * eta) as f64;
    let expected = 1.0
        + s as f64 * f_i
        + (1.0 - f_i) * d as f64 / (eta2 * (1.0 - fdr_int))
            * (1.0 - crate::bsdf::testing::diffuse_fresnel_by_quadrature(eta));
    furnace_at_one_point(BsdfKind::Plastic(plastic), expected, 40_000);
}

/// Rough plastic (GGX, alpha 0.3, linear) in the same furnace: every strategy must give
/// 1 + its albedo at cos_i, the integral of eval by adaptive quadrature (to about 1e-7 per
/// cell, independent of the sampler). Light sampling and MIS see all of it through eval and
/// pdf, BSDF sampling through sample: a mistake in any one of them moves that strategy.
#[test]
fn roughplastic_furnace_for_every_strategy() {
    use crate::bsdf::RoughPlastic;
    use crate::math::Rgb;
    use crate::sampling::microfacet::{Microfacet, MicrofacetDistribution};
    use crate::sampling::quadrature::LobeGrid;
    use glam::Vec3;
    let mf = Microfacet::new(MicrofacetDistribution::Ggx, 0.3, 0.3);
    let rp = RoughPlastic::new(mf, true, 1.5, Rgb::splat(0.6), Rgb::splat(0.9), false);
    let m = Material {
        kind: BsdfKind::RoughPlastic(rp),
        two_sided: false,
    };
    let c = cos_i();
    let wi = Vec3::new((1.0 - c * c).sqrt(), 0.0, c);
    let albedo = LobeGrid::around_normal(1.0).integrate(|wo| m.eval(wi, wo).x as f64);
    assert!((0.3..1.0).contains(&albedo), "albedo {albedo}");
    furnace_at_one_point(m.kind, 1.0 + albedo, 40_000);
}
