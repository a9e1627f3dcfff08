//! Equal-time runs that hold their budgets: the spp a budget buys, from a cost model fitted
//! to the strategy's sweep rows ([`CostFit`]), and one correction of a run whose measured
//! time still misses ([`Retime`]). Reports state every run's actual time.

use super::plan::Job;
use super::results::Row;

/// A strategy's render time as a function of its spp, fitted to its sweep rows by least
/// squares: seconds = overhead + per_spp * spp. The overhead is what a render costs whatever
/// its spp (per-pixel set-up, tiles, the sampler's per-pixel state); a rate taken from the
/// sweep alone counts it as per-sample cost, which made low-spp rows look slow and equal-time
/// runs fall 10-50 % short of their budgets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CostFit {
    pub(crate) overhead: f64,
    pub(crate) per_spp: f64,
}

impl CostFit {
    /// The fit of `label`'s sweep rows; None without rows. With one spp (or a fit whose
    /// slope is not positive) the time is taken as proportional to spp.
    pub(crate) fn of(rows: &[Row], label: &str) -> Option<CostFit> {
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.is_sweep() && r.strategy == label && r.seconds > 0.0)
            .map(|r| (r.spp as f64, r.seconds))
            .collect();
        if pts.is_empty() {
            return None;
        }
        let n = pts.len() as f64;
        let (mx, my) = (
            pts.iter().map(|p| p.0).sum::<f64>() / n,
            pts.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let proportional = || CostFit {
            overhead: 0.0,
            per_spp: pts.iter().map(|p| p.1).sum::<f64>() / pts.iter().map(|p| p.0).sum::<f64>(),
        };
        if !(sxx > 0.0) {
            return Some(proportional());
        }
        let per_spp = sxy / sxx;
        let overhead = my - per_spp * mx;
        if !(per_spp > 0.0) {
            return Some(proportional());
        }
        if overhead < 0.0 {
            // Timing noise: a line through the origin fitted to the same points.
            let sxy0: f64 = pts.iter().map(|p| p.0 * p.1).sum();
            let sxx0: f64 = pts.iter().map(|p| p.0 * p.0).sum();
            return Some(CostFit {
                overhead: 0.0,
                per_spp: sxy0 / sxx0,
            });
        }
        Some(CostFit { overhead, per_spp })
    }

    /// The spp whose render the fit predicts to take `budget` seconds (at least 1).
    pub(crate) fn spp_for(&self, budget: f64) -> u32 {
        let spp = ((budget - self.overhead) / self.per_spp).round();
        if spp.is_finite() {
            spp.clamp(1.0, u32::MAX as f64) as u32
        } else {
            1
        }
    }
}

/// How far an equal-time run's time may miss its budget before it is rendered again.
pub(crate) const BUDGET_TOLERANCE: f64 = 0.05;

/// Equal-time runs that hold their budgets: a run whose time misses its budget by more than
/// [`BUDGET_TOLERANCE`] is rendered once more at the spp its own time implies (a render's
/// time is linear in its spp at these counts, and a long run measures the rate better than
/// the sweep's short ones), and the later seeds of that strategy and budget start from the
/// corrected spp.
#[derive(Default)]
pub(crate) struct Retime {
    /// Per (strategy label, budget): the factor the fitted spp needed.
    factors: Vec<(String, f64, f64)>,
}

impl Retime {
    /// Renders `job` (whose render's row is `row_of` of what `render` returns), once more if
    /// it misses its budget.
    pub(crate) fn run_with<T>(
        &mut self,
        job: &Job,
        mut render: impl FnMut(&Job) -> Result<T, String>,
        row_of: impl Fn(&T) -> &Row,
    ) -> Result<T, String> {
        let label = job.method.label();
        let at = self
            .factors
            .iter()
            .position(|(l, b, _)| *l == label && *b == job.budget);
        let factor = at.map_or(1.0, |i| self.factors[i].2);
        let scaled = |f: f64| ((job.spp as f64 * f).round().clamp(1.0, u32::MAX as f64)) as u32;
        let mut j = Job {
            spp: scaled(factor),
            ..job.clone()
        };
        let mut out = render(&j)?;
        let miss = row_of(&out).seconds / job.budget;
        let factor = if (miss - 1.0).abs() > BUDGET_TOLERANCE && miss > 0.0 {
            let f = factor / miss;
            j.spp = scaled(f);
            out = render(&j)?;
            f
        } else {
            factor
        };
        match at {
            Some(i) => self.factors[i].2 = factor,
            None => self.factors.push((label, job.budget, factor)),
        }
        Ok(out)
    }

    /// [`Retime::run_with`] of a render that returns its row.
    pub(crate) fn run(
        &mut self,
        job: &Job,
        render: impl FnMut(&Job) -> Result<Row, String>,
    ) -> Result<Row, String> {
        self.run_with(job, render, |r| r)
    }
}

/// The spp of an equal-time run of `label`: what its sweep rows' cost fit predicts to take
/// `budget` seconds.
pub(crate) fn equal_time_spp(rows: &[Row], label: &str, budget: f64) -> Result<u32, String> {
    let fit = CostFit::of(rows, label)
        .ok_or_else(|| format!("no sweep rows for {label} to time it from"))?;
    Ok(fit.spp_for(budget))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::results::test_row;

    /// Rows of 0.1 s overhead and 0.01 s per spp: the fit recovers both, and a 2 s budget
    /// takes 190 spp (a rate over the rows, 0.41 s for 21 spp, would have given 102).
    #[test]
    fn cost_fit_separates_overhead_from_per_sample_cost() {
        let mut rows = Vec::new();
        for (spp, secs) in [(1, 0.11), (4, 0.14), (16, 0.26)] {
            let mut r = test_row("s", spp, 0);
            r.seconds = secs;
            rows.push(r);
        }
        let f = CostFit::of(&rows, "s").unwrap();
        assert!(
            (f.overhead - 0.1).abs() < 1e-12 && (f.per_spp - 0.01).abs() < 1e-12,
            "{f:?}"
        );
        assert_eq!(f.spp_for(2.0), 190);
        assert_eq!(
            f.spp_for(0.05),
            1,
            "a budget below the overhead still renders once"
        );
        // One spp: proportional. A negative intercept from noise: through the origin.
        let one = CostFit::of(&rows[2..], "s").unwrap();
        assert_eq!((one.overhead, one.per_spp), (0.0, 0.26 / 16.0));
        rows[0].seconds = 0.001;
        rows[1].seconds = 0.05;
        let f = CostFit::of(&rows, "s").unwrap();
        assert_eq!(f.overhead, 0.0);
        assert!((f.per_spp - (0.001 + 4.0 * 0.05 + 16.0 * 0.26) / 273.0).abs() < 1e-15);
        assert!(CostFit::of(&rows, "other").is_none());
    }

    /// A renderer whose time is 1 ms per spp: a fitted spp 20 % short is rendered again at the
    /// spp its time implies, once, and the next seed starts there; a run within 5 % is kept.
    #[test]
    fn a_run_that_misses_its_budget_is_rendered_once_more_at_the_corrected_spp() {
        let job = |spp: u32, seed: u64| Job {
            name: "s".into(),
            method: crate::experiment::method::Method {
                strategy: crate::integrator::Strategy::combinations()[0],
                sampler: Default::default(),
            },
            kind: crate::experiment::results::EQUAL_TIME,
            budget: 1.0,
            spp,
            seed,
            image: None,
        };
        let renders = std::cell::RefCell::new(Vec::new());
        let render = |j: &Job| -> Result<Row, String> {
            renders.borrow_mut().push(j.spp);
            let mut r = test_row("s", j.spp, j.seed);
            r.seconds = 0.001 * j.spp as f64;
            Ok(r)
        };
        let mut retime = Retime::default();
        let first = retime.run(&job(800, 0), render).unwrap();
        assert_eq!((first.spp, first.seconds), (1000, 1.0));
        let second = retime.run(&job(800, 1), render).unwrap();
        assert_eq!(second.spp, 1000);
        assert_eq!(
            *renders.borrow(),
            [800, 1000, 1000],
            "one correction, then none"
        );
        // Within the tolerance: kept as it is.
        let kept = Retime::default().run(&job(970, 0), render).unwrap();
        assert_eq!(kept.spp, 970);
        assert_eq!(renders.borrow().len(), 4);
    }
}
