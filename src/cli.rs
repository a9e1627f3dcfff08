//! Command-line interface.

use crate::choices::{named, StrategyArgs};
use crate::experiment::args::SweepArgs;
use crate::film;
use crate::integrator::Strategy;
use crate::named::Named;
use crate::render::{render, RenderSettings};
use clap::{Args, Parser, Subcommand};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

#[derive(Parser, Debug)]
#[command(
    name = "directlab",
    version,
    about = "Monte Carlo direct illumination and its convergence harness"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a Mitsuba 3, Mitsuba 0.6 or Nori XML scene to EXR (plus an sRGB PNG preview).
    Render(RenderArgs),
    /// Run experiments (sweeps against a cached reference) and write their reports.
    Run(RunArgs),
    /// Run the study's figures and this project's: fig1, fig2, fig3, fig4, fig4-veach, fig5,
    /// fig5-cbox, fig5-tiles and the integrands report.
    Reproduce(ReproduceArgs),
    /// Split an experiment into fixed units (reference chunks, sweep runs, equal-time runs)
    /// for `run --shard I/N`; writes <out>/<name>/plan.json.
    Plan(crate::pipeline::shard::PlanArgs),
    /// Combine the units of sharded runs, exactly and in plan order, into the reference,
    /// results.csv, figures and report a one-machine run writes.
    Merge(crate::pipeline::shard::MergeArgs),
    /// List the done, missing and damaged units of a sharded run and the shards to rerun.
    Status(crate::pipeline::shard::StatusArgs),
    /// Run experiments on a Slurm cluster (job arrays of shards, then a merge).
    Slurm(crate::slurm::SlurmArgs),
    /// Measure render throughput per strategy and thread count.
    Bench(crate::bench::BenchArgs),
    /// Chi-square tests of every sampling routine against its pdf (warps, BSDFs, emitters),
    /// with heat maps; exits non-zero if any case fails.
    Chi2(crate::chi2cases::command::Chi2Args),
    /// Check a sampler written in any language: its program, run after `--`, answers sample
    /// and pdf requests (helpers/python/directlab_sampler.py, helpers/cpp/directlab_sampler.hpp);
    /// exits non-zero if it fails.
    #[command(after_long_help = crate::checksampler::HELP)]
    CheckSampler(crate::checksampler::CheckSamplerArgs),
    /// Welch's t-test between two noisy renders (directories of seeds' EXRs, or EXRs with
    /// variances): a p-value map and a verdict, with no reference; exits non-zero on a bias.
    Compare(crate::compare::CompareArgs),
    /// Run Nori test files (`<test type="ttest">`, `<test type="chi2test">`): scenes against
    /// references per strategy, BSDF albedos, BSDF chi-square; exits non-zero on a failure.
    Test(crate::noritest::TestArgs),
    /// The 2D test integrands of Christensen, Kensler and Kilpatrick 2018 integrated by
    /// every sampler's first 2D pair: RMSE against N, slopes against the published rates.
    Integrands(crate::integrands::report::IntegrandsArgs),
    /// The stability suite of extreme scenes (finiteness, bias and variance per strategy):
    /// short for `run experiments/extreme.toml`.
    Extreme(ExtremeArgs),
    /// Print the grammar of strategy labels (`mis-power-e1b1-pow-sa`, results.csv's `strategy`
    /// column): every estimator's form and the short names of its settings.
    Labels,
}

#[derive(Args, Debug)]
pub struct RunArgs {
    /// Experiment files (TOML).
    #[arg(required_unless_present = "all")]
    pub experiments: Vec<PathBuf>,
    /// Run every experiments/*.toml.
    #[arg(long, conflicts_with = "experiments")]
    pub all: bool,
    #[command(flatten)]
    pub sweep: SweepArgs,
    #[command(flatten)]
    pub shard: crate::pipeline::shard::ShardArgs,
}

#[derive(Args, Debug)]
pub struct ExtremeArgs {
    #[command(flatten)]
    pub sweep: SweepArgs,
}

#[derive(Args, Debug)]
pub struct ReproduceArgs {
    #[command(flatten)]
    pub sweep: SweepArgs,
}

fn run_files(files: &[PathBuf], a: &SweepArgs) -> Result<(), String> {
    use crate::experiment::events;
    use crate::pipeline::run_and_report;
    let opts = crate::experiment::args::options(a);
    let start = std::time::Instant::now();
    let mut failed = Vec::new();
    for f in files {
        // One failing experiment should not cost the others their results.
        if let Err(e) = run_and_report(f, a.quick, &opts) {
            // Errors about the file itself name it already.
            let shown = f.display().to_string();
            if e.starts_with(&shown) {
                eprintln!("error: {e}");
            } else {
                eprintln!("error: {shown}: {e}");
            }
            events::emit(
                "experiment_failed",
                serde_json::json!({ "file": f, "error": e }),
            );
            failed.push(f.display().to_string());
        }
    }
    // With nothing written, no index: it would be empty, and the run ends with the failure.
    let wrote = failed.len() < files.len();
    if wrote {
        crate::report::write_root_index(&a.out)?;
    }
    events::emit(
        "finished",
        serde_json::json!({
            "experiments": files.len(),
            "failed": failed,
            "seconds": start.elapsed().as_secs_f64(),
            "index": wrote.then(|| a.out.join("index.md")),
        }),
    );
    if wrote {
        eprintln!(
            "{} experiment(s) in {:.1} s; reports in {}",
            files.len() - failed.len(),
            start.elapsed().as_secs_f64(),
            a.out.join("index.md").display()
        );
    }
    if failed.is_empty() {
        Ok(())
    } else {
        Err(format!("failed: {}", failed.join(", ")))
    }
}

fn cmd_run(a: &RunArgs) -> Result<(), String> {
    let files = if a.all {
        crate::experiment::all_experiments()?
    } else {
        a.experiments.clone()
    };
    match a.shard.shard {
        Some(s) => crate::pipeline::shard::cmd_run_shard(&files, &a.sweep, s, a.shard.stage),
        None => run_files(&files, &a.sweep),
    }
}

fn cmd_extreme(a: &ExtremeArgs) -> Result<(), String> {
    let file = crate::experiment::experiments_dir()?.join("extreme.toml");
    run_files(&[file], &a.sweep)
}

/// The experiments `reproduce` runs (experiments/<name>.toml), in order; the integrands report
/// follows them.
pub const REPRODUCE: &[&str] = &[
    "fig1",
    "fig2",
    "fig3",
    "fig4",
    "fig4-veach",
    "fig5",
    "fig5-cbox",
    "fig5-tiles",
];

/// What `reproduce` runs, in the words the README, `--help` and experiments/README.md use
/// (a test keeps the three equal to this list).
pub fn reproduce_statement() -> String {
    format!("{} and the integrands report", REPRODUCE.join(", "))
}

fn cmd_reproduce(a: &ReproduceArgs) -> Result<(), String> {
    let dir = crate::experiment::experiments_dir()?;
    let files: Vec<PathBuf> = REPRODUCE
        .iter()
        .map(|n| dir.join(format!("{n}.toml")))
        .collect();
    let integrands = crate::integrands::report::IntegrandsArgs {
        quick: a.sweep.quick,
        out: a.sweep.out.clone(),
        viewer: a.sweep.viewer,
        ..Default::default()
    };
    let ran = run_files(&files, &a.sweep);
    crate::integrands::report::run(&integrands)?;
    crate::report::write_root_index(&a.sweep.out)?;
    ran
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Scene file (XML).
    pub scene: PathBuf,
    /// Samples per pixel (default: the scene's sampler).
    #[arg(long, short = 's', value_parser = crate::limits::parse_spp)]
    pub spp: Option<u32>,
    /// Seed (default: the scene's sampler seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long, short = 't', value_parser = crate::render::parse_threads)]
    pub threads: Option<usize>,
    /// Sampler (default: the scene's <sampler type>, mapped to the nearest directlab one).
    #[arg(long, value_parser = named::<crate::sampler::SamplerKind>())]
    pub sampler: Option<crate::sampler::SamplerKind>,
    /// Dimension allocation: a light or BSDF sample's numbers as one joint point, or padded
    /// 1D/2D draws (only the Sobol' samplers draw jointly).
    #[arg(long, value_parser = named::<crate::sampler::DimAlloc>(), default_value_t)]
    pub dims: crate::sampler::DimAlloc,
    /// Output EXR (default: <scene name>.exr in the current directory); a PNG preview is
    /// written beside it.
    #[arg(long, short = 'o')]
    pub out: Option<PathBuf>,
    /// Also write the per-pixel variance of the estimate (sample variance / spp) as EXR.
    #[arg(long)]
    pub variance: Option<PathBuf>,
    /// Set a scene parameter declared with <default>: -D name=value (repeatable).
    #[arg(short = 'D', value_parser = crate::scene::loader::parse_define)]
    pub define: Vec<(String, String)>,
    /// Write render statistics as JSON.
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// `direct`: render the direct illumination of a scene whose integrator is a path tracer
    /// or Whitted's (refused without it); the image is the direct part only.
    #[arg(long, value_parser = named::<crate::scene::loader::IntegratorMode>())]
    pub integrator: Option<crate::scene::loader::IntegratorMode>,
    #[command(flatten)]
    pub strategy: StrategyArgs,
}

#[derive(serde::Serialize)]
struct RenderStats {
    scene: String,
    strategy: String,
    spp: u32,
    seed: u64,
    sampler: &'static str,
    dims: &'static str,
    threads: usize,
    width: u32,
    height: u32,
    seconds: f64,
    samples_per_second: f64,
    non_finite_samples: u64,
    mean_rgb: [f64; 3],
    /// The global-illumination integrator the scene names, when the image is its direct part.
    direct_part_of: Option<String>,
}

/// The files `render` writes, checked before the scene is even loaded: each can be written,
/// and no two are the same file (the PNG preview sits beside the EXR, so `--out x.png` would
/// have the preview overwrite the image).
fn render_outputs(a: &RenderArgs) -> Result<PathBuf, String> {
    let out = a.out.clone().unwrap_or_else(|| {
        let stem = a
            .scene
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        PathBuf::from(format!("{stem}.exr"))
    });
    let is_exr = out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if !is_exr {
        return Err(format!(
            "--out {}: expected a file name ending in .exr (the PNG preview is written beside \
             it, with .png)",
            out.display()
        ));
    }
    let png = out.with_extension("png");
    let mut outputs: Vec<(&str, &Path)> = vec![("--out", &out), ("the PNG preview", &png)];
    if let Some(v) = &a.variance {
        outputs.push(("--variance", v));
    }
    if let Some(s) = &a.stats {
        outputs.push(("--stats", s));
    }
    crate::output::check_distinct(&outputs)?;
    for (_, p) in &outputs {
        crate::output::check_writable(p)?;
    }
    Ok(out)
}

fn cmd_render(a: &RenderArgs) -> Result<(), String> {
    let out = render_outputs(a)?;
    let scene = crate::scene::open_with(&a.scene, &a.define, a.integrator)?;
    let strategy = a
        .strategy
        .overrides()
        .apply(Strategy::from_desc(&scene.desc.integrator))?;
    let settings = RenderSettings {
        spp: a.spp.unwrap_or(scene.desc.sampler.sample_count),
        seed: a.seed.unwrap_or(scene.desc.sampler.seed),
        first_sample: 0,
        threads: a.threads,
        progress: crate::progress::tiles(std::io::stderr().is_terminal()),
        sampling: crate::sampler::Sampling {
            kind: a.sampler.unwrap_or(scene.desc.sampler.kind),
            dims: a.dims,
            run_samples: None,
        },
    };
    settings.sampler_config((scene.camera.width, scene.camera.height))?;
    let result = render(&scene, strategy, &settings);
    let stats = RenderStats {
        scene: a.scene.display().to_string(),
        strategy: strategy.label(),
        spp: settings.spp,
        seed: settings.seed,
        sampler: settings.sampling.kind.name(),
        dims: settings.sampling.dims.name(),
        threads: settings.threads.unwrap_or_else(rayon::current_num_threads),
        width: result.mean.width,
        height: result.mean.height,
        seconds: result.seconds,
        samples_per_second: result.samples_per_second(),
        non_finite_samples: result.non_finite_samples,
        mean_rgb: result.mean.mean_rgb(),
        direct_part_of: scene.desc.integrator.direct_part_of.clone(),
    };
    // The image, its preview, variance and statistics replace the old ones as one set: a
    // disk that fills part-way leaves the old files, never a new EXR beside an old PNG.
    crate::output::as_one_set(|| {
        film::write_exr(&out, &result.mean)?;
        film::write_png(&out.with_extension("png"), &result.mean)?;
        if let Some(v) = &a.variance {
            film::write_exr(v, &result.variance)?;
        }
        if let Some(p) = &a.stats {
            let json = serde_json::to_string_pretty(&stats).map_err(|e| e.to_string())?;
            crate::output::write_atomic(p, |tmp| {
                std::fs::write(tmp, json).map_err(|e| format!("{}: {e}", p.display()))
            })?;
        }
        Ok(())
    })?;
    eprintln!(
        "{}: {}x{} at {} spp with {} in {:.2} s ({:.2} M samples/s) -> {}",
        a.scene.display(),
        stats.width,
        stats.height,
        stats.spp,
        stats.strategy,
        stats.seconds,
        stats.samples_per_second / 1e6,
        out.display()
    );
    if result.non_finite_samples > 0 {
        eprintln!(
            "warning: {} non-finite samples were replaced by 0",
            result.non_finite_samples
        );
    }
    Ok(())
}

/// Runs the CLI; returns the process exit code.
pub fn main() -> i32 {
    let cli = Cli::parse();
    let r = match &cli.command {
        Command::Render(a) => cmd_render(a),
        Command::Run(a) => cmd_run(a),
        Command::Reproduce(a) => cmd_reproduce(a),
        Command::Integrands(a) => crate::integrands::report::run(a).map(|_| ()),
        Command::Bench(a) => crate::bench::run(a),
        Command::Chi2(a) => crate::chi2cases::command::run(a).and_then(|ok| {
            ok.then_some(())
                .ok_or_else(|| "some sampling routines do not match their pdfs".to_string())
        }),
        Command::CheckSampler(a) => crate::checksampler::command(a),
        Command::Compare(a) => crate::compare::command(a),
        Command::Extreme(a) => cmd_extreme(a),
        Command::Labels => {
            print!("{}", crate::labels::grammar());
            Ok(())
        }
        Command::Plan(a) => crate::pipeline::shard::cmd_plan(a),
        Command::Merge(a) => crate::pipeline::shard::cmd_merge(a),
        Command::Status(a) => crate::pipeline::shard::cmd_status(a),
        Command::Slurm(a) => crate::slurm::run(a),
        Command::Test(a) => crate::noritest::run(a).and_then(|ok| {
            ok.then_some(())
                .ok_or_else(|| "some tests failed (see the tables above)".to_string())
        }),
    };
    match r {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {e}");
            1
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Cli;
    use clap::CommandFactory;

    /// Every option and argument of every command says what it is for (`--help`), and no
    /// command takes an option it ignores.
    #[test]
    fn every_option_has_help_and_commands_take_only_what_they_use() {
        let cli = Cli::command();
        let mut missing = Vec::new();
        let mut todo: Vec<(String, &clap::Command)> = vec![("directlab".into(), &cli)];
        while let Some((path, c)) = todo.pop() {
            for a in c.get_arguments() {
                let id = a.get_id().as_str();
                if id == "help" || id == "version" {
                    continue;
                }
                if a.get_help().is_none() && a.get_long_help().is_none() {
                    missing.push(format!("{path} {id}"));
                }
            }
            for s in c.get_subcommands() {
                todo.push((format!("{path} {}", s.get_name()), s));
            }
        }
        assert!(missing.is_empty(), "options without help: {missing:?}");
        let takes = |cmd: &str, opt: &str| {
            let c = cli.find_subcommand(cmd).expect("command");
            c.get_arguments().any(|a| a.get_long() == Some(opt))
        };
        for (cmd, opt) in [
            ("status", "viewer"),
            ("status", "threads"),
            ("plan", "fresh-reference"),
            ("plan", "viewer"),
            ("merge", "threads"),
        ] {
            assert!(!takes(cmd, opt), "`{cmd} --{opt}` is accepted and ignored");
        }
        let slurm = cli.find_subcommand("slurm").unwrap();
        let submit = slurm.find_subcommand("submit").unwrap();
        assert!(!submit
            .get_arguments()
            .any(|a| a.get_long() == Some("threads")));
        for (cmd, short) in [
            ("render", 'o'),
            ("render", 't'),
            ("render", 's'),
            ("run", 'o'),
        ] {
            let c = cli.find_subcommand(cmd).unwrap();
            assert!(
                c.get_arguments().any(|a| a.get_short() == Some(short)),
                "{cmd} -{short}"
            );
        }
    }
}
