//! An experiment's counted cost: the cost model (`crate::cost`) fitted on its own runs, each
//! run's modelled seconds and how far its measured time is from them. Fitted per experiment
//! because its runs are the machine and thread count it ran on; the counts behind it are the
//! same everywhere.

use super::method::Method;
use super::results::Row;
use super::runner::Outcome;
use crate::cost::{CostModel, Work};

/// The fitted model and each row's modelled seconds (`Outcome::rows` order; None for rows
/// without counts or of a strategy the experiment no longer keeps).
pub struct Costs {
    pub model: CostModel,
    pub modelled: Vec<Option<f64>>,
}

impl Costs {
    /// The model of `o`'s runs; None when no run has counts and a time.
    pub fn of(o: &Outcome) -> Option<Costs> {
        Costs::fit(&o.rows, &o.strategies, &o.methods)
    }

    /// The model of `rows`, whose strategies are `labels` (label, name) drawn with `methods`
    /// (in the same order).
    pub fn fit(rows: &[Row], labels: &[(String, String)], methods: &[Method]) -> Option<Costs> {
        let works: Vec<Option<Work>> = rows.iter().map(|r| work_of(labels, methods, r)).collect();
        let runs: Vec<(Work, f64)> = works
            .iter()
            .zip(rows)
            .filter_map(|(w, r)| Some(((*w)?, r.seconds)))
            .collect();
        let model = CostModel::fit(&runs)?;
        let modelled = works
            .iter()
            .map(|w| w.as_ref().map(|w| model.predict(w)))
            .collect();
        Some(Costs { model, modelled })
    }

    /// Mean modelled seconds of the rows `pick` accepts (None if none has a model value).
    pub fn mean(&self, rows: &[Row], pick: impl Fn(&Row) -> bool) -> Option<f64> {
        let v: Vec<f64> = rows
            .iter()
            .zip(&self.modelled)
            .filter(|(r, _)| pick(r))
            .filter_map(|(_, m)| *m)
            .collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
    }

    /// The largest |modelled / measured - 1| over the rows `pick` accepts.
    pub fn worst_error(&self, rows: &[Row], pick: impl Fn(&Row) -> bool) -> Option<f64> {
        rows.iter()
            .zip(&self.modelled)
            .filter(|(r, _)| pick(r) && r.seconds > 0.0)
            .filter_map(|(r, m)| Some(((*m)? / r.seconds - 1.0).abs()))
            .reduce(f64::max)
    }
}

/// What `r`'s render did, if it recorded counts and its strategy is one of `labels`.
pub fn work_of(labels: &[(String, String)], methods: &[Method], r: &Row) -> Option<Work> {
    let k = labels.iter().position(|(label, _)| *label == r.strategy)?;
    let s = methods.get(k)?.strategy;
    Some(Work {
        pixels: u64::from(r.width) * u64::from(r.height),
        counts: r.counts()?,
        kind: s.kind,
        light_sampling: s.light_sampling,
    })
}
