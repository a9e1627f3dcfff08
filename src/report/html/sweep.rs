//! The image viewer of an image sweep's page: the reference and each strategy's seed-0 image
//! at the comparison spp, at the progression's spp and at equal time, as HDR data tone-mapped in the page
//! ([`super::data`], `viewer.js`).

use super::{data, Section};
use crate::experiment::analysis::metric_short;
use crate::experiment::plan::{image_path, load_image, spp_tag, time_tag};
use crate::experiment::results::{Row, EQUAL_TIME};
use crate::experiment::runner::Outcome;
use crate::film::Image;
use crate::report::tables::{metric_means, raw_metric};
use serde_json::json;

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
    // The comparison spp first (keys 1-9 flip between strategies there), then the
    // progression's other spp.
    let first = o.exp.equal_spp();
    let mut spps: Vec<u32> = o.exp.exp.figures.progression.clone();
    spps.sort_unstable();
    spps.dedup();
    spps.retain(|&s| s != first);
    spps.insert(0, first);
    for spp in spps {
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

/// The viewer of `o`'s images, for the top of its page.
pub fn section(o: &Outcome) -> Result<Section, String> {
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
    // Small films are enlarged by a whole factor (pixelated) to about 640 px.
    let cw = shown[0].width.max(1) * k.max(640 / shown[0].width.max(1)).max(1);
    let css = format!(
        "#tabs button {{ margin: 0 4px 4px 0; }} #tabs button.on {{ background: #333; color: #fff; }}
.view {{ display: inline-block; overflow: hidden; width: {cw}px; border: 1px solid #888;
  vertical-align: top; }}
canvas {{ image-rendering: pixelated; width: {cw}px; transform-origin: 0 0; display: block; }}
#bar {{ display: none; width: 300px; height: 12px;
  background: linear-gradient(90deg, #0d0d59, #00b3e6, #ffe61a, #d90d0d); }}
#help {{ display: none; }} #help.on {{ display: block; }}"
    );
    let resolution = if k > 1 {
        format!(" Shown at 1/{k} resolution per axis (box average); the EXRs hold every pixel.")
    } else {
        String::new()
    };
    let html = format!(
        r#"<p>Keys: 1-9 choose an image (arrows: next, previous), hold R for the reference, V side by side / swipe, E relMSE map,
S signed error, wheel or +/- zoom (drag to pan, 0 resets), ? help. A link can choose the
state: <code>#image=3&amp;layout=side&amp;view=relmse&amp;ev=1</code>.{resolution}</p>
<div id="help"><pre>1-9  image   &larr; &rarr;  previous, next image   R (hold)  reference      E  relMSE map (log10, decades {lo} to {hi})
S    signed error (blue: too dark, red: too bright; +-100 %)      ?  this help
V    one image / side by side with the reference / swipe (the mouse moves the split)
+ -  zoom (also the mouse wheel; nearest-neighbour, shared by both panes)   0  reset zoom
drag pan</pre></div>
<div id="tabs"></div>
<label>exposure (stops) <input id="ev" type="range" min="-6" max="6" step="0.25" value="0"></label>
<div id="caption"></div>
<div class="view"><canvas id="canvas"></canvas></div><div class="view" id="pane2"><canvas id="canvas2"></canvas></div>
<div id="bar"></div><div id="imgmetrics"></div>
"#,
        lo = hi - 5.0,
    );
    Ok(Section {
        css,
        html,
        script: format!("const DL = {dl};\n{VIEWER}"),
    })
}
