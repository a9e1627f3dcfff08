//! One check of a program's sampler on one target: the three phases of the protocol and the
//! statistics of directlab's own chi-square cases.
//!
//! 1. **sample**: rows of uniform numbers (drawn as the built-in cases draw them: f32 values
//!    of `Rng::new(seed, 0)`, so a program implementing a built-in warp gets its p-value)
//!    come back as point, claimed pdf, valid flag (0: sampling failed) and optional weights.
//! 2. **pdf**: at every valid sample (the claimed pdf must be pdf(point)), then at the nodes
//!    of the adaptive cell integration, one batch per refinement level
//!    ([`crate::stats::integrate_batched`]), so support edges are refined where they are.
//! 3. **eval** (BSDFs): f cos at the samples, so weight == f cos / pdf is checked sample by
//!    sample, and over the domain's cells, so the mean weight can be held against the
//!    albedo (white furnace: no more than 1, and all of it reached by the sampler).

use super::program::Program;
use crate::chi2cases::checks::{z_critical, WeightCheck};
use crate::chi2cases::protocol::{AnyDomain, Target};
use crate::chi2cases::tangent::Tangent;
use crate::chi2cases::{run_given, CaseConfig, Check, Outcome};
use crate::stats::integrate_batched::{
    boundary_pass_batched, integrate_rects_batched, integrate_rects_trapezoid, recheck_batched,
};
use crate::stats::Integration;
use crate::stats::{Domain, Grid, Welford};
use glam::{Vec2, Vec3};
use serde_json::{json, Value};
use std::cell::RefCell;

/// A point's coordinates as f64, in and out of the protocol.
pub trait Coords: Copy {
    const DIM: usize;
    fn read(v: &[f64]) -> Self;
    fn write(self, out: &mut Vec<f64>);
}

impl Coords for Vec2 {
    const DIM: usize = 2;
    fn read(v: &[f64]) -> Self {
        Vec2::new(v[0] as f32, v[1] as f32)
    }
    fn write(self, out: &mut Vec<f64>) {
        out.extend([self.x as f64, self.y as f64]);
    }
}

impl Coords for Vec3 {
    const DIM: usize = 3;
    fn read(v: &[f64]) -> Self {
        Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
    }
    fn write(self, out: &mut Vec<f64>) {
        out.extend([self.x as f64, self.y as f64, self.z as f64]);
    }
}

/// How one check talks to the program.
pub struct Session<'a> {
    pub program: &'a mut dyn Program,
    pub target: &'a Target,
    /// Sent with every request: the target's parameters and the user's `--param`s.
    pub params: Value,
    /// Uniform numbers per sample.
    pub dims: usize,
    /// Rows per request.
    pub batch: usize,
    /// The cell masses and the albedo, once integrated: they do not depend on the seed.
    pub integrals: Option<(Grid, f64)>,
    /// Integrate each cell by a fixed trapezoid of this many intervals a side, as Mitsuba's
    /// `ChiSquareTest` does with `ires` (to compare; adaptive when None).
    pub ires: Option<usize>,
}

/// Checks the program on `s.target`, named `name` in the outcome.
pub fn check(s: &mut Session, cfg: &CaseConfig, name: &str) -> Result<Outcome, String> {
    match s.target.domain(cfg) {
        AnyDomain::Square(d) => check_on(s, cfg, name, &d, |_| true, |_| 1.0),
        AnyDomain::Disk(d) => check_on(s, cfg, name, &d, |_| true, |_| 1.0),
        AnyDomain::Triangle(d) => check_on(s, cfg, name, &d, |_| true, |_| 1.0),
        AnyDomain::Sphere(d) => check_on(s, cfg, name, &d, |_| true, |_| 1.0),
        AnyDomain::Window(w) => check_on(
            s,
            cfg,
            name,
            &w,
            |p| w.locate(p).is_ok(),
            |p| plane_factor(&w, p),
        ),
    }
}

/// dω / (dx dy) in a tangent-plane window: cos³ of the angle to its axis.
fn plane_factor(w: &Tangent, d: Vec3) -> f64 {
    let c = d.as_dvec3().normalize().dot(w.axis());
    if c > 0.0 {
        c * c * c
    } else {
        0.0
    }
}

fn check_on<D>(
    s: &mut Session,
    cfg: &CaseConfig,
    name: &str,
    domain: &D,
    keep: impl Fn(D::Point) -> bool,
    measure: impl Fn(D::Point) -> f64,
) -> Result<Outcome, String>
where
    D: Domain,
    D::Point: Coords,
{
    let pdim = D::Point::DIM;
    let bsdf = matches!(s.target, Target::Bsdf { .. });
    // 1. Samples, from uniform numbers drawn here.
    let mut rng = crate::rng::Rng::new(cfg.seed, 0);
    let n_all = cfg.samples as usize;
    let mut points: Vec<Option<D::Point>> = Vec::with_capacity(n_all);
    let (mut claimed, mut weights) = (Vec::new(), Vec::new());
    // The valid points as the program sent them: its pdf is asked about these, not about
    // their f32 roundings (which may cross its support's edge).
    let mut exact = Vec::new();
    let mut wcols = 0;
    let (mut left, mut k) = (n_all, 0);
    while left > 0 {
        let n = left.min(s.batch);
        let u: Vec<f64> = (0..s.dims * n).map(|_| rng.next_f32() as f64).collect();
        let what = format!("sample phase, batch {k}");
        let allowed = [pdim + 2, pdim + 3, pdim + 5];
        let (v, cols) = request(s, "sample", &u, n, s.dims, &allowed, &what)?;
        wcols = cols - pdim - 2;
        for row in v.chunks_exact(cols) {
            let valid = row[pdim + 1] > 0.5;
            points.push(valid.then(|| D::Point::read(&row[..pdim])));
            if valid {
                exact.extend_from_slice(&row[..pdim]);
                claimed.push(row[pdim]);
                weights.push(max_channel(&row[pdim + 2..]));
            }
        }
        left -= n;
        k += 1;
    }
    // 2. The pdf at the samples themselves (and f cos there, for a BSDF).
    let valid: Vec<D::Point> = points.iter().flatten().copied().collect();
    let (ncol, nrow) = domain.resolution();
    let mut seen = Grid::new(ncol, nrow);
    for p in valid.iter().filter(|p| keep(**p)) {
        if let Ok((c, r)) = domain.cell_of(*p) {
            seen.data[r * ncol + c] += 1.0;
        }
    }
    let at_samples = query_rows(s, "pdf", &exact, pdim, &[1], "pdf phase at the samples")?;
    let (grid, albedo) = integrals(s, cfg, domain, &measure, bsdf, &seen)?;
    let mut checks = vec![claim_check(&claimed, &at_samples)];
    if bsdf {
        let what = "eval phase at the samples";
        let evals = query_rows(s, "eval", &exact, pdim, &[1, 3], what)?;
        let mut furnace = Welford::new();
        let mut wc = WeightCheck::default();
        for i in 0..valid.len() {
            if wcols > 0 {
                wc.record(weights[i], evals[i], claimed[i], at_samples[i]);
                furnace.push(weights[i]);
            } else {
                furnace.push(evals[i] / claimed[i]);
            }
        }
        for _ in valid.len()..n_all {
            furnace.push(0.0);
        }
        // Nothing sampled (lit from below a one-sided BSDF) has no weight to check.
        if wcols > 0 && !valid.is_empty() {
            checks.push(wc.check());
        }
        checks.extend(furnace_checks(&furnace, albedo, cfg.alpha));
    }
    // 3. The chi-square test against the cell masses.
    let queue = RefCell::new(points.into_iter());
    let mut o = run_given(
        name,
        domain,
        |_| queue.borrow_mut().next().flatten().filter(|p| keep(*p)),
        &grid,
        cfg,
    );
    o.checks.extend(checks);
    Ok(o)
}

fn max_channel(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::NEG_INFINITY, f64::max)
}

/// The claimed pdf of every valid sample equals the program's pdf() there.
fn claim_check(claimed: &[f64], at_samples: &[f64]) -> Check {
    let mismatch: Vec<(usize, f64, f64)> = claimed
        .iter()
        .zip(at_samples)
        .enumerate()
        .filter(|(_, (c, p))| (*c - *p).abs() > 1e-5 * c.abs().max(p.abs()).max(1e-300))
        .map(|(i, (c, p))| (i, *c, *p))
        .collect();
    Check {
        name: "claimed pdf",
        passed: mismatch.is_empty(),
        detail: match mismatch.first() {
            None => format!(
                "the pdf at all {} samples equals the pdf claimed with them",
                claimed.len()
            ),
            Some(&(i, c, p)) => format!(
                "{} of {} samples claim a pdf other than pdf(point): sample {i} claims {c:e}, \
                 pdf gives {p:e}",
                mismatch.len(),
                claimed.len()
            ),
        },
    }
}

/// Energy a white-furnace test is allowed beyond 1: the integration's own error.
const ALBEDO_TOL: f64 = 1e-3;

/// The mean weight estimates the part of the albedo the sampler reaches; it must be all of
/// it (a z-test at `alpha`), and the albedo no more than 1.
fn furnace_checks(w: &Welford, albedo: f64, alpha: f64) -> [Check; 2] {
    let (mean, se) = (w.mean(), w.std_error());
    let bound = z_critical(alpha) * se + ALBEDO_TOL * albedo.max(mean);
    [
        Check {
            name: "furnace",
            passed: (mean - albedo).abs() <= bound,
            detail: format!(
                "mean weight {mean:.5} (standard error {se:.1e}) against the albedo \
                 {albedo:.5} integrated from eval (allowed difference {bound:.1e})"
            ),
        },
        Check {
            name: "energy",
            passed: albedo <= 1.0 + ALBEDO_TOL,
            detail: format!("albedo (integral of f cos) {albedo:.5}, at most 1"),
        },
    ]
}

/// The cell masses of the pdf and the albedo (when `bsdf`). Both are integrated once per
/// session (they do not depend on the seed); cells that this seed's samples (`seen`)
/// reached but whose mass is 0 are looked at again every time.
fn integrals<D>(
    s: &mut Session,
    cfg: &CaseConfig,
    domain: &D,
    measure: &impl Fn(D::Point) -> f64,
    bsdf: bool,
    seen: &Grid,
) -> Result<(Grid, f64), String>
where
    D: Domain,
    D::Point: Coords,
{
    let cells = Cells::of(domain);
    let fixed = s.ires;
    let integration = cfg.integration;
    let (mut grid, albedo) = match s.integrals.take() {
        Some(known) => known,
        None => {
            let albedo = match bsdf {
                true => nodes(s, domain, measure, "eval", &[1, 3], |f| {
                    cells.integrate(f, &integration, fixed)
                })?
                .sum(),
                false => f64::NAN,
            };
            let grid = nodes(s, domain, measure, "pdf", &[1], |f| {
                cells.integrate(f, &integration, fixed)
            })?;
            (grid, albedo)
        }
    };
    if fixed.is_none() {
        nodes(s, domain, measure, "pdf", &[1], |f| {
            recheck_batched(
                &mut grid,
                &|c, r| cells.rect(c, r),
                f,
                &integration,
                cells.tol,
                seen,
            )
        })?;
    }
    s.integrals = Some((grid.clone(), albedo));
    Ok((grid, albedo))
}

/// A domain's grid of cells in parameter space.
struct Cells {
    cols: usize,
    rows: usize,
    u0: f64,
    v0: f64,
    du: f64,
    dv: f64,
    /// Errors far below one sample in a million-sample run are irrelevant.
    tol: f64,
}

impl Cells {
    fn of<D: Domain>(domain: &D) -> Cells {
        let (cols, rows) = domain.resolution();
        let ([u0, u1], [v0, v1]) = domain.bounds();
        Cells {
            cols,
            rows,
            u0,
            v0,
            du: (u1 - u0) / cols as f64,
            dv: (v1 - v0) / rows as f64,
            tol: 1e-9 / (cols * rows) as f64,
        }
    }

    fn rect(&self, c: usize, r: usize) -> ([f64; 2], [f64; 2]) {
        let (i, j) = (c as f64, r as f64);
        (
            [self.u0 + i * self.du, self.u0 + (i + 1.0) * self.du],
            [self.v0 + j * self.dv, self.v0 + (j + 1.0) * self.dv],
        )
    }

    /// Every cell's integral of `f`: adaptive with the boundary pass, or by a fixed trapezoid
    /// of `fixed` x `fixed` intervals (Mitsuba's `ires`).
    fn integrate(
        &self,
        f: &mut dyn FnMut(&[[f64; 2]]) -> Vec<f64>,
        cfg: &Integration,
        fixed: Option<usize>,
    ) -> Grid {
        let rects: Vec<_> = (0..self.rows * self.cols)
            .map(|k| self.rect(k % self.cols, k / self.cols))
            .collect();
        let data = match fixed {
            Some(n) => integrate_rects_trapezoid(&rects, f, n),
            None => integrate_rects_batched(&rects, f, cfg, self.tol),
        };
        let mut grid = Grid {
            cols: self.cols,
            rows: self.rows,
            data,
        };
        if fixed.is_none() {
            let rect = |c, r| self.rect(c, r);
            boundary_pass_batched(&mut grid, &rect, f, cfg, self.tol);
        }
        grid
    }
}

/// Runs `body` with the program's `phase` (times `measure` and the Jacobian, 0 outside the
/// domain) as a function of batches of parameter points; the first failed request ends the
/// queries and is the result.
fn nodes<D, R>(
    s: &mut Session,
    domain: &D,
    measure: &impl Fn(D::Point) -> f64,
    phase: &str,
    cols: &[usize],
    body: impl FnOnce(&mut dyn FnMut(&[[f64; 2]]) -> Vec<f64>) -> R,
) -> Result<R, String>
where
    D: Domain,
    D::Point: Coords,
{
    let mut failure = None;
    let mut level = 0;
    let jac = domain.jacobian();
    let out = body(&mut |uv: &[[f64; 2]]| {
        let pts: Vec<Option<D::Point>> = uv.iter().map(|p| domain.point(p[0], p[1])).collect();
        let send: Vec<D::Point> = pts.iter().flatten().copied().collect();
        let what = format!("{phase} phase, integration batch {level}");
        level += 1;
        let got = match failure {
            Some(_) => Ok(vec![0.0; send.len()]),
            None => query(s, phase, &send, cols, &what),
        };
        let got = got.unwrap_or_else(|e| {
            failure = Some(e);
            vec![0.0; send.len()]
        });
        let mut it = got.into_iter();
        pts.iter()
            .map(|p| p.map_or(0.0, |p| it.next().unwrap_or(0.0) * jac * measure(p)))
            .collect()
    });
    match failure {
        Some(e) => Err(e),
        None => Ok(out),
    }
}

/// The program's `phase` ("pdf" or "eval") at `points`, in batches; one value per point (the
/// channel maximum of a colour).
fn query<P: Coords>(
    s: &mut Session,
    phase: &str,
    points: &[P],
    cols: &[usize],
    what: &str,
) -> Result<Vec<f64>, String> {
    let mut rows = Vec::with_capacity(points.len() * P::DIM);
    for p in points {
        p.write(&mut rows);
    }
    query_rows(s, phase, &rows, P::DIM, cols, what)
}

/// [`query`] at points given as rows of `dim` f64.
fn query_rows(
    s: &mut Session,
    phase: &str,
    rows: &[f64],
    dim: usize,
    cols: &[usize],
    what: &str,
) -> Result<Vec<f64>, String> {
    let mut out = Vec::with_capacity(rows.len() / dim);
    for (k, chunk) in rows.chunks(s.batch.max(1) * dim).enumerate() {
        let what = format!("{what}, batch {k}");
        let (v, c) = request(s, phase, chunk, chunk.len() / dim, dim, cols, &what)?;
        out.extend(v.chunks_exact(c).map(max_channel));
    }
    Ok(out)
}

fn request(
    s: &mut Session,
    phase: &str,
    payload: &[f64],
    rows: usize,
    dim: usize,
    cols: &[usize],
    what: &str,
) -> Result<(Vec<f64>, usize), String> {
    let head = json!({
        "phase": phase,
        "domain": s.target.name(),
        "count": rows,
        "dim": dim,
        "point_dim": s.target.dim(),
        "params": s.params,
    });
    s.program.call(head, payload, rows, cols, what)
}
