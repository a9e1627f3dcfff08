//! What a run tells its caller. With `--json`, one JSON object per event on stdout (run
//! started, reference ready, result row, unit done, report written, finished), and the
//! human-readable lines that would go to stdout go to stderr instead, so stdout parses line
//! by line. Without a terminal on stderr, progress is a plain line every few seconds instead
//! of a bar.

use super::results::Row;
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::{json, Value};
use std::io::{IsTerminal, Write};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

static JSON: AtomicBool = AtomicBool::new(false);

/// Turns JSON events on for the rest of the process (`--json`).
pub fn set_json(on: bool) {
    JSON.store(on, Ordering::Relaxed);
}

pub fn json() -> bool {
    JSON.load(Ordering::Relaxed)
}

/// Prints `{"event": event, ...fields}` as one line on stdout, if `--json`.
pub fn emit(event: &str, fields: Value) {
    if !json() {
        return;
    }
    let mut obj = serde_json::Map::new();
    obj.insert("event".into(), Value::String(event.into()));
    if let Value::Object(f) = fields {
        obj.extend(f);
    }
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "{}", Value::Object(obj));
    let _ = out.flush();
}

/// A result row as an event (non-finite numbers become null).
pub fn result(experiment: &str, row: &Row) {
    if json() {
        emit("result", json!({ "experiment": experiment, "row": row }));
    }
}

/// A line for the reader: stdout, or stderr under `--json`.
pub fn say(line: &str) {
    if json() {
        eprintln!("{line}");
    } else {
        println!("{line}");
    }
}

/// Writes `rows` as JSON lines (the same rows as results.csv; NaN as null).
pub fn write_jsonl(path: &Path, rows: &[Row]) -> Result<(), String> {
    let mut text = String::new();
    for r in rows {
        text.push_str(&serde_json::to_string(r).map_err(|e| e.to_string())?);
        text.push('\n');
    }
    crate::output::write_atomic(path, |tmp| {
        std::fs::write(tmp, &text).map_err(|e| format!("{}: {e}", path.display()))
    })
}

/// Progress of a sweep in camera samples (so the estimate of the time left is right when
/// runs differ in spp by 1000x): a bar on a terminal, else a line every `EVERY`.
pub struct Progress {
    bar: ProgressBar,
    name: String,
    runs: usize,
    done_runs: usize,
    total: u64,
    done: u64,
    start: Instant,
    last: Instant,
}

const EVERY: Duration = Duration::from_secs(5);

impl Progress {
    pub fn new(name: &str, total_samples: u64, runs: usize) -> Self {
        let bar = if std::io::stderr().is_terminal() && runs > 0 {
            let b = ProgressBar::new(total_samples);
            b.set_style(
                ProgressStyle::with_template(
                    "{spinner} {msg} [{bar:30}] {percent}%, {elapsed} (eta {eta})",
                )
                .expect("static template")
                .progress_chars("=> "),
            );
            b.set_message(format!("0/{runs} runs"));
            b
        } else {
            ProgressBar::hidden()
        };
        let now = Instant::now();
        Progress {
            bar,
            name: name.into(),
            runs,
            done_runs: 0,
            total: total_samples,
            done: 0,
            start: now,
            last: now,
        }
    }

    /// More work became known (equal-time runs get their spp late).
    pub fn add(&mut self, samples: u64) {
        self.total += samples;
        self.bar.inc_length(samples);
    }

    /// A run planned at `planned` samples rendered `actual` (an equal-time run re-timed).
    pub fn replan(&mut self, planned: u64, actual: u64) {
        self.total = self.total + actual - planned.min(self.total + actual);
        self.bar.set_length(self.total);
    }

    /// One run of `samples` camera samples finished.
    pub fn run_done(&mut self, samples: u64) {
        self.done += samples;
        self.done_runs += 1;
        self.bar.inc(samples);
        self.bar
            .set_message(format!("{}/{} runs", self.done_runs, self.runs));
        if self.bar.is_hidden() && (self.last.elapsed() >= EVERY || self.done_runs == self.runs) {
            self.last = Instant::now();
            eprintln!("{}", self.line());
        }
    }

    /// The plain progress line.
    fn line(&self) -> String {
        let t = self.start.elapsed().as_secs_f64();
        let f = self.done as f64 / self.total.max(1) as f64;
        let eta = if f > 0.0 { t * (1.0 - f) / f } else { f64::NAN };
        format!(
            "{}: {}/{} runs, {:.0} % of samples, {t:.0} s elapsed, about {eta:.0} s left",
            self.name,
            self.done_runs,
            self.runs,
            100.0 * f
        )
    }

    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_is_counted_in_samples_not_runs() {
        let mut p = Progress::new("x", 1000, 2);
        p.run_done(10);
        assert!(
            p.line().contains("1/2 runs, 1 % of samples"),
            "{}",
            p.line()
        );
        p.add(1000);
        p.run_done(990);
        assert!(
            p.line().contains("2/2 runs, 50 % of samples"),
            "{}",
            p.line()
        );
    }
}
