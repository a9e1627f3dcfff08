//! `directlab check-sampler`: a sampler written in any language, checked by the engine of
//! directlab's own chi-square cases. The user's program is a pure function of what it is
//! sent ([`pipe`]): directlab owns the random numbers, the binning, the integration and the
//! statistics.
//!
//! 1. **sample**: N pairs of uniform numbers go out in batches; each comes back as a point,
//!    the pdf the program claims for it, and a valid flag (0: sampling failed).
//! 2. **pdf**: the program's pdf at every valid sample must equal the pdf it claimed there;
//!    then at the nodes of the adaptive cell integration, one batch per refinement level
//!    ([`crate::stats::integrate_batched`]), so support edges are refined where they are.
//! 3. Pearson chi-square of the histogram against those cell masses, the pdf-integral check,
//!    and a heat map of the result.

pub mod pipe;

use crate::chi2cases::Check;
use crate::chi2cases::{run_given, CaseConfig, Outcome};
use crate::limits::Bound;
use crate::stats::integrate_batched::integrate_rects_batched;
use crate::stats::{Disk, Domain, Grid};
use glam::{Vec2, Vec3};
use pipe::Pipe;
use serde_json::json;
use std::cell::RefCell;
use std::path::PathBuf;
use std::time::Duration;

const RESOLUTION: Bound = Bound {
    max: 1024,
    why: "a 1024-row grid already has a million cells (two million on the sphere)",
};

const BATCH: Bound = Bound {
    max: 1 << 22,
    why: "a message of 4 million rows is 100 MB or more; smaller batches cost nothing",
};

/// The domain of the sampler's points.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum DomainKind {
    /// Points (x, y) of the unit square [0, 1)^2, density per unit area.
    Square,
    /// Points (x, y) of the unit disk, density per unit area.
    Disk,
    /// Unit directions (x, y, z), density per steradian (hemisphere samplers too).
    Sphere,
}

#[derive(clap::Args, Debug)]
pub struct CheckSamplerArgs {
    /// The domain of the points the program returns.
    #[arg(long, value_enum)]
    pub domain: DomainKind,
    /// Samples drawn.
    #[arg(long, default_value_t = 1_000_000, value_parser = crate::limits::parser("--samples", 100, crate::limits::TEST_SAMPLES))]
    pub samples: u64,
    /// Cells along the domain's v axis (the sphere gets 2R-1 rows of cos(theta), R of phi).
    #[arg(long, default_value_t = 51, value_parser = crate::limits::parser("--resolution", 3, RESOLUTION))]
    pub resolution: u64,
    /// Seed of the uniform numbers sent (a run is reproducible from it).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Rows per message to the program.
    #[arg(long, default_value_t = 65_536, value_parser = crate::limits::parser("--batch", 1, BATCH))]
    pub batch: u64,
    /// Seconds to wait for each reply before the program is killed.
    #[arg(long, default_value_t = 60.0)]
    pub timeout: f64,
    /// Significance level of the test.
    #[arg(long, default_value_t = 0.01)]
    pub alpha: f64,
    /// Where the heat map goes.
    #[arg(long, default_value = "reports/check-sampler")]
    pub out: PathBuf,
    /// The sampler program and its arguments, after `--` (e.g. `-- python3 my_sampler.py`).
    #[arg(last = true, required = true)]
    pub command: Vec<String>,
}

/// A point's coordinates as f64, in and out of the protocol.
trait Coords: Copy {
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

/// The command: runs the check and prints its verdict; an error when it fails.
pub fn command(a: &CheckSamplerArgs) -> Result<(), String> {
    let o = run(a)?;
    let verdict = |ok: bool| if ok { "pass" } else { "FAIL" };
    println!(
        "{}: {} ({}); heat map {}",
        o.name,
        verdict(o.passed()),
        o.summary(),
        a.out.join("heatmap.png").display()
    );
    for c in &o.checks {
        println!("  {}: {} ({})", c.name, verdict(c.passed), c.detail);
    }
    o.passed()
        .then_some(())
        .ok_or_else(|| "the sampler does not match its pdf".to_string())
}

/// Runs the check; Ok(outcome) whether it passed or not, Err when the program misbehaved.
pub fn run(a: &CheckSamplerArgs) -> Result<Outcome, String> {
    if !(a.timeout.is_finite() && a.timeout > 0.0) {
        return Err(format!(
            "--timeout {}: expected a positive number of seconds",
            a.timeout
        ));
    }
    if !(a.alpha > 0.0 && a.alpha < 1.0) {
        return Err(format!("--alpha {}: expected a level in (0, 1)", a.alpha));
    }
    let mut pipe = Pipe::start(&a.command, Duration::from_secs_f64(a.timeout))?;
    let cfg = CaseConfig {
        samples: a.samples,
        resolution: a.resolution as usize,
        seed: a.seed,
        alpha: a.alpha,
        ..CaseConfig::default()
    };
    let out = match a.domain {
        DomainKind::Square => check(&mut pipe, a, &cfg, &cfg.square(), "square"),
        DomainKind::Disk => {
            let r = cfg.resolution.max(3);
            check(&mut pipe, a, &cfg, &Disk { n_phi: r, n_r2: r }, "disk")
        }
        DomainKind::Sphere => check(&mut pipe, a, &cfg, &cfg.sphere(), "sphere"),
    }?;
    pipe.finish();
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    out.write_heatmap(&a.out.join("heatmap.png"))?;
    Ok(out)
}

fn check<D>(
    pipe: &mut Pipe,
    a: &CheckSamplerArgs,
    cfg: &CaseConfig,
    domain: &D,
    name: &str,
) -> Result<Outcome, String>
where
    D: Domain,
    D::Point: Coords,
{
    let pdim = D::Point::DIM;
    let batch = a.batch as usize;
    // 1. Samples, from uniform numbers drawn here.
    let mut rng = crate::rng::Rng::new(a.seed, 0);
    let mut points: Vec<Option<D::Point>> = Vec::with_capacity(a.samples as usize);
    let mut claimed = Vec::new();
    let mut left = a.samples as usize;
    let mut k = 0;
    while left > 0 {
        let n = left.min(batch);
        let u: Vec<f64> = (0..2 * n).map(|_| rng.next_f64()).collect();
        let head = json!({"phase": "sample", "domain": name, "count": n, "dim": 2});
        let what = format!("sample phase, batch {k}");
        let v = pipe.call(head, &u, n, pdim + 2, &what)?;
        for row in v.chunks_exact(pdim + 2) {
            let valid = row[pdim + 1] > 0.5;
            points.push(valid.then(|| D::Point::read(&row[..pdim])));
            if valid {
                claimed.push(row[pdim]);
            }
        }
        left -= n;
        k += 1;
    }
    // 2. The pdf at the samples themselves.
    let valid: Vec<D::Point> = points.iter().flatten().copied().collect();
    let at_samples = query(pipe, name, &valid, batch, "pdf phase at the samples")?;
    let mismatch = claimed
        .iter()
        .zip(&at_samples)
        .enumerate()
        .filter(|(_, (c, p))| (*c - *p).abs() > 1e-5 * c.abs().max(p.abs()).max(1e-300))
        .map(|(i, (c, p))| (i, *c, *p))
        .collect::<Vec<_>>();
    let claim = Check {
        name: "claimed pdf",
        passed: mismatch.is_empty(),
        detail: match mismatch.first() {
            None => format!(
                "the pdf at all {} samples equals the pdf claimed with them",
                valid.len()
            ),
            Some(&(i, c, p)) => format!(
                "{} of {} samples claim a pdf other than pdf(point): sample {i} claims {c:e}, \
                 pdf gives {p:e}",
                mismatch.len(),
                valid.len()
            ),
        },
    };
    // 3. Cell masses from the adaptive integration, one batch per level.
    let (cols, rows) = domain.resolution();
    let ([u0, u1], [v0, v1]) = domain.bounds();
    let (du, dv) = ((u1 - u0) / cols as f64, (v1 - v0) / rows as f64);
    let rects: Vec<([f64; 2], [f64; 2])> = (0..rows * cols)
        .map(|c| {
            let (i, j) = ((c % cols) as f64, (c / cols) as f64);
            (
                [u0 + i * du, u0 + (i + 1.0) * du],
                [v0 + j * dv, v0 + (j + 1.0) * dv],
            )
        })
        .collect();
    let mut failure = None;
    let mut level = 0;
    let jac = domain.jacobian();
    let masses = integrate_rects_batched(
        &rects,
        &mut |uv: &[[f64; 2]]| {
            let pts: Vec<Option<D::Point>> = uv.iter().map(|p| domain.point(p[0], p[1])).collect();
            let send: Vec<D::Point> = pts.iter().flatten().copied().collect();
            let what = format!("pdf phase, integration level {level}");
            level += 1;
            let got = match failure {
                Some(_) => Ok(vec![0.0; send.len()]),
                None => query(pipe, name, &send, batch, &what),
            };
            let got = got.unwrap_or_else(|e| {
                failure = Some(e);
                vec![0.0; send.len()]
            });
            let mut it = got.into_iter();
            pts.iter()
                .map(|p| p.map_or(0.0, |_| it.next().unwrap_or(0.0) * jac))
                .collect()
        },
        &cfg.integration,
        1e-9 / (rows * cols) as f64,
    );
    if let Some(e) = failure {
        return Err(e);
    }
    let grid = Grid {
        cols,
        rows,
        data: masses,
    };
    let queue = RefCell::new(points.into_iter());
    let mut o = run_given(
        &format!("check-sampler/{name}"),
        domain,
        |_| queue.borrow_mut().next().flatten(),
        &grid,
        cfg,
    );
    o.checks.push(claim);
    Ok(o)
}

/// The program's pdf at `points`, in batches.
fn query<P: Coords>(
    pipe: &mut Pipe,
    domain: &str,
    points: &[P],
    batch: usize,
    what: &str,
) -> Result<Vec<f64>, String> {
    let mut out = Vec::with_capacity(points.len());
    for (k, chunk) in points.chunks(batch.max(1)).enumerate() {
        let mut payload = Vec::with_capacity(chunk.len() * P::DIM);
        for p in chunk {
            p.write(&mut payload);
        }
        let head = json!({"phase": "pdf", "domain": domain, "count": chunk.len(), "dim": P::DIM});
        let v = pipe.call(
            head,
            &payload,
            chunk.len(),
            1,
            &format!("{what}, batch {k}"),
        )?;
        out.extend(v);
    }
    Ok(out)
}
