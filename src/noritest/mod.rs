//! `directlab test FILE.xml`: Nori's test files run as they are, so that the files a course
//! gives (and the ones a user writes in its format) test directlab's estimators and BSDFs.
//!
//! - `ttest` with scenes: each scene's image (Nori's test scenes are 1x1) is averaged by
//!   luminance over `sampleCount` samples and compared with its reference by a one-sample
//!   Student t-test, once per strategy: the strategy the scene's integrator names (`direct`,
//!   `direct_mis`, ...), or every directlab strategy when it names a path tracer (whose
//!   direct part is what such test scenes hold) or with `--all-strategies`.
//! - `ttest` with BSDFs and angles: the albedo at each incidence angle by BSDF sampling.
//! - `chi2test` with BSDFs: chi-square of sampling against pdf at `testCount` incident
//!   directions per BSDF, through the same cases, tables and heat maps as `directlab chi2`.
//!
//! Significance as Nori: `significanceLevel` (0.01) for the whole file, Sidak-corrected over
//! its tests. The exit status is non-zero when a test fails.

pub mod parse;
pub mod ttest;

use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
pub struct TestArgs {
    /// Nori test files (`<test type="ttest">` or `<test type="chi2test">`).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Samples per test instead of the file's `sampleCount` (smoke runs).
    #[arg(long, value_parser = crate::limits::parser("--samples", 2, crate::limits::TEST_SAMPLES))]
    pub samples: Option<u64>,
    /// Test every directlab strategy on every scene, also where the scene names one.
    #[arg(long)]
    pub all_strategies: bool,
    /// Seed of the samplers and of the incident directions (a run is reproducible from it).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Where chi2test results (results.csv, heat maps) go: `<out>/<file stem>/`.
    #[arg(long, default_value = "reports/tests")]
    pub out: PathBuf,
    /// Set a parameter declared with <default>: -D name=value (repeatable).
    #[arg(short = 'D', value_parser = crate::scene::loader::parse_define)]
    pub define: Vec<(String, String)>,
}

/// Runs every file; Ok(true) when every test of every file passed.
pub fn run(a: &TestArgs) -> Result<bool, String> {
    // Files are read (and refused) before any test runs.
    let files = a
        .files
        .iter()
        .map(|f| parse::read(f, &a.define).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, _>>()?;
    let mut all = true;
    for f in &files {
        for w in &f.warnings {
            eprintln!("warning: {w}");
        }
        let ok = match f.kind {
            parse::Kind::TTest => ttest::run_file(f, a)?,
            parse::Kind::Chi2 => run_chi2(f, a)?,
        };
        println!(
            "{}: {}",
            f.path.display(),
            if ok { "passed" } else { "FAILED" }
        );
        all &= ok;
    }
    Ok(all)
}

/// A chi2test: every BSDF at `testCount` incident directions drawn from the cosine-weighted
/// hemisphere (as Nori's are), through `directlab chi2`'s cases. Nori's `resolution` counts
/// cos(theta) bins with twice as many in phi; directlab's sphere takes R phi columns and
/// 2R - 1 cos(theta) rows, so R = 2 x resolution gives at least Nori's bins.
fn run_chi2(f: &parse::TestFile, a: &TestArgs) -> Result<bool, String> {
    use crate::chi2cases::{bsdfs::run_bsdf, command::run_cases, Case, CaseConfig};
    use crate::rng::Rng;
    use crate::sampling::warps::square_to_cosine_hemisphere;
    let mut rng = Rng::new(a.seed, 0x6e6f7269);
    let mut cases = Vec::new();
    for b in &f.bsdfs {
        // A delta BSDF has no density: its chi-square has no degrees of freedom, and would
        // "pass" without testing anything.
        if b.value.kind.is_delta() {
            eprintln!(
                "warning: {}: {} is all-delta (no density to bin); left out of the chi2test",
                f.path.display(),
                b.label
            );
            continue;
        }
        for k in 0..f.test_count {
            let wi = square_to_cosine_hemisphere(rng.next_2d());
            let name = format!("line{}-{}/wi{k}", b.line, b.value.kind.type_name());
            let about = format!("{} sampled for wi = {wi}", b.label);
            let m = b.value.clone();
            let label = name.clone();
            cases.push(Case::new(name, about, move |cfg| {
                run_bsdf(&label, &m, m.kind.glossy_lobe(), wi, cfg)
            }));
        }
    }
    if cases.is_empty() {
        return Err(format!(
            "{}: no BSDF of this chi2test has a density to test (all are delta: mirror, \
             dielectric); it would pass with 0 degrees of freedom",
            f.path.display()
        ));
    }
    let r = 2 * f.resolution as usize;
    let samples = match (a.samples, f.samples) {
        (Some(n), _) => n,
        (None, Some(n)) => n,
        (None, None) => crate::limits::count(
            5000 * 2 * (f.resolution as u64).pow(2),
            &format!(
                "{}: the samples of each case (Nori's default of 5000 per bin at resolution {}; \
                 give sampleCount)",
                f.path.display(),
                f.resolution
            ),
            crate::limits::TEST_SAMPLES,
        )?,
    };
    let cfg = CaseConfig {
        samples,
        resolution: r,
        seed: a.seed,
        alpha: crate::stats::sidak(f.alpha, cases.len()),
        min_expected: f.min_expected,
        ..CaseConfig::default()
    };
    let stem = f.path.file_stem().unwrap_or_default().to_string_lossy();
    run_cases(
        &cases,
        &cfg,
        f.alpha,
        &a.out.join(stem.as_ref()),
        Default::default(),
    )
}
