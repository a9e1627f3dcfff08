//! The figures of one experiment, written beside its report: convergence charts, image
//! comparisons at equal spp and equal time, the spp progression, variance maps.

mod charts;
mod compare;
mod spectrum;
mod techniques;
mod variance;

pub use charts::charts;

use super::plan::{spp_tag, time_tag};
use super::results::Results;
use super::runner::Outcome;
use crate::film::{to_srgb8, Image};
use crate::plot::colormap::LogScale;
use crate::plot::panels::Panel;

/// A figure file (relative to the experiment folder) with its caption.
pub struct Figure {
    pub file: String,
    pub caption: String,
}

pub(crate) const PANEL: u32 = 320;
pub(crate) const CROP_COLOURS: [[u8; 3]; 4] =
    [[255, 60, 60], [60, 200, 255], [255, 210, 0], [255, 80, 255]];

pub(crate) fn short(v: f64) -> String {
    format!("{v:.2e}")
}

pub(crate) fn panel_of(img: &Image, exposure: f64, title: &str) -> Panel {
    Panel::new(title, img.width, img.height, to_srgb8(img, exposure))
}

pub(crate) fn map_panel(values: &[f64], w: u32, h: u32, s: &LogScale, title: &str) -> Panel {
    let rgb = values.iter().flat_map(|&v| s.colour(v)).collect();
    Panel::new(title, w, h, rgb)
}

/// All image figures of an experiment.
pub fn images(o: &Outcome) -> Result<Vec<Figure>, String> {
    let mut figs = Vec::new();
    let res = Results {
        rows: o.rows.clone(),
        dropped: 0,
    };
    let spp = o.exp.equal_spp();
    figs.extend(compare::progression(o)?);
    figs.extend(compare::comparison(
        o,
        "equal_spp.png",
        &format!("Equal samples: {spp} spp"),
        &spp_tag(spp),
        &|label| res.find_sweep(label, spp, 0).cloned(),
    )?);
    if let Some(et) = &o.exp.exp.equal_time {
        for &b in &et.seconds {
            figs.extend(compare::comparison(
                o,
                &format!("equal_time_{b}s.png"),
                &format!("Equal time: {b} s"),
                &time_tag(b),
                &|label| res.find_equal_time(label, b, 0).cloned(),
            )?);
        }
    }
    figs.extend(variance::variance_maps(o, o.exp.variance_spp())?);
    figs.extend(spectrum::spectra(o)?);
    figs.extend(techniques::techniques(o)?);
    Ok(figs)
}
