//! The lane kernel's light draws: emitter and triangle choice for eight samples (the table
//! lookups of `Direct::light_draw`), and each lane's point on the drawn triangle or sphere
//! (`light_sample`). The tables they read are built once per render in `tables`.

#![allow(clippy::needless_range_loop)]

use super::tables::{LaneLight, LaneLightKind, LightTriangle, SmallLights, SmallMesh};
use crate::emitter::{area_pdf_along, sample_at, sphere_area_point, EmitterSelector};
use crate::geometry::ray_packet::bits;
use crate::geometry::{lookup8, Mesh, PacketHits, Sphere, SurfacePoint};
use crate::math::{Rgb, V3x8};
use crate::rng::LANES;
use crate::sampling::warps::square_to_uniform_triangle;
use crate::sampling::AliasTable;
use glam::{Vec2, Vec3};

/// The sphere of each lane whose light is a sphere. Kept out of `LightDraws`: with these
/// fields it grew past what LLVM zeroes inline and became a memset call per batch.
#[derive(Default)]
pub(super) struct SphereDraws {
    pub(super) any: bool,
    sphere: [Option<Sphere>; LANES],
}

/// The light triangle of each lane and its data, gathered with scalar table lookups (for a
/// sphere light, only `shape`, `radiance`, `area` and `pmf`).
#[derive(Default)]
#[repr(C)]
pub(super) struct LightDraws {
    v: [V3x8; 3],
    ng: V3x8,
    err: V3x8,
    /// Vertex normals, where the mesh has them (`has_normals`).
    n: [V3x8; 3],
    shape: [u32; LANES],
    tri: [u32; LANES],
    radiance: V3x8,
    area: [f32; LANES],
    pub(super) pmf: [f32; LANES],
    has_normals: [bool; LANES],
    /// The lanes whose point-dependent emitter choice chose nothing (`Direct::candidate`'s
    /// None: no light sample, counted as none).
    pub(super) unchosen: u32,
    /// RIS's density of each lane's kept candidate (`ris_numbers`), which the light estimate
    /// divides by instead of pmf * pdf; written and read only under RIS.
    pub(super) p_div: [f32; LANES],
}

impl LightDraws {
    /// Lane i's triangle of a mesh light, drawn with `u`, and its record.
    #[inline(always)]
    fn triangle(
        &mut self,
        i: usize,
        triangles: &AliasTable,
        records: &[LightTriangle],
        smooth: Option<&Mesh>,
        u: f32,
    ) {
        let tri = triangles.sample(u);
        let r = &records[tri];
        for (k, v) in r.v.into_iter().enumerate() {
            self.v[k].set(i, v);
        }
        self.vertex_normals(i, smooth, tri);
        self.ng.set(i, r.ng);
        self.err.set(i, r.err);
        self.tri[i] = tri as u32;
    }

    /// `draw`'s emitter choice and copies for two to eight emitters, for all lanes at
    /// once from register-held tables (`SmallLights`); lanes whose light is a mesh then draw
    /// their triangles one by one.
    #[inline(always)]
    fn small_lights(
        &mut self,
        t: &SmallLights,
        lights: &[LaneLight],
        u_emitter: &[f32; LANES],
        u_tri: &[f32; LANES],
        spheres: &mut SphereDraws,
    ) {
        let e = t.choice.draw(u_emitter);
        self.pmf = lookup8(&t.pmf, &e);
        self.shape = lookup8(&t.shape, &e).map(f32::to_bits);
        self.radiance = V3x8 {
            x: lookup8(&t.radiance[0], &e),
            y: lookup8(&t.radiance[1], &e),
            z: lookup8(&t.radiance[2], &e),
        };
        self.area = lookup8(&t.area, &e);
        let mut meshes = 0;
        for i in 0..LANES {
            spheres.sphere[i] = t.sphere[e[i] as usize];
            meshes |= (t.meshes >> e[i] & 1) << i;
        }
        spheres.any = meshes != (1 << LANES) - 1;
        for i in bits(meshes) {
            if let LaneLightKind::Mesh {
                triangles,
                records,
                smooth,
                ..
            } = &lights[e[i] as usize].kind
            {
                self.triangle(i, triangles, records, *smooth, u_tri[i]);
            }
        }
    }

    /// `triangle` of every lane from a mesh of at most eight triangles: the alias draw
    /// (`AliasTable::sample`, the same operations) and the records' reads for all lanes at
    /// once, each a `lookup8` of a register-held table; the vertex normals of a smooth mesh
    /// lane by lane.
    #[inline(always)]
    fn small_mesh_triangles(&mut self, m: &SmallMesh, smooth: Option<&Mesh>, u: &[f32; LANES]) {
        let tri = m.triangles.draw(u);
        let f = |j: usize| lookup8(&m.fields[j], &tri);
        let v3 = |j: usize| V3x8 {
            x: f(j),
            y: f(j + 1),
            z: f(j + 2),
        };
        self.v = [v3(0), v3(3), v3(6)];
        (self.ng, self.err) = (v3(9), v3(12));
        self.tri = tri;
        if smooth.is_some() {
            (0..LANES).for_each(|i| self.vertex_normals(i, smooth, tri[i] as usize));
        }
    }

    /// Lane i's vertex normals of triangle `tri`, where the mesh has them.
    #[inline(always)]
    fn vertex_normals(&mut self, i: usize, smooth: Option<&Mesh>, tri: usize) {
        if let Some(n) = smooth.and_then(|m| m.vertex_normals(tri)) {
            for (k, n) in n.into_iter().enumerate() {
                self.n[k].set(i, n);
            }
            self.has_normals[i] = true;
        }
    }
}

impl LightDraws {
    /// Emitter and triangle choice with `selector` and the triangle's data: the table lookups
    /// of `Direct::light_draw`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)] // the lanes' arrays, each its own argument (see `shade_batch`)
    pub(super) fn draw(
        selector: &EmitterSelector,
        lights: &[LaneLight],
        small: Option<&SmallLights>,
        u_emitter: &[f32; LANES],
        u_tri: &[f32; LANES],
        at: &PacketHits,
        d: &mut LightDraws,
        spheres: &mut SphereDraws,
    ) {
        // The one field a lane's triangle leaves unwritten (a mesh without vertex normals).
        (d.has_normals, d.unchosen) = ([false; LANES], 0);
        if let Some(pmf) = selector.single() {
            // Every lane draws the one emitter: its data is copied once.
            let light = &lights[0];
            d.shape = [light.shape; LANES];
            d.radiance = V3x8::splat(light.radiance);
            d.area = [light.area; LANES];
            d.pmf = [pmf; LANES];
            match &light.kind {
                LaneLightKind::Mesh {
                    small: Some(small),
                    smooth,
                    ..
                } => d.small_mesh_triangles(small, *smooth, u_tri),
                LaneLightKind::Mesh {
                    triangles,
                    records,
                    smooth,
                    ..
                } => (0..LANES).for_each(|i| d.triangle(i, triangles, records, *smooth, u_tri[i])),
                LaneLightKind::Sphere(sphere) => {
                    (spheres.sphere, spheres.any) = ([Some(**sphere); LANES], true)
                }
            }
            return;
        }
        if let Some(t) = small {
            return d.small_lights(t, lights, u_emitter, u_tri, spheres);
        }
        for i in 0..LANES {
            // The shading point matters to the point-dependent choices (a lane without a
            // hit draws from garbage and is dropped).
            let sp = at.point(i);
            let Some((e, pmf)) = selector.sample(sp.p, sp.ns, u_emitter[i]) else {
                // No emitter chosen (`li` adds nothing): zero radiance leaves the lane's
                // light sample out, whatever an earlier draw left in the other fields.
                d.radiance.set(i, Rgb::ZERO);
                d.unchosen |= 1 << i;
                continue;
            };
            let light = &lights[e];
            d.shape[i] = light.shape;
            d.radiance.set(i, light.radiance);
            d.area[i] = light.area;
            d.pmf[i] = pmf;
            match &light.kind {
                LaneLightKind::Mesh {
                    triangles,
                    records,
                    smooth,
                    ..
                } => d.triangle(i, triangles, records, *smooth, u_tri[i]),
                LaneLightKind::Sphere(sphere) => {
                    (spheres.sphere[i], spheres.any) = (Some(**sphere), true);
                }
            }
        }
    }
}

/// Lane i's light sample: the area-sampling branches of `AreaLight::sample` for the drawn
/// triangle or sphere, seen from p: whether it was drawn, its direction, its density in
/// solid angle, its radiance and the light point.
#[inline(always)]
pub(super) fn light_sample<const SPHERES: bool>(
    p: Vec3,
    ld: &LightDraws,
    sd: &SphereDraws,
    u: &[[f32; LANES]; 4],
    i: usize,
) -> (bool, Vec3, f32, Rgb, SurfacePoint) {
    let u_point = Vec2::new(u[2][i], u[3][i]);
    let sphere = if SPHERES { sd.sphere[i] } else { None };
    let lsp = if let Some(s) = sphere {
        sphere_area_point(&s, u_point, ld.shape[i])
    } else {
        let b = square_to_uniform_triangle(u_point);
        let v = [ld.v[0].get(i), ld.v[1].get(i), ld.v[2].get(i)];
        let normals = [ld.n[0].get(i), ld.n[1].get(i), ld.n[2].get(i)];
        let face = (ld.ng.get(i), ld.err.get(i));
        let normals = ld.has_normals[i].then_some(normals);
        Mesh::point_from(v, face, normals, b, ld.shape[i], ld.tri[i])
    };
    let area = ld.area[i];
    let ls = sample_at(ld.radiance.get(i), p, &lsp, |wi, dist| {
        area_pdf_along(area, &lsp, wi, dist)
    });
    match ls {
        Some(ls) => (true, ls.wi, ls.pdf, ls.li, lsp),
        None => (false, Vec3::ZERO, 0.0, Rgb::ZERO, lsp),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::scene::Scene;

    /// A fan of `n` triangles of unequal areas (the second of zero area, which the alias
    /// table must never draw), with vertex normals or without.
    fn fan(n: usize, normals: bool) -> (Mesh, AliasTable, Vec<LightTriangle>) {
        let mut positions = vec![Vec3::new(0.1, -0.2, 1.0)];
        positions.extend((0..=n).map(|k| {
            // Rim points 1 and 2 coincide: triangle 1 has no area.
            let k = if k == 2 { 1 } else { k };
            let a = k as f32 * 0.7;
            let r = 1.0 + k as f32;
            Vec3::new(r * a.cos(), r * a.sin(), 1.0 + 0.1 * k as f32)
        }));
        let indices: Vec<[u32; 3]> = (0..n as u32).map(|k| [0, k + 1, k + 2]).collect();
        let vertex_normals = normals.then(|| {
            (0..positions.len())
                .map(|k| Vec3::new(0.1 * k as f32, -0.2, 1.0).normalize())
                .collect()
        });
        let mesh = Mesh::new(positions, vertex_normals, indices);
        let areas: Vec<f64> = (0..n)
            .map(|t| {
                let [a, b, c] = mesh.vertices(t);
                0.5 * (b - a).cross(c - a).length() as f64
            })
            .collect();
        let table = AliasTable::new(&areas).expect("a triangle of positive area");
        let records = (0..n)
            .map(|t| {
                let (ng, err) = mesh.face(t);
                LightTriangle {
                    v: mesh.vertices(t),
                    ng,
                    err,
                }
            })
            .collect();
        (mesh, table, records)
    }

    fn bits(v: &V3x8) -> [[u32; LANES]; 3] {
        v.axes().map(|a| a.map(f32::to_bits))
    }

    /// `small_mesh_triangles` draws, for every lane, bitwise what `triangle` draws with the
    /// same number: meshes of 1 to 8 triangles, flat and smooth, random numbers and edges
    /// (0, the largest below 1, the bin boundaries).
    #[test]
    fn small_mesh_draws_are_the_per_lane_draws() {
        let below_one = f32::from_bits(1.0f32.to_bits() - 1);
        let mut rng = Rng::new(3, 9);
        for n in 1..=8 {
            for normals in [false, true] {
                let (mesh, table, records) = fan(n, normals);
                let small = SmallMesh::new(&table, &records).expect("at most eight");
                let smooth = normals.then_some(&mesh);
                let edges: [f32; LANES] = std::array::from_fn(|k| match k {
                    0 => 0.0,
                    1 => below_one,
                    _ => (k as f32 - 1.0) / n as f32,
                });
                let mut batches = vec![edges];
                batches.extend((0..200).map(|_| std::array::from_fn(|_| rng.next_f32())));
                for u in batches {
                    let (mut a, mut b) = (LightDraws::default(), LightDraws::default());
                    (0..LANES).for_each(|i| a.triangle(i, &table, &records, smooth, u[i]));
                    b.small_mesh_triangles(&small, smooth, &u);
                    assert_eq!(a.tri, b.tri, "n {n}, u {u:?}");
                    assert!(a.tri.iter().all(|&t| t != 1), "the zero-area triangle");
                    for k in 0..3 {
                        assert_eq!(bits(&a.v[k]), bits(&b.v[k]));
                        assert_eq!(bits(&a.n[k]), bits(&b.n[k]));
                    }
                    assert_eq!((bits(&a.ng), bits(&a.err)), (bits(&b.ng), bits(&b.err)));
                    assert_eq!(a.has_normals, b.has_normals);
                    assert_eq!(a.has_normals, [normals; LANES]);
                }
            }
        }
    }

    /// `small_lights` draws, for every lane, bitwise what `draw`'s per-lane loop draws
    /// with the same numbers: sphere lights (the Veach scene), mesh lights (two quads), and
    /// both in one scene, by uniform and by power choice; random numbers and the edges.
    #[test]
    fn small_lights_draws_are_the_per_lane_draws() {
        use crate::emitter::EmitterSelection;
        use crate::scene::bundled_tests::load;
        let veach = load("veach-mis/veach-mis.xml");
        let quads = load("cbox-twolights/cbox-twolights.xml");
        let mut mixed = veach.clone();
        mixed
            .shapes
            .extend(quads.shapes.iter().filter(|s| s.emitter.is_some()).cloned());
        let below_one = f32::from_bits(1.0f32.to_bits() - 1);
        let mut rng = Rng::new(4, 1);
        let mut kinds = [0; 2];
        for desc in [veach, quads, mixed] {
            let scene = Scene::build(desc).unwrap();
            for selection in [EmitterSelection::Uniform, EmitterSelection::Power] {
                let strategy = crate::integrator::Strategy::combinations()
                    .into_iter()
                    .find(|s| {
                        s.kind == crate::scene::desc::StrategyKind::Mis
                            && s.emitter_samples == 1
                            && s.selection == selection
                            && s.light_sampling == crate::emitter::LightSampling::Area
                    })
                    .unwrap();
                let kernel = super::super::LaneKernel::new(&scene, strategy);
                let lanes = &kernel.tables;
                assert!(lanes.area(), "tables");
                let selector = &kernel.direct.selector;
                let small = lanes.small_lights.as_deref().expect("two to eight lights");
                let n = scene.emitters.len() as f32;
                let edges: [f32; LANES] = std::array::from_fn(|k| match k {
                    0 => 0.0,
                    1 => below_one,
                    _ => (k as f32 - 1.0) / n,
                });
                let mut batches = vec![(edges, edges)];
                batches.extend((0..300).map(|_| {
                    let mut u = || std::array::from_fn(|_| rng.next_f32());
                    (u(), u())
                }));
                let hits = crate::geometry::PacketHits::default();
                for (u_e, u_t) in batches {
                    let (mut a, mut b) = (LightDraws::default(), LightDraws::default());
                    let (mut sa, mut sb) = (SphereDraws::default(), SphereDraws::default());
                    let lights = &lanes.lights;
                    LightDraws::draw(selector, lights, None, &u_e, &u_t, &hits, &mut a, &mut sa);
                    LightDraws::draw(
                        selector,
                        lights,
                        Some(small),
                        &u_e,
                        &u_t,
                        &hits,
                        &mut b,
                        &mut sb,
                    );
                    assert_eq!(a.shape, b.shape, "u {u_e:?}");
                    assert_eq!(a.pmf.map(f32::to_bits), b.pmf.map(f32::to_bits));
                    assert_eq!(a.area.map(f32::to_bits), b.area.map(f32::to_bits));
                    assert_eq!(bits(&a.radiance), bits(&b.radiance));
                    assert_eq!(sa.any, sb.any);
                    for i in 0..LANES {
                        match (sa.sphere[i], sb.sphere[i]) {
                            (Some(x), Some(y)) => {
                                assert_eq!((x.center, x.radius), (y.center, y.radius));
                                assert_eq!(x.flip_normals, y.flip_normals);
                                kinds[0] += 1;
                            }
                            (None, None) => {
                                assert_eq!(a.tri[i], b.tri[i]);
                                for k in 0..3 {
                                    assert_eq!(a.v[k].get(i), b.v[k].get(i));
                                }
                                assert_eq!(
                                    (a.ng.get(i), a.err.get(i)),
                                    (b.ng.get(i), b.err.get(i))
                                );
                                kinds[1] += 1;
                            }
                            _ => panic!("lane {i}: a sphere in one draw only"),
                        }
                    }
                }
            }
        }
        assert!(
            kinds.iter().all(|&k| k > 1000),
            "sphere and mesh lanes {kinds:?}"
        );
    }

    /// Meshes of more than eight triangles keep the per-lane tables.
    #[test]
    fn larger_meshes_have_no_small_tables() {
        let (_, table, records) = fan(9, false);
        assert!(SmallMesh::new(&table, &records).is_none());
    }
}
