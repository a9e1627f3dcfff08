//! End-to-end estimator tests on scenes with known answers. Each statistical assertion is a
//! two-sided z- or t-test of the image mean (pixels are independent, so its variance is the
//! sum of the per-pixel variances over N^2), Sidak-corrected over the cases of its test.
//!
//! Family-wise significance is `ALPHA` = 1e-3 per test function: with about ten such
//! families, a change that reshuffles the random numbers false-alarms somewhere with
//! probability ~1% (at 0.01 it was ~10%, and it happened: z = 3.77 vs 3.50 at one seed). The
//! defects these tests exist for give |z| of 10 to 100+.

use super::Strategy;
use crate::emitter::EmitterSelection;
use crate::render::{render, RenderOutput, RenderSettings};
use crate::scene::desc::StrategyKind;
use crate::scene::{fixtures, Scene};
use glam::Vec3;
use statrs::distribution::{ContinuousCDF, Normal};

/// Family-wise significance of every test in this module (see the module comment).
pub(crate) const ALPHA: f64 = 1e-3;

pub(crate) fn all_strategies() -> Vec<Strategy> {
    Strategy::combinations()
}

/// Two-sided critical |z| at level alpha, Sidak-corrected for `m` tests.
pub(crate) fn z_critical(alpha: f64, m: usize) -> f64 {
    let a = 1.0 - (1.0 - alpha).powf(1.0 / m as f64);
    Normal::new(0.0, 1.0).unwrap().inverse_cdf(1.0 - a / 2.0)
}

/// z statistic of the image mean of channel 0 against `expected`. A zero-variance estimate
/// (BSDF sampling in a furnace) must be exact up to f32 rounding: that case returns z = 0
/// only if it is within 1e-6 relative, and infinity otherwise.
pub(crate) fn image_z(out: &RenderOutput, expected: f64) -> (f64, f64) {
    let n = out.mean.data.len() as f64;
    let mean = out.mean.data.iter().map(|p| p[0]).sum::<f64>() / n;
    let var = out.variance.data.iter().map(|p| p[0]).sum::<f64>() / (n * n);
    if var == 0.0 {
        let exact = (mean - expected).abs() <= 1e-6 * expected.abs();
        return (if exact { 0.0 } else { f64::INFINITY }, mean);
    }
    ((mean - expected) / var.sqrt(), mean)
}

pub(crate) fn settings(spp: u32, seed: u64) -> RenderSettings {
    RenderSettings::new(spp, seed)
}

#[test]
fn furnace_renders_one_plus_albedo_for_every_strategy() {
    let albedo = 0.6;
    let strategies = all_strategies();
    let zc = z_critical(ALPHA, strategies.len() * 2);
    for split in [false, true] {
        let scene = Scene::build(fixtures::furnace(albedo, split, 16)).unwrap();
        for s in &strategies {
            let out = render(&scene, *s, &settings(32, 1));
            assert_eq!(out.non_finite_samples, 0);
            let (z, mean) = image_z(&out, 1.0 + albedo as f64);
            assert!(
                z.abs() < zc,
                "{} split={split}: mean {mean} vs {}, z = {z:.2} (critical {zc:.2})",
                s.label(),
                1.0 + albedo
            );
        }
    }
}

#[test]
fn furnace_catches_a_missing_emitter_pmf() {
    // The study's bug: with six emitters, forgetting to divide by pmf = 1/6 scales the
    // reflected term by 1/6. The test above must be able to see an error of that size.
    let scene = Scene::build(fixtures::furnace(0.6, true, 16)).unwrap();
    let out = render(&scene, all_strategies()[0], &settings(32, 1));
    let (z, _) = image_z(&out, 1.0 + 0.6 / 6.0);
    assert!(
        z.abs() > 10.0,
        "a biased reference value must be rejected, z = {z}"
    );
}

#[test]
fn same_seed_same_bytes_for_any_thread_count() {
    let scene = Scene::build(fixtures::furnace(0.5, true, 24)).unwrap();
    let s = Strategy::from_desc(&scene.desc.integrator);
    let mut a = settings(8, 7);
    a.threads = Some(1);
    let mut b = a.clone();
    b.threads = Some(2);
    let (ra, rb) = (render(&scene, s, &a), render(&scene, s, &b));
    let bytes = |o: &RenderOutput| {
        o.mean
            .data
            .iter()
            .flat_map(|p| p.map(f64::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(bytes(&ra), bytes(&rb));
    let mut c = a.clone();
    c.seed = 8;
    assert_ne!(
        bytes(&ra),
        bytes(&render(&scene, s, &c)),
        "a different seed must change the image"
    );
}

/// Lambert: a sphere of radiance L, radius r, centre at distance d and angle theta from the
/// receiver's normal, entirely above the horizon, gives E = pi L (r/d)^2 cos(theta).
#[test]
fn sphere_light_matches_closed_form_for_every_strategy() {
    let (albedo, radiance) = (0.7f32, 3.0f32);
    let cases = [
        (Vec3::new(0.0, 0.0, 2.0), 0.5, Vec3::new(3.0, 0.0, 1.0)),
        (Vec3::new(1.5, 0.5, 1.0), 0.3, Vec3::new(-2.0, 0.0, 2.0)),
        (Vec3::new(0.0, 0.2, 0.25), 0.2, Vec3::new(0.0, -3.0, 3.0)),
    ];
    let strategies = all_strategies();
    let zc = z_critical(ALPHA, strategies.len() * cases.len());
    for (c, r, eye) in cases {
        let d = c.length();
        let expected = (albedo as f64 / std::f64::consts::PI)
            * std::f64::consts::PI
            * radiance as f64
            * (r as f64 / d as f64).powi(2)
            * (c.z / d) as f64;
        let scene = Scene::build(fixtures::light_over_floor(
            fixtures::sphere_light(c, r, radiance),
            albedo,
            Vec3::ZERO,
            eye,
        ))
        .unwrap();
        for s in &strategies {
            // BSDF sampling of a small light is noisy: give it more samples.
            let spp = if s.kind == StrategyKind::Bsdf {
                200_000
            } else {
                20_000
            };
            let out = render(&scene, *s, &settings(spp, 3));
            assert_eq!(out.non_finite_samples, 0);
            let (z, mean) = image_z(&out, expected);
            assert!(
                z.abs() < zc,
                "{} sphere {c} r {r}: {mean} vs {expected}, z = {z:.2} (critical {zc:.2})",
                s.label()
            );
        }
    }
}

/// Self-intersection and shadow leaks at any scene scale: the furnace, scaled by 1e-3 .. 1e4
/// and moved away from the origin (where absolute rounding error grows), still renders 1 + a.
#[test]
fn furnace_holds_at_every_scene_scale() {
    let albedo = 0.5;
    let scales = [1e-3f32, 1e-1, 1e2, 1e4];
    let strategies = [all_strategies()[1], all_strategies()[6]];
    let zc = z_critical(ALPHA, scales.len() * 2 * strategies.len());
    for scale in scales {
        for shift in [0.0f32, 10.0] {
            let mut desc = fixtures::furnace(albedo, true, 16);
            let m = glam::Mat4::from_translation(Vec3::splat(shift * scale))
                * glam::Mat4::from_scale(Vec3::splat(scale));
            fixtures::transform(&mut desc, m);
            let scene = Scene::build(desc).unwrap();
            for s in strategies {
                let out = render(&scene, s, &settings(32, 5));
                assert_eq!(out.non_finite_samples, 0);
                let (z, mean) = image_z(&out, 1.0 + albedo as f64);
                assert!(
                    z.abs() < zc,
                    "{} scale {scale} shift {shift}: {mean}, z = {z:.2}",
                    s.label()
                );
            }
        }
    }
}

/// Point lights (delta): E = I cos(theta) / d^2. Every strategy must see them, BSDF sampling
/// included (it falls back to light sampling for delta lights). Mixed with an area light
/// so that MIS and emitter choice are exercised together. z-test, ALPHA, Sidak.
#[test]
fn point_lights_match_closed_form_for_every_strategy() {
    use crate::scene::desc::PointLightDesc;
    let albedo = 0.8f32;
    let (pos, intensity) = (Vec3::new(0.5, -0.3, 1.5), 2.0f32);
    let (c, r, radiance) = (Vec3::new(-1.0, 0.5, 1.0), 0.25f32, 4.0f32);
    let mut desc = fixtures::light_over_floor(
        fixtures::sphere_light(c, r, radiance),
        albedo,
        Vec3::ZERO,
        Vec3::new(0.0, -3.0, 3.0),
    );
    desc.point_lights.push(PointLightDesc {
        position: pos,
        intensity: crate::math::Rgb::splat(intensity),
        origin: "<test>".into(),
    });
    let scene = Scene::build(desc).unwrap();
    let d2 = pos.length_squared() as f64;
    let e_point = intensity as f64 * (pos.z as f64 / d2.sqrt()) / d2;
    let dc = c.length() as f64;
    let e_sphere =
        std::f64::consts::PI * radiance as f64 * (r as f64 / dc).powi(2) * (c.z as f64 / dc);
    let expected = albedo as f64 / std::f64::consts::PI * (e_point + e_sphere);
    let strategies = all_strategies();
    let zc = z_critical(ALPHA, strategies.len());
    for s in &strategies {
        let spp = if s.kind == StrategyKind::Bsdf {
            200_000
        } else {
            50_000
        };
        let out = render(&scene, *s, &settings(spp, 9));
        assert_eq!(out.non_finite_samples, 0);
        let (z, mean) = image_z(&out, expected);
        assert!(
            z.abs() < zc,
            "{}: {mean} vs {expected}, z = {z:.2} (critical {zc:.2})",
            s.label()
        );
    }
}

/// The MIS weights are the heuristic the strategy names, over its sample counts, and not just
/// any partition of unity. Every partition of unity is unbiased, so the image mean cannot see a
/// weight that is wrong; the variance can. A diffuse receiver (albedo a) at the centre of an
/// inward-facing emitting sphere (radiance L): a light sample has solid-angle density 1/(4 pi)
/// in every direction and a BSDF sample cos/pi, so, with c the cosine, a light sample is worth
/// 4 a L c w_l(c) above the horizon (0 below, probability 1/2) and a BSDF sample a L w_b(c).
/// With w_l = h(ne / 4pi, nb c / pi) and w_b = h(nb c / pi, ne / 4pi) (h the balance or power
/// heuristic), the variance of one pixel sample follows by quadrature; for one-sample MIS the
/// counts become the technique probabilities and the value is divided by its probability.
///
/// The measured sample variance (2^20 samples of one pixel; relative standard error about
/// 0.3 % for these bounded values) must be within 3 % of the prediction. The wrong weights
/// this is for move it by 1.3x to 2.7x (power computed as balance or the reverse; the counts
/// left out of the weights at ne = 2, nb = 3), which the test asserts of its own predictions.
#[test]
fn mis_variance_is_the_named_heuristics_with_its_sample_counts() {
    use crate::emitter::LightSampling;
    use crate::scene::desc::{AreaEmitterDesc, Heuristic, ShapeDesc, ShapeGeometry};
    use std::f64::consts::PI;
    let (albedo, radiance) = (0.5f32, 2.0f32);
    let mut desc = fixtures::floor_probe(albedo, Vec3::ZERO, Vec3::new(0.0, 0.0, 0.5));
    desc.shapes.push(ShapeDesc {
        geometry: ShapeGeometry::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
            flip_normals: true,
        },
        bsdf: fixtures::diffuse(0.0),
        emitter: Some(AreaEmitterDesc {
            radiance: crate::math::Rgb::splat(radiance),
        }),
        origin: "<enclosing sphere>".into(),
    });
    let scene = Scene::build(desc).unwrap();
    let al = (albedo * radiance) as f64;

    let h = |k: Heuristic, a: f64, b: f64| match k {
        Heuristic::Balance => a / (a + b),
        Heuristic::Power => a * a / (a * a + b * b),
    };
    let quad = |f: &dyn Fn(f64) -> f64| {
        let n = 20_000;
        (0..n).map(|i| f((i as f64 + 0.5) / n as f64)).sum::<f64>() / n as f64
    };
    // (mean, variance) of one pixel sample; `wn` are the counts the weights use.
    let predict = |kind: StrategyKind, k: Heuristic, n: (f64, f64), wn: (f64, f64)| {
        let (pl, pb) = (1.0 / (4.0 * PI), |c: f64| c / PI);
        let x = |c: f64| 4.0 * al * c * h(k, wn.0 * pl, wn.1 * pb(c));
        let y = |c: f64| al * h(k, wn.1 * pb(c), wn.0 * pl);
        let ex = |p: i32| quad(&|c| x(c).powi(p) * 0.5);
        let ey = |p: i32| quad(&|c| y(c).powi(p) * 2.0 * c);
        match kind {
            StrategyKind::MisOneSample => {
                let m = ex(1) + ey(1);
                (m, ex(2) / wn.0 + ey(2) / wn.1 - m * m)
            }
            _ => (
                ex(1) + ey(1),
                (ex(2) - ex(1).powi(2)) / n.0 + (ey(2) - ey(1).powi(2)) / n.1,
            ),
        }
    };
    for kind in [StrategyKind::Mis, StrategyKind::MisOneSample] {
        for heuristic in [Heuristic::Balance, Heuristic::Power] {
            for (ne, nb) in [(1u32, 1u32), (2, 3)] {
                let s = Strategy {
                    kind,
                    heuristic,
                    emitter_samples: ne,
                    bsdf_samples: nb,
                    selection: EmitterSelection::Uniform,
                    light_sampling: LightSampling::Area,
                    hide_emitters: false,
                };
                let n = (ne as f64, nb as f64);
                // One-sample MIS weighs by the technique probabilities.
                let wn = match kind {
                    StrategyKind::MisOneSample => (n.0 / (n.0 + n.1), n.1 / (n.0 + n.1)),
                    _ => n,
                };
                let (mean, var) = predict(kind, heuristic, n, wn);
                assert!((mean - al).abs() < 1e-6 * al, "the prediction is unbiased");
                let other = match heuristic {
                    Heuristic::Balance => Heuristic::Power,
                    Heuristic::Power => Heuristic::Balance,
                };
                let wrong = predict(kind, other, n, wn).1;
                assert!((wrong / var - 1.0).abs() > 0.25, "{s:?}: {wrong} vs {var}");
                if kind == StrategyKind::Mis && ne != nb {
                    let dropped = predict(kind, heuristic, n, (1.0, 1.0)).1;
                    assert!(
                        (dropped / var - 1.0).abs() > 0.25,
                        "{s:?}: {dropped} vs {var}"
                    );
                }
                let spp = 1 << 20;
                let out = render(&scene, s, &settings(spp, 17));
                let measured = out.variance.data[0][0] * spp as f64;
                let got = out.mean.data[0][0];
                assert!((got - al).abs() < 0.01 * al, "{}: mean {got}", s.label());
                assert!(
                    (measured / var - 1.0).abs() < 0.03,
                    "{}: sample variance {measured}, predicted {var}",
                    s.label()
                );
            }
        }
    }
}

/// Paths only one technique can make, at sample counts 2 (light) and 3 (BSDF), so that each
/// technique's division by its own count and each fallback matters: a mirror floor under a
/// large emitting quad (every strategy sees L through the mirror; light sampling through its
/// fallback to BSDF samples) and a point light over a diffuse floor (BSDF sampling through
/// its fallback to light samples). Most strategies are exact here (zero variance: the value
/// must be within 1e-6); one-sample MIS is z-tested (ALPHA, Sidak over all cases).
#[test]
fn delta_paths_at_sample_counts_two_and_three() {
    use crate::bsdf::{BsdfKind, Mirror};
    use crate::scene::desc::PointLightDesc;
    let radiance = 3.0f32;
    let mut mirror = fixtures::floor_probe(0.5, Vec3::ZERO, Vec3::new(0.0, -3.0, 3.0));
    mirror.shapes[0].bsdf = fixtures::one_sided(BsdfKind::Mirror(Mirror));
    // At z = 4, facing down: the mirrored camera ray, direction (0, 1, 1) / sqrt 2, meets it
    // at y = 4.
    mirror.shapes.push(fixtures::square_z(
        10.0,
        4.0,
        false,
        fixtures::diffuse(0.0),
        Some(crate::math::Rgb::splat(radiance)),
    ));
    let albedo = 0.8f32;
    let (pos, intensity) = (Vec3::new(0.5, -0.3, 1.5), 2.0f32);
    let mut point = fixtures::floor_probe(albedo, Vec3::ZERO, Vec3::new(0.0, -3.0, 3.0));
    point.point_lights.push(PointLightDesc {
        position: pos,
        intensity: crate::math::Rgb::splat(intensity),
        origin: "<test>".into(),
    });
    let d2 = pos.length_squared() as f64;
    let e_point = intensity as f64 * (pos.z as f64 / d2.sqrt()) / d2;
    let cases = [
        (Scene::build(mirror).unwrap(), radiance as f64),
        (
            Scene::build(point).unwrap(),
            albedo as f64 / std::f64::consts::PI * e_point,
        ),
    ];
    let strategies: Vec<Strategy> = all_strategies()
        .into_iter()
        .map(|s| Strategy {
            emitter_samples: 2,
            bsdf_samples: 3,
            ..s
        })
        .collect();
    let zc = z_critical(ALPHA, strategies.len() * cases.len());
    for (scene, expected) in &cases {
        for s in &strategies {
            let out = render(scene, *s, &settings(4096, 5));
            assert_eq!(out.non_finite_samples, 0);
            let (z, mean) = image_z(&out, *expected);
            assert!(
                z.abs() < zc,
                "{} on {}: {mean} vs {expected}, z = {z:.2} (critical {zc:.2})",
                s.label(),
                if scene.emitters[0].is_delta() {
                    "the point light"
                } else {
                    "the mirror"
                }
            );
        }
    }
}

/// The estimator draws its sampler's groups in the order `crate::sampler` documents, for every
/// strategy at 2 light and 3 BSDF samples: on a diffuse floor under an area light, a mirror
/// floor (delta BSDF: BSDF groups in place of light groups) and a diffuse floor under a point
/// light (BSDF sampling adds a light group per BSDF sample), and plastic (light sampling adds
/// a BSDF group per light group for its delta coating). 64 camera samples each, so that
/// one-sample MIS picks both techniques.
#[test]
fn estimator_draws_the_documented_dimension_groups() {
    use crate::bsdf::{BsdfKind, Mirror};
    use crate::rng::Rng;
    use crate::sampler::{BsdfDims, LightDims, Sampler};
    use crate::scene::desc::PointLightDesc;
    struct Recorder(Rng, String);
    impl Sampler for Recorder {
        fn film(&mut self) -> glam::Vec2 {
            self.1.push('f');
            self.0.film()
        }
        fn technique(&mut self) -> f32 {
            self.1.push('t');
            self.0.technique()
        }
        fn light(&mut self) -> LightDims {
            self.1.push('L');
            self.0.light()
        }
        fn bsdf(&mut self) -> BsdfDims {
            self.1.push('B');
            self.0.bsdf()
        }
    }
    let eye = Vec3::new(0.0, -3.0, 3.0);
    let light = fixtures::square_z(1.0, 2.0, false, fixtures::diffuse(0.0), Some(Vec3::ONE));
    let diffuse = fixtures::light_over_floor(light.clone(), 0.5, Vec3::ZERO, eye);
    let mut mirror = fixtures::light_over_floor(light, 0.5, Vec3::ZERO, eye);
    mirror.shapes[0].bsdf = fixtures::one_sided(BsdfKind::Mirror(Mirror));
    let mut point = fixtures::floor_probe(0.5, Vec3::ZERO, eye);
    point.point_lights.push(PointLightDesc {
        position: Vec3::new(0.0, 0.0, 2.0),
        intensity: Vec3::ONE,
        origin: "<test>".into(),
    });
    let mut plastic = mirror.clone();
    plastic.shapes[0].bsdf = fixtures::one_sided(BsdfKind::Plastic(crate::bsdf::Plastic::new(
        1.5,
        Vec3::splat(0.5),
        Vec3::ONE,
        false,
    )));
    let mut one_sample_picks = (0, 0);
    let scenes = [
        ("diffuse", diffuse),
        ("mirror", mirror),
        ("point", point),
        ("plastic", plastic),
    ];
    for (name, desc) in scenes {
        let scene = Scene::build(desc).unwrap();
        for s in all_strategies() {
            let s = Strategy {
                emitter_samples: 2,
                bsdf_samples: 3,
                ..s
            };
            let direct = super::Direct::new(&scene, s);
            let want = match (s.kind, name) {
                (StrategyKind::Light, "mirror") => "fBB",
                (StrategyKind::Light, "plastic") => "fLBLB",
                (StrategyKind::Light, _) => "fLL",
                (StrategyKind::Bsdf, "point") => "fBBBLLL",
                (StrategyKind::Bsdf, _) => "fBBB",
                (StrategyKind::Mis, "mirror") => "fBBB",
                (StrategyKind::Mis, _) => "fLLBBB",
                (StrategyKind::MisOneSample, "mirror") => "ftB",
                (StrategyKind::MisOneSample, _) => "ft?",
            };
            for i in 0..64 {
                let mut r = Recorder(Rng::for_sample(1, 0, i), String::new());
                let ray = scene.camera.generate_ray(0, 0, &mut r);
                direct.li(&ray, &mut r);
                let got = r.1;
                match want.strip_suffix('?') {
                    Some(head) => {
                        assert!(
                            got == format!("{head}L") || got == format!("{head}B"),
                            "{got}"
                        );
                        let picks = &mut one_sample_picks;
                        *if got.ends_with('L') {
                            &mut picks.0
                        } else {
                            &mut picks.1
                        } += 1;
                    }
                    None => assert_eq!(got, want, "{} on the {name} floor", s.label()),
                }
            }
        }
    }
    assert!(
        one_sample_picks.0 > 0 && one_sample_picks.1 > 0,
        "{one_sample_picks:?}"
    );
}
