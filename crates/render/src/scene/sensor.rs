//! Sensor, film, reconstruction filter, sampler and integrator elements.

use super::desc::*;
use super::error::SceneError;
use super::loader::{
    similarity_scale, unknown, unsupported, IntegratorMode, Loader, DIRECT_PART_OF,
};
use super::props::Plugin;
use super::xml::{parse_float, Element};
use crate::named::Named;
use glam::Mat4;

/// The widest reconstruction filter accepted, in pixels.
pub const MAX_FILTER_RADIUS: f32 = 64.0;

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

impl<'a> Loader<'a> {
    pub(super) fn default_film(&self) -> FilmDesc {
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

    pub(super) fn integrator(&mut self, e: &'a Element) -> Result<IntegratorDesc, SceneError> {
        let p = Plugin::new(e, &["type", "id", "name"])?;
        let ty = p.ty.as_str();
        let default_heuristic = if self.is_nori() {
            Heuristic::Balance
        } else {
            Heuristic::Power
        };
        let mut direct_part_of = None;
        let (mut strategy, mut heuristic) = match ty {
            "direct" => (StrategyKind::Mis, default_heuristic),
            "direct_ems" => (StrategyKind::Light, default_heuristic),
            "direct_mats" => (StrategyKind::Bsdf, default_heuristic),
            "direct_mis" => (StrategyKind::Mis, Heuristic::Balance),
            t if DIRECT_PART_OF.iter().any(|(n, _)| *n == t) => {
                if self.mode != Some(IntegratorMode::Direct) {
                    return Err(e.err(format!(
                        "integrator '{t}' renders global illumination, and directlab renders \
                         direct illumination only; to render this scene's direct illumination, \
                         pass --integrator direct (in an experiment file: integrator = \"direct\")"
                    )));
                }
                direct_part_of = Some(t.to_string());
                let kind = DIRECT_PART_OF.iter().find(|(n, _)| *n == t).map(|x| x.1);
                let h = match t.starts_with("path_") || t == "whitted" {
                    true => Heuristic::Balance,
                    false => Heuristic::Power,
                };
                (kind.expect("listed"), h)
            }
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
        let samples = |key| p.bounded(key, crate::limits::TECHNIQUE_SAMPLES);
        let shading = match shading {
            Some(_) => samples("shading_samples")?,
            None => None,
        };
        let emitter_samples = samples("emitter_samples")?.or(shading).unwrap_or(1);
        let bsdf_samples = samples("bsdf_samples")?.or(shading).unwrap_or(1);
        let hide_emitters = p.boolean("hide_emitters")?.unwrap_or(false);
        if direct_part_of.is_some() {
            for key in ["max_depth", "rr_depth"] {
                p.ignore(key, "the direct part has one bounce", &mut self.warnings);
            }
        }
        p.ignore(
            "strict_normals",
            "directlab always uses the geometric normal for visibility",
            &mut self.warnings,
        );
        p.finish()?;
        let strategy = strategy
            .with_sample_counts(emitter_samples, bsdf_samples)
            .map_err(|m| e.err(m))?;
        Ok(IntegratorDesc {
            strategy,
            heuristic,
            emitter_samples,
            bsdf_samples,
            hide_emitters,
            direct_part_of,
        })
    }

    pub(super) fn sensor(
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
            FilterDesc::Tent { radius } | FilterDesc::Gaussian { radius, .. }
                if !(radius <= MAX_FILTER_RADIUS) =>
            {
                Err(e.err(format!(
                    "filter radius {radius} pixels: at most {MAX_FILTER_RADIUS} is accepted (a \
                     wider filter spreads every sample over the whole film, and its weights \
                     underflow to a black image)"
                )))
            }
            FilterDesc::Gaussian { stddev, .. } if stddev <= 0.0 => {
                Err(e.err("gaussian stddev must be positive"))
            }
            f => Ok(f),
        }
    }

    pub(super) fn sampler(&mut self, e: &'a Element) -> Result<SamplerDesc, SceneError> {
        let p = Plugin::new(e, &["type", "id", "name"])?;
        let default_count = if self.is_nori() { 1 } else { 4 };
        let sample_count = p
            .bounded("sample_count", crate::limits::SPP)?
            .unwrap_or(default_count);
        let seed = p.count("seed")?.unwrap_or(0) as u64;
        use crate::sampler::SamplerKind;
        let names: Vec<&str> = SamplerKind::CHOICES.iter().map(|c| c.name).collect();
        let (kind, nearest) = match (SamplerKind::from_name(&p.ty), p.ty.as_str()) {
            (Ok(kind), _) => (kind, false),
            (_, "multijitter" | "orthogonal") => (SamplerKind::Stratified, true),
            (_, "ldsampler" | "low_discrepancy" | "halton" | "hammersley") => {
                (SamplerKind::Sobol, true)
            }
            (_, t) if KNOWN_SAMPLERS.contains(&t) => (SamplerKind::Independent, true),
            (_, t) => {
                return Err(unknown(
                    e,
                    "sampler",
                    t,
                    &format!(
                        "{} (or Mitsuba's multijitter, orthogonal, ldsampler)",
                        names.join(", ")
                    ),
                ))
            }
        };
        let why = format!(
            "sampler '{}' is rendered by directlab's '{}'",
            p.ty,
            kind.name()
        );
        for key in [
            "dimension",
            "jitter",
            "scramble",
            "scramble_seed",
            "resolution",
        ] {
            p.ignore(key, &why, &mut self.warnings);
        }
        p.finish()?;
        if nearest {
            self.warn(
                e,
                format!("{why}, the nearest one (same mean, different noise and convergence)"),
            );
        }
        if sample_count == 0 {
            return Err(e.err("sample_count must be at least 1"));
        }
        Ok(SamplerDesc {
            sample_count,
            seed,
            kind,
        })
    }
}
