//! BSDF elements and `<ref>`s to them. Each registered BSDF reads its own parameters
//! (`crate::bsdf::Bsdf::from_params`) through `ElementParams`, which ties its errors to the
//! file, line and element; `twosided` is the wrapper `Material::two_sided`.

use super::error::SceneError;
use super::loader::Loader;
use super::props::Plugin;
use super::xml::Element;
use crate::bsdf::params::Params;
use crate::bsdf::{BsdfKind, Material, REGISTERED};
use crate::math::Rgb;

/// The BSDF types `bsdf` reads: the registered ones and `twosided`. Every one must have a
/// white-furnace case (`bsdf_furnace_tests`).
pub(crate) fn supported_bsdfs() -> Vec<&'static str> {
    let mut v = REGISTERED.to_vec();
    v.push("twosided");
    v
}

const KNOWN_BSDFS: &[&str] = &[
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

/// A `<bsdf>` element's parameters as `Params`: errors point at the parameter's element
/// when there is one, warnings go to the loader's list.
struct ElementParams<'p, 'a, 'l> {
    plugin: &'p Plugin<'a>,
    loader: &'l mut Loader<'a>,
}

impl Params for ElementParams<'_, '_, '_> {
    type Error = SceneError;
    fn float(&mut self, name: &'static str) -> Result<Option<f32>, SceneError> {
        self.plugin.float(name)
    }
    fn color(&mut self, name: &'static str) -> Result<Option<Rgb>, SceneError> {
        self.plugin.color(name)
    }
    fn string(&mut self, name: &'static str) -> Result<Option<String>, SceneError> {
        Ok(self.plugin.string(name)?.map(|(s, _)| s))
    }
    fn boolean(&mut self, name: &'static str) -> Result<Option<bool>, SceneError> {
        self.plugin.boolean(name)
    }
    fn error(&self, name: Option<&'static str>, message: String) -> SceneError {
        match name.and_then(|n| self.plugin.element_of(n)) {
            Some(e) => e.err(message),
            None => self.plugin.err(message),
        }
    }
    fn warn(&mut self, message: String) {
        self.loader.warn(self.plugin.elem, message);
    }
    fn reject(&mut self, name: &'static str) -> Result<(), SceneError> {
        self.plugin.reject(name)
    }
}

impl<'a> Loader<'a> {
    pub(super) fn bsdf(&mut self, e: &'a Element) -> Result<Material, SceneError> {
        let p = Plugin::new(e, &["type", "id", "name"])?;
        let material = match p.ty.as_str() {
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
                if inner.two_sided {
                    return Err(e.err("twosided cannot nest another twosided"));
                }
                if !inner.kind.two_sided_ok() {
                    return Err(e.err(format!(
                        "twosided cannot wrap a {} (it already handles both sides)",
                        inner.kind.type_name()
                    )));
                }
                Material {
                    two_sided: true,
                    ..inner
                }
            }
            ty => {
                let mut params = ElementParams {
                    plugin: &p,
                    loader: self,
                };
                match BsdfKind::parse(ty, &mut params) {
                    Some(kind) => Material {
                        kind: kind?,
                        two_sided: false,
                    },
                    None if KNOWN_BSDFS.contains(&ty) => {
                        return Err(e.err(format!("bsdf '{ty}' is not supported yet")))
                    }
                    None => {
                        return Err(e.err(format!(
                            "unknown bsdf type '{ty}'; supported: {}",
                            supported_bsdfs().join(", ")
                        )))
                    }
                }
            }
        };
        p.finish()?;
        Ok(material)
    }

    /// `<ref id="..."/>` (optionally with name="bsdf") to a top-level BSDF.
    pub(super) fn bsdf_ref(&mut self, e: &'a Element) -> Result<Material, SceneError> {
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
    ) -> Result<Material, SceneError> {
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

#[cfg(test)]
pub(crate) mod tests {
    use crate::bsdf::{Material, REGISTERED};
    use crate::scene::load_scene_str;
    use std::path::Path;

    /// The shape's material of a Mitsuba 3 scene around `bsdf`, or the loader's message.
    pub(crate) fn read(bsdf: &str) -> Result<Material, String> {
        let xml = format!(
            r#"<scene version="3.0.0">
                 <sensor type="perspective"><float name="fov" value="45"/></sensor>
                 <shape type="rectangle">{bsdf}</shape>
                 <emitter type="point"><point name="position" x="0" y="0" z="1"/></emitter>
               </scene>"#
        );
        load_scene_str(&xml, Path::new("t.xml"), &[])
            .map(|d| d.shapes[0].bsdf.clone())
            .map_err(|e| e.to_string())
    }

    #[test]
    fn every_registered_type_reads_with_its_defaults_and_flags_delta() {
        for ty in REGISTERED {
            let m = read(&format!(r#"<bsdf type="{ty}"/>"#)).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(m.kind.type_name(), *ty);
            assert!(!m.two_sided);
            let delta = matches!(*ty, "conductor" | "dielectric" | "mirror");
            assert_eq!(m.is_delta(), delta, "{ty}");
        }
        let m = read(r#"<bsdf type="twosided"><bsdf type="roughconductor"/></bsdf>"#).unwrap();
        assert!(m.two_sided && m.kind.type_name() == "roughconductor");
    }

    /// What a BSDF's defaults are (`BsdfKind::parse` with `Defaults`, which the tests of
    /// the registry use) is what the scene reader makes of an element with no parameters.
    #[test]
    fn defaults_are_an_empty_element() {
        use crate::bsdf::{params::Defaults, BsdfKind};
        for ty in REGISTERED {
            let m = read(&format!(r#"<bsdf type="{ty}"/>"#)).unwrap();
            let d = BsdfKind::parse(ty, &mut Defaults).unwrap().unwrap();
            assert_eq!(m.kind, d, "{ty}");
        }
    }

    /// A reflectance of exactly 1 is quiet, above 1 (in one channel) warned; an index
    /// component of exactly the largest accepted is read.
    #[test]
    fn reflectance_warnings_and_index_bounds() {
        let warnings = |bsdf: &str| {
            let xml = format!(
                r#"<scene version="3.0.0"><sensor type="perspective"/>
                   <shape type="rectangle">{bsdf}</shape>
                   <emitter type="point"><point name="position" x="0" y="0" z="1"/></emitter>
                   </scene>"#
            );
            load_scene_str(&xml, Path::new("t.xml"), &[])
                .unwrap()
                .warnings
        };
        let quiet = r#"<bsdf type="diffuse"><rgb name="reflectance" value="1, 0.5, 0"/></bsdf>"#;
        assert!(warnings(quiet).is_empty(), "{:?}", warnings(quiet));
        let loud = r#"<bsdf type="diffuse"><rgb name="reflectance" value="0.2, 1.2, 0"/></bsdf>"#;
        assert!(
            warnings(loud).iter().any(|w| w.contains("reflectance")),
            "{:?}",
            warnings(loud)
        );
        let max = crate::bsdf::fresnel::MAX_INDEX;
        let edge = format!(
            r#"<bsdf type="conductor"><rgb name="eta" value="{max}"/><rgb name="k" value="{max}"/></bsdf>"#
        );
        read(&edge).unwrap_or_else(|e| panic!("{e}"));
        let over = format!(
            r#"<bsdf type="conductor"><rgb name="eta" value="1"/><rgb name="k" value="{}"/></bsdf>"#,
            max * 1.01
        );
        assert!(read(&over).unwrap_err().contains("must lie in"));
    }

    /// Bad parameters end in an error that names the element's line and the problem.
    #[test]
    fn bad_parameters_are_refused_with_the_reason() {
        let cases = [
            (
                r#"<bsdf type="roughconductor"><float name="alpha" value="0"/></bsdf>"#,
                "alpha",
            ),
            (
                r#"<bsdf type="roughconductor"><float name="alpha_u" value="0.1"/></bsdf>"#,
                "alpha_v",
            ),
            (
                r#"<bsdf type="dielectric"><float name="int_ior" value="-1.5"/></bsdf>"#,
                "int_ior must be positive",
            ),
            (
                r#"<bsdf type="dielectric"><string name="int_ior" value="unobtainium"/></bsdf>"#,
                "unknown IOR name",
            ),
            (
                r#"<bsdf type="twosided"><bsdf type="dielectric"/></bsdf>"#,
                "cannot wrap a dielectric",
            ),
            (
                r#"<bsdf type="twosided"><bsdf type="twosided"><bsdf type="diffuse"/></bsdf></bsdf>"#,
                "cannot nest",
            ),
            (
                r#"<bsdf type="conductor"><rgb name="eta" value="0.2, 1e30, 1"/><rgb name="k" value="1"/></bsdf>"#,
                "conductor eta",
            ),
            (
                r#"<bsdf type="conductor"><string name="material" value="Zz"/></bsdf>"#,
                "material \"Zz\"",
            ),
            (
                r#"<bsdf type="microfacet"><rgb name="kd" value="1.2, 0.1, 0.1"/></bsdf>"#,
                "must not exceed 1",
            ),
            (
                r#"<bsdf type="diffuse"><rgb name="reflectance" value="-0.5"/></bsdf>"#,
                "non-negative",
            ),
            (
                r#"<bsdf type="diffuse"><rgb name="reflectance" value="0.5"/><rgb name="albedo" value="0.5"/></bsdf>"#,
                "not both",
            ),
            (
                r#"<bsdf type="diffuse"><float name="roughness" value="0.5"/></bsdf>"#,
                "roughness",
            ),
            (r#"<bsdf type="roughdielectric"/>"#, "not supported yet"),
            (
                r#"<bsdf type="roughplastic"><float name="alpha_u" value="0.1"/><float name="alpha_v" value="0.3"/></bsdf>"#,
                "isotropic roughness only",
            ),
            (
                r#"<bsdf type="roughplastic"><float name="int_ior" value="1.5"/><float name="ext_ior" value="1.5"/></bsdf>"#,
                "must differ",
            ),
            (
                r#"<bsdf type="roughconductor"><float name="alpha_u" value="0"/><float name="alpha_v" value="0.1"/></bsdf>"#,
                "alpha) must be positive",
            ),
            (
                r#"<bsdf type="roughconductor"><float name="alpha_u" value="0.1"/><float name="alpha_v" value="0"/></bsdf>"#,
                "alpha) must be positive",
            ),
            (
                r#"<bsdf type="roughconductor"><string name="distribution" value="phong"/></bsdf>"#,
                "\"phong\" is not supported yet",
            ),
            (
                r#"<bsdf type="roughplastic"><string name="distribution" value="blinn"/></bsdf>"#,
                "expected distribution \"beckmann\" or \"ggx\", found \"blinn\"",
            ),
            (
                r#"<bsdf type="plastic"><float name="int_ior" value="0"/></bsdf>"#,
                "int_ior must be positive",
            ),
            (
                r#"<bsdf type="microfacet"><float name="alpha" value="0"/></bsdf>"#,
                "alpha) must be positive",
            ),
            (
                r#"<bsdf type="conductor"><string name="material" value="Au"/><rgb name="eta" value="1"/><rgb name="k" value="1"/></bsdf>"#,
                "not both",
            ),
            (
                r#"<bsdf type="plastic"><rgb name="diffuse_reflectance" value="0"/><rgb name="specular_reflectance" value="0"/></bsdf>"#,
                "both black",
            ),
            (
                r#"<bsdf type="plastic"><string name="int_ior" value="glass"/></bsdf>"#,
                "unknown IOR name",
            ),
            (
                r#"<bsdf type="plastic"><boolean name="nonlinear" value="maybe"/></bsdf>"#,
                "nonlinear",
            ),
            (r#"<bsdf type="velvet"/>"#, "unknown bsdf type 'velvet'"),
        ];
        for (bsdf, words) in cases {
            let e = read(bsdf).expect_err(bsdf);
            assert!(e.contains(words) && e.contains("t.xml:"), "{bsdf}: {e}");
        }
    }
}
