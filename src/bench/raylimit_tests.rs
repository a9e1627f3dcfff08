use super::*;
use crate::bsdf::{BsdfKind, Material, RoughConductor};
use crate::math::look_at;
use crate::sampling::microfacet::Microfacet;
use crate::sampling::microfacet::MicrofacetDistribution;
use crate::scene::fixtures;
use glam::Vec3;

/// The floor seen from (0, -1, 1) under a triangle light that emits towards it, from 2
/// above it or (`below`) from 2 below it, behind the floor's one-sided diffuse surface.
fn floor_and_light(below: bool, floor: Option<Material>) -> Scene {
    let z = if below { -2.0 } else { 2.0 };
    let mut tri = [
        Vec3::new(-1.0, -1.0, z),
        Vec3::new(0.0, 1.0, z),
        Vec3::new(1.0, -1.0, z),
    ];
    if below {
        tri.swap(1, 2);
    }
    let mut d = fixtures::triangle_over_floor(tri, 1.0, 0.5, Vec3::ZERO, 1.0);
    d.camera.to_world = look_at(Vec3::new(0.0, -1.0, 1.0), Vec3::ZERO, Vec3::Z);
    if let Some(b) = floor {
        d.shapes[0].bsdf = b;
    }
    Scene::build(d).expect("fixture scene")
}

/// A light below the floor's horizon gives its light samples zero BSDF value: the
/// renderer traces no shadow ray for them, nor does the mix.
#[test]
fn no_shadow_ray_below_the_horizon() {
    for below in [false, true] {
        let scene = floor_and_light(below, None);
        let mix = ray_mix(&scene, 64, EmitterSelection::Uniform);
        let hits = mix
            .camera_rays()
            .filter(|r| scene.intersect(r).is_some())
            .count();
        assert_eq!(hits, 64, "the camera sees the floor");
        let expected = if below { 0 } else { hits };
        assert_eq!(mix.n_shadow, expected, "light below the floor: {below}");
        assert_eq!(mix.shadow_rays().count(), expected);
        assert_eq!(
            mix.bsdf.len(),
            hits,
            "a diffuse floor draws a BSDF ray per hit"
        );
    }
}

/// The band-by-band pairing runs over an image whose height is not a multiple of the
/// band (its last band is short), on one thread and two, and gives a share below 1
/// (some traversal timed) and finite (some render timed); a mix of other samples per
/// pixel is refused.
#[test]
fn banded_share_over_a_short_last_band() {
    let mut d = fixtures::triangle_over_floor(
        [
            Vec3::new(-1.0, -1.0, 2.0),
            Vec3::new(0.0, 1.0, 2.0),
            Vec3::new(1.0, -1.0, 2.0),
        ],
        1.0,
        0.5,
        Vec3::ZERO,
        1.0,
    );
    (d.film.width, d.film.height) = (6, BAND_ROWS + 3);
    let scene = Scene::build(d).expect("fixture scene");
    let mis = crate::bench::power_mis();
    let direct = crate::integrator::LaneKernel::new(&scene, mis);
    let mix = ray_mix(&scene, 8, mis.selection);
    for threads in [1, 2] {
        let (share, outside) = measure_interleaved(&direct, &mix, (8, 24), threads, 1);
        assert!(
            share < 1.0 && share.is_finite() && outside.is_finite(),
            "{threads} threads: {share}"
        );
    }
    let refused =
        std::panic::AssertUnwindSafe(|| measure_interleaved(&direct, &mix, (16, 24), 1, 1));
    let other = std::panic::catch_unwind(refused);
    assert!(other.is_err(), "a 16-spp pairing of an 8-spp mix");
}

/// The packets are the renderer's: up to `LANES` consecutive samples of one pixel (the
/// rays the camera makes for them, in order), each shadow and BSDF ray in its camera
/// ray's lane.
#[test]
fn packets_are_a_pixels_groups_of_samples() {
    let scene = floor_and_light(false, None);
    let spp = 12;
    let mix = ray_mix(&scene, spp, EmitterSelection::Uniform);
    let cam = &scene.camera;
    let pixels = (cam.width * cam.height) as usize;
    assert_eq!(
        mix.packets.len(),
        2 * pixels,
        "a group of 8 and one of 4 per pixel"
    );
    assert_eq!(mix.n_camera, pixels * spp as usize);
    let (mut shadows, mut bsdfs) = (0, 0);
    for (k, p) in mix.packets.iter().enumerate() {
        let (pixel, s0) = (k / 2, 8 * (k % 2) as u32);
        let n = if k % 2 == 0 { 8 } else { 4 };
        assert_eq!(p.camera_mask, (1 << n) - 1);
        for lane in 0..n {
            let (x, y) = (pixel as u32 % cam.width, pixel as u32 / cam.width);
            let mut rng = Rng::for_sample(7, pixel as u64, (s0 + lane as u32) as u64);
            assert_eq!(p.camera.d(lane), cam.generate_ray(x, y, &mut rng).d);
            let hit = scene.intersect(&p.camera.ray(lane)).is_some();
            assert_eq!(
                p.shadow_mask >> lane & 1 != 0,
                hit,
                "the light is above the floor"
            );
            assert_eq!(
                p.bsdf[lane] != NONE,
                hit,
                "a diffuse floor draws a BSDF ray"
            );
            if hit {
                let b = &mix.bsdf[p.bsdf[lane] as usize].0;
                assert!(p.shadow.ray(lane).o.distance(b.o) < 1e-3, "same hit point");
            }
            shadows += hit as usize;
            bsdfs += hit as usize;
        }
        assert_eq!(p.shadow_mask >> n, 0);
    }
    assert_eq!((shadows, bsdfs), (mix.n_shadow, mix.bsdf.len()));
    assert!(shadows > 0);
}

/// Warm chunks hold the mix's rays: each packet as it is, each BSDF ray at its rebased
/// index, and all BSDF rays once, in order (chunks of 3 groups, so that some chunks end
/// in the middle of a pixel and some lanes have no BSDF ray).
#[test]
fn warm_chunks_hold_the_mixs_rays() {
    let scene = floor_and_light(false, None);
    let mix = ray_mix(&scene, 12, EmitterSelection::Uniform);
    assert!(mix.packets.iter().any(|p| p.bsdf.contains(&NONE)));
    let mut warm = Warm::default();
    let mut all = Vec::new();
    for chunk in mix.packets.chunks(3) {
        let w = warm.load(&mix, chunk);
        assert_eq!(w.bsdf_packets.len(), chunk.len());
        for ((p, q), lanes) in chunk.iter().zip(&w.packets).zip(&w.bsdf_packets) {
            assert_eq!(
                (p.camera_mask, p.shadow_mask),
                (q.camera_mask, q.shadow_mask)
            );
            assert_eq!(p.camera.d, q.camera.d);
            assert_eq!(p.shadow.o, q.shadow.o);
            for (i, (&b, &c)) in p.bsdf.iter().zip(&q.bsdf).enumerate() {
                assert_eq!(b == NONE, c == NONE);
                assert_eq!(
                    lanes.2 >> i & 1 == 0,
                    b == NONE,
                    "lane {i} of the BSDF packet"
                );
                if b != NONE {
                    let (ray, skip) = mix.bsdf[b as usize];
                    assert_eq!(ray.d, w.bsdf[c as usize].0.d);
                    assert_eq!((lanes.0.ray(i).o, lanes.0.ray(i).d), (ray.o, ray.d));
                    assert_eq!((lanes.0.skip[i], lanes.1[i]), (ray.skip, skip));
                }
            }
        }
        all.extend(w.bsdf.iter().map(|b| b.0.d));
    }
    assert_eq!(all, mix.bsdf.iter().map(|b| b.0.d).collect::<Vec<_>>());
}

/// On a rough conductor of roughness 0.01, BSDF rays leave within 8 degrees of the mirror
/// direction. A cosine-distributed ray lands there with probability about 1 %, so 64 of
/// them all do with probability below 1e-100.
#[test]
fn bsdf_rays_are_the_materials_draws() {
    let rough = fixtures::one_sided(BsdfKind::RoughConductor(RoughConductor {
        mf: Microfacet::new(MicrofacetDistribution::Beckmann, 0.01, 0.01),
        sample_visible: true,
        eta: Rgb::splat(0.0),
        k: Rgb::splat(1.0),
        specular_reflectance: Rgb::splat(1.0),
    }));
    let scene = floor_and_light(false, Some(rough));
    let mix = ray_mix(&scene, 64, EmitterSelection::Uniform);
    assert_eq!(mix.bsdf.len(), 64);
    for (c, b) in mix.camera_rays().zip(&mix.bsdf) {
        let mirror = Vec3::new(c.d.x, c.d.y, -c.d.z);
        let cos = b.0.d.normalize().dot(mirror.normalize());
        assert!(
            cos > 0.99,
            "BSDF ray {:?} is {cos} off mirror {mirror:?}",
            b.0.d
        );
    }
}
