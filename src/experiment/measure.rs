//! One render's row: its errors against the reference (raw and corrected for the
//! reference's noise), the errors its own variance predicts, z^2, image mean and variance.

use super::cache::Reference;
use super::metric::{Eps, Inputs, MetricDef, EXTRA_METRICS};
use super::plan::Job;
use super::results::Row;
use super::schema::{ErrorMetric, Experiment};
use crate::metrics;
use crate::render::RenderOutput;

/// What a row measures beside MSE and relMSE.
#[derive(Clone, Debug)]
pub(crate) struct Extra {
    pub(crate) report: Vec<ErrorMetric>,
    pub(crate) mape_eps: f64,
    /// Tone mapping of SSIM and FLIP (the figures' exposure).
    pub(crate) exposure: f64,
}

impl Extra {
    pub(crate) fn of(exp: &Experiment) -> Extra {
        Extra {
            report: exp.metrics.report.clone(),
            mape_eps: exp.metrics.mape_epsilon,
            exposure: exp.figures.exposure.unwrap_or(1.0),
        }
    }

    /// Bytes that change when any of it does (part of the rows' context).
    pub(crate) fn key(&self) -> String {
        let names: Vec<&str> = self.report.iter().map(|m| m.slug()).collect();
        format!("{}|{}|{}", names.join(","), self.mape_eps, self.exposure)
    }

    /// The registered metrics the experiment reports.
    fn chosen(&self) -> impl Iterator<Item = &'static MetricDef> + '_ {
        EXTRA_METRICS
            .iter()
            .filter(|d| self.report.contains(&d.metric))
    }
}

pub(crate) fn measure(
    r: &Reference,
    eps: f64,
    extra: &Extra,
    context: &str,
    job: &Job,
    out: &RenderOutput,
) -> Row {
    let mse = metrics::mse(&out.mean, &r.mean);
    let relmse = metrics::rel_mse(&out.mean, &r.mean, eps);
    let n = out.mean.data.len() as f64;
    let mut var_sum = [0.0f64; 3];
    let mut rel_var = 0.0f64;
    let (mut z2, mut z2_n) = (0.0f64, 0u64);
    let level = r.mean.mean_rgb().iter().map(|v| v.abs()).sum::<f64>() / 3.0;
    for (((v, m), x), rv) in out
        .variance
        .data
        .iter()
        .zip(&r.mean.data)
        .zip(&out.mean.data)
        .zip(&r.variance.data)
    {
        for c in 0..3 {
            var_sum[c] += v[c];
            rel_var += v[c] / (m[c] * m[c] + eps);
            // Pixels where neither image varies (background, emitter interiors) carry no
            // information. The cached reference is stored in f32, so its rounding (relative
            // 6e-8) is part of the noise, and differences below 1e-9 of the image's level are
            // immaterial; without these floors near-exact pixels give z^2 = 1e40.
            let floor = 1e-7 * m[c].abs().max(x[c].abs()) + 1e-9 * level;
            let var = v[c] + rv[c] + floor * floor;
            if out.spp > 1 && v[c] + rv[c] > 0.0 {
                z2 += (x[c] - m[c]).powi(2) / var;
                z2_n += 1;
            }
        }
    }
    let mean = out.mean.mean_rgb();
    // Per pixel squared error: a few pixels holding most of it (a tiny bright light seen
    // directly) make the image mean's z-test unreliable at this spp (`report::means`).
    let pixel_err = out
        .mean
        .data
        .iter()
        .zip(&r.mean.data)
        .map(|(x, m)| (0..3).map(|c| (x[c] - m[c]).powi(2)).sum())
        .collect();
    let mut row = Row {
        context: context.to_string(),
        case: String::new(),
        strategy: job.method.label(),
        name: job.name.clone(),
        kind: job.kind.to_string(),
        budget_s: job.budget,
        spp: job.spp,
        seed: job.seed,
        width: out.mean.width,
        height: out.mean.height,
        seconds: out.seconds,
        samples_per_s: out.samples_per_second(),
        mse,
        mse_corrected: mse - r.info.mse_floor,
        relmse,
        relmse_corrected: relmse - r.info.relmse_floor,
        relmse_eps: eps,
        mse_predicted: var_sum.iter().sum::<f64>() / (3.0 * n),
        relmse_predicted: rel_var / (3.0 * n),
        mean_z2: if z2_n > 0 { z2 / z2_n as f64 } else { f64::NAN },
        mean_r: mean[0],
        mean_g: mean[1],
        mean_b: mean[2],
        mean_var_r: var_sum[0] / (n * n),
        mean_var_g: var_sum[1] / (n * n),
        mean_var_b: var_sum[2] / (n * n),
        non_finite: out.non_finite_samples,
        near_floor: mse < 2.0 * r.info.mse_floor || relmse < 2.0 * r.info.relmse_floor,
        z: None,
        max_sample: None,
        top_share: Some(crate::stats::top_share(pixel_err)),
        trimmed_relmse: None,
        mape: None,
        smape: None,
        ssim_error: None,
        flip: None,
        mape_eps: extra
            .chosen()
            .any(|d| d.eps == Eps::Mape)
            .then_some(extra.mape_eps),
        exposure: extra
            .chosen()
            .any(|d| d.tone_mapped)
            .then_some(extra.exposure),
        ..Default::default()
    };
    let inputs = Inputs {
        img: &out.mean,
        reference: &r.mean,
        relmse_eps: eps,
        mape_eps: extra.mape_eps,
        exposure: extra.exposure,
    };
    let mut not_applicable = Vec::new();
    for d in extra.chosen() {
        // A metric that does not apply to this film is an empty value with its reason, even
        // where it would compute a number (trimmed relMSE on a few pixels is relMSE).
        let why = (d.not_applicable)(out.mean.width, out.mean.height);
        let v = match why {
            Some(_) => None,
            None => (d.compute)(&inputs),
        };
        if v.is_none() {
            let why = why.unwrap_or("not defined for this image");
            not_applicable.push(format!("{}: {why}", d.slug));
        }
        (d.set)(&mut row, v);
    }
    row.not_applicable = not_applicable.join("; ");
    row.set_counts(&out.counts);
    row
}
