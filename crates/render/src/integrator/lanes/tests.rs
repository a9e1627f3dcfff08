//! Lane kernel tests that need the kernel whole; the bitwise comparisons with `li` are in
//! `render_lanes_tests`.

use crate::bsdf::BsdfKind;
use crate::geometry::{Ray, RayPacket};
use crate::integrator::{LaneKernel, Strategy};
use crate::rng::{Rng, LANES};
use crate::sampler::IndependentLanes;
use crate::sampling::microfacet::ITERS;
use crate::scene::desc::StrategyKind;
use crate::scene::Scene;
use glam::Vec3;

/// Cost guard: in a batch of rough-conductor hits, lanes without a covered hit (rays
/// that leave the scene) take no slope steps past the fixed ones. Their inversions are
/// garbage (NaN), which used to bisect to the 64-step limit: 61 steps per empty lane.
#[test]
fn empty_lanes_of_a_rough_batch_take_no_further_steps() {
    let scene = Scene::build(crate::scene::bundled_tests::load("veach-mis/veach-mis.xml"))
        .unwrap_or_else(|e| panic!("{e}"));
    let mis = Strategy::combinations()
        .into_iter()
        .find(|s| s.kind == StrategyKind::Mis && s.emitter_samples == 1)
        .unwrap();
    let kernel = LaneKernel::new(&scene, mis);
    let cam = &scene.camera;
    let mut rng = Rng::new(2, 7);
    // A camera ray onto a plate, down the middle column of the image.
    let plate = (0..cam.height)
        .map(|y| cam.generate_ray(cam.width / 2, y, &mut rng))
        .find(|r| {
            scene
                .intersect(r)
                .is_some_and(|h| matches!(scene.material(&h.sp).kind, BsdfKind::RoughConductor(_)))
        })
        .expect("a ray onto a plate");
    let away = Ray::new(plate.o, Vec3::Y);
    assert!(scene.intersect(&away).is_none());
    let mut rays = RayPacket::splat(&away);
    (0..4).for_each(|i| rays.set(i, &plate));
    let batches = 64;
    let mut scratch = crate::integrator::LaneScratch::default();
    ITERS.with(|c| c.set(0));
    for b in 0..batches {
        let mut lanes = IndependentLanes::for_pixel_samples(9, 8 * b);
        kernel.li_lanes(&rays, LANES, &mut lanes, &mut scratch);
    }
    let per_batch = ITERS.with(|c| c.get()) as f64 / batches as f64;
    eprintln!("{per_batch} steps past the fixed ones per batch");
    // The four plate lanes converge within the fixed steps in these batches (with
    // Newton steps a fourth was needed about 4 % of the time).
    assert!(per_batch < 1.0, "{per_batch} further steps per batch");
}
