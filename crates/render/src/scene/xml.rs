//! Generic XML layer: an element tree that remembers where each element came from, with
//! `$name` substitution already applied, plus the number parsers every dialect shares.
//!
//! Keeping positions on our own tree (rather than passing roxmltree nodes around) lets every
//! later stage build a precise error without access to the original document.

use super::error::SceneError;
use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::rc::Rc;

/// A string of the scene document: a range of the shared source text, or (after `$name`
/// substitution or entity expansion) a string of its own. Ranges cost no allocation, which
/// is what lets a scene of a million elements load in seconds.
#[derive(Clone)]
pub struct Text {
    src: Rc<str>,
    start: u32,
    end: u32,
}

impl Text {
    fn owned(s: &str) -> Text {
        Text {
            src: Rc::from(s),
            start: 0,
            end: s.len() as u32,
        }
    }

    /// The text.
    pub fn as_str(&self) -> &str {
        &self.src[self.start as usize..self.end as usize]
    }
}

impl std::ops::Deref for Text {
    type Target = str;
    fn deref(&self) -> &str {
        self.as_str()
    }
}

impl PartialEq<&str> for Text {
    fn eq(&self, other: &&str) -> bool {
        self.as_str() == *other
    }
}

impl std::fmt::Display for Text {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::fmt::Debug for Text {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?}", self.as_str())
    }
}

#[derive(Clone, Debug)]
struct Attr {
    name: Text,
    /// After `$name` substitution.
    value: Text,
    /// As written, for messages.
    raw: Text,
}

/// An XML element with `$name` substitution done, its line and file kept for messages.
#[derive(Clone, Debug)]
pub struct Element {
    /// The tag name.
    pub tag: Text,
    attrs: Vec<Attr>,
    /// Child elements, in document order.
    pub children: Vec<Element>,
    /// 1-based line of its opening tag.
    pub line: u32,
    /// The file it was read from.
    pub file: Rc<Path>,
}

impl Element {
    /// The value of attribute `name`, after `$name` substitution.
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|a| a.name.as_str() == name)
            .map(|a| a.value.as_str())
    }

    /// The opening tag with its attributes as written (each clipped), for messages.
    pub fn display(&self) -> String {
        let mut d = format!("<{}", clip(&self.tag));
        for a in &self.attrs {
            d.push_str(&format!(" {}=\"{}\"", clip(&a.name), clip(&a.raw)));
        }
        d.push('>');
        d
    }

    /// An error about this element (its file, line and opening tag).
    pub fn err(&self, message: impl Into<String>) -> SceneError {
        SceneError {
            file: self.file.to_path_buf(),
            line: Some(self.line),
            element: Some(self.display()),
            message: message.into(),
        }
    }

    /// "file:line <tag ...>", the form used in warnings and `ShapeDesc::origin`.
    pub fn origin(&self) -> String {
        format!("{}:{} {}", self.file.display(), self.line, self.display())
    }

    /// The value of attribute `name`, or an error saying it is missing.
    pub fn required_attr(&self, name: &str) -> Result<&str, SceneError> {
        self.attr(name)
            .ok_or_else(|| self.err(format!("expected a '{name}' attribute")))
    }

    /// Unknown attributes are almost always typos (`vaule=`), which would otherwise silently
    /// fall back to a default.
    pub fn check_attrs(&self, allowed: &[&str]) -> Result<(), SceneError> {
        for Attr { name: k, .. } in &self.attrs {
            if !allowed.contains(&k.as_str()) {
                return Err(self.err(format!(
                    "unexpected attribute '{k}'; expected one of: {}",
                    allowed.join(", ")
                )));
            }
        }
        Ok(())
    }

    /// The value of attribute `name` as a float, if present.
    pub fn float_attr(&self, name: &str) -> Result<Option<f32>, SceneError> {
        self.attr(name)
            .map(|v| parse_float(v).map_err(|m| self.err(m)))
            .transpose()
    }

    /// A triple written either as `value="a, b, c"` or as x/y/z attributes (missing ones take
    /// `default`). A single number in `value` is splatted, as Mitsuba does.
    pub fn vec3_attrs(&self, default: f32) -> Result<[f32; 3], SceneError> {
        if let Some(v) = self.attr("value") {
            if self.attr("x").is_some() || self.attr("y").is_some() || self.attr("z").is_some() {
                return Err(self.err("give either 'value' or x/y/z attributes, not both"));
            }
            return parse_vec3(v).map_err(|m| self.err(m));
        }
        Ok([
            self.float_attr("x")?.unwrap_or(default),
            self.float_attr("y")?.unwrap_or(default),
            self.float_attr("z")?.unwrap_or(default),
        ])
    }
}

/// `s` for a message: in full up to 60 characters, else its start and its length, so a
/// megabyte-long attribute is not echoed back whole.
pub fn clip(s: &str) -> std::borrow::Cow<'_, str> {
    const KEEP: usize = 60;
    if s.len() <= KEEP || s.chars().count() <= KEEP {
        return s.into();
    }
    let head: String = s.chars().take(KEEP - 20).collect();
    format!("{head}... ({} characters)", s.chars().count()).into()
}

/// Parses one finite number. NaN and infinities are rejected here, once, so no later stage has
/// to think about them.
pub fn parse_float(s: &str) -> Result<f32, String> {
    let t = s.trim();
    match t.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("expected a finite number, found \"{}\"", clip(t))),
        Err(_) => Err(format!("expected a number, found \"{}\"", clip(t))),
    }
}

/// Numbers separated by commas and/or whitespace.
pub fn parse_floats(s: &str) -> Result<Vec<f32>, String> {
    s.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(parse_float)
        .collect()
}

/// One number (used for all three) or three, separated by commas or spaces.
pub fn parse_vec3(s: &str) -> Result<[f32; 3], String> {
    match parse_floats(s)?.as_slice() {
        [v] => Ok([*v; 3]),
        [a, b, c] => Ok([*a, *b, *c]),
        other => Err(format!(
            "expected 1 or 3 numbers, found {} in \"{}\"",
            other.len(),
            clip(s.trim())
        )),
    }
}

/// An integer.
pub fn parse_int(s: &str) -> Result<i64, String> {
    let t = s.trim();
    t.parse::<i64>()
        .map_err(|_| format!("expected an integer, found \"{}\"", clip(t)))
}

/// `true` or `false`, in any case.
pub fn parse_bool(s: &str) -> Result<bool, String> {
    match s.trim().to_ascii_lowercase().as_str() {
        "true" => Ok(true),
        "false" => Ok(false),
        _ => Err(format!(
            "expected true or false, found \"{}\"",
            clip(s.trim())
        )),
    }
}

/// camelCase -> snake_case, so Mitsuba 0.6 / Nori names (`toWorld`, `intIOR`, `sampleCount`)
/// meet the Mitsuba 3 names (`to_world`, `int_ior`, `sample_count`) in one lookup table.
pub fn normalize_name(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    let mut prev_lower = false;
    for c in name.chars() {
        if c.is_ascii_uppercase() && prev_lower {
            out.push('_');
        }
        prev_lower = c.is_ascii_lowercase() || c.is_ascii_digit();
        out.push(c.to_ascii_lowercase());
    }
    out
}

/// Replaces every `$name` by its value; an undefined name is reported by name.
fn substitute(value: &str, params: &Params) -> Result<String, String> {
    let mut out = String::with_capacity(value.len());
    let mut rest = value;
    while let Some(i) = rest.find('$') {
        out.push_str(&rest[..i]);
        let after = &rest[i + 1..];
        let len = after
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(after.len());
        if len == 0 {
            out.push('$');
            rest = after;
            continue;
        }
        let name = &after[..len];
        match params.values.get(name) {
            Some(v) => {
                params.used.borrow_mut().insert(name.to_string());
                out.push_str(v)
            }
            None => {
                return Err(format!(
                    "'${name}' is not defined: add <default name=\"{name}\" value=\"...\"/> \
                     or pass -D {name}=..."
                ))
            }
        }
        rest = &after[len..];
    }
    out.push_str(rest);
    Ok(out)
}

/// The `$name` parameters of a document, and which of them an attribute used.
struct Params {
    values: HashMap<String, String>,
    used: std::cell::RefCell<HashSet<String>>,
}

/// Line numbers of byte offsets, from a table of line starts: one binary search per element
/// (roxmltree's `text_pos_at` scans from the document's start each time, which made loading
/// quadratic in the element count).
struct Lines(Vec<usize>);

impl Lines {
    fn new(text: &str) -> Self {
        let starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        Lines(starts)
    }

    /// 1-based line of byte offset `pos`.
    fn of(&self, pos: usize) -> u32 {
        self.0.partition_point(|&s| s <= pos) as u32
    }
}

/// The deepest element nesting accepted. Scenes nest a handful of levels; the limit keeps a
/// malicious or broken file from exhausting the stack of the recursive conversion.
pub const MAX_DEPTH: usize = 256;

/// Parses `xml` into an element tree. `<default>` elements directly under the root define
/// parameters (in document order, so one default may use an earlier one); `defines` override
/// them, as Mitsuba's `-D` does, and are visible to the defaults that use them. A define that
/// the document neither declares with `<default>` nor uses as `$name` is an error: it is
/// almost always a typo that would otherwise be silently ignored.
pub fn parse_document(
    xml: &str,
    file: &Path,
    defines: &[(String, String)],
) -> Result<Element, SceneError> {
    // Some exported Mitsuba 0.6 scenes carry a DOCTYPE; it is harmless.
    let options = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    if u32::try_from(xml.len()).is_err() {
        return Err(SceneError::new(
            file,
            format!(
                "document is {} bytes; at most 4 GiB are accepted",
                xml.len()
            ),
        ));
    }
    let src: Rc<str> = Rc::from(xml);
    let doc = roxmltree::Document::parse_with_options(&src, options).map_err(|e| SceneError {
        file: file.to_path_buf(),
        line: Some(e.pos().row),
        element: None,
        message: format!("malformed XML: {e}"),
    })?;
    let cx = Context {
        file: Rc::from(file),
        lines: Lines::new(xml),
        src: src.clone(),
    };
    let root = doc.root_element();
    check_depth(&cx, root)?;

    let mut params = Params {
        values: defines.iter().cloned().collect(),
        used: Default::default(),
    };
    let mut declared = HashSet::new();
    for node in root.children().filter(|n| n.is_element()) {
        if node.tag_name().name() != "default" {
            continue;
        }
        let raw = convert(&cx, node, None)?;
        raw.check_attrs(&["name", "value"])?;
        let name = raw.required_attr("name")?.to_string();
        let value = substitute(raw.required_attr("value")?, &params).map_err(|m| raw.err(m))?;
        declared.insert(name.clone());
        if !defines.iter().any(|(k, _)| *k == name) {
            params.values.insert(name, value);
        }
    }
    let tree = convert(&cx, root, Some(&params))?;
    let used = params.used.borrow();
    if let Some((name, _)) = defines
        .iter()
        .find(|(k, _)| !declared.contains(k) && !used.contains(k))
    {
        let mut known: Vec<&String> = declared.iter().collect();
        known.sort();
        let known = if known.is_empty() {
            "it declares none".to_string()
        } else {
            format!(
                "it declares {}",
                known
                    .iter()
                    .map(|k| k.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        };
        return Err(SceneError::new(
            file,
            format!(
                "parameter '{}' is set (-D or an experiment's defines) but the scene neither \
                 declares it with <default name=\"{0}\"> nor uses ${0}; {known}",
                clip(name)
            ),
        ));
    }
    Ok(tree)
}

/// The parameters `xml` declares with `<default name=...>` directly under its root, in
/// document order: what a caller may set with a define (the bench sets `res` only where a
/// scene declares it). A document that does not parse declares none.
pub fn declared_parameters(xml: &str) -> Vec<String> {
    let options = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    let Ok(doc) = roxmltree::Document::parse_with_options(xml, options) else {
        return Vec::new();
    };
    doc.root_element()
        .children()
        .filter(|n| n.is_element() && n.tag_name().name() == "default")
        .filter_map(|n| n.attribute("name").map(str::to_string))
        .collect()
}

/// What every element's conversion reads.
struct Context {
    file: Rc<Path>,
    lines: Lines,
    /// The document, which `Text`s share.
    src: Rc<str>,
}

impl Context {
    /// `s` as a range of the document when it is one (names, and values without entities),
    /// else as a string of its own.
    fn text(&self, s: &str) -> Text {
        let base = self.src.as_ptr() as usize;
        let at = s.as_ptr() as usize;
        if at >= base && at + s.len() <= base + self.src.len() {
            let start = (at - base) as u32;
            Text {
                src: self.src.clone(),
                start,
                end: start + s.len() as u32,
            }
        } else {
            Text::owned(s)
        }
    }
}

/// Refuses nesting deeper than [`MAX_DEPTH`], walking the tree without recursion.
fn check_depth(cx: &Context, root: roxmltree::Node) -> Result<(), SceneError> {
    let mut stack = vec![(root, 1usize)];
    while let Some((node, depth)) = stack.pop() {
        if depth > MAX_DEPTH {
            return Err(SceneError {
                file: cx.file.to_path_buf(),
                line: Some(cx.lines.of(node.range().start)),
                element: Some(format!("<{}>", clip(node.tag_name().name()))),
                message: format!("elements nest deeper than {MAX_DEPTH} levels"),
            });
        }
        stack.extend(
            node.children()
                .filter(|n| n.is_element())
                .map(|c| (c, depth + 1)),
        );
    }
    Ok(())
}

fn convert(
    cx: &Context,
    node: roxmltree::Node,
    params: Option<&Params>,
) -> Result<Element, SceneError> {
    let mut elem = Element {
        tag: cx.text(node.tag_name().name()),
        attrs: Vec::with_capacity(node.attributes().len()),
        children: Vec::new(),
        line: cx.lines.of(node.range().start),
        file: cx.file.clone(),
    };
    for a in node.attributes() {
        let raw = cx.text(a.value());
        elem.attrs.push(Attr {
            name: cx.text(a.name()),
            value: raw.clone(),
            raw,
        });
    }
    // <default> values were substituted when the parameter table was built.
    if let Some(p) = params.filter(|_| elem.tag != "default") {
        for i in 0..elem.attrs.len() {
            if elem.attrs[i].raw.contains('$') {
                let value = substitute(&elem.attrs[i].raw, p).map_err(|m| elem.err(m))?;
                elem.attrs[i].value = Text::owned(&value);
            }
        }
    }
    let n = node.children().filter(|n| n.is_element()).count();
    if n > 0 {
        elem.children.reserve_exact(n);
        for child in node.children().filter(|n| n.is_element()) {
            elem.children.push(convert(cx, child, params)?);
        }
    }
    Ok(elem)
}

#[cfg(test)]
#[path = "xml_tests.rs"]
mod tests;
