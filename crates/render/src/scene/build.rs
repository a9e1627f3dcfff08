//! From a `SceneDesc` to the renderer's runtime scene: materials, emitters, sampling tables
//! and the BVH. Checks what only makes sense once geometry is known (degenerate emitters).

use super::desc::{AreaEmitterDesc, SceneDesc, ShapeGeometry};
use crate::bsdf::Material;
use crate::camera::Camera;
use crate::emitter::{AreaLight, Emitter, LightSample, PointLight};
use crate::geometry::{
    Accel, Hit, Mesh, PacketHits, Ray, RayPacket, Shape, ShapeKind, Sphere, SurfacePoint, NO_SKIP,
};
use crate::math::{offset_origin, Rgb};
use crate::sampling::AliasTable;
use std::fmt;

/// A scene the renderer cannot use, with the element it came from.
#[derive(Debug, Clone)]
pub struct BuildError {
    /// The shape or light it came from (`file.xml:LINE <shape ...>`).
    pub origin: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.origin, self.message)
    }
}

impl std::error::Error for BuildError {}

/// A scene ready to render: shapes, materials, emitters, their acceleration structures and
/// the camera, built from a `SceneDesc`.
pub struct Scene {
    /// The description it was built from.
    pub desc: SceneDesc,
    /// Shapes in world space.
    pub shapes: Vec<Shape>,
    /// Materials, one per shape.
    pub materials: Vec<Material>,
    /// Emitters: area lights (on shapes) and point lights.
    pub emitters: Vec<Emitter>,
    /// The BVH over every shape.
    pub accel: Accel,
    /// The emitting shapes alone, when they are at most a quarter of the surface area and half
    /// the primitives: a BSDF ray that misses all of them cannot end on an emitter, and then
    /// most BSDF rays miss (see `bsdf_ray_hit`).
    pub emitter_accel: Option<Accel>,
    /// The camera and its film.
    pub camera: Camera,
    /// Non-fatal findings of the reader and the build (printed by the CLI).
    pub warnings: Vec<String>,
}

/// The emitter-only structure of the BSDF-ray pre-test (`Scene::bsdf_ray_hit`), where it
/// pays: most BSDF rays must miss every emitter (the emitters' share of the surface area stands
/// in for that chance), and the pre-test must be cheap (their share of the primitives).
fn emitter_pretest(shapes: &[Shape], emitters: &[Emitter], accel: &Accel) -> Option<Accel> {
    let all_area: f64 = shapes.iter().map(Shape::area).sum();
    let emitter_area: f64 = emitters
        .iter()
        .map(|e| match e {
            Emitter::Area(a) => a.area as f64,
            Emitter::Point(_) => 0.0,
        })
        .sum();
    let is_emitter = |s: &Shape| s.emitter.is_some();
    (4.0 * emitter_area <= all_area
        && 2 * Accel::primitive_count_where(shapes, is_emitter) <= accel.primitive_count())
    .then(|| Accel::build_where(shapes, is_emitter))
}

fn err(origin: &str, message: impl Into<String>) -> BuildError {
    BuildError {
        origin: origin.to_string(),
        message: message.into(),
    }
}

fn check_rgb(origin: &str, what: &str, c: Rgb) -> Result<(), BuildError> {
    if !c.is_finite() || c.min_element() < 0.0 {
        return Err(err(
            origin,
            format!("{what} must be finite and non-negative, found {c}"),
        ));
    }
    Ok(())
}

/// The runtime shape of a shape description, with its input checked.
fn shape_kind(o: &str, geometry: &ShapeGeometry) -> Result<ShapeKind, BuildError> {
    Ok(match geometry {
        ShapeGeometry::Mesh {
            positions,
            normals,
            indices,
        } => {
            if let Some(p) = positions.iter().find(|p| !p.is_finite()) {
                return Err(err(o, format!("mesh has a non-finite vertex {p}")));
            }
            if let Some(t) = indices
                .iter()
                .find(|t| t.iter().any(|&i| i as usize >= positions.len()))
            {
                return Err(err(
                    o,
                    format!(
                        "triangle {t:?} indexes past the {} vertices",
                        positions.len()
                    ),
                ));
            }
            ShapeKind::Mesh(Mesh::new(
                positions.clone(),
                normals.clone(),
                indices.clone(),
            ))
        }
        ShapeGeometry::Sphere {
            center,
            radius,
            flip_normals,
        } => {
            if !center.is_finite() || !radius.is_finite() || *radius <= 0.0 {
                return Err(err(o, format!("sphere needs a finite centre and positive radius, found {center} / {radius}")));
            }
            ShapeKind::Sphere(Sphere {
                center: *center,
                radius: *radius,
                flip_normals: *flip_normals,
            })
        }
    })
}

/// The area light of shape `shape` (its area, and the triangle table of a mesh), with its
/// input checked; degenerate triangles and zero radiance are warnings.
fn area_light(
    o: &str,
    shape: u32,
    kind: &ShapeKind,
    e: &AreaEmitterDesc,
    warnings: &mut Vec<String>,
) -> Result<Emitter, BuildError> {
    check_rgb(o, "emitter radiance", e.radiance)?;
    let (area, triangles) = match kind {
        ShapeKind::Mesh(m) => {
            let areas: Vec<f64> = (0..m.indices.len())
                .map(|t| m.triangle_area(t) as f64)
                .collect();
            if let Some(t) = areas.iter().position(|a| !a.is_finite()) {
                return Err(err(o, format!(
                    "emitter triangle {t}'s area overflows single precision (more than {:e}): the scene is too large for f32; scale it down",
                    f32::MAX
                )));
            }
            let degenerate = areas.iter().filter(|a| **a == 0.0).count();
            let table = AliasTable::new(&areas).ok_or_else(|| {
                // Far from the origin, f32 cannot tell a mesh's vertices apart: a to_world
                // that moves a light there leaves it no area, which is not the mesh's fault.
                let far = m
                    .positions
                    .iter()
                    .map(|p| p.abs().max_element())
                    .fold(0.0f32, f32::max);
                let why = if far > 1e6 {
                    format!(
                        "its vertices lie up to {far:e} from the origin, where single precision \
                         spaces numbers {:e} apart, so its triangles collapse (check the \
                         to_world transform; move the scene closer to the origin)",
                        far * f32::EPSILON
                    )
                } else {
                    "every triangle is degenerate".to_string()
                };
                err(o, format!("emitter mesh has zero total area: {why}"))
            })?;
            if degenerate > 0 {
                warnings.push(format!(
                    "{o}: {degenerate} zero-area triangle(s) in an emitter mesh are never sampled (they emit nothing)"
                ));
            }
            (table.total() as f32, Some(table))
        }
        ShapeKind::Sphere(s) => (s.area(), None),
    };
    if !area.is_finite() {
        return Err(err(o, format!(
            "the emitter's total area overflows single precision (more than {:e}): the scene is too large for f32; scale it down",
            f32::MAX
        )));
    }
    if e.radiance == Rgb::ZERO {
        warnings.push(format!("{o}: emitter has zero radiance: {NEVER_CHOSEN}"));
    }
    Ok(Emitter::Area(AreaLight {
        shape,
        radiance: e.radiance,
        area,
        triangles,
    }))
}

/// What the warnings about emitters that emit nothing add: which emitter choices skip them.
const NEVER_CHOSEN: &str = "power, exhaustive, bvh and ris choice never pick it (pmf 0); \
                            uniform choice spends its share of light samples on it";

/// Where a shadow ray from an origin to a target (at t = 1) stops: just short of the target.
const SHADOW_TMAX: f32 = 1.0 - 1e-4;

impl Scene {
    /// Builds the runtime scene: meshes and spheres, materials, emitters and their sampling
    /// tables, the BVHs and the camera; a scene the renderer cannot use is an error naming its
    /// element.
    pub fn build(desc: SceneDesc) -> Result<Scene, BuildError> {
        let n = desc.shapes.len();
        let mut shapes = Vec::with_capacity(n);
        let mut materials = Vec::with_capacity(n);
        let mut emitters = Vec::new();
        let mut warnings = desc.warnings.clone();
        for sd in &desc.shapes {
            let o = sd.origin.as_str();
            let shape_index = shapes.len() as u32;
            materials.push(sd.bsdf.clone());
            let kind = shape_kind(o, &sd.geometry)?;
            let emitter = match &sd.emitter {
                Some(e) => {
                    emitters.push(area_light(o, shape_index, &kind, e, &mut warnings)?);
                    Some(emitters.len() as u32 - 1)
                }
                None => None,
            };
            shapes.push(Shape {
                kind,
                material: shape_index,
                emitter,
            });
        }
        for pl in &desc.point_lights {
            if !pl.position.is_finite() {
                return Err(err(
                    &pl.origin,
                    format!("point light position must be finite, found {}", pl.position),
                ));
            }
            check_rgb(&pl.origin, "point light intensity", pl.intensity)?;
            if pl.intensity == Rgb::ZERO {
                warnings.push(format!(
                    "{}: point light has zero intensity: {NEVER_CHOSEN}",
                    pl.origin
                ));
            }
            emitters.push(Emitter::Point(PointLight {
                position: pl.position,
                intensity: pl.intensity,
            }));
        }
        if emitters.is_empty() {
            return Err(err(
                &desc.source.display().to_string(),
                "scene has no emitters; directlab renders direct illumination only",
            ));
        }
        let accel = Accel::build(&shapes);
        let emitter_accel = emitter_pretest(&shapes, &emitters, &accel);
        let camera = Camera::new(&desc.camera, &desc.film);
        Ok(Scene {
            shapes,
            materials,
            emitters,
            accel,
            emitter_accel,
            camera,
            warnings,
            desc,
        })
    }

    /// The closest hit of `ray` within its interval.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.accel.intersect(ray, &self.shapes)
    }

    /// `intersect` of each ray set in `active`, traced as one packet, into `out` (see
    /// `Accel::intersect8_into`).
    #[inline]
    pub fn intersect8_into(&self, rays: &RayPacket, active: u32, out: &mut PacketHits) {
        self.accel.intersect8_into(rays, active, &self.shapes, out)
    }

    /// The closest hit if it lies on an emitter.
    #[inline]
    pub fn intersect_emitter(&self, ray: &Ray) -> Option<Hit> {
        let shapes = &self.shapes;
        self.accel
            .intersect_if(ray, shapes, |s| shapes[s].emitter.is_some())
    }

    /// The ray a BSDF sample leaving `sp` in direction `d` traces, and the triangle the
    /// emitter-only structure must skip for it (see `bsdf_ray_hit`).
    #[inline]
    pub fn bsdf_ray(&self, sp: &SurfacePoint, d: glam::Vec3) -> (Ray, u32) {
        let skip = self
            .emitter_accel
            .as_ref()
            .map_or(NO_SKIP, |e| e.skip_id(sp));
        (self.spawn_ray(sp, d), skip)
    }

    /// `intersect_emitter` for a BSDF ray, with the same answer: first an any-hit query
    /// against the emitters alone; only a ray that hits one needs the full closest-hit query.
    /// (A lane that is a hit for a closest-hit query, whose interval only shrinks, is a hit
    /// for the any-hit query over the whole interval: the watertight test's decisions are
    /// monotone in tmax.)
    #[inline(always)]
    pub fn bsdf_ray_hit(&self, ray: &Ray, emitter_skip: u32) -> Option<Hit> {
        match self.bsdf_ray_may_hit(ray) {
            false => None,
            true => self.bsdf_ray_hit_traced(ray, emitter_skip),
        }
    }

    /// `bsdf_ray_hit`'s reject, inline: false for a ray that reaches no light's bounds (most
    /// BSDF rays end here), whose answer is then None.
    #[inline(always)]
    pub fn bsdf_ray_may_hit(&self, ray: &Ray) -> bool {
        self.emitter_accel.as_ref().is_none_or(|e| e.may_hit(ray))
    }

    /// `bsdf_ray_hit`'s reject (`Accel::may_hit`) of each ray set in `active`, in lanes: the
    /// mask of those it lets through, whose answer is then `bsdf_ray_hit_traced`'s. Without
    /// `SPHERES`, only the box reject: the answers stay right, and the lane kernel of scenes
    /// without sphere lights compiles as if there were no sphere test (a branch that is never
    /// taken still cost that kernel measurably, as it changed how the loop compiled).
    #[inline(always)]
    pub fn bsdf_rays_may_hit<const SPHERES: bool>(&self, rays: &RayPacket, active: u32) -> u32 {
        match &self.emitter_accel {
            Some(e) if SPHERES => e.may_hit8_past_box(rays, e.may_hit8(rays) & active),
            Some(e) => e.may_hit8(rays) & active,
            None => active,
        }
    }

    /// `bsdf_ray_hit` past the reject: out of line, since few BSDF rays get here. Its
    /// any-hit query is skipped where the reject already was one (a few sphere lights).
    #[inline(never)]
    pub fn bsdf_ray_hit_traced(&self, ray: &Ray, emitter_skip: u32) -> Option<Hit> {
        if let Some(e) = self
            .emitter_accel
            .as_ref()
            .filter(|e| !e.may_hit_is_occluded())
        {
            if !e.occluded(&Ray {
                skip: emitter_skip,
                ..*ray
            }) {
                return None;
            }
        }
        self.intersect_emitter(ray)
    }

    /// Mutual visibility of a surface point and a point on a light. Both ends are moved off
    /// their surfaces and the shadow ray stops just short of the light, so neither the
    /// receiver nor the light itself counts as a blocker.
    #[inline]
    pub fn visible(&self, from: &SurfacePoint, ls: &LightSample) -> bool {
        !self.accel.occluded(&self.shadow_ray(from, ls))
    }

    /// A ray leaving `sp` in direction `d`.
    #[inline]
    pub fn spawn_ray(&self, sp: &SurfacePoint, d: glam::Vec3) -> Ray {
        Scene::ray_from(sp.spawn_origin(d), d, self.accel.skip_id(sp))
    }

    /// The unbounded ray from origin `o` (already off its surface) along `d`, skipping
    /// triangle `skip`: `spawn_ray` once its origin and skip id are known (the lane kernel
    /// has both per lane).
    #[inline(always)]
    pub fn ray_from(o: glam::Vec3, d: glam::Vec3, skip: u32) -> Ray {
        Ray {
            skip,
            ..Ray::new(o, d)
        }
    }

    /// The shadow ray `visible` traces (unnormalised direction, t in [0, 1 - 1e-4]).
    #[inline]
    pub fn shadow_ray(&self, from: &SurfacePoint, ls: &LightSample) -> Ray {
        let (o, target) = Scene::shadow_ends(from, ls);
        Scene::shadow_ray_to(o, target, self.accel.skip_id(from))
    }

    /// The ends of `shadow_ray`: its origin off `from`, and its target off the light (at a
    /// delta light, the light's point).
    #[inline(always)]
    pub fn shadow_ends(from: &SurfacePoint, ls: &LightSample) -> (glam::Vec3, glam::Vec3) {
        let o = from.spawn_origin(ls.p - from.p);
        let target = if ls.delta {
            ls.p
        } else {
            offset_origin(ls.p, ls.ng, ls.err_scale, o - ls.p)
        };
        (o, target)
    }

    /// The shadow ray from origin `o` to `target`, both already off their surfaces.
    #[inline(always)]
    pub fn shadow_ray_to(o: glam::Vec3, target: glam::Vec3, skip: u32) -> Ray {
        Ray {
            o,
            d: target - o,
            tmin: 0.0,
            tmax: SHADOW_TMAX,
            skip,
        }
    }

    /// The material of the shape `sp` lies on.
    #[inline]
    pub fn material(&self, sp: &SurfacePoint) -> &Material {
        &self.materials[self.shapes[sp.shape as usize].material as usize]
    }

    /// The emitter of the shape `sp` lies on, with its index, if the shape emits.
    #[inline]
    pub fn emitter_at(&self, sp: &SurfacePoint) -> Option<(usize, &Emitter)> {
        let e = self.shapes[sp.shape as usize].emitter? as usize;
        Some((e, &self.emitters[e]))
    }
}
