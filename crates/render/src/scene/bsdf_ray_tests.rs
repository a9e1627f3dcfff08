//! The emitter pre-test of BSDF rays (`Scene::bsdf_ray_hit`) gives exactly the answer of the
//! full closest-hit query (`intersect_emitter`) on the bundled scenes that use it, for rays
//! leaving ordinary surfaces and rays leaving the lights themselves.

use super::Scene;
use crate::emitter::LightSampling;
use crate::geometry::ray_packet::PACKET;
use crate::geometry::{Hit, RayPacket};
use crate::rng::Rng;
use crate::sampling::warps::square_to_uniform_sphere;

fn open(rel: &str) -> Scene {
    Scene::build(super::bundled_tests::load(rel)).unwrap_or_else(|e| panic!("{e}"))
}

fn same(a: &Option<Hit>, b: &Option<Hit>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => {
            a.t.to_bits() == b.t.to_bits() && a.sp.shape == b.sp.shape && a.sp.prim == b.sp.prim
        }
        _ => false,
    }
}

/// From each of `n` camera hits: a ray in a uniform direction and one towards a light point;
/// from the light points seen there, a ray in a uniform direction. Returns how many rays from
/// surfaces and from lights hit an emitter.
fn check(scene: &Scene, n: u32) -> (u32, u32) {
    assert!(scene.emitter_accel.is_some(), "pre-test not in use");
    let cam = &scene.camera;
    let mut rng = Rng::new(11, 5);
    let (mut from_surface, mut from_light) = (0, 0);
    // Every ray, for the lane kernel's form of the query below.
    let rays = std::cell::RefCell::new(Vec::new());
    let compare = |sp: &crate::geometry::SurfacePoint, d: glam::Vec3| {
        let (ray, skip) = scene.bsdf_ray(sp, d);
        let (fast, full) = (
            scene.bsdf_ray_hit(&ray, skip),
            scene.intersect_emitter(&ray),
        );
        assert!(same(&fast, &full), "ray {ray:?}: {fast:?} vs {full:?}");
        rays.borrow_mut().push((ray, skip, full));
        full.is_some() as u32
    };
    for _ in 0..n {
        let (x, y) = (rng.next_u32() % cam.width, rng.next_u32() % cam.height);
        let Some(hit) = scene.intersect(&cam.generate_ray(x, y, &mut rng)) else {
            continue;
        };
        from_surface += compare(&hit.sp, square_to_uniform_sphere(rng.next_2d()));
        let e = rng.next_u32() as usize % scene.emitters.len();
        let (u_prim, u) = (rng.next_f32(), rng.next_2d());
        let Some(ls) =
            scene.emitters[e].sample(&scene.shapes, hit.sp.p, u_prim, u, LightSampling::Area)
        else {
            continue;
        };
        let to_light = ls.p - hit.sp.p;
        from_surface += compare(&hit.sp, to_light);
        if let Some(on_light) = scene.intersect(&scene.spawn_ray(&hit.sp, to_light)) {
            if scene.emitter_at(&on_light.sp).is_some() {
                from_light += compare(&on_light.sp, square_to_uniform_sphere(rng.next_2d()));
            }
        }
    }
    // The lane kernel's form: eight rays' reject in lanes (`bsdf_rays_may_hit`), then
    // `bsdf_ray_hit_traced` of each it lets through; lanes outside the mask hold rays too.
    for (k, chunk) in rays.borrow().chunks(PACKET).enumerate() {
        let mut packet = RayPacket::default();
        chunk
            .iter()
            .enumerate()
            .for_each(|(i, r)| packet.set(i, &r.0));
        let active = ((1 << chunk.len()) - 1) & !(1 << (k % PACKET));
        let (open, boxed) = (
            scene.bsdf_rays_may_hit::<true>(&packet, active),
            scene.bsdf_rays_may_hit::<false>(&packet, active),
        );
        assert_eq!(open & !active, 0, "lanes outside the mask let through");
        assert_eq!(
            open & !boxed,
            0,
            "the sphere test lets through what the box turns away"
        );
        for (i, (ray, skip, full)) in chunk.iter().enumerate() {
            if active >> i & 1 != 0 {
                let fast = match open >> i & 1 != 0 {
                    true => scene.bsdf_ray_hit_traced(ray, *skip),
                    false => None,
                };
                assert!(
                    same(&fast, full),
                    "lanes, ray {ray:?}: {fast:?} vs {full:?}"
                );
            }
        }
    }
    (from_surface, from_light)
}

#[test]
fn pretest_matches_the_full_query() {
    for rel in [
        "cbox/cbox.xml",
        "cbox-meshlight/cbox-meshlight.xml",
        "cbox-twolights/cbox-twolights.xml",
        "veach-mis/veach-mis.xml",
    ] {
        let (surface, light) = check(&open(rel), 20_000);
        // Enough rays end on a light for a wrong skip or a missed emitter to show.
        assert!(
            surface > 100,
            "{rel}: {surface} rays from surfaces hit a light"
        );
        eprintln!("{rel}: {surface} surface rays and {light} light-origin rays hit a light");
    }
}
