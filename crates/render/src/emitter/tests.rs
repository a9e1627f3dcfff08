//! Emitter-level checks by hand: power (which the power-proportional choice divides by, so
//! a wrong power stays unbiased and only the variance shows it) and the point light's sample.

use super::*;
use crate::scene::desc::PointLightDesc;
use crate::scene::fixtures::{diffuse, mesh, shapes_only, sphere};
use crate::scene::Scene;

fn scene_with_lights() -> Scene {
    // A 2 x 3 rectangle (area 6) and a sphere of radius 0.5 (area pi), plus a point light.
    let rect = mesh(
        vec![
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(2.0, 0.0, 1.0),
            Vec3::new(2.0, 3.0, 1.0),
            Vec3::new(0.0, 3.0, 1.0),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
        diffuse(0.0),
        Some(Rgb::new(1.0, 2.0, 3.0)),
    );
    let ball = sphere(
        Vec3::new(5.0, 0.0, 0.0),
        0.5,
        diffuse(0.0),
        Some(Rgb::splat(4.0)),
    );
    let mut d = shapes_only(vec![rect, ball]);
    d.point_lights.push(PointLightDesc {
        position: Vec3::new(4.0, 6.0, 3.0),
        intensity: Rgb::new(2.0, 2.0, 2.0),
        origin: "<test>".into(),
    });
    Scene::build(d).unwrap()
}

#[test]
fn power_is_pi_area_radiance_and_four_pi_intensity() {
    let s = scene_with_lights();
    let lum = 0.212_671 + 0.715_160 * 2.0 + 0.072_169 * 3.0;
    let expected = [
        std::f64::consts::PI * 6.0 * lum,
        std::f64::consts::PI * std::f64::consts::PI * 4.0,
        4.0 * std::f64::consts::PI * 2.0,
    ];
    assert_eq!(s.emitters.len(), 3);
    for (e, want) in s.emitters.iter().zip(expected) {
        assert!(
            (e.power() - want).abs() <= 1e-5 * want,
            "{} against {want}",
            e.power()
        );
    }
    assert_eq!(
        s.emitters.iter().map(Emitter::is_delta).collect::<Vec<_>>(),
        [false, false, true]
    );
}

#[test]
fn point_light_sample_by_hand() {
    let s = scene_with_lights();
    let pl = &s.emitters[2];
    let ref_p = Vec3::new(1.0, 2.0, 3.0);
    // d = (3, 4, 0): distance 5.
    for mode in [LightSampling::Area, LightSampling::SolidAngle] {
        let ls = pl
            .sample(&s.shapes, ref_p, 0.3, Vec2::new(0.1, 0.9), mode)
            .unwrap();
        let wi = Vec3::new(0.6, 0.8, 0.0);
        assert!((ls.wi - wi).length() < 1e-6, "{:?}", ls.wi);
        assert!((ls.ng + wi).length() < 1e-6, "{:?}", ls.ng);
        assert_eq!(ls.p, Vec3::new(4.0, 6.0, 3.0));
        assert!((ls.dist - 5.0).abs() < 1e-6);
        assert!((ls.li - Rgb::splat(2.0 / 25.0)).abs().max_element() < 1e-7);
        assert_eq!((ls.pdf, ls.delta), (1.0, true));
        assert_eq!(ls.err_scale, Vec3::ZERO);
        // Seen from the light's own position there is no direction.
        assert!(pl
            .sample(
                &s.shapes,
                Vec3::new(4.0, 6.0, 3.0),
                0.3,
                Vec2::splat(0.5),
                mode
            )
            .is_none());
        // Nor from infinitely far away.
        assert!(pl
            .sample(
                &s.shapes,
                Vec3::new(f32::MAX, 0.0, 0.0),
                0.3,
                Vec2::splat(0.5),
                mode
            )
            .is_none());
    }
}

/// One-sided emission ends exactly at the shading normal's horizon (Mitsuba and Nori emit
/// only where cos > 0), and an edge-on light point has density 0, not infinity.
#[test]
fn grazing_light_points_emit_nothing_and_have_no_density() {
    use crate::geometry::SurfacePoint;
    let sp = SurfacePoint {
        p: Vec3::ZERO,
        ng: Vec3::Z,
        ns: Vec3::Y,
        shape: 0,
        prim: 0,
        err_scale: Vec3::ZERO,
    };
    // wi has no y component, so the shading cosine is exactly zero; the geometric one is not.
    let ref_p = Vec3::new(1.0, 0.0, 1.0);
    assert!(sample_at(Rgb::ONE, ref_p, &sp, |_, _| 1.0).is_none());
    let lit = SurfacePoint { ns: Vec3::Z, ..sp };
    // A density that is zero, infinite or NaN makes no sample.
    for bad in [0.0, f32::INFINITY, f32::NAN] {
        assert!(
            sample_at(Rgb::ONE, ref_p, &lit, |_, _| bad).is_none(),
            "{bad}"
        );
    }
    let ls = sample_at(Rgb::ONE, ref_p, &lit, |wi, d| {
        area_pdf_along(2.0, &lit, wi, d)
    })
    .unwrap();
    // dist^2 / (area cos) = 2 / (2 * cos 45°).
    assert!(
        (ls.pdf - std::f32::consts::SQRT_2).abs() < 1e-6,
        "{}",
        ls.pdf
    );
    assert_eq!(area_pdf_along(2.0, &lit, Vec3::X, 1.0), 0.0);
    // Radiance leaves only above the shading horizon.
    let s = scene_with_lights();
    let Emitter::Area(rect) = &s.emitters[0] else {
        unreachable!()
    };
    assert_eq!(rect.le(&lit, Vec3::Z), Rgb::new(1.0, 2.0, 3.0));
    assert_eq!(rect.le(&lit, Vec3::X), Rgb::ZERO);
    assert_eq!(rect.le(&lit, -Vec3::Z), Rgb::ZERO);
}

/// A sphere seen from outside is sampled in its cone, with density 1 / (2 pi (1 - cos
/// theta_max)) and every direction inside the cone; from inside, from a point within the
/// 1e-5 margin of its surface, or when its normals point inwards, by area.
#[test]
fn sphere_light_uses_its_cone_exactly_when_seen_from_outside() {
    let mut rng = crate::rng::Rng::new(3, 0);
    let outside = ball(false);
    // At 1.2 radii the point is outside by far more than the margin of 1e-5 in dc^2 / r^2.
    for ref_p in [
        C + Vec3::new(2.0, 0.0, 0.0),
        C + Vec3::new(0.0, -3.0, 4.0),
        C + Vec3::new(0.0, 1.2, 0.0),
    ] {
        let d2 = (ref_p - C).length_squared();
        let one_minus = 1.0 - (1.0 - 1.0 / d2).sqrt();
        let cos_max = 1.0 - one_minus;
        let (mut n, mut sum_cos) = (0, 0.0f64);
        for _ in 0..2000 {
            let u = Vec2::new(rng.next_f32(), rng.next_f32());
            let Some(ls) = outside.emitters[0].sample(
                &outside.shapes,
                ref_p,
                0.5,
                u,
                LightSampling::SolidAngle,
            ) else {
                continue;
            };
            n += 1;
            sum_cos += ls.wi.dot((C - ref_p).normalize()) as f64;
            let want = 1.0 / (2.0 * PI * one_minus);
            assert!(
                (ls.pdf / want - 1.0).abs() < 1e-4,
                "{} against {want}",
                ls.pdf
            );
            assert!(ls.wi.dot((C - ref_p).normalize()) >= cos_max - 1e-5);
            // The point is the first hit of the ray along wi.
            assert!(((ls.p - C).length() - 1.0).abs() < 1e-5, "{}", ls.p);
            assert!(((ls.p - ref_p).normalize() - ls.wi).length() < 1e-5);
            assert!(((ls.p - ref_p).length() - ls.dist).abs() < 1e-5);
            assert!(ls.ng.dot(ls.wi) < 0.0);
            let pdf = outside.emitters[0].pdf(
                &outside.shapes,
                ref_p,
                &point_of(&ls),
                LightSampling::SolidAngle,
            );
            assert!((pdf / want - 1.0).abs() < 1e-4, "{pdf} against {want}");
        }
        // Every direction in the cone meets the sphere's near side, which faces the point.
        assert!(n >= 1990, "{ref_p}: only {n} of 2000 cone samples");
        // Uniform in the cone: cos theta uniform on [cos_max, 1], so its mean is off by more
        // than 5 standard errors with probability 6e-7.
        let (mean, want) = (sum_cos / n as f64, (1.0 + cos_max as f64) / 2.0);
        let se = one_minus as f64 / 12f64.sqrt() / (n as f64).sqrt();
        assert!(
            (mean - want).abs() < 5.0 * se,
            "{ref_p}: mean cos {mean} against {want}"
        );
    }
}

/// Seen from inside, or with its normals inwards, or within the margin of its surface, a
/// sphere light is sampled by area, as `sphere_light_uses_its_cone_exactly_when_seen_from_outside`'s
/// other side.
#[test]
fn sphere_light_is_sampled_by_area_where_its_cone_does_not_apply() {
    use crate::sampling::warps::square_to_uniform_sphere;
    let mut rng = crate::rng::Rng::new(3, 1);
    let outside = ball(false);
    // Inside (lit where the normals point inwards), just outside the surface (within the
    // margin), and inward normals from outside: uniform points on the sphere, by area.
    let cases = [
        (ball(true), C + Vec3::new(0.2, 0.1, -0.3)),
        (ball(true), C + Vec3::new(3.0, 0.0, 0.0)),
    ];
    for (s, ref_p) in &cases {
        let mut n = 0;
        for _ in 0..200 {
            let u = Vec2::new(rng.next_f32(), rng.next_f32());
            let Some(ls) =
                s.emitters[0].sample(&s.shapes, *ref_p, 0.5, u, LightSampling::SolidAngle)
            else {
                continue;
            };
            n += 1;
            // The point is where area sampling puts it for these numbers.
            assert!(
                (ls.p - C - square_to_uniform_sphere(u)).length() < 1e-5,
                "{ref_p}"
            );
            let (pdf, eval, want) = by_area(s, *ref_p, &ls);
            assert!(
                (pdf / want - 1.0).abs() < 1e-4,
                "{ref_p}: {pdf} against {want}"
            );
            assert!(
                (eval / want - 1.0).abs() < 1e-4,
                "{ref_p}: {eval} against {want}"
            );
        }
        assert!(n > 20, "{ref_p}: only {n} samples face the point");
    }
    // Within the margin almost no uniform point faces the reference point: the density of
    // the nearest one tells area from cone.
    let ref_p = C + Vec3::new(1.000_002_5, 0.0, 0.0);
    let near = LightSample {
        p: C + Vec3::X,
        ng: Vec3::X,
        err_scale: Vec3::ZERO,
        wi: Vec3::NEG_X,
        dist: (ref_p - C).x - 1.0,
        li: Rgb::ONE,
        pdf: 0.0,
        delta: false,
    };
    let (_, eval, want) = by_area(&outside, ref_p, &near);
    assert!((eval / want - 1.0).abs() < 1e-3, "{eval} against {want}");
}

/// Centre of the test sphere: off the origin, so that centre - p and p - centre differ.
const C: Vec3 = Vec3::new(0.5, -1.0, 2.0);

/// A unit sphere light at `C`, its normals inwards with `flip`.
fn ball(flip: bool) -> Scene {
    let mut d = shapes_only(vec![sphere(C, 1.0, diffuse(0.0), Some(Rgb::ONE))]);
    if let crate::scene::desc::ShapeGeometry::Sphere { flip_normals, .. } =
        &mut d.shapes[0].geometry
    {
        *flip_normals = flip;
    }
    Scene::build(d).unwrap()
}

/// A sphere sample's reported density, `pdf()`'s, and the area density in solid angle.
fn by_area(s: &Scene, ref_p: Vec3, ls: &LightSample) -> (f32, f32, f32) {
    let cos_l = ls.ng.dot(ls.wi).abs();
    let want = ls.dist * ls.dist / (4.0 * PI * cos_l);
    let got = s.emitters[0].pdf(&s.shapes, ref_p, &point_of(ls), LightSampling::SolidAngle);
    (ls.pdf, got, want)
}

/// The surface point a light sample names, as a BSDF ray would find it.
fn point_of(ls: &LightSample) -> crate::geometry::SurfacePoint {
    crate::geometry::SurfacePoint {
        p: ls.p,
        ng: ls.ng,
        ns: ls.ng,
        shape: 0,
        prim: 0,
        err_scale: ls.err_scale,
    }
}
