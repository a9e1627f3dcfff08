//! Command-line interface.

use crate::experiment::args::SweepArgs;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

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
    Render(crate::render_cmd::RenderArgs),
    /// Run experiments (sweeps against a cached reference) and write their reports.
    Run(RunArgs),
    /// Run the study's figures and this project's: fig1, fig2, fig3, fig4, fig4-veach,
    /// fig4-blue, fig5, fig5-cbox, fig5-tiles and the integrands report.
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
    /// How small a bias `compare` finds: renders a configuration as two independent sides,
    /// puts known biases into one, and tables the detection rate per spp and bias.
    ComparePower(crate::compare::power::PowerArgs),
    /// The renderer's regression guard: every bundled scene against stored per-tile means
    /// by the two-run test (`--store` rewrites them).
    Guard(crate::compare::guard::GuardArgs),
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
    "fig4-blue",
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

/// Runs the CLI; returns the process exit code.
pub fn main() -> i32 {
    let cli = Cli::parse();
    if let Some(bug) = directlab_render::seeded::current() {
        // A test build (`seeded-bugs`) with DIRECTLAB_SEEDED_BUG set: never silently.
        eprintln!(
            "warning: seeded bug '{}' is active ({bug:?}): this run's images are wrong on purpose",
            directlab_render::seeded::tag()
        );
    }
    let r = match &cli.command {
        Command::Render(a) => crate::render_cmd::command(a),
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
        Command::ComparePower(a) => crate::compare::power::command(a),
        Command::Guard(a) => crate::compare::guard::command(a),
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
