//! `index.html` of an image sweep: one self-contained page (no server, no network, no
//! modules, no fetch) with the reference and each strategy's seed-0 image at the comparison
//! spp and at equal time, as HDR data tone-mapped in the page ([`super::data`]).

use super::data;
use crate::experiment::analysis::metric_short;
use crate::experiment::plan::{image_path, load_image, spp_tag, time_tag};
use crate::experiment::results::{Row, EQUAL_TIME};
use crate::experiment::runner::Outcome;
use crate::film::Image;
use crate::report::tables::{metric_means, raw_metric};
use serde_json::json;
use std::fmt::Write;

/// Films above this many pixels are shown box-averaged by an integer factor, so that a page
/// stays a few MB; the EXRs keep every pixel.
pub const MAX_PIXELS: u64 = 200_000;

const VIEWER: &str = include_str!("viewer.js");

/// An image the page shows: its title, the HDR image and the row that measured it.
type Shown<'a> = (String, Image, Option<&'a Row>);

/// The images the page shows, the reference first.
fn images(o: &Outcome) -> Result<Vec<Shown<'_>>, String> {
    let mut v = vec![(
        format!("reference ({} spp)", o.reference.info.spp),
        o.reference.mean.clone(),
        None,
    )];
    let spp = o.exp.equal_spp();
    for (label, name) in &o.strategies {
        let p = image_path(&o.dir, label, &spp_tag(spp), 0);
        if p.exists() {
            let row = o
                .rows
                .iter()
                .find(|r| r.is_sweep() && &r.strategy == label && r.spp == spp && r.seed == 0);
            v.push((format!("{name}, {spp} spp"), load_image(&p)?.0, row));
        }
    }
    if let Some(et) = &o.exp.exp.equal_time {
        for &b in &et.seconds {
            for (label, name) in &o.strategies {
                let p = image_path(&o.dir, label, &time_tag(b), 0);
                if p.exists() {
                    let row = o.rows.iter().find(|r| {
                        r.kind == EQUAL_TIME
                            && &r.strategy == label
                            && r.budget_s == b
                            && r.seed == 0
                    });
                    v.push((format!("{name}, {b} s"), load_image(&p)?.0, row));
                }
            }
        }
    }
    Ok(v)
}

/// The row's metrics as (name, value) pairs, for the page's caption.
fn row_metrics(o: &Outcome, row: Option<&Row>) -> Vec<(String, f64)> {
    let Some(r) = row else {
        return Vec::new();
    };
    let (metrics, _) = metric_means(o);
    let mut v: Vec<(String, f64)> = metrics
        .iter()
        .map(|&m| (metric_short(m).to_string(), raw_metric(r, m)))
        .collect();
    v.push(("spp".into(), r.spp as f64));
    v.push(("seconds".into(), r.seconds));
    v
}

/// The metric table (strategies x metrics at the comparison spp), sortable by any column.
fn table(o: &Outcome) -> String {
    let (metrics, rows) = metric_means(o);
    let mut t = String::from("<table id=\"metrics\"><thead><tr><th>strategy</th>");
    for m in &metrics {
        let _ = write!(t, "<th>{}</th>", escape(metric_short(*m)));
    }
    t.push_str("</tr></thead><tbody>");
    for (name, values) in rows {
        let _ = write!(t, "<tr><td>{}</td>", escape(&name));
        for v in values {
            let _ = write!(t, "<td data-v=\"{v:e}\">{v:.3e}</td>");
        }
        t.push_str("</tr>");
    }
    t.push_str("</tbody></table>");
    t
}

/// The experiment's SVG plots, inline (an <img> of a file would work too, but a page that
/// carries its plots can be mailed as one file).
fn plots(o: &Outcome) -> String {
    let mut names: Vec<String> = std::fs::read_dir(&o.dir)
        .map(|rd| {
            rd.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.ends_with(".svg"))
                .collect()
        })
        .unwrap_or_default();
    // The main convergence plot first, then the others by name.
    names.sort_by_key(|n| (n != "convergence.svg", n.clone()));
    let mut s = String::new();
    for n in names {
        if let Ok(svg) = std::fs::read_to_string(o.dir.join(&n)) {
            let _ = write!(
                s,
                "<figure class=\"plot\">{svg}<figcaption>{}</figcaption></figure>",
                escape(&n)
            );
        }
    }
    s
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Writes `<dir>/index.html`.
pub fn write(o: &Outcome) -> Result<(), String> {
    let imgs = images(o)?;
    let (w, h) = (o.width, o.height);
    let k = data::factor(w, h, MAX_PIXELS);
    let shown: Vec<Image> = imgs
        .iter()
        .map(|(_, i, _)| data::downsample(i, k))
        .collect();
    let eps = o.exp.exp.metrics.relmse_epsilon;
    // One relMSE scale for the scene: five decades below the worst image's mean relMSE.
    let worst = imgs
        .iter()
        .skip(1)
        .map(|(_, i, _)| crate::metrics::rel_mse(i, &o.reference.mean, eps))
        .fold(1e-12f64, f64::max);
    let hi = worst.log10().ceil() + 1.0;
    // The selftest's known answer: a mid-tone pixel of the second image, tone-mapped here.
    let exposure = o.exp.exp.figures.exposure.unwrap_or(1.0);
    let check = shown.get(1).map(|img| {
        let dec: Vec<[f64; 3]> = img
            .data
            .iter()
            .map(|p| data::from_rgbe(data::rgbe(*p)))
            .collect();
        let p = dec
            .iter()
            .position(|v| (0.02..0.2).contains(&(v[0] * exposure)))
            .unwrap_or(0);
        let one = Image {
            width: 1,
            height: 1,
            data: vec![dec[p]],
        };
        json!({ "pixel": p, "srgb8": crate::film::to_srgb8(&one, exposure) })
    });
    let images: Vec<_> = imgs
        .iter()
        .zip(&shown)
        .map(|((t, _, row), s)| {
            json!({ "title": t, "data": data::encode(s), "metrics": row_metrics(o, *row) })
        })
        .collect();
    let dl = json!({
        "name": o.exp.name,
        "width": shown[0].width,
        "height": shown[0].height,
        "factor": k,
        "exposure": exposure,
        "check": check,
        "eps": eps,
        "relmse_lo": hi - 5.0,
        "relmse_hi": hi,
        "signed_range": 1.0,
        "images": images,
    });
    let title = o.title();
    let mut html = String::new();
    let _ = write!(
        html,
        r#"<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>{t}</title>
<style>
body {{ font: 14px sans-serif; margin: 1em; background: #fafafa; }}
#tabs button {{ margin: 0 4px 4px 0; }} #tabs button.on {{ background: #333; color: #fff; }}
.view {{ display: inline-block; overflow: hidden; width: {cw}px; border: 1px solid #888;
  vertical-align: top; }}
canvas {{ image-rendering: pixelated; width: {cw}px; transform-origin: 0 0; display: block; }}
#bar {{ display: none; width: 300px; height: 12px;
  background: linear-gradient(90deg, #0d0d59, #00b3e6, #ffe61a, #d90d0d); }}
#help {{ display: none; }} #help.on {{ display: block; }}
table {{ border-collapse: collapse; }} td, th {{ border: 1px solid #ccc; padding: 2px 6px; }}
th {{ cursor: pointer; }} figure.plot {{ display: inline-block; margin: 4px; }}
figure.plot svg {{ width: 480px; height: auto; }}
</style></head><body>
<h1>{t}</h1>
<p>Keys: 1-9 choose an image, hold R for the reference, V side by side / swipe, E relMSE map,
S signed error, wheel or +/- zoom (drag to pan, 0 resets), ? help.
Shown at 1/{k} resolution per axis (box average); <a href="index.md">the report</a>.</p>
<div id="help"><pre>1-9  image      R (hold)  reference      E  relMSE map (log10, decades {lo} to {hi})
S    signed error (blue: too dark, red: too bright; +-100 %)      ?  this help
V    one image / side by side with the reference / swipe (the mouse moves the split)
+ -  zoom (also the mouse wheel; nearest-neighbour, shared by both panes)   0  reset zoom
drag pan</pre></div>
<div id="tabs"></div>
<label>exposure (stops) <input id="ev" type="range" min="-6" max="6" step="0.25" value="0"></label>
<div id="caption"></div>
<div class="view"><canvas id="canvas"></canvas></div><div class="view" id="pane2"><canvas id="canvas2"></canvas></div>
<div id="bar"></div><div id="imgmetrics"></div>
<h2>Metrics at {spp} spp (mean over seeds; click a column to sort)</h2>
{table}
<h2>Plots</h2>
{plots}
<div id="selftest"></div>
<script>const DL = {dl};</script>
<script>{viewer}</script>
</body></html>
"#,
        t = escape(&title),
        // Small films are enlarged by a whole factor (pixelated) to about 640 px.
        cw = shown[0].width.max(1) * k.max(640 / shown[0].width.max(1)).max(1),
        k = k,
        lo = hi - 5.0,
        hi = hi,
        dl = dl,
        viewer = VIEWER,
        spp = o.exp.equal_spp(),
        table = table(o),
        plots = plots(o)
    );
    let path = o.dir.join("index.html");
    crate::output::write_atomic(&path, |tmp| {
        std::fs::write(tmp, &html).map_err(|e| format!("{}: {e}", path.display()))
    })
}

/// `<root>/index.html`: every report of `entries` (Markdown link, title), linking its
/// interactive page where it has one.
pub fn write_root(root: &std::path::Path, entries: &[(String, String)]) -> Result<(), String> {
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
