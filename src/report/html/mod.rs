//! The HTML reports: every report's `index.md` also as a self-contained `index.html` (no
//! server, no network, no modules, no fetch: it works opened from disk) with sortable tables
//! and its figures inline ([`markdown`]); an image sweep's page adds the interactive image
//! viewer on top ([`sweep`], HDR data in [`data`]). `doc.js` sorts the tables and, opened
//! with `#selftest`, checks the page and writes a pass/fail line the browser test reads.

pub mod data;
pub mod markdown;
pub mod sweep;

pub use markdown::Figures;
use std::fmt::Write;
use std::path::Path;

const DOC: &str = include_str!("doc.js");

pub use crate::experiment::args::Viewer;

impl Viewer {
    pub fn figures(self) -> Figures {
        match self {
            Viewer::Full => Figures::Embed,
            Viewer::None => Figures::Link,
        }
    }
}

/// A part of a page above its report: its style, markup and script.
pub struct Section {
    pub css: String,
    pub html: String,
    pub script: String,
}

pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The page of the report `md` (whose first line is its `# title`), with `top` above it.
pub fn page(dir: &Path, md: &str, top: Option<&Section>, figures: Figures) -> String {
    let (title, rest) = match md.split_once('\n') {
        Some((first, rest)) if first.starts_with("# ") => (first[2..].trim(), rest),
        _ => ("Report", md),
    };
    let (body, counts) = markdown::body(rest, dir, figures);
    let doc = serde_json::json!({
        "svgs": counts.svgs,
        "imgs": counts.imgs,
        "tables": counts.tables,
    });
    let mut html = String::new();
    let _ = write!(
        html,
        r#"<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>{t}</title>
<style>
body {{ font: 14px sans-serif; margin: 1em; background: #fafafa; }} #doc {{ max-width: 1400px; }}
table {{ border-collapse: collapse; margin: 0.5em 0; }}
td, th {{ border: 1px solid #ccc; padding: 2px 6px; }} th {{ cursor: pointer; background: #eee; }}
span.plot svg {{ width: 560px; height: auto; margin: 4px; }} img {{ max-width: 100%; }}
{css}
</style></head><body>
<h1>{t}</h1>
{top}<div id="doc">
{body}</div>
<p><a href="index.md">Markdown</a>{up}</p>
<div id="selftest"></div>
<script>const DOC = {doc};
{DOC}</script>
{script}</body></html>
"#,
        t = escape(title),
        // The reports root's index, where this page sits in one.
        up = if dir.parent().is_some_and(|p| p.join("index.md").exists()) {
            " · <a href=\"../index.html\">all reports</a>"
        } else {
            ""
        },
        css = top.map_or("", |s| &s.css),
        top = top.map_or("", |s| &s.html),
        script = top.map_or(String::new(), |s| format!(
            "<script>{}</script>\n",
            s.script
        )),
    );
    html
}

/// Writes `<dir>/index.html` for the report `md`.
pub fn write(dir: &Path, md: &str, top: Option<&Section>, figures: Figures) -> Result<(), String> {
    let html = page(dir, md, top, figures);
    let path = dir.join("index.html");
    crate::output::write_atomic(&path, |tmp| {
        std::fs::write(tmp, &html).map_err(|e| format!("{}: {e}", path.display()))
    })
}

/// `<root>/index.html`: every report of `entries` (Markdown link, title), linking its
/// interactive page where it has one.
pub fn write_root(root: &Path, entries: &[(String, String)]) -> Result<(), String> {
    let mut items = String::new();
    for (md, title) in entries {
        let html = md.strip_suffix(".md").map(|b| format!("{b}.html"));
        let link = match html {
            Some(h) if root.join(&h).exists() => h,
            _ => md.clone(),
        };
        let _ = writeln!(
            items,
            "<li><a href=\"{}\">{}</a></li>",
            escape(&link),
            escape(title)
        );
    }
    let page = format!(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Reports</title></head>\n\
         <body><h1>Reports</h1>\n<p>Written by <code>directlab run</code> / <code>directlab \
         reproduce</code>.</p>\n<ul>\n{items}</ul>\n</body></html>\n"
    );
    let path = root.join("index.html");
    crate::output::write_atomic(&path, |tmp| {
        std::fs::write(tmp, &page).map_err(|e| format!("{}: {e}", path.display()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_page_links_the_reports_index_only_inside_a_reports_root() {
        let root = std::env::temp_dir().join(format!("directlab-page-{}", std::process::id()));
        let dir = root.join("exp");
        std::fs::create_dir_all(&dir).unwrap();
        let md = "# A <title>\n\n| x |\n|---|\n| 1 |\n";
        let alone = page(&dir, md, None, Figures::Embed);
        assert!(alone.contains("<h1>A &lt;title&gt;</h1>"), "{alone}");
        assert!(alone.contains("\"tables\":1"), "{alone}");
        assert!(!alone.contains("all reports"), "{alone}");
        std::fs::write(root.join("index.md"), "# Reports\n").unwrap();
        let inside = page(&dir, md, None, Figures::Embed);
        assert!(inside.contains("<a href=\"../index.html\">all reports</a>"));
        std::fs::remove_dir_all(&root).unwrap();
    }
}
