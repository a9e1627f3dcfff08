//! From the element tree to a `SceneDesc`: dialect detection, the scene-level checks and the
//! mapping of shapes and emitters. Sensors, films, samplers and integrators are in `sensor.rs`,
//! BSDFs in `bsdf.rs`.
//!
//! One reader serves Mitsuba 3, Mitsuba 0.6 and Nori: names are normalised to snake_case and
//! both dialects' element names are accepted; only defaults differ by dialect.

use super::desc::*;
use super::error::SceneError;
use super::mesh::{self, TriMesh};
use super::props::Plugin;
use super::xml::{parse_document, Element};
use crate::bsdf::{BsdfKind, Diffuse, Material};
use glam::{Mat3, Mat4, Vec3};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// The XML dialect of a scene file, from its `version` attribute.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dialect {
    /// `<scene version="3.x">` (also 2.x, which has the same names).
    Mitsuba3,
    /// `<scene version="0.x">`: camelCase names.
    Mitsuba06,
    /// `<scene>` without a version.
    Nori,
}

/// How a scene's `<integrator>` is read (`--integrator`, `integrator = ...` in experiment
/// files).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(try_from = "String")]
pub enum IntegratorMode {
    /// Render the direct illumination of a scene whose integrator is a path tracer or
    /// Whitted's (Nori's path_mis, path_ems, path_mats, whitted; Mitsuba's path, volpath):
    /// the image is then the direct part only
    Direct,
}

impl crate::named::Named for IntegratorMode {
    const WHAT: &'static str = "integrator mode";
    const CHOICES: &'static [crate::named::Choice<Self>] = &[crate::named::Choice {
        value: IntegratorMode::Direct,
        name: "direct",
        help: "render the direct part of a path tracer's or Whitted's scene",
    }];
}
crate::named_impls!(IntegratorMode);

/// Global-illumination integrators whose direct illumination directlab renders under
/// `--integrator direct`, and the strategy their direct part uses: Nori's path_ems and
/// whitted sample emitters, path_mats the BSDF, path_mis both with the balance heuristic;
/// Mitsuba's path tracers both with the power heuristic.
pub const DIRECT_PART_OF: &[(&str, StrategyKind)] = &[
    ("path_mis", StrategyKind::Mis),
    ("path_ems", StrategyKind::Light),
    ("path_mats", StrategyKind::Bsdf),
    ("whitted", StrategyKind::Light),
    ("path", StrategyKind::Mis),
    ("volpath", StrategyKind::Mis),
];

/// A `-D name=value` define from the command line.
pub fn parse_define(s: &str) -> Result<(String, String), String> {
    let (k, v) = s
        .split_once('=')
        .ok_or_else(|| format!("expected name=value, found '{s}'"))?;
    if k.is_empty() {
        return Err(format!("expected name=value, found '{s}'"));
    }
    Ok((k.to_string(), v.to_string()))
}

/// Reads a scene file. `defines` are the CLI's `-D name=value` overrides.
pub fn load_scene(path: &Path, defines: &[(String, String)]) -> Result<SceneDesc, SceneError> {
    load_scene_with(path, defines, None)
}

/// [`load_scene`] with the integrator read as `mode` says.
pub fn load_scene_with(
    path: &Path,
    defines: &[(String, String)],
    mode: Option<IntegratorMode>,
) -> Result<SceneDesc, SceneError> {
    let xml = read_text_file(path, MAX_SCENE_BYTES, "scene file")?;
    let root = parse_document(&xml, path, defines)?;
    load_scene_element(&root, path, mode)
}

/// The largest scene file read (meshes live in their own files): far above any hand-written
/// or exported scene, and a bound on what a wrong path (a device, a log) can cost.
pub const MAX_SCENE_BYTES: u64 = 1 << 30;

/// Reads a text file of at most `limit` bytes. Anything but a regular file (a device such as
/// `/dev/zero`, a FIFO, a directory) is refused before reading, since it may never end.
pub fn read_text_file(path: &Path, limit: u64, what: &str) -> Result<String, SceneError> {
    use std::io::Read;
    let fail = |m: String| SceneError::new(path, m);
    let meta = std::fs::metadata(path).map_err(|e| fail(format!("cannot read {what}: {e}")))?;
    if !meta.is_file() {
        return Err(fail(format!(
            "cannot read {what}: expected a regular file, found {}",
            if meta.is_dir() {
                "a directory"
            } else {
                "a device, FIFO or socket"
            }
        )));
    }
    if meta.len() > limit {
        return Err(fail(format!(
            "{what} is {} bytes, more than the {limit} accepted",
            meta.len()
        )));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    std::fs::File::open(path)
        .and_then(|f| f.take(limit + 1).read_to_end(&mut bytes))
        .map_err(|e| fail(format!("cannot read {what}: {e}")))?;
    if bytes.len() as u64 > limit {
        return Err(fail(format!(
            "{what} is more than the {limit} bytes accepted"
        )));
    }
    String::from_utf8(bytes).map_err(|e| {
        fail(format!(
            "cannot read {what}: not UTF-8 text (invalid byte at offset {})",
            e.utf8_error().valid_up_to()
        ))
    })
}

/// Reads a scene from a string; `path` names it in messages and relative mesh paths are
/// resolved against its folder.
pub fn load_scene_str(
    xml: &str,
    path: &Path,
    defines: &[(String, String)],
) -> Result<SceneDesc, SceneError> {
    let root = parse_document(xml, path, defines)?;
    if root.tag != "scene" {
        return Err(root.err("expected <scene> as the root element"));
    }
    load_scene_element(&root, path, None)
}

/// A scene from its `<scene>` element (the root of a scene file, or a scene inside a Nori
/// test file); `path` is the file it came from.
pub fn load_scene_element(
    root: &Element,
    path: &Path,
    mode: Option<IntegratorMode>,
) -> Result<SceneDesc, SceneError> {
    if root.tag != "scene" {
        return Err(root.err("expected <scene> as the root element"));
    }
    root.check_attrs(&["version"])?;
    let dialect = match root.attr("version") {
        None => Dialect::Nori,
        Some(v) if v.starts_with("3.") || v.starts_with("2.") => Dialect::Mitsuba3,
        Some(v) if v.starts_with("0.") => Dialect::Mitsuba06,
        Some(v) => {
            return Err(root.err(format!(
                "unsupported scene version \"{v}\"; expected 3.x (Mitsuba 3), 0.x (Mitsuba 0.6) \
                 or none (Nori)"
            )))
        }
    };
    let mut loader = Loader::new(dialect, path, mode);
    let mut desc = loader.scene(root, path)?;
    desc.warnings = loader.warnings;
    Ok(desc)
}

/// A BSDF from its `<bsdf>` element in `dialect` (a BSDF inside a Nori test file); its
/// warnings are returned beside it.
pub fn load_bsdf_element(
    e: &Element,
    path: &Path,
    dialect: Dialect,
) -> Result<(Material, Vec<String>), SceneError> {
    let mut loader = Loader::new(dialect, path, None);
    let m = loader.bsdf(e)?;
    Ok((m, loader.warnings))
}

pub(super) struct Loader<'a> {
    pub(super) dialect: Dialect,
    base_dir: PathBuf,
    pub(super) warnings: Vec<String>,
    /// Top-level BSDFs by id, parsed on first use so references may point forwards.
    pub(super) bsdf_elems: HashMap<String, &'a Element>,
    pub(super) bsdfs: HashMap<String, Material>,
    pub(super) resolving: HashSet<String>,
    pub(super) mode: Option<IntegratorMode>,
}

/// Plugin types that exist in Mitsuba or Nori but that directlab does not implement; naming
/// them gives a "not supported yet" instead of an "unknown type" message.
#[rustfmt::skip]
const KNOWN_SHAPES: &[&str] = &[
    "ply", "serialized", "disk", "cylinder", "shapegroup", "instance", "hair", "heightfield",
    "bsplinecurve", "linearcurve", "sdfgrid", "ellipsoids", "ellipsoidsmesh", "merge",
];
#[rustfmt::skip]
const KNOWN_EMITTERS: &[&str] = &[
    "envmap", "constant", "directional", "spot", "projector", "sunsky", "sky", "sun",
    "collimated", "directionalarea", "environment", "envlight",
];

pub(super) fn unsupported(elem: &Element, kind: &str, ty: &str) -> SceneError {
    elem.err(format!("{kind} '{ty}' is not supported yet"))
}

pub(super) fn unknown(elem: &Element, kind: &str, ty: &str, supported: &str) -> SceneError {
    elem.err(format!(
        "unknown {kind} type '{ty}'; supported: {supported}"
    ))
}

impl<'a> Loader<'a> {
    /// A loader for a document at `path` (relative mesh paths resolve against its folder).
    fn new(dialect: Dialect, path: &Path, mode: Option<IntegratorMode>) -> Self {
        Loader {
            dialect,
            base_dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
            warnings: Vec::new(),
            bsdf_elems: HashMap::new(),
            bsdfs: HashMap::new(),
            resolving: HashSet::new(),
            mode,
        }
    }

    pub(super) fn is_nori(&self) -> bool {
        self.dialect == Dialect::Nori
    }

    pub(super) fn warn(&mut self, elem: &Element, message: impl AsRef<str>) {
        self.warnings
            .push(format!("{}: {}", elem.origin(), message.as_ref()));
    }

    fn scene(&mut self, root: &'a Element, path: &Path) -> Result<SceneDesc, SceneError> {
        for e in root.children.iter().filter(|e| e.tag == "bsdf") {
            match e.attr("id") {
                Some(id) => {
                    if let Some(prev) = self.bsdf_elems.insert(id.to_string(), e) {
                        return Err(
                            e.err(format!("id '{id}' is already used on line {}", prev.line))
                        );
                    }
                }
                None => self.warn(e, "top-level bsdf without an id is never used"),
            }
        }
        // Parse every top-level BSDF, used or not, so mistakes in unused ones are still found.
        for e in root.children.iter().filter(|e| e.tag == "bsdf") {
            match e.attr("id") {
                Some(id) => {
                    self.resolve_bsdf(id, e)?;
                }
                None => {
                    self.bsdf(e)?;
                }
            }
        }

        let mut sensor: Option<(CameraDesc, Option<FilmDesc>, Option<SamplerDesc>)> = None;
        let mut sampler: Option<SamplerDesc> = None;
        let mut integrator: Option<IntegratorDesc> = None;
        let mut shapes = Vec::with_capacity(root.children.len());
        let mut point_lights = Vec::new();
        for e in &root.children {
            match e.tag.as_str() {
                "default" | "bsdf" => {}
                "integrator" => {
                    if integrator.is_some() {
                        return Err(e.err("only one <integrator> is allowed"));
                    }
                    integrator = Some(self.integrator(e)?);
                }
                "sensor" | "camera" => {
                    if sensor.is_some() {
                        return Err(e.err("only one sensor/camera is allowed"));
                    }
                    sensor = Some(self.sensor(e)?);
                }
                "sampler" => {
                    if sampler.is_some() {
                        return Err(e.err("only one <sampler> is allowed"));
                    }
                    sampler = Some(self.sampler(e)?);
                }
                "shape" | "mesh" => shapes.push(self.shape(e)?),
                "emitter" => point_lights.push(self.point_light(e)?),
                "texture" | "medium" | "phase" | "volume" | "include" | "path" | "alias" => {
                    return Err(e.err(format!("<{}> is not supported yet", e.tag)))
                }
                "film" | "rfilter" => {
                    return Err(e.err(format!("<{}> must be nested in the sensor", e.tag)))
                }
                other => {
                    return Err(e.err(format!(
                        "unknown element <{other}> in <scene>; expected integrator, sensor \
                         (camera), sampler, film, bsdf, shape (mesh), emitter or default"
                    )))
                }
            }
        }

        let Some((camera, film, nested_sampler)) = sensor else {
            return Err(root.err("scene has no <sensor> (Mitsuba) or <camera> (Nori)"));
        };
        let sampler = match (sampler, nested_sampler) {
            (Some(_), Some(_)) => {
                return Err(root.err("scene has two samplers (one in the sensor, one outside)"))
            }
            (a, b) => a.or(b).unwrap_or(SamplerDesc {
                sample_count: if self.is_nori() { 1 } else { 4 },
                seed: 0,
                kind: Default::default(),
            }),
        };
        let film = film.unwrap_or(self.default_film());
        if shapes.iter().all(|s: &ShapeDesc| s.emitter.is_none()) && point_lights.is_empty() {
            return Err(
                root.err("scene has no emitters; directlab renders direct illumination only")
            );
        }
        Ok(SceneDesc {
            source: path.to_path_buf(),
            camera,
            film,
            sampler,
            integrator: integrator.unwrap_or(IntegratorDesc {
                strategy: StrategyKind::Mis,
                heuristic: Heuristic::Power,
                emitter_samples: 1,
                bsdf_samples: 1,
                hide_emitters: false,
                direct_part_of: None,
            }),
            shapes,
            point_lights,
            warnings: Vec::new(),
        })
    }

    fn shape(&mut self, e: &'a Element) -> Result<ShapeDesc, SceneError> {
        let p = Plugin::new(e, &["type", "id", "name"])?;
        let to_world = p.transform("to_world")?.unwrap_or(Mat4::IDENTITY);
        let flip = p.boolean("flip_normals")?.unwrap_or(false);
        let geometry = match p.ty.as_str() {
            ty @ ("obj" | "rectangle" | "cube") => {
                let mut mesh = match ty {
                    "obj" => {
                        let (file, fe) = p
                            .string("filename")?
                            .ok_or_else(|| e.err("expected a 'filename' parameter"))?;
                        let path = self.base_dir.join(&file);
                        p.reject("max_smooth_angle")?;
                        p.ignore(
                            "flip_tex_coords",
                            "meshes carry no texture coordinates",
                            &mut self.warnings,
                        );
                        mesh::load_obj(&path).map_err(|m| fe.err(m))?
                    }
                    "rectangle" => mesh::rectangle(),
                    _ => mesh::cube(),
                };
                let face_normals = p.boolean("face_normals")?.unwrap_or(false);
                let det = to_world.determinant();
                if det.abs() < 1e-30 {
                    return Err(e.err("to_world is singular (zero scale?)"));
                }
                if det < 0.0 {
                    self.warn(
                        e,
                        "to_world mirrors the shape; triangles keep their vertex order, so the \
                         winding-based normal flips relative to the (transformed) vertex \
                         normals; add flip_normals if the wrong side faces out",
                    );
                }
                mesh.transform(&to_world);
                if face_normals {
                    mesh.normals = None;
                }
                if flip {
                    mesh.flip();
                }
                let TriMesh {
                    positions,
                    normals,
                    indices,
                } = mesh;
                ShapeGeometry::Mesh {
                    positions,
                    normals,
                    indices,
                }
            }
            "sphere" => {
                let center = p.vec3("center")?.unwrap_or(Vec3::ZERO);
                let radius = p.float("radius")?.unwrap_or(1.0);
                if radius <= 0.0 {
                    return Err(e.err(format!("sphere radius must be positive, found {radius}")));
                }
                let scale = similarity_scale(&to_world).ok_or_else(|| {
                    e.err(
                        "non-uniform scale (or shear) on a sphere is not supported; to_world \
                           may only translate, rotate and scale uniformly",
                    )
                })?;
                ShapeGeometry::Sphere {
                    center: to_world.transform_point3(center),
                    radius: radius * scale,
                    flip_normals: flip,
                }
            }
            t if KNOWN_SHAPES.contains(&t) => return Err(unsupported(e, "shape", t)),
            t => return Err(unknown(e, "shape", t, "obj, rectangle, cube, sphere")),
        };
        let bsdf = match p.nested_one(&["bsdf", "ref"])? {
            Some(b) if b.tag == "ref" => self.bsdf_ref(b)?,
            Some(b) => self.bsdf(b)?,
            None => Material {
                kind: BsdfKind::Diffuse(Diffuse {
                    reflectance: Vec3::splat(0.5),
                }),
                two_sided: false,
            },
        };
        let emitter = p
            .nested_one(&["emitter"])?
            .map(|em| self.area_emitter(em))
            .transpose()?;
        p.finish()?;
        Ok(ShapeDesc {
            geometry,
            bsdf,
            emitter,
            origin: e.origin(),
        })
    }

    fn area_emitter(&mut self, e: &'a Element) -> Result<AreaEmitterDesc, SceneError> {
        let p = Plugin::new(e, &["type", "id", "name"])?;
        match p.ty.as_str() {
            "area" => {}
            t @ ("point" | "pointlight") => {
                return Err(e.err(format!(
                    "emitter '{t}' cannot be attached to a shape; declare it at the top level"
                )))
            }
            t if KNOWN_EMITTERS.contains(&t) => return Err(unsupported(e, "emitter", t)),
            t => return Err(unknown(e, "emitter", t, "area (in a shape), point")),
        }
        // Mitsuba defaults to unit radiance; Nori requires it.
        let radiance = match p.color("radiance")? {
            Some(r) => r,
            None if self.is_nori() => return Err(e.err("expected a 'radiance' parameter")),
            None => Vec3::ONE,
        };
        p.ignore(
            "sampling_weight",
            "emitters are chosen by power",
            &mut self.warnings,
        );
        p.finish()?;
        Ok(AreaEmitterDesc { radiance })
    }

    fn point_light(&mut self, e: &'a Element) -> Result<PointLightDesc, SceneError> {
        let p = Plugin::new(e, &["type", "id", "name"])?;
        let ty = p.ty.clone();
        match ty.as_str() {
            "point" | "pointlight" => {}
            "area" => {
                return Err(e.err(
                    "an area emitter must be nested in the shape (<shape>/<mesh>) that emits",
                ))
            }
            t if KNOWN_EMITTERS.contains(&t) => return Err(unsupported(e, "emitter", t)),
            t => {
                return Err(unknown(
                    e,
                    "emitter",
                    t,
                    "area (in a shape), point, pointlight",
                ))
            }
        }
        let position = match (p.vec3("position")?, p.transform("to_world")?) {
            (Some(_), Some(_)) => {
                return Err(e.err("give either 'position' or 'to_world', not both"))
            }
            (Some(pos), None) => pos,
            (None, Some(m)) => m.transform_point3(Vec3::ZERO),
            (None, None) => Vec3::ZERO,
        };
        let intensity = p.color("intensity")?;
        // Nori's `point` takes the total power in watts; its `pointlight` calls the intensity
        // "radiance".
        let power = p.color("power")?;
        let radiance = if ty == "pointlight" {
            p.color("radiance")?
        } else {
            None
        };
        p.ignore(
            "sampling_weight",
            "emitters are chosen by power",
            &mut self.warnings,
        );
        p.finish()?;
        let intensity =
            match (intensity, power, radiance) {
                (Some(i), None, None) | (None, None, Some(i)) => i,
                (None, Some(w), None) => w / (4.0 * std::f32::consts::PI),
                (None, None, None) => Vec3::ONE,
                _ => return Err(e.err(
                    "give only one of 'intensity' (W/sr), 'power' (W) or 'radiance' (pointlight)",
                )),
            };
        Ok(PointLightDesc {
            position,
            intensity,
            origin: e.origin(),
        })
    }
}

/// The uniform scale factor of a translate/rotate/uniform-scale matrix, or None for anything
/// else (non-uniform scale, shear, projection).
pub(super) fn similarity_scale(m: &Mat4) -> Option<f32> {
    if m.row(3).abs_diff_eq(glam::Vec4::W, 1e-6) {
        let l = Mat3::from_mat4(*m);
        let s = l.x_axis.length();
        let tol = 1e-4 * s * s;
        let gram = l.transpose() * l;
        let ok = s > 0.0 && gram.abs_diff_eq(Mat3::from_diagonal(Vec3::splat(s * s)), tol);
        ok.then_some(s)
    } else {
        None
    }
}

#[cfg(test)]
#[path = "loader_bsdf_tests.rs"]
mod bsdf_tests;
#[cfg(test)]
#[path = "loader_nori_tests.rs"]
mod nori_tests;
#[cfg(test)]
#[path = "loader_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "error_tests.rs"]
mod error_tests;
