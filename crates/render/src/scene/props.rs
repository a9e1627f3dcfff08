//! The parameters of one plugin element (`<bsdf type="diffuse">` ...), read by name.
//!
//! Every read marks the parameter as used; `finish` then rejects whatever the plugin did not
//! read. That is how misspelt or unsupported parameters become errors instead of silently
//! falling back to defaults. Names are compared after camelCase -> snake_case normalisation.

use super::desc::Rgb;
use super::error::SceneError;
use super::transform::parse_transform;
use super::xml::{normalize_name, parse_bool, parse_float, parse_int, parse_vec3, Element};
use glam::{Mat4, Vec3};
use std::cell::{Cell, RefCell};

/// Element names that hold a parameter value (everything else inside a plugin is a nested
/// plugin or a reference).
const PROPERTY_TAGS: &[&str] = &[
    "float",
    "integer",
    "boolean",
    "string",
    "rgb",
    "srgb",
    "color",
    "spectrum",
    "point",
    "vector",
    "transform",
];

struct Prop<'a> {
    name: String,
    elem: &'a Element,
    used: Cell<bool>,
}

/// A plugin element (`<bsdf type=...>`, `<shape ...>`, ...) and its parameters: each read
/// marks its parameter used, and a parameter nobody read is an error naming it.
pub struct Plugin<'a> {
    /// The element.
    pub elem: &'a Element,
    /// Its `type` attribute.
    pub ty: String,
    props: Vec<Prop<'a>>,
    nested: Vec<(&'a Element, Cell<bool>)>,
    /// Names the plugin asked for, listed when an unknown one is found.
    queried: RefCell<Vec<&'static str>>,
}

impl<'a> Plugin<'a> {
    /// The plugin `elem`, which may carry the attributes `attrs` besides `type`.
    pub fn new(elem: &'a Element, attrs: &[&str]) -> Result<Self, SceneError> {
        elem.check_attrs(attrs)?;
        let ty = elem.required_attr("type")?.to_string();
        let mut props: Vec<Prop<'a>> = Vec::new();
        // Name to index, so a plugin with many parameters is checked in linear time.
        let mut seen: std::collections::HashMap<String, usize> = Default::default();
        let mut nested = Vec::new();
        for child in &elem.children {
            let tag = child.tag.as_str();
            if tag == "texture" || tag == "blackbody" {
                let what = child.attr("type").unwrap_or(tag);
                return Err(child.err(format!(
                    "{tag} '{what}' is not supported yet (only constant colours)"
                )));
            }
            if !PROPERTY_TAGS.contains(&tag) {
                nested.push((child, Cell::new(false)));
                continue;
            }
            child.check_attrs(match tag {
                "rgb" | "srgb" | "color" => &["name", "value", "intent"],
                "spectrum" => &["name", "value", "filename", "intent"],
                "point" | "vector" => &["name", "value", "x", "y", "z"],
                "transform" => &["name"],
                _ => &["name", "value"],
            })?;
            let name = normalize_name(child.required_attr("name")?);
            if let Some(&first) = seen.get(&name) {
                return Err(child.err(format!(
                    "parameter '{name}' is given twice (first on line {})",
                    props[first].elem.line
                )));
            }
            seen.insert(name.clone(), props.len());
            props.push(Prop {
                name,
                elem: child,
                used: Cell::new(false),
            });
        }
        Ok(Plugin {
            elem,
            ty,
            props,
            nested,
            queried: RefCell::new(Vec::new()),
        })
    }

    /// "bsdf 'diffuse'" and the like.
    pub fn what(&self) -> String {
        format!("{} '{}'", self.elem.tag, self.ty)
    }

    /// An error about this plugin's element.
    pub fn err(&self, message: impl Into<String>) -> SceneError {
        self.elem.err(message)
    }

    fn get(&self, key: &'static str) -> Option<&Prop<'a>> {
        self.queried.borrow_mut().push(key);
        let p = self.props.iter().find(|p| p.name == key)?;
        p.used.set(true);
        Some(p)
    }

    /// The element that gives parameter `key`, if it is given.
    pub fn element_of(&self, key: &str) -> Option<&'a Element> {
        self.props.iter().find(|p| p.name == key).map(|p| p.elem)
    }

    /// Whether parameter `key` is given.
    pub fn has(&self, key: &'static str) -> bool {
        self.props.iter().any(|p| p.name == key)
    }

    fn value(p: &Prop<'a>) -> Result<&'a str, SceneError> {
        p.elem.required_attr("value")
    }

    fn wrong_type(p: &Prop, expected: &str) -> SceneError {
        p.elem.err(format!(
            "parameter '{}' expects {expected}, not <{}>",
            p.name, p.elem.tag
        ))
    }

    /// The float parameter `key`, if given.
    pub fn float(&self, key: &'static str) -> Result<Option<f32>, SceneError> {
        let Some(p) = self.get(key) else {
            return Ok(None);
        };
        match p.elem.tag.as_str() {
            "float" | "integer" => parse_float(Self::value(p)?)
                .map(Some)
                .map_err(|m| p.elem.err(m)),
            _ => Err(Self::wrong_type(p, "a <float>")),
        }
    }

    /// A non-negative integer (sample counts, image sizes, seeds).
    pub fn count(&self, key: &'static str) -> Result<Option<u32>, SceneError> {
        let Some(p) = self.get(key) else {
            return Ok(None);
        };
        if p.elem.tag != "integer" {
            return Err(Self::wrong_type(p, "an <integer>"));
        }
        let v = parse_int(Self::value(p)?).map_err(|m| p.elem.err(m))?;
        u32::try_from(v).map(Some).map_err(|_| {
            p.elem
                .err(format!("expected a non-negative integer, found {v}"))
        })
    }

    /// The integer parameter `key`, if given, within `bound` ([`crate::limits`]): an error
    /// names the element (file and line), the parameter and the limit.
    pub fn bounded(
        &self,
        key: &'static str,
        bound: crate::limits::Bound,
    ) -> Result<Option<u32>, SceneError> {
        let Some(v) = self.count(key)? else {
            return Ok(None);
        };
        let p = self.get(key).expect("count found it");
        crate::limits::count(
            v as u64,
            &format!("'{}'", p.elem.attr("name").unwrap_or(key)),
            bound,
        )
        .map(|_| Some(v))
        .map_err(|m| p.elem.err(m))
    }

    /// The boolean parameter `key`, if given.
    pub fn boolean(&self, key: &'static str) -> Result<Option<bool>, SceneError> {
        let Some(p) = self.get(key) else {
            return Ok(None);
        };
        if p.elem.tag != "boolean" {
            return Err(Self::wrong_type(p, "a <boolean>"));
        }
        parse_bool(Self::value(p)?)
            .map(Some)
            .map_err(|m| p.elem.err(m))
    }

    /// The string parameter `key` and its element, if given.
    pub fn string(&self, key: &'static str) -> Result<Option<(String, &'a Element)>, SceneError> {
        let Some(p) = self.get(key) else {
            return Ok(None);
        };
        if p.elem.tag != "string" {
            return Err(Self::wrong_type(p, "a <string>"));
        }
        Ok(Some((Self::value(p)?.to_string(), p.elem)))
    }

    /// Colours: `<rgb>`/`<color>` (linear), `<srgb>` (gamma-encoded, converted to linear),
    /// constant `<spectrum>`, or a `<float>` used as grey.
    pub fn color(&self, key: &'static str) -> Result<Option<Rgb>, SceneError> {
        let Some(p) = self.get(key) else {
            return Ok(None);
        };
        let e = p.elem;
        let rgb = match e.tag.as_str() {
            "rgb" | "color" => parse_vec3(Self::value(p)?).map_err(|m| e.err(m))?,
            "srgb" => {
                let v = Self::value(p)?.trim();
                let c = match v.strip_prefix('#') {
                    Some(hex) => parse_hex(hex).ok_or_else(|| {
                        e.err(format!("expected a colour like #ff8000, found \"{v}\""))
                    })?,
                    None => parse_vec3(v).map_err(|m| e.err(m))?,
                };
                c.map(srgb_to_linear)
            }
            "spectrum" => {
                if e.attr("filename").is_some() {
                    return Err(e.err("spectra from files are not supported yet"));
                }
                let v = Self::value(p)?;
                if v.contains(':') {
                    return Err(e.err(
                        "spectra given per wavelength are not supported yet; use <rgb> or a \
                         constant value",
                    ));
                }
                [parse_float(v).map_err(|m| e.err(m))?; 3]
            }
            "float" | "integer" => [parse_float(Self::value(p)?).map_err(|m| e.err(m))?; 3],
            _ => {
                return Err(Self::wrong_type(
                    p,
                    "a colour (<rgb>, <spectrum> or <float>)",
                ))
            }
        };
        Ok(Some(Vec3::from(rgb)))
    }

    /// `<point>` or `<vector>` (either is accepted: dialects disagree on which to use).
    pub fn vec3(&self, key: &'static str) -> Result<Option<Vec3>, SceneError> {
        let Some(p) = self.get(key) else {
            return Ok(None);
        };
        match p.elem.tag.as_str() {
            "point" | "vector" => Ok(Some(Vec3::from(p.elem.vec3_attrs(0.0)?))),
            _ => Err(Self::wrong_type(p, "a <point> or <vector>")),
        }
    }

    /// The transform parameter `key` (Mitsuba's `to_world` and the like), if given.
    pub fn transform(&self, key: &'static str) -> Result<Option<Mat4>, SceneError> {
        let Some(p) = self.get(key) else {
            return Ok(None);
        };
        if p.elem.tag != "transform" {
            return Err(Self::wrong_type(p, "a <transform>"));
        }
        parse_transform(p.elem).map(Some)
    }

    /// Marks a harmless parameter as read and records a warning if it was given.
    pub fn ignore(&self, key: &'static str, why: &str, warnings: &mut Vec<String>) {
        if let Some(p) = self.get(key) {
            warnings.push(format!("{}: ignored: {why}", p.elem.origin()));
        }
    }

    /// Errors if the parameter is present: known to Mitsuba/Nori but not implemented here.
    pub fn reject(&self, key: &'static str) -> Result<(), SceneError> {
        match self.get(key) {
            Some(p) => Err(p.elem.err(format!(
                "parameter '{key}' of {} is not supported yet",
                self.what()
            ))),
            None => Ok(()),
        }
    }

    /// Nested elements with one of the given tags, in document order.
    pub fn nested(&self, tags: &[&str]) -> Vec<&'a Element> {
        self.nested
            .iter()
            .filter(|(e, _)| tags.contains(&e.tag.as_str()))
            .map(|(e, used)| {
                used.set(true);
                *e
            })
            .collect()
    }

    /// At most one nested element with one of the given tags.
    pub fn nested_one(&self, tags: &[&str]) -> Result<Option<&'a Element>, SceneError> {
        match self.nested(tags).as_slice() {
            [] => Ok(None),
            [one] => Ok(Some(*one)),
            [_, second, ..] => {
                Err(second.err(format!("{} takes only one <{}>", self.what(), tags[0])))
            }
        }
    }

    /// Rejects every parameter and nested element the plugin did not read.
    pub fn finish(&self) -> Result<(), SceneError> {
        if let Some(p) = self.props.iter().find(|p| !p.used.get()) {
            let mut known = self.queried.borrow().clone();
            known.sort_unstable();
            known.dedup();
            let list = if known.is_empty() {
                "it takes no parameters".to_string()
            } else {
                format!("expected one of: {}", known.join(", "))
            };
            return Err(p.elem.err(format!(
                "unknown parameter '{}' for {}; {list}",
                p.name,
                self.what()
            )));
        }
        if let Some((e, _)) = self.nested.iter().find(|(_, used)| !used.get()) {
            return Err(e.err(format!("unexpected <{}> inside {}", e.tag, self.what())));
        }
        Ok(())
    }
}

fn parse_hex(hex: &str) -> Option<[f32; 3]> {
    if hex.len() != 6 || !hex.is_ascii() {
        return None;
    }
    let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).ok();
    Some([
        byte(0)? as f32 / 255.0,
        byte(2)? as f32 / 255.0,
        byte(4)? as f32 / 255.0,
    ])
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::xml::parse_document;
    use std::path::Path;

    fn root(body: &str) -> Element {
        let xml = format!("<scene>\n<bsdf type=\"x\">\n{body}\n</bsdf>\n</scene>");
        parse_document(&xml, Path::new("p.xml"), &[]).unwrap()
    }

    #[test]
    fn typed_reads_and_unknown_parameters() {
        let r = root(
            r##"<float name="alpha" value="0.2"/><rgb name="kd" value="0.1, 0.2, 0.3"/>
               <integer name="sampleCount" value="8"/><boolean name="flip" value="true"/>
               <srgb name="s" value="#ff0000"/><spectrum name="sp" value="0.5"/>
               <point name="pos" x="1" z="3"/><string name="typo" value="1"/>"##,
        );
        let p = Plugin::new(&r.children[0], &["type"]).unwrap();
        assert_eq!(p.float("alpha").unwrap(), Some(0.2));
        assert_eq!(p.color("kd").unwrap(), Some(Vec3::new(0.1, 0.2, 0.3)));
        assert_eq!(p.count("sample_count").unwrap(), Some(8));
        assert_eq!(p.boolean("flip").unwrap(), Some(true));
        assert_eq!(p.color("s").unwrap(), Some(Vec3::new(1.0, 0.0, 0.0)));
        assert_eq!(p.color("sp").unwrap(), Some(Vec3::splat(0.5)));
        assert_eq!(p.vec3("pos").unwrap(), Some(Vec3::new(1.0, 0.0, 3.0)));
        assert_eq!(p.float("missing").unwrap(), None);
        let e = p.finish().unwrap_err().to_string();
        assert!(
            e.starts_with("p.xml:6: <string name=\"typo\" value=\"1\">"),
            "{e}"
        );
        assert!(e.contains("unknown parameter 'typo' for bsdf 'x'"), "{e}");
        assert!(
            e.contains("expected one of: alpha, flip, kd, missing, pos"),
            "{e}"
        );
    }

    #[test]
    fn type_mismatch_duplicates_and_nan() {
        let r = root(r#"<rgb name="alpha" value="1"/>"#);
        let p = Plugin::new(&r.children[0], &["type"]).unwrap();
        let e = p.float("alpha").unwrap_err().to_string();
        assert!(e.contains("expects a <float>"), "{e}");

        let r = root(r#"<float name="a" value="1"/><float name="a" value="2"/>"#);
        let e = Plugin::new(&r.children[0], &["type"])
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("given twice"), "{e}");

        let r = root(r#"<rgb name="c" value="1, nan, 0"/>"#);
        let p = Plugin::new(&r.children[0], &["type"]).unwrap();
        let e = p.color("c").unwrap_err().to_string();
        assert!(e.contains("p.xml:3: <rgb") && e.contains("finite"), "{e}");

        let r = root(r#"<texture type="bitmap" name="reflectance"/>"#);
        let e = Plugin::new(&r.children[0], &["type"])
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("texture 'bitmap' is not supported yet"), "{e}");
    }

    #[test]
    fn unread_nested_element_is_an_error() {
        let r = root(r#"<film type="hdrfilm"/>"#);
        let p = Plugin::new(&r.children[0], &["type"]).unwrap();
        let e = p.finish().unwrap_err().to_string();
        assert!(e.contains("unexpected <film> inside bsdf 'x'"), "{e}");
    }
}
