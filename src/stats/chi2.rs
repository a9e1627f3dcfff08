//! Pearson chi-square test of a sampler against the pdf it claims (Nori's warptest and
//! Mitsuba's `ChiSquareTest` in spirit).
//!
//! Samples are binned on a [`Domain`]'s grid; expected counts are `N * integral of the pdf
//! over each cell`, integrated adaptively so sharp support edges stay exact. Cells expected
//! to get fewer than `min_expected` samples are pooled (Nori's rule). Samples the sampler
//! fails to produce (`None`) form one more category, "lost", whose expected count is
//! `N * (1 - integral of the pdf)`: a sampler that fails 10 % of the time passes only if
//! its pdf integrates to 0.9. The lost category enters the statistic only when samples were
//! lost, so a tiny integration error in the total cannot fail a lossless sampler.

use super::domain::Domain;
use super::integrate::{integrate_rect, Integration};
use crate::rng::Rng;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Parameters of one chi-square run.
#[derive(Clone, Copy, Debug)]
pub struct Chi2Config {
    /// Number of sampler calls N.
    pub samples: u64,
    /// Significance level for this case; pass `sidak(alpha, cases)` when testing a batch.
    pub threshold: f64,
    /// The sampler draws from `Rng::new(seed, 0)`, so a run is reproducible.
    pub seed: u64,
    /// Cells expected to receive fewer samples than this are pooled.
    pub min_expected: f64,
    /// Samples tolerated in cells of expected count 0 (an integral below 1e-12 N, i.e.
    /// numerically nothing), as a fraction of N. Nori uses 1e-5 to forgive f32 rounding at
    /// the support's boundary; 0 makes any stray sample fatal.
    pub zero_tolerance: f64,
    pub integration: Integration,
}

impl Default for Chi2Config {
    fn default() -> Self {
        Chi2Config {
            samples: 1_000_000,
            threshold: 0.01,
            seed: 0,
            min_expected: 5.0,
            zero_tolerance: 1e-5,
            integration: Integration::default(),
        }
    }
}

/// Verdict of a statistical test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    Pass,
    Fail,
}

/// Row-major grid of per-cell values; `row` follows the domain's v parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    pub cols: usize,
    pub rows: usize,
    pub data: Vec<f64>,
}

impl Grid {
    pub fn new(cols: usize, rows: usize) -> Self {
        Grid {
            cols,
            rows,
            data: vec![0.0; cols * rows],
        }
    }
    pub fn get(&self, col: usize, row: usize) -> f64 {
        self.data[row * self.cols + col]
    }
    pub fn sum(&self) -> f64 {
        self.data.iter().sum()
    }

    /// The cell and its (up to 8) neighbours.
    pub fn neighbours(&self, c: usize, r: usize) -> impl Iterator<Item = (usize, usize)> {
        let (cols, rows) = (self.cols, self.rows);
        (r.saturating_sub(1)..=(r + 1).min(rows - 1)).flat_map(move |rr| {
            (c.saturating_sub(1)..=(c + 1).min(cols - 1)).map(move |cc| (cc, rr))
        })
    }

    /// Cells on the support's boundary: their 3x3 neighbourhood holds both empty and
    /// non-empty cells.
    pub fn boundary_cells(&self) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for r in 0..self.rows {
            for c in 0..self.cols {
                let (mut empty, mut full) = (false, false);
                for (cc, rr) in self.neighbours(c, r) {
                    let x = self.get(cc, rr);
                    empty |= x == 0.0;
                    full |= x > 0.0;
                }
                if empty && full {
                    out.push((c, r));
                }
            }
        }
        out
    }
}

/// Everything a report or heat map needs about one run.
#[derive(Clone, Debug)]
pub struct Chi2Result {
    pub domain: &'static str,
    /// What the grid's columns and rows are ([`Domain::axes`]).
    pub axes: [&'static str; 2],
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
    pub threshold: f64,
    pub verdict: Verdict,
    /// Why it failed, or a one-line summary when it passed.
    pub reason: String,
    pub observed: Grid,
    pub expected: Grid,
    pub samples: u64,
    /// Sampler calls that returned None.
    pub lost: u64,
    /// Samples outside the domain (never binned; any makes the test fail).
    pub outside: u64,
    /// Integral of the pdf over the domain: 1 for a sampler that never fails.
    pub pdf_integral: f64,
}

impl Chi2Result {
    pub fn passed(&self) -> bool {
        self.verdict == Verdict::Pass
    }
}

/// Integrates `pdf` over every cell: the expected fraction of samples per cell.
/// Negative or NaN pdf values are counted (and treated as 0) so the caller can fail on them.
pub fn cell_integrals<D: Domain>(
    domain: &D,
    pdf: impl Fn(D::Point) -> f64,
    cfg: &Integration,
) -> (Grid, u64) {
    cell_integrals_seen(domain, pdf, cfg, None)
}

/// [`cell_integrals`], then cells that `observed` says received samples but that integrate
/// to 0 are integrated again from `recheck_split x recheck_split` rectangles: the corner of
/// a light seen at a grazing angle is a wedge thinner than any node spacing chosen in
/// advance, and the samples show where to look. A cell still empty after that is one where
/// the sampler produced what its pdf calls impossible.
pub fn cell_integrals_seen<D: Domain>(
    domain: &D,
    pdf: impl Fn(D::Point) -> f64,
    cfg: &Integration,
    observed: Option<&Grid>,
) -> (Grid, u64) {
    let (cols, rows) = domain.resolution();
    let ([u0, u1], [v0, v1]) = domain.bounds();
    let (du, dv) = ((u1 - u0) / cols as f64, (v1 - v0) / rows as f64);
    let jac = domain.jacobian();
    let mut bad = 0u64;
    let mut f = |u: f64, v: f64| match domain.point(u, v) {
        None => 0.0,
        Some(p) => {
            let x = pdf(p);
            if x.is_nan() || x < 0.0 {
                bad += 1;
                0.0
            } else {
                x * jac
            }
        }
    };
    // Errors far below one sample in a million-sample run are irrelevant.
    let abs_tol = 1e-9 / (cols * rows) as f64;
    let mut grid = Grid::new(cols, rows);
    for r in 0..rows {
        for c in 0..cols {
            let u = [u0 + c as f64 * du, u0 + (c + 1) as f64 * du];
            let v = [v0 + r as f64 * dv, v0 + (r + 1) as f64 * dv];
            grid.data[r * cols + c] = integrate_rect(&mut f, u, v, cfg, abs_tol);
        }
    }
    // Second look at cells on the support's boundary (a 3x3 neighbourhood holding both
    // empty and non-empty cells) with a finer start and the same finest scale: a sliver's tip
    // can pass between all nodes of the first pass, leaving its cells empty or underweighted.
    // An empty cell found non-empty puts its neighbours on the list, following the tip.
    if cfg.boundary_split > cfg.initial_split.max(1) {
        let fine = cfg.finer(cfg.boundary_split);
        let mut todo = grid.boundary_cells();
        let mut done = vec![false; cols * rows];
        while let Some((c, r)) = todo.pop() {
            if std::mem::replace(&mut done[r * cols + c], true) {
                continue;
            }
            let u = [u0 + c as f64 * du, u0 + (c + 1) as f64 * du];
            let v = [v0 + r as f64 * dv, v0 + (r + 1) as f64 * dv];
            let was = grid.data[r * cols + c];
            let now = integrate_rect(&mut f, u, v, &fine, abs_tol);
            grid.data[r * cols + c] = now;
            if was == 0.0 && now > 0.0 {
                todo.extend(
                    grid.neighbours(c, r)
                        .filter(|&(cc, rr)| !done[rr * cols + cc]),
                );
            }
        }
    }
    if let Some(seen) = observed.filter(|_| cfg.recheck_split > 1) {
        let fine = cfg.finer(cfg.recheck_split);
        for r in 0..rows {
            for c in 0..cols {
                if grid.get(c, r) == 0.0 && seen.get(c, r) > 0.0 {
                    let u = [u0 + c as f64 * du, u0 + (c + 1) as f64 * du];
                    let v = [v0 + r as f64 * dv, v0 + (r + 1) as f64 * dv];
                    grid.data[r * cols + c] = integrate_rect(&mut f, u, v, &fine, abs_tol);
                }
            }
        }
    }
    (grid, bad)
}

/// Outcome of the Pearson statistic over (observed, expected) categories.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pearson {
    pub statistic: f64,
    /// Categories used after pooling, minus one.
    pub dof: usize,
}

/// Pearson statistic with Nori's pooling: categories sorted by expected count; those below
/// `min_expected` are pooled; while the pool is still below `min_expected` the next
/// larger category joins it. Categories with expected count 0 must have been removed (their
/// observed counts are the caller's failure criterion).
pub fn pearson(cells: &mut [(f64, f64)], min_expected: f64) -> Option<Pearson> {
    cells.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (mut pool_obs, mut pool_exp) = (0.0, 0.0);
    let (mut stat, mut used) = (0.0, 0usize);
    for &(obs, exp) in cells.iter() {
        if exp < min_expected || (pool_exp > 0.0 && pool_exp < min_expected) {
            pool_obs += obs;
            pool_exp += exp;
        } else {
            stat += (obs - exp) * (obs - exp) / exp;
            used += 1;
        }
    }
    if pool_exp > 0.0 {
        stat += (pool_obs - pool_exp) * (pool_obs - pool_exp) / pool_exp;
        used += 1;
    }
    (used >= 2).then_some(Pearson {
        statistic: stat,
        dof: used - 1,
    })
}

/// Upper tail of the chi-square distribution: the test's p-value.
pub fn chi2_sf(statistic: f64, dof: usize) -> f64 {
    ChiSquared::new(dof as f64)
        .expect("positive degrees of freedom")
        .sf(statistic)
}

/// The test's categories (observed, expected): every cell with expected samples, plus
/// "lost" when the sampler failed at all. An error where the sampler put samples (or
/// failures) where the pdf leaves no probability.
fn categories(result: &Chi2Result, cfg: &Chi2Config) -> Result<Vec<(f64, f64)>, String> {
    let (cols, rows) = (result.observed.cols, result.observed.rows);
    let (n, lost, pdf_integral) = (result.samples, result.lost, result.pdf_integral);
    let nf = n as f64;
    let zero = 1e-12 * nf;
    let tolerated = cfg.zero_tolerance * nf;
    let mut cells: Vec<(f64, f64)> = Vec::with_capacity(cols * rows + 1);
    for (i, (&obs, &exp)) in result
        .observed
        .data
        .iter()
        .zip(&result.expected.data)
        .enumerate()
    {
        if exp > zero {
            cells.push((obs, exp));
        } else if obs > tolerated {
            let (c, r) = (i % cols, i / cols);
            return Err(format!(
                    "{obs} samples in cell (col {c}, row {r}) where the pdf integrates to 0 \
                     (tolerance {tolerated:.1}): the sampler produces points its pdf says are impossible"
            ));
        }
    }
    if lost > 0 {
        let exp_lost = (nf * (1.0 - pdf_integral)).max(0.0);
        if exp_lost <= zero && lost as f64 > tolerated {
            return Err(format!(
                "sampler failed (returned None) {lost} times of {n}, but the pdf integrates \
                     to {pdf_integral:.6}, leaving no probability for failure"
            ));
        }
        if exp_lost > zero {
            cells.push((lost as f64, exp_lost));
        }
    }
    Ok(cells)
}

/// The sampler's histogram on a domain's grid.
struct Histogram {
    observed: Grid,
    lost: u64,
    outside: u64,
    first_outside: Option<String>,
}

fn histogram<D: Domain>(
    domain: &D,
    mut sampler: impl FnMut(&mut Rng) -> Option<D::Point>,
    cfg: &Chi2Config,
) -> Histogram {
    let (cols, rows) = domain.resolution();
    let mut h = Histogram {
        observed: Grid::new(cols, rows),
        lost: 0,
        outside: 0,
        first_outside: None,
    };
    let mut rng = Rng::new(cfg.seed, 0);
    for _ in 0..cfg.samples {
        match sampler(&mut rng).map(|p| domain.cell_of(p)) {
            None => h.lost += 1,
            Some(Ok((c, r))) => h.observed.data[r * cols + c] += 1.0,
            Some(Err(why)) => {
                h.outside += 1;
                h.first_outside.get_or_insert(why);
            }
        }
    }
    h
}

/// Runs the sampler `cfg.samples` times and tests its histogram against `pdf`.
pub fn chi2_test<D: Domain>(
    domain: &D,
    sampler: impl FnMut(&mut Rng) -> Option<D::Point>,
    pdf: impl Fn(D::Point) -> f64,
    cfg: &Chi2Config,
) -> Chi2Result {
    let h = histogram(domain, sampler, cfg);
    let (fractions, bad_pdf) =
        cell_integrals_seen(domain, &pdf, &cfg.integration, Some(&h.observed));
    judge(domain, h, &fractions, bad_pdf, cfg)
}

/// [`chi2_test`] against cell masses the caller worked out (exactly, from the geometry of
/// the density's support): `fractions` holds each cell's integral of the pdf.
pub fn chi2_test_given<D: Domain>(
    domain: &D,
    sampler: impl FnMut(&mut Rng) -> Option<D::Point>,
    fractions: &Grid,
    cfg: &Chi2Config,
) -> Chi2Result {
    let h = histogram(domain, sampler, cfg);
    assert_eq!(
        (fractions.cols, fractions.rows),
        domain.resolution(),
        "cell masses on another grid"
    );
    let bad = fractions.data.iter().filter(|x| !(**x >= 0.0)).count() as u64;
    judge(domain, h, fractions, bad, cfg)
}

fn judge<D: Domain>(
    domain: &D,
    h: Histogram,
    fractions: &Grid,
    bad_pdf: u64,
    cfg: &Chi2Config,
) -> Chi2Result {
    let n = cfg.samples;
    let nf = n as f64;
    let Histogram {
        observed,
        lost,
        outside,
        first_outside,
    } = h;
    let pdf_integral = fractions.sum();
    let expected = Grid {
        data: fractions.data.iter().map(|x| x.max(0.0) * nf).collect(),
        ..*fractions
    };

    let mut result = Chi2Result {
        domain: domain.name(),
        axes: domain.axes(),
        statistic: f64::NAN,
        dof: 0,
        p_value: 0.0,
        threshold: cfg.threshold,
        verdict: Verdict::Fail,
        reason: String::new(),
        observed,
        expected,
        samples: n,
        lost,
        outside,
        pdf_integral,
    };
    let fail = |mut r: Chi2Result, reason: String| {
        r.reason = reason;
        r
    };

    if let Some(why) = first_outside {
        return fail(
            result,
            format!(
                "{outside} of {n} samples outside the {} (first: {why})",
                domain.name()
            ),
        );
    }
    if bad_pdf > 0 {
        return fail(
            result,
            format!("pdf returned NaN or a negative value at {bad_pdf} integration nodes"),
        );
    }

    let mut cells = match categories(&result, cfg) {
        Ok(cells) => cells,
        Err(reason) => return fail(result, reason),
    };

    let Some(p) = pearson(&mut cells, cfg.min_expected) else {
        return fail(
            result,
            "fewer than two usable cells; raise the sample count".into(),
        );
    };
    result.statistic = p.statistic;
    result.dof = p.dof;
    result.p_value = chi2_sf(p.statistic, p.dof);
    let summary = format!(
        "chi2 = {:.2}, dof = {}, p = {:.4e} vs threshold {:.4e}; pdf integral {:.6}, lost {}",
        p.statistic, p.dof, result.p_value, cfg.threshold, pdf_integral, lost
    );
    if result.p_value >= cfg.threshold {
        result.verdict = Verdict::Pass;
        result.reason = summary;
    } else {
        result.reason = format!(
            "rejected: sample histogram does not match the pdf ({summary}); {}; {}",
            integral_or_shape(pdf_integral, n, lost),
            worst_cells(&result, cfg.min_expected)
        );
    }
    result
}

/// Which part failed: the pdf's integral against the share of samples that landed, or the
/// histogram's shape with the integral right.
fn integral_or_shape(pdf_integral: f64, n: u64, lost: u64) -> String {
    let landed = (n - lost.min(n)) as f64 / n.max(1) as f64;
    if (pdf_integral - landed).abs() > 0.01 * landed.max(1e-12) {
        format!(
            "the pdf integrates to {pdf_integral:.4} over the grid but {landed:.4} of the samples \
             landed: the integral failed (a wrong pdf, or mass the grid does not resolve)"
        )
    } else {
        "the pdf's integral matches the samples: the histogram's shape failed".to_string()
    }
}

/// The three cells that add most to the statistic, with their counts.
fn worst_cells(r: &Chi2Result, min_expected: f64) -> String {
    let cols = r.observed.cols;
    let mut cells: Vec<(usize, f64, f64, f64)> = r
        .observed
        .data
        .iter()
        .zip(&r.expected.data)
        .enumerate()
        .filter(|(_, (_, &e))| e >= min_expected)
        .map(|(i, (&o, &e))| (i, o, e, (o - e) * (o - e) / e))
        .collect();
    cells.sort_by(|a, b| b.3.total_cmp(&a.3));
    let list: Vec<String> = cells
        .iter()
        .take(3)
        .map(|&(i, o, e, c)| {
            format!(
                "(col {}, row {}) {o:.0} observed vs {e:.1} expected, {c:.1} of the statistic",
                i % cols,
                i / cols
            )
        })
        .collect();
    format!("worst cells: {}", list.join("; "))
}

#[cfg(test)]
#[path = "chi2_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "chi2_boundary_tests.rs"]
mod boundary_tests;

#[cfg(test)]
#[path = "chi2_rules_tests.rs"]
mod rules_tests;
