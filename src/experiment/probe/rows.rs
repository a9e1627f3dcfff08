//! From one stream of samples to its `results.csv` rows: one per sweep spp k, whose errors
//! are those of the stream's batch means of k samples.

use super::samples::Drawn;
use super::stats::{batch_mse, norm, Stream};
use crate::experiment::results::{Row, SWEEP};

/// Where a stream came from and what it is measured against.
pub(crate) struct StreamInfo<'a> {
    pub case: &'a str,
    pub context: &'a str,
    pub name: &'a str,
    pub label: String,
    pub seed: u64,
    pub reference: f64,
    pub eps: f64,
    pub seconds: f64,
}

pub(crate) fn rows(
    info: &StreamInfo,
    x: &[f64],
    drawn: &Drawn,
    st: &Stream,
    spp: &[u32],
) -> Vec<Row> {
    let n = x.len() as f64;
    let nrm = norm(info.reference, info.eps);
    // Channel 0 from the stored samples (exact two-pass variance); g and b from the sums.
    let mean = [st.mean, drawn.mean[1], drawn.mean[2]];
    let var = [st.variance, drawn.variance[1], drawn.variance[2]];
    spp.iter()
        .map(|&k| {
            let mse = batch_mse(x, k as usize, info.reference);
            let predicted = st.variance / k as f64;
            let mut row = Row {
                context: info.context.to_string(),
                case: info.case.to_string(),
                strategy: info.label.clone(),
                name: info.name.to_string(),
                kind: SWEEP.to_string(),
                budget_s: 0.0,
                spp: k,
                seed: info.seed,
                width: 1,
                height: 1,
                // The time k of the stream's samples took.
                seconds: info.seconds * k as f64 / n,
                samples_per_s: n / info.seconds.max(1e-9),
                mse,
                mse_corrected: mse,
                relmse: mse / nrm,
                relmse_corrected: mse / nrm,
                relmse_eps: info.eps,
                mse_predicted: predicted,
                relmse_predicted: predicted / nrm,
                mean_z2: if predicted > 0.0 {
                    mse / predicted
                } else {
                    f64::NAN
                },
                mean_r: mean[0],
                mean_g: mean[1],
                mean_b: mean[2],
                mean_var_r: var[0] / n,
                mean_var_g: var[1] / n,
                mean_var_b: var[2] / n,
                non_finite: st.non_finite,
                near_floor: false,
                z: Some(st.z),
                max_sample: Some(st.max_sample),
                top_share: Some(st.top_share),
                trimmed_relmse: None,
                mape: None,
                smape: None,
                mape_eps: None,
                ssim_error: None,
                flip: None,
                exposure: None,
                ..Default::default()
            };
            // The k samples of the row did k / n of what the stream did.
            row.set_counts_share(&drawn.counts, k as f64 / n);
            row
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::stats::stream;
    use super::*;

    #[test]
    fn rows_carry_batch_errors_and_stream_statistics() {
        // Alternating 0, 2: the mean is exactly 1; batches of even size are exact.
        let x: Vec<f64> = (0..64).map(|i| (i % 2) as f64 * 2.0).collect();
        let st = stream(&x, 0, 1.0);
        let info = StreamInfo {
            case: "c",
            context: "ctx",
            name: "light",
            label: "light-e1-uni-area".into(),
            seed: 0,
            reference: 1.0,
            eps: 0.0,
            seconds: 2.0,
        };
        // The stream of 64 samples cast 64 camera rays and 32 shadow rays.
        let drawn = Drawn {
            counts: crate::counts::Counts {
                camera_rays: 64,
                shadow_rays: 32,
                ..Default::default()
            },
            ..Drawn::default()
        };
        let r = rows(&info, &x, &drawn, &st, &[1, 2]);
        assert_eq!(r.len(), 2);
        assert_eq!((r[0].spp, r[1].spp), (1, 2));
        assert_eq!(r[0].mse, 1.0);
        assert_eq!(r[1].mse, 0.0);
        assert_eq!(r[0].relmse, 1.0, "eps 0 and r = 1: relative = absolute");
        assert_eq!(r[1].seconds, 2.0 * 2.0 / 64.0);
        assert_eq!(r[0].z, Some(0.0));
        assert_eq!(r[0].max_sample, Some(2.0));
        assert_eq!(r[0].case, "c");
        // Each row did its share of the stream's work: 2 of 64 samples, 2 camera rays.
        assert_eq!((r[1].camera_rays, r[1].shadow_rays), (Some(2.0), Some(1.0)));
        assert_eq!(r[0].counts().unwrap().camera_rays, 1);
    }
}
