//! The registry of image metrics: MSE and relMSE (always measured, corrected for the
//! reference's noise, with predicted values) and, one line of `metrics!` each, the metrics an
//! experiment may report beside them. A line gives the metric its name in experiment files,
//! its name in `metrics.csv`, its caption, its `Row` column, its epsilon and tone mapping and
//! the function that computes it; parsing, the error listing valid names, `results.csv`,
//! `metrics.csv`, the captions and the convergence plots follow. A metric is then one
//! function in `src/metrics/` with its hand-computed case beside it (the line names it, so a
//! line cannot be written without one) and one line here, plus its `Row` column.

use super::results::Row;
use crate::film::Image;
pub use crate::metrics::Inputs;
use crate::metrics::{flip, pointwise, ssim, Compute};
use crate::output::write_atomic;
use serde::Serialize;
use std::path::Path;

/// The epsilon a metric is defined with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Eps {
    /// None.
    None,
    /// relMSE's (`metrics.relmse_epsilon`).
    Relmse,
    /// MAPE's (`metrics.mape_epsilon`).
    Mape,
}

/// A metric reported beside MSE and relMSE.
pub struct MetricDef {
    pub metric: ErrorMetric,
    /// Its name in experiment files and file names.
    pub slug: &'static str,
    /// Its name in `metrics.csv`.
    pub long: &'static str,
    /// Its caption.
    pub short: &'static str,
    pub eps: Eps,
    /// Whether it is measured on tone-mapped images (then the exposure is part of it).
    pub tone_mapped: bool,
    /// What else defines it, for its label ("" for nothing).
    pub detail: &'static str,
    /// Its value in a row (None: not chosen, or it does not apply).
    pub value: fn(&Row) -> Option<f64>,
    /// Stores its value in a row.
    pub set: fn(&mut Row, Option<f64>),
    /// Computes it (None where it does not apply, such as SSIM on a film smaller than its
    /// window).
    pub compute: Compute,
    /// Why it does not apply to a film of this width and height, if it does not.
    pub not_applicable: fn(u32, u32) -> Option<&'static str>,
}

macro_rules! metrics {
    (@not_applicable) => { |_, _| None };
    (@not_applicable $na:expr) => { $na };
    ($($variant:ident {
        slug: $slug:literal, long: $long:literal, short: $short:literal, field: $field:ident,
        eps: $eps:ident, tone_mapped: $tone:literal, detail: $detail:literal,
        compute: $compute:expr, hand: $hand:path, doc: $doc:literal
        $(, not_applicable: $na:expr)? $(,)?
    })*) => {
        /// An error of a render against the reference. MSE and relMSE are corrected for the
        /// reference's noise and have predicted values (they can be `primary`); the others
        /// are reported beside them (`report`), raw.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
        #[serde(try_from = "String")]
        pub enum ErrorMetric {
            /// Mean squared error.
            Mse,
            /// Relative MSE, (x - r)^2 / (r^2 + eps).
            Relmse,
            $(#[doc = $doc] $variant,)*
        }

        /// Every metric reported beside MSE and relMSE, in the order tables show them.
        pub const EXTRA_METRICS: &[MetricDef] = &[$(MetricDef {
            metric: ErrorMetric::$variant,
            slug: $slug,
            long: $long,
            short: $short,
            eps: Eps::$eps,
            tone_mapped: $tone,
            detail: $detail,
            value: |r: &Row| r.$field,
            set: |r: &mut Row, v| r.$field = v,
            compute: $compute,
            not_applicable: metrics!(@not_applicable $($na)?),
        },)*];

        /// Each registered metric's hand-computed case (a function beside the metric, given
        /// the line's `compute`): a line cannot be written without one.
        #[cfg(test)]
        pub(crate) const HAND: &[(&str, fn(Compute))] = &[$(($slug, $hand)),*];
    };
}

metrics! {
    TrimmedRelmse {
        slug: "trimmed-relmse", long: "trimmed-relmse", short: "trimmed relMSE",
        field: trimmed_relmse, eps: Relmse, tone_mapped: false,
        detail: "largest 0.1 % dropped",
        compute: |i| Some(pointwise::trimmed_rel_mse(i.img, i.reference, i.relmse_eps, pointwise::TRIM)),
        hand: pointwise::hand::trimmed_relmse,
        doc: "relMSE without its largest 0.1 % of terms.",
        not_applicable: |w, h| pointwise::trim_not_applicable(w as usize, h as usize),
    }
    Mape {
        slug: "mape", long: "mape", short: "MAPE", field: mape, eps: Mape,
        tone_mapped: false, detail: "",
        compute: |i| Some(pointwise::mape(i.img, i.reference, i.mape_eps)),
        hand: pointwise::hand::mape,
        doc: "mean |x - r| / (|r| + eps).",
    }
    Smape {
        slug: "smape", long: "smape", short: "SMAPE", field: smape, eps: Mape,
        tone_mapped: false, detail: "no factor 2",
        compute: |i| Some(pointwise::smape(i.img, i.reference, i.mape_eps)),
        hand: pointwise::hand::smape,
        doc: "mean |x - r| / (|x| + |r| + eps), without a factor 2.",
    }
    Ssim {
        slug: "ssim", long: "1-ssim", short: "1-SSIM", field: ssim_error, eps: None,
        tone_mapped: true, detail: "",
        compute: |i| {
            let tm = |x: &Image| crate::film::to_srgb_unit(x, i.exposure);
            let (w, h) = (i.img.width as usize, i.img.height as usize);
            ssim::ssim(&tm(i.img), &tm(i.reference), w, h).map(|s| 1.0 - s)
        },
        hand: ssim::hand::ssim_error,
        doc: "1 - SSIM on tone-mapped sRGB.",
        not_applicable: |w, h| ssim::not_applicable(w as usize, h as usize),
    }
    Flip {
        slug: "flip", long: "flip", short: "FLIP", field: flip, eps: None,
        tone_mapped: true, detail: "67 ppd",
        compute: |i| Some(flip::flip(i.img, i.reference, i.exposure)),
        hand: flip::hand::flip,
        doc: "Mean FLIP on tone-mapped 8-bit sRGB.",
    }
}

impl ErrorMetric {
    /// Its row of the registry (None for MSE and relMSE).
    pub fn def(self) -> Option<&'static MetricDef> {
        EXTRA_METRICS.iter().find(|d| d.metric == self)
    }

    /// Every metric beside MSE and relMSE, the default of `report`.
    pub fn extra() -> Vec<ErrorMetric> {
        EXTRA_METRICS.iter().map(|d| d.metric).collect()
    }

    /// Its name in experiment files and file names.
    pub fn slug(self) -> &'static str {
        match self {
            ErrorMetric::Mse => "mse",
            ErrorMetric::Relmse => "relmse",
            m => m.def().expect("registered").slug,
        }
    }

    /// Its name in `metrics.csv`.
    pub fn long(self) -> &'static str {
        self.def().map_or_else(|| self.slug(), |d| d.long)
    }

    /// Short name for captions; figure titles state epsilon.
    pub fn short(self) -> &'static str {
        match self {
            ErrorMetric::Mse => "MSE",
            ErrorMetric::Relmse => "relMSE",
            m => m.def().expect("registered").short,
        }
    }

    /// Whether it is measured on tone-mapped images (then the exposure is part of it).
    pub fn tone_mapped(self) -> bool {
        self.def().is_some_and(|d| d.tone_mapped)
    }

    /// The metric with what defines it: epsilon, trimming, tone mapping (`exposure`).
    pub fn label(self, eps: f64, mape_eps: f64, exposure: f64) -> String {
        let Some(d) = self.def() else {
            return match self {
                ErrorMetric::Relmse => format!("relMSE (eps {eps})"),
                _ => "MSE".into(),
            };
        };
        let mut parts = Vec::new();
        match d.eps {
            Eps::None => {}
            Eps::Relmse => parts.push(format!("eps {eps}")),
            Eps::Mape => parts.push(format!("eps {mape_eps}")),
        }
        if d.tone_mapped {
            parts.push(format!("sRGB at exposure {exposure}, clamped"));
        }
        if !d.detail.is_empty() {
            parts.push(d.detail.to_string());
        }
        format!("{} ({})", d.short, parts.join(", "))
    }

    /// Every name an experiment file may give.
    pub fn names() -> Vec<&'static str> {
        ["mse", "relmse"]
            .into_iter()
            .chain(EXTRA_METRICS.iter().map(|d| d.slug))
            .collect()
    }
}

impl std::str::FromStr for ErrorMetric {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "mse" => Ok(ErrorMetric::Mse),
            "relmse" => Ok(ErrorMetric::Relmse),
            t => EXTRA_METRICS
                .iter()
                .find(|d| d.slug == t)
                .map(|d| d.metric)
                .ok_or_else(|| {
                    format!(
                        "unknown metric '{t}': expected one of {}",
                        ErrorMetric::names().join(", ")
                    )
                }),
        }
    }
}

impl TryFrom<String> for ErrorMetric {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        s.parse()
    }
}

/// One value of `metrics.csv`: a run's error in one metric, named with what defines it.
#[derive(Serialize)]
struct MetricRow<'a> {
    case: &'a str,
    strategy: &'a str,
    name: &'a str,
    kind: &'a str,
    budget_s: f64,
    spp: u32,
    seed: u64,
    metric: &'static str,
    /// Empty where the metric has none.
    epsilon: Option<f64>,
    /// "linear" or the display transform SSIM and FLIP compare.
    tone_mapping: String,
    /// MSE and relMSE as measured (not corrected for the reference's noise; results.csv has
    /// both); empty where the metric does not apply to the run.
    value: Option<f64>,
    /// Why the value is empty ("" when there is one).
    note: String,
}

/// `metrics.csv`: every run's every measured metric, one per row, each row naming the
/// metric, its epsilon and its tone mapping.
pub fn write_long(path: &Path, rows: &[Row]) -> Result<(), String> {
    use ErrorMetric as M;
    write_atomic(path, |tmp| {
        let mut w = csv::Writer::from_path(tmp).map_err(|e| e.to_string())?;
        for r in rows {
            let tm = |e: Option<f64>| match e {
                Some(x) => format!("exposure {x}; clamp to [0 1]; sRGB"),
                None => String::new(),
            };
            let mut values = vec![
                (M::Mse, Some(r.mse), None, String::from("linear")),
                (
                    M::Relmse,
                    Some(r.relmse),
                    Some(r.relmse_eps),
                    "linear".into(),
                ),
            ];
            for d in EXTRA_METRICS {
                let epsilon = match d.eps {
                    Eps::None => None,
                    Eps::Relmse => Some(r.relmse_eps),
                    Eps::Mape => r.mape_eps,
                };
                let tone = if d.tone_mapped {
                    tm(r.exposure)
                } else {
                    "linear".into()
                };
                values.push((d.metric, (d.value)(r), epsilon, tone));
            }
            for (m, v, epsilon, tone_mapping) in values {
                let note = r
                    .not_applicable
                    .split("; ")
                    .find_map(|n| n.strip_prefix(m.slug()).and_then(|x| x.strip_prefix(": ")));
                let (value, note) = match (v, note) {
                    (Some(x), _) if x.is_finite() => (Some(x), String::new()),
                    (Some(_), _) => (None, "not a finite number".to_string()),
                    (None, Some(why)) => (None, why.to_string()),
                    (None, None) => continue,
                };
                w.serialize(MetricRow {
                    case: &r.case,
                    strategy: &r.strategy,
                    name: &r.name,
                    kind: &r.kind,
                    budget_s: r.budget_s,
                    spp: r.spp,
                    seed: r.seed,
                    metric: m.long(),
                    epsilon,
                    tone_mapping,
                    value,
                    note,
                })
                .map_err(|e| e.to_string())?;
            }
        }
        w.flush().map_err(|e| e.to_string())
    })
}

#[cfg(test)]
#[path = "metric_tests.rs"]
mod tests;
