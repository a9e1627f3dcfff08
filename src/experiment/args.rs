//! Options every command that runs experiments shares.

use super::RunOptions;
use clap::Args;
use std::path::PathBuf;

/// Options of the commands that run experiments (`run`, `reproduce`, `extreme`).
#[derive(Args, Debug, Clone)]
pub struct SweepArgs {
    /// Small resolution and spp from each file's [quick] table (tests, smoke runs); written
    /// to `<name>-quick`.
    #[arg(long)]
    pub quick: bool,
    /// Reports folder; each experiment writes into `<out>/<name>/`.
    #[arg(long, short = 'o', default_value = "reports")]
    pub out: PathBuf,
    /// Worker threads (default: all cores). Images do not depend on it; timings do.
    #[arg(long, short = 't', value_parser = crate::render::parse_threads)]
    pub threads: Option<usize>,
    /// Render the references again even if the cache has them (after upgrading a
    /// dependency; changes to the renderer's own source are detected).
    #[arg(long)]
    pub fresh_reference: bool,
    /// Print one JSON object per event on stdout (run started, reference, result row, unit
    /// done, report written, finished); the other output goes to stderr.
    #[arg(long)]
    pub json: bool,
    /// `none`: HTML reports without embedded images (no image viewer; figures linked beside
    /// the page), for small pages.
    #[arg(long, value_enum, default_value_t)]
    pub viewer: Viewer,
}

/// Options of the commands that only find experiments' outputs (`plan`, `status`, `slurm
/// submit`): no rendering or report options, which they would ignore.
#[derive(Args, Debug, Clone)]
pub struct SelectArgs {
    /// The experiments' quick form (each file's [quick] table), written to `<name>-quick`.
    #[arg(long)]
    pub quick: bool,
    /// Reports folder; each experiment writes into `<out>/<name>/`.
    #[arg(long, short = 'o', default_value = "reports")]
    pub out: PathBuf,
    /// Print one JSON object per event on stdout; the other output goes to stderr.
    #[arg(long)]
    pub json: bool,
}

impl SelectArgs {
    /// The full set, with every option these commands do not take at its default.
    pub fn sweep(&self) -> SweepArgs {
        SweepArgs {
            quick: self.quick,
            out: self.out.clone(),
            threads: None,
            fresh_reference: false,
            json: self.json,
            viewer: Viewer::default(),
        }
    }
}

/// Options of `merge`: the outputs to find and how the report's pages are written.
#[derive(Args, Debug, Clone)]
pub struct ReportArgs {
    #[command(flatten)]
    pub select: SelectArgs,
    /// `none`: HTML reports without embedded images (no image viewer; figures linked beside
    /// the page), for small pages.
    #[arg(long, value_enum, default_value_t)]
    pub viewer: Viewer,
}

impl ReportArgs {
    pub fn sweep(&self) -> SweepArgs {
        SweepArgs {
            viewer: self.viewer,
            ..self.select.sweep()
        }
    }
}

/// The runner's options from the command line's (and `--json` switched on for the
/// process).
pub fn options(a: &SweepArgs) -> RunOptions {
    super::events::set_json(a.json);
    RunOptions {
        out: a.out.clone(),
        threads: a.threads,
        fresh_reference: a.fresh_reference,
        viewer: a.viewer,
    }
}

/// What the HTML pages carry (`--viewer`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Viewer {
    /// The image viewer with embedded HDR images, plots inline, small figures embedded.
    #[default]
    Full,
    /// No embedded images: no image viewer, every figure linked beside the page.
    None,
}
