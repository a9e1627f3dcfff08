//! Scenes built in code for tests and benchmarks, where a closed form is known.

use super::desc::*;
use super::mesh::TriMesh;
use crate::bsdf::{BsdfKind, Diffuse, Material};
use crate::math::look_at;
use glam::{Mat4, Vec3};
use std::path::PathBuf;

fn base(camera: Mat4, fov: f32, width: u32, height: u32, shapes: Vec<ShapeDesc>) -> SceneDesc {
    SceneDesc {
        source: PathBuf::from("<fixture>"),
        camera: CameraDesc {
            to_world: camera,
            fov_degrees: fov,
            fov_axis: FovAxis::X,
            near_clip: 1e-4,
            far_clip: 1e6,
        },
        film: FilmDesc {
            width,
            height,
            filter: FilterDesc::Box,
        },
        sampler: SamplerDesc {
            sample_count: 16,
            seed: 0,
            kind: Default::default(),
        },
        integrator: IntegratorDesc {
            strategy: StrategyKind::Light,
            heuristic: Heuristic::Balance,
            emitter_samples: 1,
            bsdf_samples: 1,
            hide_emitters: false,
            direct_part_of: None,
        },
        shapes,
        point_lights: vec![],
        warnings: vec![],
    }
}

/// A mesh shape of `bsdf`, emitting `radiance` on its front side if given.
pub fn mesh(
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    bsdf: Material,
    radiance: Option<Rgb>,
) -> ShapeDesc {
    let m = TriMesh {
        positions,
        normals: None,
        indices,
    };
    tri_mesh(m, bsdf, radiance, "<fixture>")
}

/// A shape of the triangle mesh `m` (with its vertex normals, if any), emitting `radiance`
/// if given.
pub fn tri_mesh(m: TriMesh, bsdf: Material, radiance: Option<Rgb>, origin: &str) -> ShapeDesc {
    ShapeDesc {
        geometry: ShapeGeometry::Mesh {
            positions: m.positions,
            normals: m.normals,
            indices: m.indices,
        },
        bsdf,
        emitter: radiance.map(|radiance| AreaEmitterDesc { radiance }),
        origin: origin.into(),
    }
}

/// A sphere shape, emitting `radiance` if given.
pub fn sphere(center: Vec3, radius: f32, bsdf: Material, radiance: Option<Rgb>) -> ShapeDesc {
    ShapeDesc {
        geometry: ShapeGeometry::Sphere {
            center,
            radius,
            flip_normals: false,
        },
        bsdf,
        emitter: radiance.map(|radiance| AreaEmitterDesc { radiance }),
        origin: "<fixture sphere>".into(),
    }
}

/// A one-sided diffuse material of albedo `a`.
pub fn diffuse(a: f32) -> Material {
    one_sided(BsdfKind::Diffuse(Diffuse {
        reflectance: Rgb::splat(a),
    }))
}

/// `kind` on the front side only.
pub fn one_sided(kind: BsdfKind) -> Material {
    Material {
        kind,
        two_sided: false,
    }
}

/// The square [-half, half]^2 at height `z`, facing +z if `up`, else -z.
pub fn square_z(half: f32, z: f32, up: bool, bsdf: Material, radiance: Option<Rgb>) -> ShapeDesc {
    let s = half;
    let indices = if up {
        vec![[0, 1, 2], [0, 2, 3]]
    } else {
        vec![[0, 2, 1], [0, 3, 2]]
    };
    mesh(
        vec![
            Vec3::new(-s, -s, z),
            Vec3::new(s, -s, z),
            Vec3::new(s, s, z),
            Vec3::new(-s, s, z),
        ],
        indices,
        bsdf,
        radiance,
    )
}

fn floor(albedo: f32) -> ShapeDesc {
    square_z(50.0, 0.0, true, diffuse(albedo), None)
}

/// A large diffuse floor z = 0 (normal +z), seen by a one-pixel camera with a tiny field of
/// view that looks at the receiver point `x` from `eye`. Add lights to it.
pub fn floor_probe(albedo: f32, x: Vec3, eye: Vec3) -> SceneDesc {
    let up = if (eye - x).cross(Vec3::Y).length() > 1e-3 {
        Vec3::Y
    } else {
        Vec3::X
    };
    base(look_at(eye, x, up), 1e-3, 1, 1, vec![floor(albedo)])
}

/// `floor_probe` under one area light.
pub fn light_over_floor(light: ShapeDesc, albedo: f32, x: Vec3, eye: Vec3) -> SceneDesc {
    let mut d = floor_probe(albedo, x, eye);
    d.shapes.push(light);
    d
}

/// A one-sided triangle light (emitting towards the side its counter-clockwise winding
/// faces) over the floor, the receiver `x` seen from straight above.
pub fn triangle_over_floor(
    tri: [Vec3; 3],
    radiance: f32,
    albedo: f32,
    x: Vec3,
    height: f32,
) -> SceneDesc {
    let light = mesh(
        tri.to_vec(),
        vec![[0, 1, 2]],
        diffuse(0.0),
        Some(Rgb::splat(radiance)),
    );
    light_over_floor(light, albedo, x, x + Vec3::Z * height)
}

/// A spherical light of the given radiance over the floor.
pub fn sphere_light(center: Vec3, radius: f32, radiance: f32) -> ShapeDesc {
    sphere(center, radius, diffuse(0.0), Some(Rgb::splat(radiance)))
}

/// A closed cube [-1,1]^3 whose inward-facing faces are diffuse (albedo `a`) and emit L = 1.
/// With direct lighting only, every pixel is exactly 1 + a. `split` makes each face its own
/// emitter (exercising emitter choice), otherwise the cube is one emitter mesh.
pub fn furnace(a: f32, split: bool, width: u32) -> SceneDesc {
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let mut faces: [[Vec3; 4]; 6] = [
        [
            v(-1., -1., -1.),
            v(-1., 1., -1.),
            v(1., 1., -1.),
            v(1., -1., -1.),
        ],
        [
            v(-1., -1., 1.),
            v(1., -1., 1.),
            v(1., 1., 1.),
            v(-1., 1., 1.),
        ],
        [
            v(-1., -1., -1.),
            v(1., -1., -1.),
            v(1., -1., 1.),
            v(-1., -1., 1.),
        ],
        [
            v(-1., 1., -1.),
            v(-1., 1., 1.),
            v(1., 1., 1.),
            v(1., 1., -1.),
        ],
        [
            v(-1., -1., -1.),
            v(-1., -1., 1.),
            v(-1., 1., 1.),
            v(-1., 1., -1.),
        ],
        [
            v(1., -1., -1.),
            v(1., 1., -1.),
            v(1., 1., 1.),
            v(1., -1., 1.),
        ],
    ];
    // Wind every face so its normal (right-hand rule) points into the cube.
    for f in &mut faces {
        let n = (f[1] - f[0]).cross(f[2] - f[0]);
        if n.dot(f[0] + f[2]) > 0.0 {
            f.reverse();
        }
    }
    let quad = |f: &[Vec3; 4]| (f.to_vec(), vec![[0u32, 1, 2], [0, 2, 3]]);
    let shapes = if split {
        faces
            .iter()
            .map(|f| {
                let (p, i) = quad(f);
                mesh(p, i, diffuse(a), Some(Rgb::ONE))
            })
            .collect()
    } else {
        let mut p = Vec::new();
        let mut idx = Vec::new();
        for f in &faces {
            let b = p.len() as u32;
            p.extend_from_slice(f);
            idx.push([b, b + 1, b + 2]);
            idx.push([b, b + 2, b + 3]);
        }
        vec![mesh(p, idx, diffuse(a), Some(Rgb::ONE))]
    };
    let cam = look_at(
        Vec3::new(0.2, -0.3, -0.5),
        Vec3::new(0.0, 0.3, 1.0),
        Vec3::Y,
    );
    base(cam, 100.0, width, width, shapes)
}

/// Applies a transform to the whole scene: geometry, lights and camera.
pub fn transform(desc: &mut SceneDesc, m: Mat4) {
    let scale = m.transform_vector3(Vec3::X).length();
    for s in &mut desc.shapes {
        match &mut s.geometry {
            ShapeGeometry::Mesh {
                positions, normals, ..
            } => {
                positions
                    .iter_mut()
                    .for_each(|p| *p = m.transform_point3(*p));
                if let Some(n) = normals {
                    let nm = m.inverse().transpose();
                    n.iter_mut()
                        .for_each(|v| *v = nm.transform_vector3(*v).normalize());
                }
            }
            ShapeGeometry::Sphere { center, radius, .. } => {
                *center = m.transform_point3(*center);
                *radius *= scale;
            }
        }
    }
    for p in &mut desc.point_lights {
        p.position = m.transform_point3(p.position);
    }
    // Clip distances are camera-space depths: the scaled camera matrix scales them already.
    desc.camera.to_world = m * desc.camera.to_world;
}

/// A side x side grid of square lights in the plane z = `height`, facing down (-z), centred
/// on the origin with centres `pitch` apart, each of half-size `half` and its own emitter;
/// light (i, j) has radiance `radiance(i, j)`. Lights in one plane facing down cannot shadow
/// one another for a point below them: over a floor, the exact answer is the sum of
/// Lambert's formula over the lights (`analytic::polygon_irradiance`).
pub fn light_grid(
    side: usize,
    pitch: f32,
    half: f32,
    height: f32,
    radiance: impl Fn(usize, usize) -> f32,
) -> Vec<ShapeDesc> {
    let mut out = Vec::with_capacity(side * side);
    let start = -0.5 * pitch * (side as f32 - 1.0);
    for j in 0..side {
        for i in 0..side {
            let c = Vec3::new(start + pitch * i as f32, start + pitch * j as f32, height);
            // This winding faces -z.
            let v = vec![
                c + Vec3::new(-half, -half, 0.0),
                c + Vec3::new(-half, half, 0.0),
                c + Vec3::new(half, half, 0.0),
                c + Vec3::new(half, -half, 0.0),
            ];
            let l = Rgb::splat(radiance(i, j));
            out.push(mesh(v, vec![[0, 1, 2], [0, 2, 3]], diffuse(0.0), Some(l)));
        }
    }
    out
}

/// The quads of `light_grid`, as polygons for Lambert's formula (counter-clockwise seen
/// from below), with their radiances.
pub fn light_grid_polygons(shapes: &[ShapeDesc]) -> Vec<(Vec<glam::DVec3>, f64)> {
    shapes
        .iter()
        .filter_map(|s| {
            let ShapeGeometry::Mesh { positions, .. } = &s.geometry else {
                return None;
            };
            let l = s.emitter.as_ref()?.radiance.x as f64;
            Some((positions.iter().map(|p| p.as_dvec3()).collect(), l))
        })
        .collect()
}

/// Just these shapes (and a 1x1 camera that nothing depends on): for testing light sampling
/// on its own, where no receiver or floor should be in the way.
pub fn shapes_only(shapes: Vec<ShapeDesc>) -> SceneDesc {
    let cam = look_at(Vec3::new(0.0, 0.0, -10.0), Vec3::ZERO, Vec3::Y);
    base(cam, 30.0, 1, 1, shapes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    #[test]
    fn furnace_normals_point_inwards() {
        let d = furnace(0.5, false, 4);
        let ShapeGeometry::Mesh {
            positions, indices, ..
        } = &d.shapes[0].geometry
        else {
            unreachable!()
        };
        for t in indices {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            let n = (b - a).cross(c - a);
            let centre = (a + b + c) / 3.0;
            assert!(
                n.dot(-centre) > 0.0,
                "face normal must point to the cube's centre"
            );
        }
        assert!(Scene::build(d).is_ok());
    }
}
