//! `index.html` of an image sweep: one self-contained page (no server, no network, no
//! modules, no fetch) with the reference and each strategy's seed-0 image at the comparison
//! spp and at equal time, as HDR data tone-mapped in the page ([`super::data`]).

use super::data;
use crate::experiment::plan::{image_path, load_image, spp_tag, time_tag};
use crate::experiment::runner::Outcome;
use crate::film::Image;
use serde_json::json;
use std::fmt::Write;

/// Films above this many pixels are shown box-averaged by an integer factor, so that a page
/// stays a few MB; the EXRs keep every pixel.
pub const MAX_PIXELS: u64 = 200_000;

const VIEWER: &str = include_str!("viewer.js");

/// The images the page shows: (title, HDR image), the reference first.
fn images(o: &Outcome) -> Result<Vec<(String, Image)>, String> {
    let mut v = vec![(
        format!("reference ({} spp)", o.reference.info.spp),
        o.reference.mean.clone(),
    )];
    let spp = o.exp.equal_spp();
    for (label, name) in &o.strategies {
        let p = image_path(&o.dir, label, &spp_tag(spp), 0);
        if p.exists() {
            v.push((format!("{name}, {spp} spp"), load_image(&p)?.0));
        }
    }
    if let Some(et) = &o.exp.exp.equal_time {
        for &b in &et.seconds {
            for (label, name) in &o.strategies {
                let p = image_path(&o.dir, label, &time_tag(b), 0);
                if p.exists() {
                    v.push((format!("{name}, {b} s"), load_image(&p)?.0));
                }
            }
        }
    }
    Ok(v)
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
    let shown: Vec<Image> = imgs.iter().map(|(_, i)| data::downsample(i, k)).collect();
    let eps = o.exp.exp.metrics.relmse_epsilon;
    // One relMSE scale for the scene: five decades below the worst image's mean relMSE.
    let worst = imgs
        .iter()
        .skip(1)
        .map(|(_, i)| crate::metrics::rel_mse(i, &o.reference.mean, eps))
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
        .map(|((t, _), s)| json!({ "title": t, "data": data::encode(s) }))
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
canvas {{ image-rendering: pixelated; width: {cw}px; border: 1px solid #888; }}
#bar {{ display: none; width: 300px; height: 12px;
  background: linear-gradient(90deg, #0d0d59, #00b3e6, #ffe61a, #d90d0d); }}
#help {{ display: none; }} #help.on {{ display: block; }}
</style></head><body>
<h1>{t}</h1>
<p>Keys: 1-9 choose an image, hold R for the reference, E relMSE map, S signed error, ? help.
Shown at 1/{k} resolution per axis (box average); <a href="index.md">the report</a>.</p>
<div id="help"><pre>1-9  image      R (hold)  reference      E  relMSE map (log10, decades {lo} to {hi})
S    signed error (blue: too dark, red: too bright; +-100 %)      ?  this help</pre></div>
<div id="tabs"></div>
<label>exposure (stops) <input id="ev" type="range" min="-6" max="6" step="0.25" value="0"></label>
<div id="caption"></div><canvas id="canvas"></canvas><div id="bar"></div>
<div id="selftest"></div>
<script>const DL = {dl};</script>
<script>{viewer}</script>
</body></html>
"#,
        t = escape(&title),
        cw = shown[0].width.max(1) * k.max(1),
        k = k,
        lo = hi - 5.0,
        hi = hi,
        dl = dl,
        viewer = VIEWER
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
