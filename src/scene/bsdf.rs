//! BSDF elements and `<ref>`s to them, plus the named-IOR and metal tables.

use super::desc::{BsdfDesc, MicrofacetDistribution, Rgb};
use super::error::SceneError;
use super::loader::Loader;
use super::props::Plugin;
use super::xml::Element;
use glam::Vec3;

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

/// Complex IOR (eta, k) of common metals, projected to linear RGB from Mitsuba's measured
/// spectra (values as tabulated by the Tungsten renderer). Mitsuba 3's own RGB projection may
/// differ in the third digit.
pub(crate) const METALS: &[(&str, [f32; 3], [f32; 3])] = &[
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

/// The BSDF types `bsdf` reads: every one must have a white-furnace case
/// (`bsdf_furnace_tests`).
pub(crate) const SUPPORTED_BSDFS: [&str; 7] = [
    "diffuse",
    "twosided",
    "conductor",
    "roughconductor",
    "dielectric",
    "mirror",
    "microfacet",
];

const KNOWN_BSDFS: &[&str] = &[
    "plastic",
    "roughplastic",
    "roughdielectric",
    "thindielectric",
    "principled",
    "principledthinfilm",
    "blendbsdf",
    "mask",
    "bumpmap",
    "normalmap",
    "measured",
    "pplastic",
    "hair",
    "polarizer",
    "retarder",
    "circular",
    "coating",
    "roughcoating",
    "phong",
    "ward",
    "difftrans",
    "irawan",
    "hk",
    "null",
    "roughdiffuse",
    "mixturebsdf",
];

const DEFAULT_INT_IOR: f32 = 1.5046;
const DEFAULT_EXT_IOR: f32 = 1.000277;

fn ior(p: &Plugin, key: &'static str, default: f32) -> Result<f32, SceneError> {
    if let Some(v) = p.float(key).ok().flatten() {
        return positive_ior(p, key, v);
    }
    match p.string(key) {
        Ok(Some((name, se))) => IORS
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name.trim()))
            .map(|(_, v)| *v)
            .ok_or_else(|| {
                let names: Vec<&str> = IORS.iter().map(|(n, _)| *n).collect();
                se.err(format!(
                    "unknown IOR name \"{name}\"; expected a number or one of: {}",
                    names.join(", ")
                ))
            }),
        Ok(None) => Ok(default),
        // Neither a float nor a string: let `float` report the type (or NaN) problem.
        Err(_) => p.float(key).map(|v| v.unwrap_or(default)),
    }
}

fn positive_ior(p: &Plugin, key: &str, v: f32) -> Result<f32, SceneError> {
    if v > 0.0 {
        Ok(v)
    } else {
        Err(p.err(format!("{key} must be positive, found {v}")))
    }
}

/// eta, k and specular_reflectance of `conductor` / `roughconductor`.
fn conductor_params(p: &Plugin) -> Result<(Rgb, Rgb, Rgb), SceneError> {
    let eta = p.color("eta")?;
    let k = p.color("k")?;
    let material = p.string("material")?;
    let (eta, k) = match (eta, k, material) {
        (Some(eta), Some(k), None) => (eta, k),
        (None, None, material) => {
            let (name, elem) = material.unwrap_or(("none".into(), p.elem));
            let (_, eta, k) = METALS
                .iter()
                .find(|(n, _, _)| *n == name.trim())
                .ok_or_else(|| {
                    let names: Vec<&str> = METALS.iter().map(|(n, _, _)| *n).collect();
                    elem.err(format!(
                        "conductor material \"{name}\" is not supported yet; available: {} \
                         (or give eta and k)",
                        names.join(", ")
                    ))
                })?;
            (Vec3::from(*eta), Vec3::from(*k))
        }
        (_, _, Some((_, elem))) => {
            return Err(elem.err("give either a material name or eta and k, not both"))
        }
        _ => return Err(p.err("give both 'eta' and 'k' (or a material name)")),
    };
    for (key, v) in [("eta", eta), ("k", k)] {
        let max = crate::bsdf::fresnel::MAX_INDEX;
        if v.min_element() < 0.0 || v.max_element() > max {
            return Err(p.err(format!(
                "conductor {key} must lie in [0, {max:e}] in every channel, found {v}"
            )));
        }
    }
    let spec = p.color("specular_reflectance")?.unwrap_or(Vec3::ONE);
    Ok((eta, k, spec))
}

impl<'a> Loader<'a> {
    /// A reflectance above 1 reflects more light than arrives: legal input (Mitsuba renders
    /// it), but almost always a mistake (values in 0..255, a wrong unit), so it is said.
    fn warn_above_one(&mut self, e: &Element, name: &str, v: Vec3) {
        if v.max_element() > 1.0 {
            self.warn(
                e,
                format!("{name} {v} exceeds 1 in some channel: the material creates energy"),
            );
        }
    }

    pub(super) fn bsdf(&mut self, e: &'a Element) -> Result<BsdfDesc, SceneError> {
        let p = Plugin::new(e, &["type", "id", "name"])?;
        let bsdf = match p.ty.as_str() {
            "diffuse" => {
                let r = p.color("reflectance")?;
                let a = p.color("albedo")?;
                if r.is_some() && a.is_some() {
                    return Err(e.err("give either 'reflectance' or 'albedo', not both"));
                }
                let reflectance = r.or(a).unwrap_or(Vec3::splat(0.5));
                self.warn_above_one(e, "reflectance", reflectance);
                BsdfDesc::Diffuse { reflectance }
            }
            "twosided" => {
                let inner = match p.nested(&["bsdf", "ref"]).as_slice() {
                    [one] => *one,
                    [] => return Err(e.err("twosided needs one nested <bsdf> or <ref>")),
                    [_, second, ..] => {
                        return Err(second
                            .err("twosided with a different BSDF per side is not supported yet"))
                    }
                };
                let inner = if inner.tag == "ref" {
                    self.bsdf_ref(inner)?
                } else {
                    self.bsdf(inner)?
                };
                BsdfDesc::TwoSided(Box::new(inner))
            }
            "conductor" => {
                let (eta, k, specular_reflectance) = conductor_params(&p)?;
                self.warn_above_one(e, "specular_reflectance", specular_reflectance);
                BsdfDesc::Conductor {
                    eta,
                    k,
                    specular_reflectance,
                }
            }
            "roughconductor" => {
                let (eta, k, specular_reflectance) = conductor_params(&p)?;
                self.warn_above_one(e, "specular_reflectance", specular_reflectance);
                let distribution = match p.string("distribution")? {
                    None => MicrofacetDistribution::Beckmann,
                    Some((s, se)) => match s.to_ascii_lowercase().as_str() {
                        "beckmann" => MicrofacetDistribution::Beckmann,
                        "ggx" => MicrofacetDistribution::Ggx,
                        "phong" | "as" => {
                            return Err(se.err(format!(
                                "microfacet distribution \"{s}\" is not supported yet"
                            )))
                        }
                        _ => {
                            return Err(se.err(format!(
                                "expected distribution \"beckmann\" or \"ggx\", found \"{s}\""
                            )))
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
                        return Err(e.err("give either 'alpha' or 'alpha_u'/'alpha_v', not both"))
                    }
                    _ => return Err(e.err("give both 'alpha_u' and 'alpha_v'")),
                };
                if alpha_u <= 0.0 || alpha_v <= 0.0 {
                    return Err(e.err("roughness (alpha) must be positive"));
                }
                // Mitsuba 0.6 has no such flag; it always sampled visible normals.
                let sample_visible = p.boolean("sample_visible")?.unwrap_or(true);
                BsdfDesc::RoughConductor {
                    distribution,
                    alpha_u,
                    alpha_v,
                    sample_visible,
                    eta,
                    k,
                    specular_reflectance,
                }
            }
            "dielectric" => {
                let int_ior = ior(&p, "int_ior", DEFAULT_INT_IOR)?;
                let ext_ior = ior(&p, "ext_ior", DEFAULT_EXT_IOR)?;
                p.reject("specular_reflectance")?;
                p.reject("specular_transmittance")?;
                BsdfDesc::Dielectric { int_ior, ext_ior }
            }
            "mirror" => BsdfDesc::Mirror,
            "microfacet" => {
                let alpha = p.float("alpha")?.unwrap_or(0.1);
                if alpha <= 0.0 {
                    return Err(e.err("roughness (alpha) must be positive"));
                }
                BsdfDesc::NoriMicrofacet {
                    alpha,
                    int_ior: ior(&p, "int_ior", DEFAULT_INT_IOR)?,
                    ext_ior: ior(&p, "ext_ior", DEFAULT_EXT_IOR)?,
                    kd: p.color("kd")?.unwrap_or(Vec3::splat(0.5)),
                }
            }
            t if KNOWN_BSDFS.contains(&t) => {
                return Err(e.err(format!("bsdf '{t}' is not supported yet")))
            }
            t => {
                return Err(e.err(format!(
                    "unknown bsdf type '{t}'; supported: {}",
                    SUPPORTED_BSDFS.join(", ")
                )))
            }
        };
        p.finish()?;
        Ok(bsdf)
    }

    /// `<ref id="..."/>` (optionally with name="bsdf") to a top-level BSDF.
    pub(super) fn bsdf_ref(&mut self, e: &'a Element) -> Result<BsdfDesc, SceneError> {
        e.check_attrs(&["id", "name"])?;
        if let Some(child) = e.children.first() {
            return Err(child.err("<ref> takes no nested elements"));
        }
        let id = e.required_attr("id")?;
        let Some(target) = self.bsdf_elems.get(id).copied() else {
            return Err(e.err(format!("no top-level <bsdf> has id '{id}'")));
        };
        self.resolve_bsdf(id, target)
    }

    pub(super) fn resolve_bsdf(
        &mut self,
        id: &str,
        target: &'a Element,
    ) -> Result<BsdfDesc, SceneError> {
        if let Some(b) = self.bsdfs.get(id) {
            return Ok(b.clone());
        }
        if !self.resolving.insert(id.to_string()) {
            return Err(target.err(format!("bsdf '{id}' refers to itself")));
        }
        let b = self.bsdf(target)?;
        self.resolving.remove(id);
        self.bsdfs.insert(id.to_string(), b.clone());
        Ok(b)
    }
}
