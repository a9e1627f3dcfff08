//! A report's Markdown as the body of its HTML page: pulldown-cmark renders text, lists and
//! tables; figures become inline SVG where the plot has an SVG beside its PNG, embedded PNG
//! when small, and a relative link when large (image panels the viewer shows anyway) or when
//! the page is written without embedded images.

use pulldown_cmark::{CowStr, Event, Options, Parser, Tag, TagEnd};
use std::path::Path;

/// PNG figures up to this size are embedded; larger ones are linked beside the page.
pub const EMBED_PNG_BYTES: u64 = 300_000;

/// How a page carries its figures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Figures {
    /// SVG inline, small PNGs as data URLs: the page is one file.
    Embed,
    /// Every figure an `<img>` of the file beside the page (`--viewer none`).
    Link,
}

/// What a page's body holds, for its selftest.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Counts {
    pub svgs: usize,
    pub imgs: usize,
    pub tables: usize,
}

/// The HTML of `md`, with figures resolved against `dir` (the page's folder).
pub fn body(md: &str, dir: &Path, figures: Figures) -> (String, Counts) {
    let mut counts = Counts::default();
    let mut events: Vec<Event> = Vec::new();
    // Inside ![alt](dest): the destination and the alt text collected so far.
    let mut image: Option<(String, String)> = None;
    for ev in Parser::new_ext(md, Options::ENABLE_TABLES) {
        match ev {
            Event::Start(Tag::Image { dest_url, .. }) => {
                image = Some((dest_url.to_string(), String::new()));
            }
            Event::End(TagEnd::Image) => {
                if let Some((dest, alt)) = image.take() {
                    let html = figure(&dest, &alt, dir, figures, &mut counts);
                    events.push(Event::InlineHtml(CowStr::from(html)));
                }
            }
            Event::Text(t) | Event::Code(t) if image.is_some() => {
                if let Some((_, alt)) = image.as_mut() {
                    alt.push_str(&t);
                }
            }
            _ if image.is_some() => {}
            Event::Start(Tag::Table(_)) => {
                counts.tables += 1;
                events.push(ev);
            }
            _ => events.push(ev),
        }
    }
    let mut out = String::new();
    pulldown_cmark::html::push_html(&mut out, events.into_iter());
    (out, counts)
}

/// A file of the page's own folder (no absolute paths, no `..`, no URLs).
fn local(dir: &Path, dest: &str) -> Option<std::path::PathBuf> {
    let p = Path::new(dest);
    let plain = !dest.contains(':')
        && p.components()
            .all(|c| matches!(c, std::path::Component::Normal(_)));
    plain.then(|| dir.join(p))
}

fn figure(dest: &str, alt: &str, dir: &Path, figures: Figures, counts: &mut Counts) -> String {
    let alt = super::escape(alt);
    let linked = |counts: &mut Counts, dest: &str| {
        counts.imgs += 1;
        format!("<img src=\"{}\" alt=\"{alt}\">", super::escape(dest))
    };
    let Some(path) = local(dir, dest) else {
        return linked(counts, dest);
    };
    if figures == Figures::Link {
        return linked(counts, dest);
    }
    // The report is written as one set: its figures may still be under their new names.
    let svg = crate::output::pending(&path.with_extension("svg"));
    let path = crate::output::pending(&path);
    if let Ok(text) = std::fs::read_to_string(&svg) {
        if let Some(at) = text.find("<svg") {
            counts.svgs += 1;
            return format!(
                "<span class=\"plot\" title=\"{alt}\">{}</span>",
                &text[at..]
            );
        }
    }
    let small = std::fs::metadata(&path).is_ok_and(|m| m.len() <= EMBED_PNG_BYTES);
    let png = dest.to_ascii_lowercase().ends_with(".png");
    match std::fs::read(&path) {
        Ok(bytes) if small && png => {
            counts.imgs += 1;
            format!(
                "<img src=\"data:image/png;base64,{}\" alt=\"{alt}\">",
                super::data::base64(&bytes)
            )
        }
        _ => linked(counts, dest),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_text_and_every_kind_of_figure() {
        let dir = std::env::temp_dir().join(format!("directlab-md-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("plot.png"), b"png").unwrap();
        std::fs::write(
            dir.join("plot.svg"),
            "<?xml version=\"1.0\"?>\n<svg id=\"s\"></svg>",
        )
        .unwrap();
        std::fs::write(dir.join("small.png"), b"\x89PNG").unwrap();
        std::fs::write(dir.join("big.png"), vec![0u8; EMBED_PNG_BYTES as usize + 1]).unwrap();
        let md = "# T\n\n**bold** `x<y`\n\n| a | b |\n|---|---|\n| 1 | 2 |\n\n\
                  ![the plot](plot.png)\n\n![small](small.png)\n\n![big](big.png)\n\n\
                  ![up](../x.png)\n";
        let (html, n) = body(md, &dir, Figures::Embed);
        assert!(html.contains("<h1>T</h1>"), "{html}");
        assert!(html.contains("<code>x&lt;y</code>"), "{html}");
        assert!(
            html.contains("<table>") && html.contains("<th>a</th>"),
            "{html}"
        );
        assert!(
            html.contains("<svg id=\"s\"></svg>") && !html.contains("<?xml"),
            "{html}"
        );
        assert!(html.contains("data:image/png;base64,iVBORw=="), "{html}");
        assert!(html.contains("<img src=\"big.png\""), "{html}");
        assert!(html.contains("<img src=\"../x.png\""), "not read: {html}");
        assert_eq!(
            n,
            Counts {
                svgs: 1,
                imgs: 3,
                tables: 1
            }
        );
        let (linked, n) = body(md, &dir, Figures::Link);
        assert!(
            !linked.contains("data:") && !linked.contains("<svg"),
            "{linked}"
        );
        assert!(
            linked.contains("<img src=\"plot.png\" alt=\"the plot\""),
            "{linked}"
        );
        assert_eq!(n.imgs, 4);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
