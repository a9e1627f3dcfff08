//! Random scenes for property tests of the renderer's fast paths: every material the scene
//! format has, mesh and sphere lights of any size, smooth-shaded meshes read from OBJ files
//! (shading normals that differ from the geometric ones), point lights now and then, and
//! cameras of every `fov_axis` on portrait and landscape films.
//!
//! `random_scene(seed)` is a pure function of the seed, so a failing case is reproduced by its
//! seed alone. What each scene holds is listed in its `Features`, so a test can check that its
//! seeds cover what it claims to test.

use super::desc::*;
use super::fixtures::{diffuse, sphere, tri_mesh};
use super::mesh::{cube, load_obj, TriMesh};
use crate::bsdf::{
    BsdfKind, Conductor, Dielectric, Diffuse, Material, Mirror, NoriMicrofacet, Plastic,
    RoughConductor, RoughPlastic,
};
use crate::math::look_at;
use crate::rng::Rng;
use crate::sampling::microfacet::{Microfacet, MicrofacetDistribution};
use glam::{Mat4, Vec3};
use std::path::{Path, PathBuf};

/// What a random scene holds, for tallying a test's coverage.
#[derive(Clone, Debug, Default)]
pub struct Features {
    /// Shapes by material name (`diffuse`, `rough-beckmann-grey`, ...).
    pub materials: Vec<&'static str>,
    /// Area lights: `mesh`, `mesh-big` (more than eight triangles), `mesh-smooth`, `sphere`.
    pub lights: Vec<&'static str>,
    /// Receivers with vertex normals read from an OBJ file.
    pub smooth_receivers: usize,
    pub point_lights: usize,
}

/// A generated scene and what it holds.
pub struct RandomScene {
    pub desc: SceneDesc,
    pub features: Features,
}

struct Gen {
    rng: Rng,
    dir: PathBuf,
    objs: u32,
}

impl Gen {
    fn f(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.rng.next_f32()
    }

    fn below(&mut self, n: u32) -> u32 {
        ((self.rng.next_f32() * n as f32) as u32).min(n - 1)
    }

    fn chance(&mut self, p: f32) -> bool {
        self.rng.next_f32() < p
    }

    fn rgb(&mut self, lo: f32, hi: f32) -> Rgb {
        Rgb::new(self.f(lo, hi), self.f(lo, hi), self.f(lo, hi))
    }

    fn unit(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(self.f(-1.0, 1.0), self.f(-1.0, 1.0), self.f(-1.0, 1.0));
            if (0.01..1.0).contains(&v.length_squared()) {
                return v.normalize();
            }
        }
    }

    /// A material of every kind the format has, weighted towards those the lanes shade.
    fn material(&mut self) -> (Material, &'static str) {
        let rough = |g: &mut Gen, distribution, grey: bool| {
            let alpha_u = g.f(0.02, 0.9);
            let alpha_v = if g.chance(0.5) {
                alpha_u
            } else {
                g.f(0.02, 0.9)
            };
            let (eta, k) = if grey {
                (Rgb::splat(g.f(0.1, 2.5)), Rgb::splat(g.f(0.0, 5.0)))
            } else {
                (g.rgb(0.1, 2.5), g.rgb(0.0, 5.0))
            };
            BsdfKind::RoughConductor(RoughConductor {
                mf: Microfacet::new(distribution, alpha_u, alpha_v),
                sample_visible: g.chance(0.85),
                eta,
                k,
                specular_reflectance: g.rgb(0.3, 1.0),
            })
        };
        let (kind, name) = match self.below(24) {
            0..=6 => (
                BsdfKind::Diffuse(Diffuse {
                    reflectance: self.rgb(0.0, 0.95),
                }),
                "diffuse",
            ),
            7..=11 => (
                rough(self, MicrofacetDistribution::Beckmann, true),
                "rough-beckmann-grey",
            ),
            12 => (rough(self, MicrofacetDistribution::Ggx, true), "rough-ggx"),
            13 => (
                rough(self, MicrofacetDistribution::Beckmann, false),
                "rough-coloured",
            ),
            14 => {
                let kind = BsdfKind::Diffuse(Diffuse {
                    reflectance: self.rgb(0.0, 0.95),
                });
                return (
                    Material {
                        kind,
                        two_sided: true,
                    },
                    "twosided",
                );
            }
            15 => (
                BsdfKind::Conductor(Conductor {
                    eta: self.rgb(0.1, 2.5),
                    k: self.rgb(0.0, 5.0),
                    specular_reflectance: Rgb::ONE,
                }),
                "conductor",
            ),
            16 => (
                BsdfKind::Dielectric(Dielectric {
                    eta: self.f(1.1, 2.0),
                }),
                "dielectric",
            ),
            17 => (BsdfKind::Mirror(Mirror), "mirror"),
            18 => (
                BsdfKind::Plastic(Plastic::new(
                    self.f(1.2, 2.0),
                    self.rgb(0.0, 0.9),
                    self.rgb(0.5, 1.0),
                    self.chance(0.5),
                )),
                "plastic",
            ),
            19 => {
                let distribution = match self.chance(0.5) {
                    true => MicrofacetDistribution::Beckmann,
                    false => MicrofacetDistribution::Ggx,
                };
                let alpha = self.f(0.05, 0.6);
                let kind = BsdfKind::RoughPlastic(RoughPlastic::new(
                    Microfacet::new(distribution, alpha, alpha),
                    self.chance(0.85),
                    self.f(1.2, 2.0),
                    self.rgb(0.0, 0.9),
                    self.rgb(0.5, 1.0),
                    self.chance(0.5),
                ));
                (kind, "roughplastic")
            }
            20 => {
                let kind = rough(self, MicrofacetDistribution::Beckmann, true);
                return (
                    Material {
                        kind,
                        two_sided: true,
                    },
                    "twosided-rough",
                );
            }
            _ => (
                BsdfKind::NoriMicrofacet(NoriMicrofacet::new(
                    self.f(0.05, 0.6),
                    self.f(1.2, 1.8),
                    1.0,
                    self.rgb(0.0, 0.5),
                )),
                "nori-microfacet",
            ),
        };
        (
            Material {
                kind,
                two_sided: false,
            },
            name,
        )
    }

    /// Writes `m` as an OBJ file with its vertex normals and reads it back as a user's mesh
    /// would be read.
    fn through_obj(&mut self, m: &TriMesh) -> TriMesh {
        use std::fmt::Write;
        let mut s = String::new();
        for p in &m.positions {
            writeln!(s, "v {} {} {}", p.x, p.y, p.z).unwrap();
        }
        for n in m.normals.as_deref().unwrap_or_default() {
            writeln!(s, "vn {} {} {}", n.x, n.y, n.z).unwrap();
        }
        for t in &m.indices {
            let [a, b, c] = t.map(|i| i + 1);
            match m.normals {
                Some(_) => writeln!(s, "f {a}//{a} {b}//{b} {c}//{c}").unwrap(),
                None => writeln!(s, "f {a} {b} {c}").unwrap(),
            }
        }
        self.objs += 1;
        let path = self.dir.join(format!("mesh{}.obj", self.objs));
        std::fs::write(&path, s).unwrap();
        load_obj(&path).unwrap()
    }

    /// A smooth-shaded UV sphere: vertex normals radial, so they differ from every face's.
    fn uv_sphere(&mut self, center: Vec3, radius: f32) -> TriMesh {
        let (rings, segments) = (3 + self.below(5), 4 + self.below(8));
        let mut positions = Vec::new();
        for r in 0..=rings {
            let theta = std::f32::consts::PI * r as f32 / rings as f32;
            for s in 0..segments {
                let phi = std::f32::consts::TAU * s as f32 / segments as f32;
                let (st, ct) = theta.sin_cos();
                positions.push(Vec3::new(st * phi.cos(), st * phi.sin(), ct));
            }
        }
        let mut indices = Vec::new();
        for r in 0..rings {
            for s in 0..segments {
                let at = |r: u32, s: u32| r * segments + s % segments;
                let (a, b, c, d) = (at(r, s), at(r, s + 1), at(r + 1, s), at(r + 1, s + 1));
                // Counter-clockwise seen from outside; the poles' degenerate halves dropped.
                if r > 0 {
                    indices.push([a, c, b]);
                }
                if r + 1 < rings {
                    indices.push([b, c, d]);
                }
            }
        }
        let normals = positions.clone();
        let positions = positions.iter().map(|&p| center + radius * p).collect();
        self.through_obj(&TriMesh {
            positions,
            normals: Some(normals),
            indices,
        })
    }

    /// A floor of `n`x`n` quads with bumps, its vertex normals those of the smooth height
    /// field: a receiver whose shading normals lean by tens of degrees.
    fn bumpy_floor(&mut self, size: f32) -> TriMesh {
        let n = 2 + self.below(5);
        let (amp, freq) = (self.f(0.05, 0.4), self.f(0.5, 2.5));
        let h = |x: f32, y: f32| amp * (freq * x).sin() * (freq * y).cos();
        let grad = |x: f32, y: f32| {
            Vec3::new(
                -amp * freq * (freq * x).cos() * (freq * y).cos(),
                amp * freq * (freq * x).sin() * (freq * y).sin(),
                1.0,
            )
            .normalize()
        };
        let (mut positions, mut normals, mut indices) = (vec![], vec![], vec![]);
        for j in 0..=n {
            for i in 0..=n {
                let (x, y) = (
                    size * (2.0 * i as f32 / n as f32 - 1.0),
                    size * (2.0 * j as f32 / n as f32 - 1.0),
                );
                positions.push(Vec3::new(x, y, h(x, y)));
                normals.push(grad(x, y));
            }
        }
        for j in 0..n {
            for i in 0..n {
                let at = |i: u32, j: u32| j * (n + 1) + i;
                indices.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                indices.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        self.through_obj(&TriMesh {
            positions,
            normals: Some(normals),
            indices,
        })
    }

    /// A disc of `n` triangles of radius about `r` at `c`, facing `normal`: a fan around the
    /// centre, or for one or two triangles a triangle or quad of the rim alone.
    fn fan(&mut self, c: Vec3, normal: Vec3, r: f32, n: u32) -> TriMesh {
        let frame = crate::math::Frame::from_normal(normal);
        let (centre, rim) = match n {
            1 | 2 => (false, n + 2),
            _ => (true, n),
        };
        let mut positions = if centre { vec![c] } else { vec![] };
        for i in 0..rim {
            let phi = std::f32::consts::TAU * i as f32 / rim as f32;
            let jitter = self.f(0.6, 1.0);
            positions.push(c + frame.to_world(Vec3::new(phi.cos(), phi.sin(), 0.0)) * r * jitter);
        }
        let indices = match centre {
            true => (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect(),
            false => (0..n).map(|i| [0, i + 1, i + 2]).collect(),
        };
        TriMesh {
            positions,
            normals: None,
            indices,
        }
    }
}

/// The scene of `seed`. Its OBJ files are written under `dir`.
impl Gen {
    /// A floor under everything, so most pixels see a receiver, and one to four objects.
    fn receivers(&mut self, f: &mut Features, shapes: &mut Vec<ShapeDesc>) {
        let (bsdf, name) = self.material();
        f.materials.push(name);
        let floor = match self.chance(0.5) {
            true => {
                f.smooth_receivers += 1;
                self.bumpy_floor(3.0)
            }
            false => {
                let mut m = super::mesh::rectangle();
                m.transform(&Mat4::from_scale(Vec3::splat(3.0)));
                m
            }
        };
        shapes.push(tri_mesh(floor, bsdf, None, "<random floor>"));

        for _ in 0..1 + self.below(4) {
            let (bsdf, name) = self.material();
            f.materials.push(name);
            let c = Vec3::new(self.f(-1.5, 1.5), self.f(-1.5, 1.5), self.f(0.3, 1.2));
            let r = self.f(0.15, 0.6);
            shapes.push(match self.below(4) {
                0 => {
                    f.smooth_receivers += 1;
                    let m = self.uv_sphere(c, r);
                    tri_mesh(m, bsdf, None, "<random smooth sphere>")
                }
                1 => sphere(c, r, bsdf, None),
                2 => {
                    let mut m = cube();
                    m.transform(&(Mat4::from_translation(c) * Mat4::from_scale(Vec3::splat(r))));
                    tri_mesh(m, bsdf, None, "<random cube>")
                }
                _ => {
                    let v = [self.unit(), self.unit(), self.unit()].map(|d| c + 2.0 * r * d);
                    tri_mesh(
                        TriMesh {
                            positions: v.to_vec(),
                            normals: None,
                            indices: vec![[0, 1, 2]],
                        },
                        bsdf,
                        None,
                        "<random triangle>",
                    )
                }
            });
        }
    }

    /// One to ten lights: the lanes' small tables hold up to eight emitters and up to eight
    /// triangles per mesh, so both sides of each limit come up.
    fn lights(&mut self, f: &mut Features, shapes: &mut Vec<ShapeDesc>) {
        let lights = match self.chance(0.75) {
            true => 1 + self.below(4),
            false => 5 + self.below(6),
        };
        for _ in 0..lights {
            let c = Vec3::new(self.f(-2.5, 2.5), self.f(-2.5, 2.5), self.f(1.5, 3.5));
            let radiance = self.rgb(0.5, 8.0);
            // Emitters reflect as well, now and then.
            let bsdf = match self.chance(0.3) {
                true => self.material().0,
                false => diffuse(0.0),
            };
            if self.chance(0.3) {
                f.lights.push("sphere");
                shapes.push(sphere(c, self.f(0.05, 0.4), bsdf, Some(radiance)));
                continue;
            }
            // Mostly facing down towards the scene, sometimes away (one-sided: dark from below).
            let towards = (Vec3::new(self.f(-1.0, 1.0), self.f(-1.0, 1.0), 0.0) - c).normalize();
            let normal = match self.chance(0.85) {
                true => (towards + 0.4 * self.unit()).normalize(),
                false => self.unit(),
            };
            let n = match self.chance(0.6) {
                true => 1 + self.below(8),
                false => 9 + self.below(12),
            };
            let r = self.f(0.1, 0.6);
            let mut m = self.fan(c, normal, r, n);
            f.lights.push(if n > 8 { "mesh-big" } else { "mesh" });
            if self.chance(0.3) {
                f.lights.push("mesh-smooth");
                m.normals = Some(
                    m.positions
                        .iter()
                        .map(|&p| (normal + 0.5 * (p - c)).normalize())
                        .collect(),
                );
                m = self.through_obj(&m);
            }
            shapes.push(tri_mesh(m, bsdf, Some(radiance), "<random light>"));
        }
    }

    /// Now and then a point light.
    fn point_lights(&mut self, f: &mut Features) -> Vec<PointLightDesc> {
        let mut point_lights = Vec::new();
        if self.chance(0.12) {
            f.point_lights += 1;
            point_lights.push(PointLightDesc {
                position: Vec3::new(self.f(-2.0, 2.0), self.f(-2.0, 2.0), self.f(1.0, 3.0)),
                intensity: self.rgb(1.0, 10.0),
                origin: "<random point light>".into(),
            });
        }
        point_lights
    }

    /// A camera looking at the scene from above, with any fov axis and film size and filter.
    fn camera_and_film(&mut self) -> (CameraDesc, FilmDesc) {
        let dir = Vec3::new(self.f(-1.0, 1.0), self.f(-1.0, 1.0), self.f(0.3, 1.2)).normalize();
        let eye = dir * self.f(4.0, 7.0);
        let target = Vec3::new(self.f(-0.5, 0.5), self.f(-0.5, 0.5), self.f(0.0, 0.5));
        let up = if dir.cross(Vec3::Z).length() > 0.05 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        let fov_axis = [
            FovAxis::X,
            FovAxis::Y,
            FovAxis::Diagonal,
            FovAxis::Smaller,
            FovAxis::Larger,
        ][self.below(5) as usize];
        let filter = match self.below(3) {
            0 => FilterDesc::Box,
            1 => FilterDesc::Tent {
                radius: self.f(0.5, 2.0),
            },
            _ => {
                let stddev = self.f(0.3, 1.0);
                FilterDesc::Gaussian {
                    stddev,
                    radius: 2.0 * stddev,
                }
            }
        };
        let camera = CameraDesc {
            to_world: look_at(eye, target, up),
            fov_degrees: self.f(25.0, 60.0),
            fov_axis,
            near_clip: 1e-3,
            far_clip: 1e4,
        };
        let film = FilmDesc {
            width: 5 + self.below(10),
            height: 5 + self.below(10),
            filter,
        };
        (camera, film)
    }
}

pub fn random_scene(seed: u64, dir: &Path) -> RandomScene {
    let dir = dir.join(format!("scene{seed}"));
    std::fs::create_dir_all(&dir).unwrap();
    let mut g = Gen {
        rng: Rng::new(seed, 0x5ce7e),
        dir,
        objs: 0,
    };
    let mut f = Features::default();
    let mut shapes = Vec::new();
    g.receivers(&mut f, &mut shapes);
    g.lights(&mut f, &mut shapes);
    let point_lights = g.point_lights(&mut f);
    let (camera, film) = g.camera_and_film();
    let desc = SceneDesc {
        source: PathBuf::from(format!("<random scene {seed}>")),
        camera,
        film,
        sampler: SamplerDesc {
            sample_count: 8,
            seed,
            kind: Default::default(),
        },
        integrator: IntegratorDesc {
            strategy: StrategyKind::Mis,
            heuristic: Heuristic::Balance,
            emitter_samples: 1,
            bsdf_samples: 1,
            hide_emitters: false,
            direct_part_of: None,
        },
        shapes,
        point_lights,
        warnings: vec![],
    };
    RandomScene { desc, features: f }
}
