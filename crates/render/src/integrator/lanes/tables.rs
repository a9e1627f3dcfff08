//! The tables the lane kernel reads, built once per render: the lights it can sample
//! (one 64-byte record per light triangle) and one row per shape (its material as the lanes
//! shade it, its emitter and its skip-id bases), so that a lane's lookups touch one table each
//! where the scene keeps the same data in several.

use crate::emitter::{AreaLight, Emitter, EmitterSelector, LightSampling};
use crate::geometry::{lookup8, Mesh, ShapeKind, Sphere, NO_SKIP};
use crate::integrator::Strategy;
use crate::rng::LANES;
use crate::sampling::elementary::small_int_bits;
use crate::sampling::AliasTable;
use crate::scene::Scene;
use glam::Vec3;

/// An emitter the lanes can sample: what `light_draws` reads of its area light, copied in
/// (behind the `AreaLight` it was one more cache line per lane), and its shape.
pub(super) struct LaneLight<'a> {
    pub(super) shape: u32,
    pub(super) radiance: Vec3,
    pub(super) area: f32,
    pub(super) kind: LaneLightKind<'a>,
}

pub(super) enum LaneLightKind<'a> {
    /// A mesh, with its triangle table, its triangles' records, and the mesh itself where it
    /// has vertex normals (None for flat meshes, which then need no look at the mesh).
    Mesh {
        triangles: &'a AliasTable,
        records: Vec<LightTriangle>,
        smooth: Option<&'a Mesh>,
        /// The same tables in lane form, for a mesh of at most eight triangles.
        small: Option<Box<SmallMesh>>,
    },
    Sphere(&'a Sphere),
}

impl<'a> LaneLight<'a> {
    fn new(light: &AreaLight, kind: LaneLightKind<'a>) -> Self {
        LaneLight {
            shape: light.shape,
            radiance: light.radiance,
            area: light.area,
            kind,
        }
    }
}

/// What `light_draws` reads of a light triangle, in one 64-byte record: `Mesh` keeps the
/// vertices behind an index array and the face in a third table, three or four cache lines
/// apart.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
pub(super) struct LightTriangle {
    pub(super) v: [Vec3; 3],
    pub(super) ng: Vec3,
    pub(super) err: Vec3,
}

impl LightTriangle {
    fn of(mesh: &Mesh, tri: usize) -> Self {
        let (ng, err) = mesh.face(tri);
        LightTriangle {
            v: mesh.vertices(tri),
            ng,
            err,
        }
    }
}

/// An alias table of at most eight bins (`AliasTable`, or the emitter choice) as tables of
/// eight entries, which `lookup8` reads for eight lanes at once.
pub(super) struct LaneAlias {
    n: u32,
    keep: [f32; 8],
    /// Each bin's alias, as f32 bits (the lookup moves bits).
    alias: [f32; 8],
}

impl LaneAlias {
    /// The table of `n` (1 to 8) bins whose keep probability and alias `bin` gives.
    fn new(n: usize, bin: impl Fn(usize) -> (f32, u32)) -> Self {
        debug_assert!((1..=8).contains(&n));
        let mut t = LaneAlias {
            n: n as u32,
            keep: [0.0; 8],
            alias: [0.0; 8],
        };
        for i in 0..n {
            let (keep, alias) = bin(i);
            (t.keep[i], t.alias[i]) = (keep, f32::from_bits(alias));
        }
        t
    }

    /// `AliasTable::sample` of each lane's number, with the same operations.
    #[inline(always)]
    pub(super) fn draw(&self, u: &[f32; LANES]) -> [u32; LANES] {
        let (nf, last) = (self.n as f32, (self.n - 1) as f32);
        let (mut x, mut binf, mut bin) = ([0.0; LANES], [0.0f32; LANES], [0u32; LANES]);
        for k in 0..LANES {
            x[k] = u[k] * nf;
            // `bin_index(x, n)`: the clamp to n - 1, an integer, commutes with truncation.
            // The truncated float is the bin exactly (n <= 8), its integer the low bits of
            // `small_int_bits` (`as u32` would be a scalar conversion per lane).
            binf[k] = x[k].max(0.0).min(last).trunc();
            bin[k] = small_int_bits(binf[k]) & 0xff;
        }
        let (keep, alias) = (lookup8(&self.keep, &bin), lookup8(&self.alias, &bin));
        let mut out = [0u32; LANES];
        for k in 0..LANES {
            let frac = x[k] - binf[k];
            out[k] = if frac < keep[k] {
                bin[k]
            } else {
                alias[k].to_bits()
            };
        }
        out
    }
}

/// A light mesh of at most eight triangles (a quad light has two) as tables of eight
/// entries, one per triangle: its alias table's bins and its records' fields, which
/// `lookup8` reads for eight lanes at once. Drawn with a scalar lookup per lane, the Cornell
/// box light's triangles took about a fifth of the lane kernel's time.
pub(super) struct SmallMesh {
    pub(super) triangles: LaneAlias,
    /// The records' fields, field-major: `v[0].x, v[0].y, v[0].z, v[1].x, ..., ng.x, ...,
    /// err.z`.
    pub(super) fields: [[f32; 8]; 15],
}

impl SmallMesh {
    pub(super) fn new(triangles: &AliasTable, records: &[LightTriangle]) -> Option<Self> {
        if records.len() > 8 || records.len() != triangles.len() {
            return None;
        }
        let mut m = SmallMesh {
            triangles: LaneAlias::new(records.len(), |t| triangles.bin(t)),
            fields: [[0.0; 8]; 15],
        };
        for (t, r) in records.iter().enumerate() {
            let vectors = [r.v[0], r.v[1], r.v[2], r.ng, r.err];
            for (j, x) in vectors.iter().flat_map(|v| v.to_array()).enumerate() {
                m.fields[j][t] = x;
            }
        }
        Some(m)
    }
}

/// A material the lanes shade (`Bsdf::lane_covered`: any whose BSDF has a density, but for
/// a rough conductor's coloured index), with its batch key: the
/// lanes of one batch share a BSDF type and sidedness, so that one instance of the shading
/// code runs them.
#[derive(Clone, Copy)]
pub(super) struct LaneMaterial {
    /// Its index in `Scene::materials`.
    pub(super) index: u32,
    /// The BSDF type's registration index and the sidedness.
    pub(super) key: u32,
    pub(super) two_sided: bool,
}

/// What `camera_hits` needs of a hit's shape, in one lookup where `Scene::material`,
/// `Scene::emitter_at` and the two `skip_id`s read five tables.
#[derive(Clone, Copy)]
pub(super) struct LaneShape {
    /// None for a material left to the scalar path.
    pub(super) material: Option<LaneMaterial>,
    pub(super) emitter: Option<u32>,
    pub(super) skip_base: u32,
    pub(super) emitter_skip_base: u32,
}

/// The tables of the lanes: one light per emitter, one record per shape.
pub(super) struct LaneTables<'a> {
    /// Whether some emitter is a sphere (the lanes then test for sphere lights).
    pub(super) spheres: bool,
    /// One per emitter, where the lanes draw light samples from them (`area`).
    pub(super) lights: Vec<LaneLight<'a>>,
    pub(super) shapes: Vec<LaneShape>,
    /// The emitter choice in lane form, for two to eight emitters.
    pub(super) small_lights: Option<Box<SmallLights>>,
}

/// Two to eight emitters (the Veach scene has five) as tables of eight entries, one per
/// emitter, which `lookup8` reads for eight lanes at once: the emitter choice's bins and
/// pmf, and what `light_draws` copies of the drawn light. A lane whose light is a mesh
/// still draws its triangle alone. Drawn with a scalar choice and copy per lane, the Veach
/// scene's lights took about two fifths of the lane kernel's time.
pub(super) struct SmallLights {
    pub(super) choice: LaneAlias,
    pub(super) pmf: [f32; 8],
    /// Each light's shape, as f32 bits.
    pub(super) shape: [f32; 8],
    pub(super) radiance: [[f32; 8]; 3],
    pub(super) area: [f32; 8],
    /// Each light's sphere, if it is one.
    pub(super) sphere: [Option<Sphere>; 8],
    /// The lights that are meshes, as a mask.
    pub(super) meshes: u32,
}

impl SmallLights {
    pub(super) fn new(lights: &[LaneLight], selector: &EmitterSelector) -> Option<Self> {
        let fits = (2..=8).contains(&lights.len()) && selector.len() == lights.len();
        if !fits || !selector.point_independent() {
            return None;
        }
        let mut t = SmallLights {
            choice: LaneAlias::new(lights.len(), |e| selector.bin(e)),
            pmf: [0.0; 8],
            shape: [0.0; 8],
            radiance: [[0.0; 8]; 3],
            area: [0.0; 8],
            sphere: [None; 8],
            meshes: 0,
        };
        for (e, light) in lights.iter().enumerate() {
            t.pmf[e] = selector.pmf(Vec3::ZERO, Vec3::ZERO, e);
            (t.shape[e], t.area[e]) = (f32::from_bits(light.shape), light.area);
            for (c, r) in light.radiance.to_array().into_iter().enumerate() {
                t.radiance[c][e] = r;
            }
            match light.kind {
                LaneLightKind::Sphere(s) => t.sphere[e] = Some(*s),
                LaneLightKind::Mesh { .. } => t.meshes |= 1 << e,
            }
        }
        Some(t)
    }
}

impl LaneTables<'_> {
    /// Whether the lanes draw light samples from `lights` (area sampling, every emitter an
    /// area light on a mesh or a sphere); otherwise with `Direct::candidate`, lane by lane.
    #[inline(always)]
    pub(super) fn area(&self) -> bool {
        !self.lights.is_empty()
    }
}

/// The lanes' tables for the scene and strategy.
pub(super) fn lane_setup<'a>(
    scene: &'a Scene,
    s: &Strategy,
    selector: &EmitterSelector,
) -> LaneTables<'a> {
    let lights = lane_lights(scene, s).unwrap_or_default();
    let small_lights = SmallLights::new(&lights, selector).map(Box::new);
    let spheres = scene.emitters.iter().any(|e| match e {
        Emitter::Area(light) => {
            matches!(
                scene.shapes[light.shape as usize].kind,
                ShapeKind::Sphere(_)
            )
        }
        Emitter::Point(_) => false,
    });
    let shapes = (0u32..)
        .zip(&scene.shapes)
        .map(|(shape, sh)| {
            let mat = &scene.materials[sh.material as usize];
            let material = mat.kind.lane_covered().then(|| LaneMaterial {
                index: sh.material,
                key: 2 * mat.kind.index() as u32 + mat.two_sided as u32,
                two_sided: mat.two_sided,
            });
            LaneShape {
                material,
                emitter: sh.emitter,
                skip_base: scene.accel.skip_base(shape),
                emitter_skip_base: scene
                    .emitter_accel
                    .as_ref()
                    .map_or(NO_SKIP, |e| e.skip_base(shape)),
            }
        })
        .collect();
    LaneTables {
        spheres,
        lights,
        shapes,
        small_lights,
    }
}

/// The lane lights, one per emitter, if the lanes draw from tables: area sampling, every
/// emitter an area light on a mesh or a sphere.
fn lane_lights<'a>(scene: &'a Scene, s: &Strategy) -> Option<Vec<LaneLight<'a>>> {
    let covered = s.light_sampling == LightSampling::Area && !scene.emitters.is_empty();
    if !covered {
        return None;
    }
    scene
        .emitters
        .iter()
        .map(|e| match e {
            Emitter::Area(light) => {
                match (&scene.shapes[light.shape as usize].kind, &light.triangles) {
                    (ShapeKind::Mesh(mesh), Some(triangles)) => {
                        let records: Vec<_> = (0..triangles.len())
                            .map(|t| LightTriangle::of(mesh, t))
                            .collect();
                        let kind = LaneLightKind::Mesh {
                            triangles,
                            small: SmallMesh::new(triangles, &records).map(Box::new),
                            records,
                            smooth: mesh.normals.is_some().then_some(mesh),
                        };
                        Some(LaneLight::new(light, kind))
                    }
                    (ShapeKind::Sphere(sphere), _) => {
                        Some(LaneLight::new(light, LaneLightKind::Sphere(sphere)))
                    }
                    _ => None,
                }
            }
            Emitter::Point(_) => None,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Accel, SurfacePoint};
    use crate::integrator::Strategy;
    use crate::scene::bundled_tests::load;
    use crate::scene::desc::StrategyKind;

    fn mis() -> Strategy {
        Strategy::combinations()
            .into_iter()
            .find(|s| s.kind == StrategyKind::Mis && s.emitter_samples == 1)
            .unwrap()
    }

    /// Each shape's row says what the scene's own tables say: the material as the lanes
    /// classify it, the emitter, and skip ids equal to `Accel::skip_id` for its triangles.
    #[test]
    fn shape_rows_agree_with_the_scene() {
        for rel in [
            "cbox-materials/cbox-materials.xml",
            "veach-mis/veach-mis.xml",
        ] {
            let mut desc = load(rel);
            // Point lights send a scene to the scalar path.
            desc.point_lights.clear();
            let scene = Scene::build(desc).unwrap();
            let lanes = lane_setup(
                &scene,
                &mis(),
                &EmitterSelector::new(&scene.emitters, &scene.shapes, mis().selection),
            );
            assert!(lanes.area(), "{rel}: tables");
            assert_eq!(lanes.shapes.len(), scene.shapes.len());
            // Rows by (lanes shade it, two-sided).
            let mut kinds = [[0; 2]; 2];
            for (i, (row, shape)) in lanes.shapes.iter().zip(&scene.shapes).enumerate() {
                let mat = &scene.materials[shape.material as usize];
                match row.material {
                    Some(m) => {
                        assert!(
                            !mat.is_delta() && mat.kind.lane_covered(),
                            "{rel} shape {i}"
                        );
                        assert_eq!(m.index, shape.material, "{rel} shape {i}");
                        assert_eq!(m.two_sided, mat.two_sided, "{rel} shape {i}");
                        kinds[0][mat.two_sided as usize] += 1;
                    }
                    None => {
                        assert!(!mat.kind.lane_covered(), "{rel} shape {i}");
                        kinds[1][mat.two_sided as usize] += 1;
                    }
                }
                // One key per BSDF type and sidedness.
                for (other, o) in lanes.shapes.iter().zip(&scene.shapes) {
                    let om = &scene.materials[o.material as usize];
                    if let (Some(a), Some(b)) = (row.material, other.material) {
                        let same = mat.kind.type_name() == om.kind.type_name()
                            && mat.two_sided == om.two_sided;
                        assert_eq!(a.key == b.key, same, "{rel} shape {i}");
                    }
                }
                assert_eq!(row.emitter, shape.emitter);
                let prims = match &shape.kind {
                    ShapeKind::Mesh(m) => m.indices.len() as u32,
                    ShapeKind::Sphere(_) => 1,
                };
                for prim in [0, prims / 2, prims - 1] {
                    let sp = SurfacePoint {
                        p: Vec3::ZERO,
                        ng: Vec3::Z,
                        ns: Vec3::Z,
                        shape: i as u32,
                        prim,
                        err_scale: Vec3::ZERO,
                    };
                    let emitter_skip = scene.emitter_accel.as_ref().map(|e| e.skip_id(&sp));
                    assert_eq!(
                        Accel::skip_from(row.skip_base, prim),
                        scene.accel.skip_id(&sp)
                    );
                    assert_eq!(
                        Accel::skip_from(row.emitter_skip_base, prim),
                        emitter_skip.unwrap_or(NO_SKIP)
                    );
                }
            }
            assert!(kinds[0][0] > 0, "{rel}: {kinds:?}");
            if rel.starts_with("cbox") {
                assert!(kinds[1][0] > 0, "{rel}: delta materials {kinds:?}");
            }
        }
    }

    /// A mesh light's records are its triangles' vertices, face normals and error scales.
    #[test]
    fn light_triangle_records_are_the_mesh_triangles() {
        let scene = Scene::build(load("cbox-meshlight/cbox-meshlight.xml")).unwrap();
        let lanes = lane_setup(
            &scene,
            &mis(),
            &EmitterSelector::new(&scene.emitters, &scene.shapes, mis().selection),
        );
        assert!(lanes.area());
        let mut checked = 0;
        for (light, e) in lanes.lights.iter().zip(&scene.emitters) {
            let LaneLightKind::Mesh {
                records, smooth, ..
            } = &light.kind
            else {
                continue;
            };
            let Emitter::Area(area) = e else {
                panic!("a lane light is an area light");
            };
            assert_eq!(
                (light.shape, light.radiance, light.area),
                (area.shape, area.radiance, area.area)
            );
            let ShapeKind::Mesh(mesh) = &scene.shapes[area.shape as usize].kind else {
                panic!("a mesh light's shape is a mesh");
            };
            assert_eq!(smooth.is_some(), mesh.normals.is_some());
            assert_eq!(records.len(), mesh.indices.len());
            for (t, r) in records.iter().enumerate() {
                assert_eq!(r.v, mesh.vertices(t));
                assert_eq!((r.ng, r.err), mesh.face(t));
                checked += 1;
            }
        }
        assert!(checked > 2, "{checked} light triangles");
    }
}
