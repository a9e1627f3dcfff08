//! The image viewer of an image sweep's page: the reference and each strategy's images at the
//! comparison spp, at the progression's spp and at equal time, every kept seed's too, as HDR
//! data tone-mapped in the page ([`super::data`], `viewer.js`). Images are embedded at full
//! resolution while the page stays within its budget (`figures.page_mb`, default
//! [`PAGE_MB`]);
//! beyond it they are box-averaged by the smallest integer factor that fits, and the page says
//! so.

use super::{data, Section};
use crate::experiment::analysis::metric_short;
use crate::experiment::plan::{image_path, load_image, spp_tag, time_tag};
use crate::experiment::results::{Row, EQUAL_TIME};
use crate::experiment::runner::Outcome;
use crate::experiment::schema::PAGE_MB;
use crate::film::Image;
use crate::report::tables::{metric_means, raw_metric};
use serde_json::json;

const VIEWER: &str = include_str!("viewer.js");

/// An image the page shows: its title, its group in the picker, the HDR image and the row
/// that measured it.
struct Shown<'a> {
    title: String,
    group: &'static str,
    img: Image,
    row: Option<&'a Row>,
}

/// The images the page shows: the reference, then seed 0 at the comparison spp (keys 1-9
/// flip between strategies there), at the progression's other spp and at equal time, then
/// every other kept seed.
fn images(o: &Outcome) -> Result<Vec<Shown<'_>>, String> {
    let mut v = vec![Shown {
        title: format!("reference ({} spp)", o.reference.info.spp),
        group: "reference",
        img: o.reference.mean.clone(),
        row: None,
    }];
    let first = o.exp.equal_spp();
    let mut spps: Vec<u32> = o.exp.exp.figures.progression.clone();
    spps.sort_unstable();
    spps.dedup();
    spps.retain(|&s| s != first);
    let sweep = At::Spp(first);
    kept(o, sweep, 0, "comparison spp", &mut v)?;
    for &spp in &spps {
        kept(o, At::Spp(spp), 0, "progression", &mut v)?;
    }
    let budgets = o.exp.exp.equal_time.as_ref();
    if let Some(et) = budgets {
        for &b in &et.seconds {
            kept(o, At::Time(b), 0, "equal time", &mut v)?;
        }
    }
    for seed in 1..o.exp.exp.seeds as u64 {
        kept(o, sweep, seed, "other seeds", &mut v)?;
    }
    if let Some(et) = budgets {
        for seed in 1..et.seeds as u64 {
            for &b in &et.seconds {
                kept(o, At::Time(b), seed, "other seeds", &mut v)?;
            }
        }
    }
    Ok(v)
}

/// Where an image was measured: at a sample count or a time budget.
#[derive(Clone, Copy)]
enum At {
    Spp(u32),
    Time(f64),
}

/// Every strategy's kept image of `seed` at `at`, appended to `v`.
fn kept<'a>(
    o: &'a Outcome,
    at: At,
    seed: u64,
    group: &'static str,
    v: &mut Vec<Shown<'a>>,
) -> Result<(), String> {
    for (label, name) in &o.strategies {
        let (tag, what) = match at {
            At::Spp(spp) => (spp_tag(spp), format!("{spp} spp")),
            At::Time(b) => (time_tag(b), format!("{b} s")),
        };
        let p = image_path(&o.dir, label, &tag, seed);
        if !p.exists() {
            continue;
        }
        let row = o.rows.iter().find(|r| {
            &r.strategy == label
                && r.seed == seed
                && match at {
                    At::Spp(spp) => r.is_sweep() && r.spp == spp,
                    At::Time(b) => r.kind == EQUAL_TIME && r.budget_s == b,
                }
        });
        let title = match seed {
            0 => format!("{name}, {what}"),
            s => format!("{name}, {what}, seed {s}"),
        };
        let img = load_image(&p)?.0;
        v.push(Shown {
            title,
            group,
            img,
            row,
        });
    }
    Ok(())
}

/// The smallest integer box-average factor at which every image's embedded data fits
/// `budget` bytes (1: full resolution), and those data.
fn fit(imgs: &[&Image], budget: f64) -> (u32, Vec<String>) {
    let (w, h) = (imgs[0].width, imgs[0].height);
    let mut k = 1u32;
    loop {
        let enc: Vec<String> = imgs
            .iter()
            .map(|i| data::encode(&data::downsample(i, k)))
            .collect();
        let total = enc.iter().map(|s| s.len()).sum::<usize>() as f64;
        if total <= budget || k >= w.min(h) {
            return (k, enc);
        }
        // The data shrink about as the pixel count: jump near the fitting factor.
        let guess = (k as f64 * (total / budget).sqrt()).floor() as u32;
        k = guess.clamp(k + 1, w.min(h).max(k + 1));
    }
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
    let budget_mb = o.exp.exp.figures.page_mb.unwrap_or(PAGE_MB);
    let all: Vec<&Image> = imgs.iter().map(|s| &s.img).collect();
    let (k, encoded) = fit(&all, budget_mb * 1e6);
    let shown: Vec<Image> = imgs.iter().map(|s| data::downsample(&s.img, k)).collect();
    let eps = o.exp.exp.metrics.relmse_epsilon;
    // One relMSE scale for the scene: five decades below the worst image's mean relMSE.
    let worst = imgs
        .iter()
        .skip(1)
        .map(|s| crate::metrics::rel_mse(&s.img, &o.reference.mean, eps))
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
        .zip(encoded)
        .map(|(s, d)| {
            json!({ "title": s.title, "group": s.group, "data": d,
                    "metrics": row_metrics(o, s.row) })
        })
        .collect();
    let (w, h) = (shown[0].width.max(1), shown[0].height.max(1));
    let dl = json!({
        "name": o.exp.name,
        "width": w,
        "height": h,
        "factor": k,
        // Small films are enlarged by a whole factor (pixelated) to about 640 px.
        "scale": k.max(640 / w).max(1),
        "exposure": exposure,
        "check": check,
        "eps": eps,
        "relmse_lo": hi - 5.0,
        "relmse_hi": hi,
        "signed_range": 1.0,
        "images": images,
    });
    let css =
        "#tabs button { margin: 0 4px 4px 0; } #tabs button.on { background: #333; color: #fff; }
#views { display: flex; flex-wrap: wrap; gap: 8px; align-items: flex-start; }
.view { overflow: hidden; border: 1px solid #888; }
canvas { image-rendering: pixelated; width: 100%; transform-origin: 0 0; display: block; }
#legend { display: none; margin-top: 4px; } #bar { width: 300px; height: 12px; }
#ticks { position: relative; width: 300px; height: 1.3em; font-size: 11px; }
#ticks span { position: absolute; transform: translateX(-50%); white-space: nowrap; }
#probe { font: 12px monospace; min-height: 1.3em; white-space: pre; }
#help { display: none; } #help.on { display: block; }"
            .to_string();
    let resolution = if k > 1 {
        format!(
            " <b>Shown at 1/{k} resolution per axis (box average)</b>: at full resolution the \
             images exceed the page budget of {budget_mb} MB (<code>figures.page_mb</code>); \
             the EXRs hold every pixel."
        )
    } else {
        format!(" Every image at full resolution (page budget {budget_mb} MB).")
    };
    let html = format!(
        r#"<p>Keys: 1-9 the first images, arrows (or N, P) next and previous, the list picks any; hold R for the reference,
V side by side / swipe, E relMSE map, S signed error, wheel or +/- zoom (drag to pan, 0 resets), ? help. The
pixel under the cursor is read out below the image. The address follows the view
(<code>#image=3&amp;layout=side&amp;view=relmse&amp;ev=1</code>), so a link shares it.{resolution}</p>
<div id="help"><pre>1-9  image   &larr; &rarr; (N P)  next, previous image   R (hold)  reference      E  relMSE map (log10, decades {lo} to {hi})
S    signed error (blue: too dark, red: too bright; +-100 %)      ?  this help
V    one image / side by side with the reference / swipe (the mouse moves the split)
+ -  zoom (also the mouse wheel; nearest-neighbour, shared by both panes)   0  reset zoom
drag pan</pre></div>
<div id="tabs"></div>
<div><select id="picker"></select> <button id="prev">&larr;</button> <button id="next">&rarr;</button>
<label>exposure <input id="ev" type="range" min="-6" max="6" step="0.25" value="0"></label>
<span id="evtext"></span></div>
<div id="caption"></div>
<div id="views"><div class="view" id="pane1"><canvas id="canvas"></canvas></div><div class="view" id="pane2"><canvas id="canvas2"></canvas></div></div>
<div id="legend"><div id="bartitle"></div><div id="bar"></div><div id="ticks"></div></div>
<div id="probe"></div><div id="imgmetrics"></div>
"#,
        lo = hi - 5.0,
    );
    Ok(Section {
        css,
        html,
        script: format!("const DL = {dl};\n{VIEWER}"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(w: u32, h: u32, seed: u64) -> Image {
        let mut r = crate::rng::Rng::new(seed, 0);
        let mut img = Image::new(w, h);
        for p in img.data.iter_mut() {
            *p = [r.next_f64(), r.next_f64(), r.next_f64()];
        }
        img
    }

    #[test]
    fn images_stay_full_size_within_the_budget_and_shrink_only_beyond_it() {
        let imgs: Vec<Image> = (0..3).map(|s| noise(96, 64, s)).collect();
        let refs: Vec<&Image> = imgs.iter().collect();
        let (k, enc) = fit(&refs, 1e9);
        assert_eq!(k, 1);
        let full: usize = enc.iter().map(|s| s.len()).sum();
        // Noise barely compresses: about 4 bytes a pixel, 4/3 in base64.
        assert!(full > 3 * 96 * 64 * 4, "{full}");
        let (k, enc) = fit(&refs, full as f64 / 3.0);
        let small: usize = enc.iter().map(|s| s.len()).sum();
        assert!(k >= 2 && small as f64 <= full as f64 / 3.0, "{k} {small}");
        // The smallest such factor.
        let (k1, _) = fit(&refs, small as f64);
        assert_eq!(k1, k);
        let before: usize = refs
            .iter()
            .map(|i| data::encode(&data::downsample(i, k - 1)).len())
            .sum();
        assert!(before as f64 > full as f64 / 3.0, "{before}");
    }
}
