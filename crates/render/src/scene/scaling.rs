//! Scenes for the scaling benchmarks and the packet tests, built in code: a tessellated sphere of a chosen triangle
//! count over a floor, and a floor under a grid of a chosen number of small quad lights.

use crate::math::look_at;
use crate::scene::desc::*;
use crate::scene::fixtures::{diffuse, floor_probe, mesh};
use glam::Vec3;

/// A UV sphere of about `n_tris` triangles (radius 1, resting on the floor z = 0) under one
/// quad light, seen by a 64x64 camera.
pub fn tessellated(n_tris: usize) -> SceneDesc {
    // rings x (2 rings) quads of two triangles each.
    let rings = (((n_tris / 4) as f64).sqrt() as usize).max(3);
    let segs = rings * 2;
    let mut p = Vec::new();
    for i in 0..=rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segs {
            let phi = std::f32::consts::TAU * j as f32 / segs as f32;
            p.push(Vec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                1.0 + theta.cos(),
            ));
        }
    }
    let mut idx = Vec::new();
    for i in 0..rings as u32 {
        for j in 0..segs as u32 {
            let (a, b) = (i * segs as u32 + j, i * segs as u32 + (j + 1) % segs as u32);
            let (c, d) = (a + segs as u32, b + segs as u32);
            // Outward winding; the pole rows give zero-area triangles, which the BVH skips.
            idx.push([a, c, b]);
            idx.push([b, c, d]);
        }
    }
    let mut desc = floor_probe(0.5, Vec3::ZERO, Vec3::new(0.0, -5.0, 3.0));
    desc.shapes.push(mesh(p, idx, diffuse(0.7), None));
    desc.shapes
        .push(quad_light(Vec3::new(0.0, 0.0, 4.0), 1.0, 5.0));
    view(&mut desc);
    desc
}

/// A floor under `n` small quad lights in a grid (each its own emitter) at height 3.
pub fn many_lights(n: usize) -> SceneDesc {
    let mut desc = floor_probe(0.5, Vec3::ZERO, Vec3::new(0.0, -5.0, 3.0));
    let side = (n as f64).sqrt().ceil() as usize;
    let pitch = 6.0 / side as f32;
    for k in 0..n {
        let (i, j) = (k % side, k / side);
        let c = Vec3::new(
            -3.0 + pitch * (i as f32 + 0.5),
            -3.0 + pitch * (j as f32 + 0.5),
            3.0,
        );
        desc.shapes
            .push(quad_light(c, pitch * 0.4, 20.0 / n as f32));
    }
    view(&mut desc);
    desc
}

/// A downward-facing square light of half-size `h` centred at `c`.
fn quad_light(c: Vec3, h: f32, radiance: f32) -> ShapeDesc {
    let v = vec![
        c + Vec3::new(-h, -h, 0.0),
        c + Vec3::new(-h, h, 0.0),
        c + Vec3::new(h, h, 0.0),
        c + Vec3::new(h, -h, 0.0),
    ];
    mesh(
        v,
        vec![[0, 1, 2], [0, 2, 3]],
        diffuse(0.0),
        Some(Rgb::splat(radiance)),
    )
}

fn view(desc: &mut SceneDesc) {
    desc.camera.to_world = look_at(Vec3::new(0.0, -6.0, 4.0), Vec3::new(0.0, 0.0, 1.0), Vec3::Z);
    desc.camera.fov_degrees = 45.0;
    desc.film.width = 64;
    desc.film.height = 64;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    #[test]
    fn scaling_scenes_have_the_requested_size() {
        let s = Scene::build(tessellated(10_000)).unwrap();
        let tris = s.accel.primitive_count();
        assert!((8_000..14_000).contains(&tris), "{tris}");
        let s = Scene::build(many_lights(100)).unwrap();
        assert_eq!(s.emitters.len(), 100);
    }
}
