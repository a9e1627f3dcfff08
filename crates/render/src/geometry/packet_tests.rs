use super::*;
use crate::rng::Rng;
use glam::Vec3;

/// Up to eight rays as a packet and its active mask. The other lanes, which no answer
/// may read, hold by turns a NaN ray and the first ray reversed and unbounded (it hits
/// what lies behind), both skipping primitive 0.
fn packet_of(rays: &[Ray]) -> (RayPacket, u32) {
    let nan = Vec3::splat(f32::NAN);
    let nan_ray = Ray {
        tmin: f32::NAN,
        tmax: f32::NAN,
        skip: 0,
        ..Ray::new(nan, nan)
    };
    let back = Ray {
        skip: 0,
        ..Ray::new(rays[0].o, -rays[0].d)
    };
    let mut out = RayPacket::splat(&nan_ray);
    for i in 0..PACKET {
        out.set(
            i,
            rays.get(i)
                .unwrap_or(if i % 2 == 0 { &nan_ray } else { &back }),
        );
    }
    (out, (1u32 << rays.len()) - 1)
}

/// The packet's box set-up in lanes is bitwise the one-ray set-up (`slab_inv`,
/// `near_planes`) of each ray, also for zero, negative zero, tiny (1/d overflows to the
/// clamp) and infinite direction components.
#[test]
fn box_set_up_is_the_one_ray_set_up() {
    use super::super::bvh::{near_planes, slab_inv};
    let mut rng = Rng::new(5, 1);
    let special = [
        0.0,
        -0.0,
        1e-39,
        -1e-39,
        f32::INFINITY,
        -f32::INFINITY,
        1e-3,
        -2.0,
    ];
    for round in 0..500 {
        let rays: [Ray; PACKET] = std::array::from_fn(|i| {
            let mut c = [0; 3].map(|_| rng.next_f32() * 2.0 - 1.0);
            c[(round + i) % 3] = special[(round * 3 + i) % special.len()];
            let o = Vec3::new(rng.next_f32(), -rng.next_f32(), rng.next_f32() * 9.0);
            Ray {
                tmin: rng.next_f32(),
                ..Ray::new(o, Vec3::from_array(c))
            }
        });
        let (packet, _) = packet_of(&rays);
        let b = Boxes::new(&packet.o, &packet.d, &packet.tmin);
        for (i, r) in rays.iter().enumerate() {
            let inv = slab_inv(r.d).to_array().map(f32::to_bits);
            assert_eq!([0, 1, 2].map(|a| b.inv[a][i].to_bits()), inv, "{:?}", r.d);
            assert_eq!(b.near(i), near_planes(slab_inv(r.d)), "{:?}", r.d);
            assert_eq!([0, 1, 2].map(|a| b.o[a][i]), r.o.to_array());
            assert_eq!(b.tmin[i], r.tmin);
        }
    }
}

#[test]
fn transpose8_moves_each_bit_to_its_mirror() {
    for r in 0..8 {
        for c in 0..8 {
            assert_eq!(transpose8(1 << (8 * r + c)), 1 << (8 * c + r), "({r}, {c})");
        }
    }
    let mut rng = Rng::new(3, 1);
    for _ in 0..100 {
        let x = (rng.next_f32().to_bits() as u64) << 32 | rng.next_f32().to_bits() as u64;
        assert_eq!(transpose8(transpose8(x)), x);
    }
}

/// Packets of coherent and of scattered rays, with and without a shared dominant axis,
/// get each ray's own closest hit (with its surface point) and occlusion answer, bitwise,
/// from the bundled Cornell box's and Veach scene's geometry (flat triangles and spheres),
/// and from the Cornell box with vertex normals on half its meshes (smooth shading).
#[test]
fn packets_match_single_rays() {
    use crate::scene::desc::ShapeGeometry;
    let cbox = "cbox/cbox.xml";
    // The bench's 1e5-triangle sweep scene: a tree large enough to prefetch.
    let big = "tessellated sphere";
    for (path, smooth) in [
        (cbox, false),
        ("veach-mis/veach-mis.xml", false),
        (cbox, true),
        (big, false),
    ] {
        let mut desc = if path == big {
            crate::scene::scaling::tessellated(100_000)
        } else {
            crate::scene::bundled_tests::load(path)
        };
        if smooth {
            for shape in desc.shapes.iter_mut().step_by(2) {
                if let ShapeGeometry::Mesh {
                    positions, normals, ..
                } = &mut shape.geometry
                {
                    *normals = Some(positions.iter().map(|p| p.normalize()).collect());
                }
            }
        }
        let scene = crate::scene::Scene::build(desc).expect(path);
        let smooth_meshes = scene.shapes.iter().filter(
            |s| matches!(&s.kind, crate::geometry::ShapeKind::Mesh(m) if m.normals.is_some()),
        );
        assert_eq!(smooth_meshes.count() > 0, smooth, "{path}");
        let accel = &scene.accel;
        assert_eq!(accel.bvh.prefetches(), path == big, "{path}");
        let shapes = &scene.shapes;
        let (lo, hi) = accel.bounds();
        let mut rng = Rng::new(9, 9);
        let mut u3 = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        let (mut hits, mut blocked, mut wide) = (0, 0, 0);
        for round in 0..3000 {
            let n = 2 + round % 7;
            let o = lo + (hi - lo) * u3();
            let aim = lo + (hi - lo) * u3();
            let spread = [0.001, 0.05, 1.0][round % 3];
            let rays: Vec<Ray> = (0..n)
                .map(|i| {
                    let target = aim + (hi - lo) * (u3() - 0.5) * spread;
                    let mut ray = Ray::new(o + (hi - lo) * (u3() - 0.5) * 0.01, target - o);
                    if round % 2 == 1 {
                        // Shadow-ray style: a finite interval.
                        ray.tmax = 1.0 - 1e-4;
                    }
                    if i % 3 == 2 {
                        ray.tmin = 0.2;
                    }
                    ray
                })
                .collect();
            let (packet, active) = packet_of(&rays);
            let r = Rays::new(&packet, active);
            wide += r.wide(active).is_some() as u32;
            let got = accel.intersect8(&packet, active, shapes);
            let occluded = accel.occluded8(&packet, active);
            for (i, ray) in rays.iter().enumerate() {
                let want = accel.intersect(ray, shapes);
                let key = |h: &Option<crate::geometry::Hit>| {
                    h.map(|h| {
                        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                        let sp = h.sp;
                        let vectors = [sp.p, sp.ng, sp.ns, sp.err_scale].map(bits);
                        (h.t.to_bits(), sp.shape, sp.prim, vectors)
                    })
                };
                assert_eq!(
                    key(&got.get(i)),
                    key(&want),
                    "{path}: round {round}, ray {i}"
                );
                let blocked_one = accel.occluded(ray);
                assert_eq!(
                    occluded >> i & 1 != 0,
                    blocked_one,
                    "{path}: round {round}, ray {i}"
                );
                hits += want.is_some() as u32;
                blocked += blocked_one as u32;
            }
            assert_eq!(occluded >> n, 0);
        }
        // Every query counted here is a closest-hit and an occlusion query over the same
        // interval, so the two counts agree.
        assert_eq!(hits, blocked);
        // Random rays through the bounding box hit a sphere over a floor less often
        // than a closed box (1655 of about 15,000 rays).
        let min_hits = if path == big { 1000 } else { 2000 };
        assert!(
            hits > min_hits && wide > 1000,
            "{path}: {hits} hits, {wide} wide packets"
        );
    }
}
