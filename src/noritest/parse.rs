//! Reading Nori's test files: `<test type="ttest">` (scenes against reference values, or
//! BSDF albedos at incidence angles) and `<test type="chi2test">` (BSDF sampling against its
//! pdf). Scenes inside a test are read as their direct illumination: Nori's course test
//! scenes name path tracers on scenes where only direct light exists.

use crate::bsdf::Material;
use crate::scene::desc::SceneDesc;
use crate::scene::loader::{
    load_bsdf_element, load_scene_element, read_text_file, Dialect, IntegratorMode, MAX_SCENE_BYTES,
};
use crate::scene::props::Plugin;
use crate::scene::xml::{parse_document, Element};
use crate::scene::SceneError;
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    TTest,
    Chi2,
}

/// A scene or BSDF of the file, with the line of its element.
pub struct Item<T> {
    pub value: T,
    pub line: u32,
    /// "scene 2 (line 40)", "bsdf 'microfacet' (line 12)".
    pub label: String,
}

/// What one test file asks for.
pub struct TestFile {
    pub path: PathBuf,
    pub kind: Kind,
    /// Nori's `significanceLevel` (0.01): the family-wise level of the file's tests.
    pub alpha: f64,
    /// Nori's `sampleCount` if given (ttest default 100,000; chi2test 5,000 per cell).
    pub samples: Option<u64>,
    pub references: Vec<f64>,
    /// Incidence angles in degrees (BSDF t-tests).
    pub angles: Vec<f64>,
    pub scenes: Vec<Item<SceneDesc>>,
    pub bsdfs: Vec<Item<Material>>,
    /// chi2test: `resolution` (cos theta bins; phi gets twice as many), `minExpFrequency`,
    /// `testCount` (incident directions per BSDF).
    pub resolution: u32,
    pub min_expected: f64,
    pub test_count: u32,
    pub warnings: Vec<String>,
}

/// Numbers separated by commas and/or spaces, each named in the error by position.
fn numbers(text: &str, e: &Element, what: &str) -> Result<Vec<f64>, SceneError> {
    text.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .enumerate()
        .map(|(i, t)| match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(e.err(format!(
                "{what}: entry {} is \"{}\", expected a finite number",
                i + 1,
                crate::scene::xml::clip(t)
            ))),
        })
        .collect()
}

/// Reads a test file; `defines` are `-D name=value` overrides of its `<default>`s.
pub fn read(path: &Path, defines: &[(String, String)]) -> Result<TestFile, SceneError> {
    let xml = read_text_file(path, MAX_SCENE_BYTES, "test file")?;
    let root = parse_document(&xml, path, defines)?;
    if root.tag != "test" {
        let hint = match root.tag.as_str() {
            "scene" => " (this is a scene: render it with `directlab render`)",
            _ => "",
        };
        return Err(root.err(format!(
            "expected <test type=\"ttest\"> or <test type=\"chi2test\"> as the root element{hint}"
        )));
    }
    let p = Plugin::new(&root, &["type", "id"])?;
    let kind = match p.ty.as_str() {
        "ttest" => Kind::TTest,
        "chi2test" => Kind::Chi2,
        t => {
            return Err(root.err(format!(
                "unknown test type '{t}'; expected ttest or chi2test"
            )))
        }
    };
    let alpha = p.float("significance_level")?.unwrap_or(0.01) as f64;
    if !(alpha > 0.0 && alpha < 1.0) {
        let e = p.element_of("significance_level").unwrap_or(&root);
        return Err(e.err(format!(
            "significanceLevel must lie in (0, 1), found {alpha}"
        )));
    }
    let samples = p
        .bounded("sample_count", crate::limits::TEST_SAMPLES)?
        .map(u64::from);
    if samples.is_some_and(|n| n < 2) {
        let e = p.element_of("sample_count").unwrap_or(&root);
        return Err(e.err("sampleCount must be at least 2"));
    }
    let mut f = TestFile {
        path: path.to_path_buf(),
        kind,
        alpha,
        samples,
        references: Vec::new(),
        angles: Vec::new(),
        scenes: Vec::new(),
        bsdfs: Vec::new(),
        resolution: 10,
        min_expected: 5.0,
        test_count: 5,
        warnings: Vec::new(),
    };
    match kind {
        Kind::TTest => {
            if let Some((s, e)) = p.string("references")? {
                f.references = numbers(&s, e, "references")?;
            }
            if let Some((s, e)) = p.string("angles")? {
                f.angles = numbers(&s, e, "angles")?;
                if let Some(a) = f.angles.iter().find(|a| !(0.0..90.0).contains(*a)) {
                    return Err(e.err(format!(
                        "angles: {a} is not an incidence angle in [0, 90) degrees"
                    )));
                }
            }
        }
        Kind::Chi2 => {
            f.resolution = p.count("resolution")?.unwrap_or(10);
            if !(2..=1024).contains(&f.resolution) {
                let e = p.element_of("resolution").unwrap_or(&root);
                return Err(e.err(format!(
                    "resolution must be from 2 to 1024 bins, found {}",
                    f.resolution
                )));
            }
            f.min_expected = p.count("min_exp_frequency")?.unwrap_or(5) as f64;
            f.test_count = p
                .bounded("test_count", crate::limits::TEST_COUNT)?
                .unwrap_or(5);
            if f.test_count == 0 {
                let e = p.element_of("test_count").unwrap_or(&root);
                return Err(e.err("testCount must be at least 1"));
            }
        }
    }
    let tags: &[&str] = match kind {
        Kind::TTest => &["scene", "bsdf"],
        Kind::Chi2 => &["bsdf"],
    };
    for e in p.nested(tags) {
        if e.tag == "scene" {
            let desc = load_scene_element(e, path, Some(IntegratorMode::Direct))?;
            f.warnings.extend(desc.warnings.iter().cloned());
            let label = format!("scene {} (line {})", f.scenes.len() + 1, e.line);
            f.scenes.push(Item {
                value: desc,
                line: e.line,
                label,
            });
        } else {
            let (m, w) = load_bsdf_element(e, path, Dialect::Nori)?;
            f.warnings.extend(w);
            let ty = e.attr("type").unwrap_or("?");
            f.bsdfs.push(Item {
                value: m,
                line: e.line,
                label: format!("bsdf '{ty}' (line {})", e.line),
            });
        }
    }
    p.finish()?;
    check_counts(&f, &root)?;
    Ok(f)
}

/// The counts Nori checks: one reference per scene, or per angle (shared by every BSDF) or
/// per BSDF and angle; scenes and BSDFs not mixed; something to test.
fn check_counts(f: &TestFile, root: &Element) -> Result<(), SceneError> {
    let (r, s, b, a) = (
        f.references.len(),
        f.scenes.len(),
        f.bsdfs.len(),
        f.angles.len(),
    );
    match f.kind {
        Kind::Chi2 if b == 0 => Err(root.err("a chi2test needs at least one <bsdf>")),
        Kind::Chi2 => Ok(()),
        Kind::TTest if s > 0 && b > 0 => {
            Err(root.err("a ttest tests either scenes or BSDFs, not both"))
        }
        Kind::TTest if s == 0 && b == 0 => {
            Err(root.err("a ttest needs <scene> or <bsdf> elements to test"))
        }
        Kind::TTest if s > 0 && r != s => Err(root.err(format!(
            "{r} reference values for {s} scenes; expected one per scene"
        ))),
        Kind::TTest if b > 0 && a == 0 => {
            Err(root.err("a BSDF ttest needs <string name=\"angles\">"))
        }
        Kind::TTest if b > 0 && r != a && r != a * b => Err(root.err(format!(
            "{r} reference values for {b} BSDFs at {a} angles; expected {a} (one per angle, \
             shared by every BSDF) or {} (one per BSDF and angle, BSDF by BSDF)",
            a * b
        ))),
        Kind::TTest => Ok(()),
    }
}
