//! `results.csv`: one row per render, appended after every run (the file rewritten
//! atomically when a run replaces one) so an interrupted sweep resumes where it stopped. Rows carry a `context` hash (reference key + epsilon): rows
//! made against another scene, reference or epsilon are dropped on load, never mixed in.

use crate::counts::Counts;
use crate::output::write_atomic;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// What kind of run a row is: a point of the spp sweep, or an equal-time run whose spp was
/// derived from a time budget.
pub const SWEEP: &str = "spp";
pub const EQUAL_TIME: &str = "time";

#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Row {
    pub context: String,
    /// The `[[case]]` the row belongs to ("" for a file with one `scene`).
    #[serde(default)]
    pub case: String,
    /// Stable label (`Strategy::label`), the resume key; `name` is the legend name.
    pub strategy: String,
    pub name: String,
    pub kind: String,
    /// Time budget in seconds for equal-time rows, 0 for sweep rows.
    pub budget_s: f64,
    pub spp: u32,
    pub seed: u64,
    pub width: u32,
    pub height: u32,
    pub seconds: f64,
    pub samples_per_s: f64,
    pub mse: f64,
    /// MSE minus the reference's noise floor (its mean per-pixel variance); may be negative
    /// when the error is at the floor, which `near_floor` flags.
    pub mse_corrected: f64,
    pub relmse: f64,
    pub relmse_corrected: f64,
    pub relmse_eps: f64,
    /// MSE this run's own variance image predicts (mean variance of its pixel means); for an
    /// unbiased estimator E[mse_corrected] equals it. Zero at 1 spp (no variance estimate).
    pub mse_predicted: f64,
    /// The same for relMSE: mean of variance / (r^2 + eps). A measured relMSE far below it at
    /// low spp points to a heavy-tailed estimator (rare large samples not yet drawn).
    pub relmse_predicted: f64,
    /// Mean over pixels and channels of (x - r)^2 / (var_x + var_r): about 1 when run and
    /// reference have the same expectation (above 1 by (n-1)/(n-3) at small spp n, from the
    /// estimated variances). Well above 1 at high spp means a bias. NaN at 1 spp.
    pub mean_z2: f64,
    pub mean_r: f64,
    pub mean_g: f64,
    pub mean_b: f64,
    /// Variance of the image mean per channel, from the per-pixel variance image.
    pub mean_var_r: f64,
    pub mean_var_g: f64,
    pub mean_var_b: f64,
    pub non_finite: u64,
    /// Measured error within 2x of the reference's noise floor: not trustworthy.
    pub near_floor: bool,
    /// Probe mode only (empty otherwise), from the individual samples of the whole stream the
    /// row's batches were cut from: z of its mean against the closed form, ...
    #[serde(default)]
    pub z: Option<f64>,
    /// ... its largest sample, ...
    #[serde(default)]
    pub max_sample: Option<f64>,
    /// ... and the share of its squared error (x - r)^2 carried by its largest 0.1 %. Image
    /// rows: the share of the squared error against the reference held by the worst 0.1 % of
    /// pixels (empty in rows written before it was recorded).
    #[serde(default)]
    pub top_share: Option<f64>,
    /// The chosen metrics that do not apply to this run, each with the reason ("ssim: the
    /// film is smaller than SSIM's 11x11 window"); their values are empty, never NaN.
    #[serde(default)]
    pub not_applicable: String,
    /// The metrics `[metrics] report` chooses (empty when not chosen): relMSE without its
    /// largest 0.1 % of terms (epsilon `relmse_eps`), ...
    #[serde(default)]
    pub trimmed_relmse: Option<f64>,
    /// ... MAPE and SMAPE (epsilon `mape_eps`; SMAPE without a factor 2), ...
    #[serde(default)]
    pub mape: Option<f64>,
    #[serde(default)]
    pub smape: Option<f64>,
    #[serde(default)]
    pub mape_eps: Option<f64>,
    /// ... 1 - SSIM and mean FLIP of the images tone-mapped at `exposure` (clamped, sRGB).
    #[serde(default)]
    pub ssim_error: Option<f64>,
    #[serde(default)]
    pub flip: Option<f64>,
    #[serde(default)]
    pub exposure: Option<f64>,
    /// What the run did, per technique (`counts::Counts`, machine-independent): camera rays,
    /// light samples, shadow rays, BSDF samples, BSDF rays traced and ended at the
    /// light-bounds test, BSDF and light-density evaluations, emitters weighed by the
    /// emitter choice. Empty in probe rows and in rows written before they were recorded.
    #[serde(default)]
    pub camera_rays: Option<f64>,
    #[serde(default)]
    pub light_samples: Option<f64>,
    #[serde(default)]
    pub shadow_rays: Option<f64>,
    #[serde(default)]
    pub bsdf_samples: Option<f64>,
    #[serde(default)]
    pub bsdf_rays: Option<f64>,
    #[serde(default)]
    pub bsdf_rejected: Option<f64>,
    #[serde(default)]
    pub bsdf_evals: Option<f64>,
    #[serde(default)]
    pub light_pdf_evals: Option<f64>,
    #[serde(default)]
    pub choice_evals: Option<f64>,
}

impl Row {
    pub fn mean(&self) -> [f64; 3] {
        [self.mean_r, self.mean_g, self.mean_b]
    }

    pub fn mean_var(&self) -> [f64; 3] {
        [self.mean_var_r, self.mean_var_g, self.mean_var_b]
    }

    pub fn is_sweep(&self) -> bool {
        self.kind == SWEEP
    }

    /// The counts of the row's render; None when it has none (probe rows, older rows).
    pub fn counts(&self) -> Option<Counts> {
        let v = [
            self.camera_rays,
            self.light_samples,
            self.shadow_rays,
            self.bsdf_samples,
            self.bsdf_rays,
            self.bsdf_rejected,
            self.bsdf_evals,
            self.light_pdf_evals,
            self.choice_evals,
        ];
        let mut out = [0u64; 9];
        for (o, v) in out.iter_mut().zip(v) {
            *o = v? as u64;
        }
        Some(Counts::from_values(out))
    }

    /// Records the counts `c` of the row's render.
    pub fn set_counts(&mut self, c: &Counts) {
        self.set_counts_share(c, 1.0);
    }

    /// Records `share` of the counts `c` (a probe row's batch of k of a stream's n samples
    /// did k / n of what the stream did).
    pub fn set_counts_share(&mut self, c: &Counts, share: f64) {
        let [a, b, d, e, f, g, h, i, j] = c.values().map(|v| Some(v as f64 * share));
        (self.camera_rays, self.light_samples, self.shadow_rays) = (a, b, d);
        (self.bsdf_samples, self.bsdf_rays, self.bsdf_rejected) = (e, f, g);
        (self.bsdf_evals, self.light_pdf_evals, self.choice_evals) = (h, i, j);
    }
}

/// The rows of one experiment and where they are stored.
pub struct Results {
    pub rows: Vec<Row>,
    /// Rows of the file that belonged to another context and were dropped.
    pub dropped: usize,
}

impl Results {
    /// Reads `path` keeping the rows of `context`; a missing file is an empty table.
    pub fn load(path: &Path, context: &str) -> Result<Results, String> {
        Self::load_where(path, |r| r.context == context)
    }

    /// Reads `path` keeping the rows `keep` accepts.
    pub fn load_where(path: &Path, keep: impl Fn(&Row) -> bool) -> Result<Results, String> {
        if !path.exists() {
            return Ok(Results {
                rows: Vec::new(),
                dropped: 0,
            });
        }
        let mut rd =
            csv::Reader::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut rows = Vec::new();
        let mut dropped = 0;
        for r in rd.deserialize::<Row>() {
            match r {
                Ok(row) if keep(&row) => rows.push(row),
                // Old columns or another context: recompute rather than trust.
                _ => dropped += 1,
            }
        }
        Ok(Results { rows, dropped })
    }

    pub fn find_sweep(&self, strategy: &str, spp: u32, seed: u64) -> Option<&Row> {
        self.rows
            .iter()
            .find(|r| r.is_sweep() && r.strategy == strategy && r.spp == spp && r.seed == seed)
    }

    /// Equal-time rows are keyed by budget, not spp: the spp came from a timing measurement
    /// and would differ on the next run.
    pub fn find_equal_time(&self, strategy: &str, budget: f64, seed: u64) -> Option<&Row> {
        self.rows.iter().find(|r| {
            r.kind == EQUAL_TIME && r.strategy == strategy && r.budget_s == budget && r.seed == seed
        })
    }

    pub fn push_and_save(&mut self, row: Row, path: &Path) -> Result<(), String> {
        self.rows.push(row);
        self.save(path)
    }

    /// Adds `row` to the table and appends it to `path` as one line, which must hold exactly
    /// the table's other rows (as `save` wrote them): rewriting the whole file after each run
    /// makes a sweep's writing quadratic in its runs. A run killed while appending leaves a
    /// partial last line, which `load` drops like any unreadable row (it is rendered again).
    pub fn push_and_append(&mut self, row: Row, path: &Path) -> Result<(), String> {
        let empty = std::fs::metadata(path).map_or(true, |m| m.len() == 0);
        // A file written by a build whose rows had other columns is written again whole:
        // appended lines would not match its header.
        if empty || !header_matches(path, &row) {
            return self.push_and_save(row, path);
        }
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(path)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let mut w = csv::WriterBuilder::new()
            .has_headers(false)
            .from_writer(file);
        w.serialize(&row)
            .and_then(|()| w.flush().map_err(csv::Error::from))
            .map_err(|e| format!("{}: {e}", path.display()))?;
        self.rows.push(row);
        Ok(())
    }

    pub fn save(&self, path: &Path) -> Result<(), String> {
        write_atomic(path, |tmp| {
            let mut w = csv::Writer::from_path(tmp).map_err(|e| e.to_string())?;
            for r in &self.rows {
                w.serialize(r).map_err(|e| e.to_string())?;
            }
            w.flush().map_err(|e| e.to_string())
        })
    }
}

/// Whether the first line of `path` is the header `row`'s columns make.
fn header_matches(path: &Path, row: &Row) -> bool {
    use std::io::BufRead;
    let mut w = csv::Writer::from_writer(Vec::new());
    if w.serialize(row).is_err() {
        return false;
    }
    let Ok(bytes) = w.into_inner() else {
        return false;
    };
    let want = bytes.split(|&b| b == b'\n').next().unwrap_or_default();
    let Ok(f) = std::fs::File::open(path) else {
        return false;
    };
    let mut first = Vec::new();
    if std::io::BufReader::new(f)
        .read_until(b'\n', &mut first)
        .is_err()
    {
        return false;
    }
    first.strip_suffix(b"\n").unwrap_or(&first) == want
}

#[cfg(test)]
pub(crate) fn test_row(strategy: &str, spp: u32, seed: u64) -> Row {
    Row {
        context: "ctx".into(),
        case: String::new(),
        strategy: strategy.into(),
        name: strategy.into(),
        kind: SWEEP.into(),
        budget_s: 0.0,
        spp,
        seed,
        width: 4,
        height: 4,
        seconds: 0.5,
        samples_per_s: 1e6,
        mse: 1.0 / spp as f64,
        mse_corrected: 1.0 / spp as f64,
        relmse: 0.5 / spp as f64,
        relmse_corrected: 0.5 / spp as f64,
        relmse_eps: 0.01,
        mse_predicted: 0.0,
        relmse_predicted: 0.0,
        mean_z2: 1.0,
        mean_r: 0.1,
        mean_g: 0.2,
        mean_b: 0.3,
        mean_var_r: 1e-6,
        mean_var_g: 1e-6,
        mean_var_b: 1e-6,
        non_finite: 0,
        near_floor: false,
        z: None,
        max_sample: None,
        top_share: None,
        trimmed_relmse: None,
        mape: None,
        smape: None,
        mape_eps: None,
        ssim_error: None,
        flip: None,
        exposure: None,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_keeps_own_context_and_drops_others() {
        let dir = std::env::temp_dir().join(format!("directlab-res-{}", std::process::id()));
        let path = dir.join("results.csv");
        let mut res = Results::load(&path, "ctx").unwrap();
        assert!(res.rows.is_empty());
        res.push_and_save(test_row("light", 4, 0), &path).unwrap();
        let mut other = test_row("light", 8, 1);
        other.context = "old".into();
        res.push_and_save(other, &path).unwrap();
        let mut t = test_row("mis", 16, 0);
        t.kind = EQUAL_TIME.into();
        t.budget_s = 0.25;
        res.push_and_save(t.clone(), &path).unwrap();

        let back = Results::load(&path, "ctx").unwrap();
        assert_eq!(back.rows.len(), 2);
        assert_eq!(back.dropped, 1);
        assert_eq!(back.rows[0], test_row("light", 4, 0));
        assert!(back.find_sweep("light", 4, 0).is_some());
        assert!(back.find_sweep("light", 4, 1).is_none());
        assert!(
            back.find_sweep("mis", 16, 0).is_none(),
            "equal-time is not a sweep row"
        );
        assert_eq!(back.find_equal_time("mis", 0.25, 0), Some(&t));
        assert!(back.find_equal_time("mis", 0.5, 0).is_none());
        let header = std::fs::read_to_string(&path).unwrap();
        assert!(header.starts_with("context,case,strategy,name,kind,budget_s,spp,seed"));
        assert!(header.lines().next().unwrap().contains("relmse_eps"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Appended rows read back as saved ones; the first append to an empty file writes the
    /// header; a line cut short by a kill is dropped (and so rendered again), the rows
    /// before it kept.
    #[test]
    fn appended_rows_read_back_and_a_cut_last_line_is_dropped() {
        let dir = std::env::temp_dir().join(format!("directlab-app-{}", std::process::id()));
        let path = dir.join("results.csv");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(&path, "").unwrap();
        let mut res = Results::load(&path, "ctx").unwrap();
        let rows: Vec<Row> = (0..3).map(|s| test_row("light", 4, s)).collect();
        for r in &rows {
            res.push_and_append(r.clone(), &path).unwrap();
        }
        let back = Results::load(&path, "ctx").unwrap();
        assert_eq!((back.rows.clone(), back.dropped), (rows.clone(), 0));
        // The same as one save.
        let appended = std::fs::read_to_string(&path).unwrap();
        back.save(&path).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), appended);
        // A kill in the middle of the next append.
        let mut cut = appended.clone();
        let line = appended.lines().nth(1).unwrap();
        cut.push_str(&line[..line.len() / 2]);
        std::fs::write(&path, cut).unwrap();
        let back = Results::load(&path, "ctx").unwrap();
        assert_eq!((back.rows, back.dropped), (rows.clone(), 1));
        // A file from a build with fewer columns: the next row rewrites it whole, so every
        // line matches the header.
        back_to_old_header(&path, &rows);
        let mut res = Results::load(&path, "ctx").unwrap();
        res.push_and_append(test_row("light", 4, 9), &path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let columns = |l: &str| {
            csv::ReaderBuilder::new()
                .has_headers(false)
                .from_reader(l.as_bytes())
                .records()
                .next()
                .unwrap()
                .unwrap()
                .len()
        };
        let n = columns(text.lines().next().unwrap());
        assert!(text.lines().all(|l| columns(l) == n), "{text}");
        assert!(
            text.lines().next().unwrap().ends_with(",choice_evals"),
            "{text}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// `rows` as a build without the last column wrote them.
    fn back_to_old_header(path: &Path, rows: &[Row]) {
        Results {
            rows: rows.to_vec(),
            dropped: 0,
        }
        .save(path)
        .unwrap();
        let text = std::fs::read_to_string(path).unwrap();
        let old: String = text
            .lines()
            .map(|l| format!("{}\n", &l[..l.rfind(',').unwrap()]))
            .collect();
        std::fs::write(path, old).unwrap();
    }
}
