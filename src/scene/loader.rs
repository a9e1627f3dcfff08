//! From the element tree to a `SceneDesc`: dialect detection and the mapping of sensors,
//! films, samplers, integrators, shapes and emitters (BSDFs live in `bsdf.rs`).
//!
//! One reader serves Mitsuba 3, Mitsuba 0.6 and Nori: names are normalised to snake_case and
//! both dialects' element names are accepted; only defaults differ by dialect.

use super::desc::*;
use super::error::SceneError;
use super::mesh::{self, TriMesh};
use super::props::Plugin;
use super::xml::{parse_document, parse_float, Element};
use glam::{Mat3, Mat4, Vec3};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dialect {
    /// `<scene version="3.x">` (also 2.x, which has the same names).
    Mitsuba3,
    /// `<scene version="0.x">`: camelCase names.
    Mitsuba06,
    /// `<scene>` without a version.
    Nori,
}

/// Reads a scene file. `defines` are the CLI's `-D name=value` overrides.
pub fn load_scene(path: &Path, defines: &[(String, String)]) -> Result<SceneDesc, SceneError> {
    let xml = std::fs::read_to_string(path)
        .map_err(|e| SceneError::new(path, format!("cannot read scene file: {e}")))?;
    load_scene_str(&xml, path, defines)
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
    let mut loader = Loader {
        dialect,
        base_dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        warnings: Vec::new(),
        bsdf_elems: HashMap::new(),
        bsdfs: HashMap::new(),
        resolving: HashSet::new(),
    };
    let mut desc = loader.scene(&root, path)?;
    desc.warnings = loader.warnings;
    Ok(desc)
}

pub(super) struct Loader<'a> {
    pub(super) dialect: Dialect,
    base_dir: PathBuf,
    pub(super) warnings: Vec<String>,
    /// Top-level BSDFs by id, parsed on first use so references may point forwards.
    pub(super) bsdf_elems: HashMap<String, &'a Element>,
    pub(super) bsdfs: HashMap<String, BsdfDesc>,
    pub(super) resolving: HashSet<String>,
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
#[rustfmt::skip]
const KNOWN_INTEGRATORS: &[&str] = &[
    "path", "volpath", "volpathmis", "prb", "prb_basic", "prbvolpath", "direct_projective",
    "prb_projective", "aov", "moment", "stokes", "ptracer", "depth", "bdpt", "mlt", "pssmlt",
    "erpt", "photonmapper", "ppm", "sppm", "vpl", "ao", "normals", "av", "whitted", "path_mis",
    "path_mats", "path_ems", "simple", "volpath_simple", "irrcache", "adaptive", "field",
];
#[rustfmt::skip]
const KNOWN_SENSORS: &[&str] = &[
    "orthographic", "thinlens", "radiancemeter", "irradiancemeter", "distant", "batch",
    "fluencemeter", "spherical", "telecentric", "environment", "perspective_rdist",
];
#[rustfmt::skip]
const KNOWN_SAMPLERS: &[&str] = &[
    "stratified", "multijitter", "orthogonal", "ldsampler", "halton", "hammersley", "sobol",
    "low_discrepancy",
];

fn unsupported(elem: &Element, kind: &str, ty: &str) -> SceneError {
    elem.err(format!("{kind} '{ty}' is not supported yet"))
}

fn unknown(elem: &Element, kind: &str, ty: &str, supported: &str) -> SceneError {
    elem.err(format!(
        "unknown {kind} type '{ty}'; supported: {supported}"
    ))
}

impl<'a> Loader<'a> {
    fn is_nori(&self) -> bool {
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
        let mut shapes = Vec::new();
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
            }),
            shapes,
            point_lights,
            warnings: Vec::new(),
        })
    }

    fn default_film(&self) -> FilmDesc {
        let (width, height) = if self.is_nori() {
            (1280, 720)
        } else {
            (768, 576)
        };
        FilmDesc {
            width,
            height,
            filter: self.default_filter(),
        }
    }

    fn default_filter(&self) -> FilterDesc {
        FilterDesc::Gaussian {
            stddev: 0.5,
            radius: 2.0,
        }
    }

    fn integrator(&mut self, e: &'a Element) -> Result<IntegratorDesc, SceneError> {
        let p = Plugin::new(e, &["type", "id", "name"])?;
        let ty = p.ty.as_str();
        let default_heuristic = if self.is_nori() {
            Heuristic::Balance
        } else {
            Heuristic::Power
        };
        let (mut strategy, mut heuristic) = match ty {
            "direct" => (StrategyKind::Mis, default_heuristic),
            "direct_ems" => (StrategyKind::Light, default_heuristic),
            "direct_mats" => (StrategyKind::Bsdf, default_heuristic),
            "direct_mis" => (StrategyKind::Mis, Heuristic::Balance),
            t if KNOWN_INTEGRATORS.contains(&t) => {
                return Err(e.err(format!(
                    "only direct illumination is supported; found integrator '{t}'"
                )))
            }
            t => {
                return Err(unknown(
                    e,
                    "integrator",
                    t,
                    "direct, direct_ems, direct_mats, direct_mis",
                ))
            }
        };
        if let Some((s, se)) = p.string("sampling")? {
            if ty != "direct" {
                return Err(se.err(format!(
                    "'sampling' only applies to integrator 'direct', not '{ty}'"
                )));
            }
            (strategy, heuristic) = match s.to_ascii_lowercase().as_str() {
                "light" | "emitter" => (StrategyKind::Light, heuristic),
                "material" | "bsdf" => (StrategyKind::Bsdf, heuristic),
                "mis" => (StrategyKind::Mis, heuristic),
                _ => {
                    return Err(se.err(format!(
                        "expected sampling \"light\", \"material\" or \"MIS\", found \"{s}\""
                    )))
                }
            };
        } else if ty == "direct" && self.is_nori() {
            self.warn(
                e,
                "no 'sampling' given; using MIS with the balance heuristic",
            );
        }
        let shading = p.count("shading_samples")?;
        let emitter_samples = p.count("emitter_samples")?.or(shading).unwrap_or(1);
        let bsdf_samples = p.count("bsdf_samples")?.or(shading).unwrap_or(1);
        let hide_emitters = p.boolean("hide_emitters")?.unwrap_or(false);
        p.ignore(
            "strict_normals",
            "directlab always uses the geometric normal for visibility",
            &mut self.warnings,
        );
        p.finish()?;
        if emitter_samples == 0 && bsdf_samples == 0 {
            return Err(e.err("emitter_samples and bsdf_samples are both 0"));
        }
        Ok(IntegratorDesc {
            strategy,
            heuristic,
            emitter_samples,
            bsdf_samples,
            hide_emitters,
        })
    }

    fn sensor(
        &mut self,
        e: &'a Element,
    ) -> Result<(CameraDesc, Option<FilmDesc>, Option<SamplerDesc>), SceneError> {
        let p = Plugin::new(e, &["type", "id", "name"])?;
        match p.ty.as_str() {
            "perspective" => {}
            t if KNOWN_SENSORS.contains(&t) => return Err(unsupported(e, "sensor", t)),
            t => return Err(unknown(e, "sensor", t, "perspective")),
        }
        p.reject("principal_point_offset_x")?;
        p.reject("principal_point_offset_y")?;
        let fov_axis = match p.string("fov_axis")? {
            None => FovAxis::X,
            Some((s, se)) => match s.to_ascii_lowercase().as_str() {
                "x" => FovAxis::X,
                "y" => FovAxis::Y,
                "diagonal" => FovAxis::Diagonal,
                "smaller" => FovAxis::Smaller,
                "larger" => FovAxis::Larger,
                _ => {
                    return Err(se.err(format!(
                        "expected fov_axis x, y, diagonal, smaller or larger, found \"{s}\""
                    )))
                }
            },
        };
        let (fov, fov_axis) = match (p.float("fov")?, p.string("focal_length")?) {
            (Some(_), Some((_, fe))) => {
                return Err(fe.err("give either 'fov' or 'focal_length', not both"))
            }
            (Some(f), None) => (f, fov_axis),
            (None, _) if self.is_nori() => (30.0, fov_axis),
            // Mitsuba's default is a 50 mm lens on 36x24 mm film, measured on the diagonal.
            (None, fl) => {
                let (text, fe) = fl.unwrap_or(("50mm".into(), e));
                let mm = parse_float(text.trim().trim_end_matches("mm")).map_err(|m| fe.err(m))?;
                if mm <= 0.0 {
                    return Err(fe.err("focal_length must be positive"));
                }
                let diagonal = (36.0f32).hypot(24.0);
                (
                    2.0 * (diagonal / (2.0 * mm)).atan().to_degrees(),
                    FovAxis::Diagonal,
                )
            }
        };
        if !(fov > 0.0 && fov < 180.0) {
            return Err(e.err(format!("fov must be in (0, 180) degrees, found {fov}")));
        }
        let near_clip = p
            .float("near_clip")?
            .unwrap_or(if self.is_nori() { 1e-4 } else { 0.01 });
        let far_clip = p.float("far_clip")?.unwrap_or(10000.0);
        if !(near_clip > 0.0 && far_clip > near_clip) {
            return Err(e.err(format!(
                "expected 0 < near_clip < far_clip, found {near_clip} and {far_clip}"
            )));
        }
        let to_world = p.transform("to_world")?.unwrap_or(Mat4::IDENTITY);
        // Rays are built from this matrix; a scale would silently change their lengths (Mitsuba
        // rejects it too). Mirroring, as in Nori's `<scale value="-1,1,1"/>`, is fine.
        if !similarity_scale(&to_world).is_some_and(|s| (s - 1.0).abs() < 1e-3) {
            return Err(e.err(
                "the sensor's to_world may only rotate, translate and mirror (no scale or shear)",
            ));
        }
        p.ignore("shutter_open", "no motion blur", &mut self.warnings);
        p.ignore("shutter_close", "no motion blur", &mut self.warnings);
        p.ignore("focus_distance", "pinhole camera", &mut self.warnings);

        // Nori puts the image size and filter on the camera, Mitsuba in a nested film.
        let width = p.count("width")?;
        let height = p.count("height")?;
        let rfilter = p.nested_one(&["rfilter"])?;
        let film_elem = p.nested_one(&["film"])?;
        let sampler = p.nested_one(&["sampler"])?;
        p.finish()?;
        let mut film = match film_elem {
            Some(f) => {
                if width.is_some() || height.is_some() || rfilter.is_some() {
                    return Err(f.err(
                        "give the image size and filter either on the camera (Nori) or in the \
                         film (Mitsuba), not both",
                    ));
                }
                Some(self.film(f)?)
            }
            None if width.is_some() || height.is_some() || rfilter.is_some() => {
                let d = self.default_film();
                Some(FilmDesc {
                    width: width.unwrap_or(d.width),
                    height: height.unwrap_or(d.height),
                    filter: d.filter,
                })
            }
            None => None,
        };
        if let (Some(f), Some(film)) = (rfilter, film.as_mut()) {
            film.filter = self.rfilter(f)?;
        }
        if let Some(film) = &film {
            if film.width == 0 || film.height == 0 {
                return Err(e.err("image width and height must be positive"));
            }
        }
        let sampler = sampler.map(|s| self.sampler(s)).transpose()?;
        let camera = CameraDesc {
            to_world,
            fov_degrees: fov,
            fov_axis,
            near_clip,
            far_clip,
        };
        Ok((camera, film, sampler))
    }

    fn film(&mut self, e: &'a Element) -> Result<FilmDesc, SceneError> {
        let p = Plugin::new(e, &["type", "id", "name"])?;
        match p.ty.as_str() {
            "hdrfilm" => {}
            // Only the output encoding differs, and directlab always writes HDR.
            "ldrfilm" => {
                self.warn(e, "ldrfilm treated as hdrfilm: tone mapping is not applied");
                for key in ["tonemap_method", "gamma", "exposure", "key", "burn"] {
                    p.ignore(key, "tone mapping (ldrfilm)", &mut self.warnings);
                }
            }
            t @ ("specfilm" | "mfilm" | "tiledhdrfilm") => return Err(unsupported(e, "film", t)),
            t => return Err(unknown(e, "film", t, "hdrfilm")),
        }
        let d = self.default_film();
        let width = p.count("width")?.unwrap_or(d.width);
        let height = p.count("height")?.unwrap_or(d.height);
        for key in [
            "crop_offset_x",
            "crop_offset_y",
            "crop_width",
            "crop_height",
        ] {
            p.reject(key)?;
        }
        for key in [
            "pixel_format",
            "component_format",
            "file_format",
            "banner",
            "attach_log",
            "high_quality_edges",
            "sample_border",
        ] {
            p.ignore(key, "output-format option", &mut self.warnings);
        }
        let filter = match p.nested_one(&["rfilter"])? {
            Some(f) => self.rfilter(f)?,
            None => d.filter,
        };
        p.finish()?;
        if width == 0 || height == 0 {
            return Err(e.err("film width and height must be positive"));
        }
        Ok(FilmDesc {
            width,
            height,
            filter,
        })
    }

    fn rfilter(&mut self, e: &'a Element) -> Result<FilterDesc, SceneError> {
        let p = Plugin::new(e, &["type", "id", "name"])?;
        let filter = match p.ty.as_str() {
            "box" => {
                if let Some(r) = p.float("radius")? {
                    if r != 0.5 {
                        self.warn(
                            e,
                            format!(
                                "box radius {r} ignored; directlab's box filter is one pixel wide"
                            ),
                        );
                    }
                }
                FilterDesc::Box
            }
            "tent" => FilterDesc::Tent {
                radius: p.float("radius")?.unwrap_or(1.0),
            },
            "gaussian" => {
                let stddev = p.float("stddev")?.unwrap_or(0.5);
                // Mitsuba truncates at 4 sigma; Nori at a fixed radius of 2 pixels.
                let default_radius = if self.is_nori() { 2.0 } else { 4.0 * stddev };
                let radius = p.float("radius")?.unwrap_or(default_radius);
                FilterDesc::Gaussian { stddev, radius }
            }
            t @ ("mitchell" | "catmullrom" | "lanczos") => {
                return Err(unsupported(e, "rfilter", t))
            }
            t => return Err(unknown(e, "rfilter", t, "box, tent, gaussian")),
        };
        p.finish()?;
        match filter {
            FilterDesc::Tent { radius } | FilterDesc::Gaussian { radius, .. } if radius <= 0.0 => {
                Err(e.err("filter radius must be positive"))
            }
            FilterDesc::Gaussian { stddev, .. } if stddev <= 0.0 => {
                Err(e.err("gaussian stddev must be positive"))
            }
            f => Ok(f),
        }
    }

    fn sampler(&mut self, e: &'a Element) -> Result<SamplerDesc, SceneError> {
        let p = Plugin::new(e, &["type", "id", "name"])?;
        let default_count = if self.is_nori() { 1 } else { 4 };
        let sample_count = p.count("sample_count")?.unwrap_or(default_count);
        let seed = p.count("seed")?.unwrap_or(0) as u64;
        match p.ty.as_str() {
            "independent" => p.finish()?,
            // The sampler type only changes noise, not the mean: keep the sample count and say so.
            t if KNOWN_SAMPLERS.contains(&t) => {
                for key in [
                    "dimension",
                    "jitter",
                    "scramble",
                    "scramble_seed",
                    "resolution",
                ] {
                    p.ignore(key, "sampler replaced by 'independent'", &mut self.warnings);
                }
                p.finish()?;
                self.warn(e, format!("sampler '{t}' replaced by 'independent'"));
            }
            t => return Err(unknown(e, "sampler", t, "independent")),
        }
        if sample_count == 0 {
            return Err(e.err("sample_count must be at least 1"));
        }
        Ok(SamplerDesc { sample_count, seed })
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
            None => BsdfDesc::Diffuse {
                reflectance: Vec3::splat(0.5),
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
fn similarity_scale(m: &Mat4) -> Option<f32> {
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
#[path = "loader_tests.rs"]
mod tests;
