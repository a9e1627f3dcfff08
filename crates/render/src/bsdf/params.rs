//! How a BSDF reads its parameters: by Mitsuba's names (snake_case), through `Params`, which
//! the scene reader implements for a `<bsdf>` element (its errors then name the file, line
//! and element). Each BSDF's `from_params` lives in its own file; the helpers here are what
//! several share: named indices of refraction, conductor indices, reflectance checks.

use crate::math::Rgb;
use crate::sampling::microfacet::{Microfacet, MicrofacetDistribution};
use glam::Vec3;

/// A BSDF's parameters, read by name. Every read marks the name as used; what is given and
/// never read is an error of the reader's (a misspelt parameter must not pass silently).
pub trait Params {
    /// The error a parameter read can fail with (a scene error naming the element).
    type Error;
    /// The float parameter `name`, if given.
    fn float(&mut self, name: &'static str) -> Result<Option<f32>, Self::Error>;
    /// `<rgb>`, `<srgb>`, a constant `<spectrum>` or a `<float>` as grey.
    fn color(&mut self, name: &'static str) -> Result<Option<Rgb>, Self::Error>;
    /// The string parameter `name`, if given.
    fn string(&mut self, name: &'static str) -> Result<Option<String>, Self::Error>;
    /// The boolean parameter `name`, if given.
    fn boolean(&mut self, name: &'static str) -> Result<Option<bool>, Self::Error>;
    /// An error about parameter `name` (located at it), or about the whole BSDF.
    fn error(&self, name: Option<&'static str>, message: String) -> Self::Error;
    /// A warning: legal input that is almost always a mistake.
    fn warn(&mut self, message: String);
    /// A parameter Mitsuba knows that directlab does not implement: an error if given.
    fn reject(&mut self, name: &'static str) -> Result<(), Self::Error>;
}

/// Mitsuba's named dielectric IORs (at 589 nm).
const IORS: &[(&str, f32)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

/// Mitsuba's default interior and exterior IORs (BK7 glass in air).
pub const DEFAULT_INT_IOR: f32 = 1.5046;
/// Mitsuba's default exterior index of refraction (air).
pub const DEFAULT_EXT_IOR: f32 = 1.000277;

/// An index of refraction given as a number or by Mitsuba's name ("bk7", "water", ...).
pub fn ior<P: Params>(p: &mut P, name: &'static str, default: f32) -> Result<f32, P::Error> {
    let v = match p.float(name) {
        Ok(Some(v)) => v,
        Ok(None) => return Ok(default),
        // Not a number: a name, or else the reader's own type error.
        Err(e) => match p.string(name) {
            Ok(Some(s)) => IORS
                .iter()
                .find(|(n, _)| n.eq_ignore_ascii_case(s.trim()))
                .map(|(_, v)| *v)
                .ok_or_else(|| {
                    let names: Vec<&str> = IORS.iter().map(|(n, _)| *n).collect();
                    p.error(
                        Some(name),
                        format!(
                            "unknown IOR name \"{s}\"; expected a number or one of: {}",
                            names.join(", ")
                        ),
                    )
                })?,
            _ => return Err(e),
        },
    };
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(p.error(Some(name), format!("{name} must be positive, found {v}")))
    }
}

/// Complex IOR (eta, k) of common metals, projected to linear RGB from Mitsuba's measured
/// spectra (values as tabulated by the Tungsten renderer). Mitsuba 3's own RGB projection may
/// differ in the third digit.
pub const METALS: &[(&str, [f32; 3], [f32; 3])] = &[
    (
        "Ag",
        [0.15526, 0.11672, 0.13838],
        [4.82834, 3.12225, 2.14695],
    ),
    (
        "Al",
        [1.65746, 0.88037, 0.52123],
        [9.22387, 6.26952, 4.83700],
    ),
    (
        "Au",
        [0.14312, 0.37496, 1.44248],
        [3.98316, 2.38572, 1.60322],
    ),
    (
        "Cr",
        [4.36968, 2.91670, 1.65470],
        [5.20643, 4.23137, 3.75495],
    ),
    (
        "Cu",
        [0.20044, 0.92403, 1.10221],
        [3.91295, 2.45285, 2.14219],
    ),
    (
        "W",
        [4.37070, 3.30030, 2.99827],
        [3.50068, 2.60487, 2.27319],
    ),
    // Mitsuba's default: a perfect mirror.
    ("none", [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
];

/// eta, k and specular_reflectance of `conductor` and `roughconductor`: eta and k, or a
/// `material` name from `METALS` (default "none", a perfect mirror).
pub fn conductor<P: Params>(p: &mut P) -> Result<(Rgb, Rgb, Rgb), P::Error> {
    let eta = p.color("eta")?;
    let k = p.color("k")?;
    let material = p.string("material")?;
    let (eta, k) = match (eta, k, material) {
        (Some(eta), Some(k), None) => (eta, k),
        (None, None, material) => {
            let name = material.unwrap_or_else(|| "none".into());
            let (_, eta, k) = METALS
                .iter()
                .find(|(n, _, _)| *n == name.trim())
                .ok_or_else(|| {
                    let names: Vec<&str> = METALS.iter().map(|(n, _, _)| *n).collect();
                    p.error(
                        Some("material"),
                        format!(
                            "conductor material \"{name}\" is not supported yet; available: {} \
                             (or give eta and k)",
                            names.join(", ")
                        ),
                    )
                })?;
            (Vec3::from(*eta), Vec3::from(*k))
        }
        (_, _, Some(_)) => {
            return Err(p.error(
                Some("material"),
                "give either a material name or eta and k, not both".into(),
            ))
        }
        _ => return Err(p.error(None, "give both 'eta' and 'k' (or a material name)".into())),
    };
    for (key, v) in [("eta", eta), ("k", k)] {
        let max = super::fresnel::MAX_INDEX;
        if v.min_element() < 0.0 || v.max_element() > max {
            return Err(p.error(
                None,
                format!("conductor {key} must lie in [0, {max:e}] in every channel, found {v}"),
            ));
        }
    }
    let spec = reflectance(p, "specular_reflectance", Rgb::ONE)?;
    Ok((eta, k, spec))
}

/// A reflectance (default `default`): finite and non-negative; above 1 in some channel it is
/// legal (Mitsuba renders it) but almost always a mistake (values in 0..255, a wrong unit), so
/// it is said in a warning.
pub fn reflectance<P: Params>(
    p: &mut P,
    name: &'static str,
    default: Rgb,
) -> Result<Rgb, P::Error> {
    match p.color(name)? {
        Some(v) => checked_reflectance(p, name, v),
        None => Ok(default),
    }
}

/// `reflectance`'s checks of a value already read.
pub fn checked_reflectance<P: Params>(
    p: &mut P,
    name: &'static str,
    v: Rgb,
) -> Result<Rgb, P::Error> {
    if !(v.is_finite() && v.min_element() >= 0.0) {
        return Err(p.error(
            Some(name),
            format!("{name} must be finite and non-negative, found {v}"),
        ));
    }
    if v.max_element() > 1.0 {
        p.warn(format!(
            "{name} {v} exceeds 1 in some channel: the material creates energy"
        ));
    }
    Ok(v)
}

/// A roughness: finite and positive (default `default`).
pub fn roughness<P: Params>(p: &mut P, name: &'static str, default: f32) -> Result<f32, P::Error> {
    let a = p.float(name)?.unwrap_or(default);
    if a > 0.0 && a.is_finite() {
        Ok(a)
    } else {
        Err(p.error(Some(name), "roughness (alpha) must be positive".to_string()))
    }
}

/// A microfacet lobe's `distribution` (beckmann, ggx; default beckmann), `alpha` or
/// `alpha_u` and `alpha_v` (default 0.1) and `sample_visible` (default true), as Mitsuba's
/// rough plugins read them.
pub fn microfacet<P: Params>(p: &mut P) -> Result<(Microfacet, bool), P::Error> {
    let distribution = match p.string("distribution")? {
        None => MicrofacetDistribution::Beckmann,
        Some(s) => match s.to_ascii_lowercase().as_str() {
            "beckmann" => MicrofacetDistribution::Beckmann,
            "ggx" => MicrofacetDistribution::Ggx,
            "phong" | "as" => {
                return Err(p.error(
                    Some("distribution"),
                    format!("microfacet distribution \"{s}\" is not supported yet"),
                ))
            }
            _ => {
                return Err(p.error(
                    Some("distribution"),
                    format!("expected distribution \"beckmann\" or \"ggx\", found \"{s}\""),
                ))
            }
        },
    };
    let alpha = p.float("alpha")?;
    let alpha_u = p.float("alpha_u")?;
    let alpha_v = p.float("alpha_v")?;
    let (alpha_u, alpha_v) = match (alpha, alpha_u, alpha_v) {
        (Some(a), None, None) => (a, a),
        (None, Some(u), Some(v)) => (u, v),
        (None, None, None) => (0.1, 0.1),
        (Some(_), _, _) => {
            return Err(p.error(
                None,
                "give either 'alpha' or 'alpha_u'/'alpha_v', not both".into(),
            ))
        }
        _ => return Err(p.error(None, "give both 'alpha_u' and 'alpha_v'".into())),
    };
    if !(alpha_u > 0.0 && alpha_v > 0.0 && alpha_u.is_finite() && alpha_v.is_finite()) {
        return Err(p.error(None, "roughness (alpha) must be positive".into()));
    }
    // Mitsuba 0.6 has no such flag; it always sampled visible normals.
    let sample_visible = p.boolean("sample_visible")?.unwrap_or(true);
    Ok((
        Microfacet::new(distribution, alpha_u, alpha_v),
        sample_visible,
    ))
}

/// The coating and base of Mitsuba's `plastic` and `roughplastic`: the index ratio
/// int_ior / ext_ior (defaults "polypropylene", 1.49, and "air"), diffuse_reflectance (0.5),
/// specular_reflectance (1) and nonlinear (false). Not both reflectances black (the lobe
/// choice would divide 0 by 0).
pub fn coated<P: Params>(p: &mut P) -> Result<(f32, Rgb, Rgb, bool), P::Error> {
    let int_ior = ior(p, "int_ior", 1.49)?;
    let ext_ior = ior(p, "ext_ior", DEFAULT_EXT_IOR)?;
    let diffuse = reflectance(p, "diffuse_reflectance", Rgb::splat(0.5))?;
    let specular = reflectance(p, "specular_reflectance", Rgb::ONE)?;
    let nonlinear = p.boolean("nonlinear")?.unwrap_or(false);
    if diffuse.max_element() + specular.max_element() <= 0.0 {
        return Err(p.error(
            None,
            "diffuse_reflectance and specular_reflectance are both black".into(),
        ));
    }
    Ok((int_ior / ext_ior, diffuse, specular, nonlinear))
}

/// No parameter given: a BSDF with its defaults (`BsdfKind::parse(ty, &mut Defaults)`).
pub struct Defaults;

impl Params for Defaults {
    type Error = String;
    fn float(&mut self, _: &'static str) -> Result<Option<f32>, String> {
        Ok(None)
    }
    fn color(&mut self, _: &'static str) -> Result<Option<Rgb>, String> {
        Ok(None)
    }
    fn string(&mut self, _: &'static str) -> Result<Option<String>, String> {
        Ok(None)
    }
    fn boolean(&mut self, _: &'static str) -> Result<Option<bool>, String> {
        Ok(None)
    }
    fn error(&self, _: Option<&'static str>, message: String) -> String {
        message
    }
    fn warn(&mut self, _: String) {}
    fn reject(&mut self, _: &'static str) -> Result<(), String> {
        Ok(())
    }
}
