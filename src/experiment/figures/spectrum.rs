//! Error spectra per sampler ([`crate::stats::spectrum`]): for an experiment with a sampler
//! axis whose every seed's image at the comparison spp is kept (`figures.seed_images`), one
//! chart per strategy with a line per sampler, and `spectrum.csv`.

use super::Figure;
use crate::experiment::plan::{image_path, load_image, spp_tag};
use crate::experiment::runner::Outcome;
use crate::plot::{write_chart, Line, LogLogChart};
use crate::stats::spectrum::{error_spectrum, white_low_share, Spectrum, LOW};
use std::fmt::Write;

/// The spectrum of one kept strategy's seeds at `spp` (None: fewer than two seeds' images).
fn of_label(o: &Outcome, label: &str, spp: u32) -> Result<Option<Spectrum>, String> {
    let mut seeds = Vec::new();
    for seed in 0..o.exp.exp.seeds as u64 {
        let p = image_path(&o.dir, label, &spp_tag(spp), seed);
        if !crate::output::pending(&p).exists() && !p.exists() {
            continue;
        }
        let (img, _) = load_image(&p)?;
        seeds.push(
            img.data
                .iter()
                .map(|c| (c[0] + c[1] + c[2]) / 3.0)
                .collect(),
        );
    }
    if seeds.len() < 2 {
        return Ok(None);
    }
    let (w, h) = (o.width as usize, o.height as usize);
    Ok(Some(error_spectrum(&seeds, w, h)))
}

/// A strategy's label without the sampler, its legend name, and per sampler its spectrum.
type Group = (String, String, Vec<(String, Spectrum)>);

/// The charts and `spectrum.csv`; nothing without a sampler axis or kept seed images.
pub(super) fn spectra(o: &Outcome) -> Result<Vec<Figure>, String> {
    let x = &o.exp.exp;
    if x.samplers.len() < 2 || !x.figures.seed_images {
        return Ok(Vec::new());
    }
    let spp = o.exp.equal_spp();
    // Strategies in order, each with its samplers' spectra (labels `base~sampler`).
    let mut groups: Vec<Group> = Vec::new();
    for (label, name) in &o.strategies {
        let Some(s) = of_label(o, label, spp)? else {
            continue;
        };
        let (base, sampler) = label.split_once('~').unwrap_or((label, "independent"));
        // The legend name without the sampler (`MIS power, zsobol`).
        let short_name = name
            .rsplit_once(", ")
            .map_or(name.as_str(), |n| n.0)
            .to_string();
        match groups.iter_mut().find(|g| g.0 == base) {
            Some(g) => g.2.push((sampler.to_string(), s)),
            None => groups.push((base.to_string(), short_name, vec![(sampler.to_string(), s)])),
        }
    }
    let mut csv =
        String::from("strategy,sampler,seeds,mse,frequency,power_over_mse,ci95_low,ci95_high\n");
    let mut figs = Vec::new();
    for (base, name, lines) in &groups {
        let mut shares = String::new();
        for (sampler, s) in lines {
            let (lo, hi) = s.low_interval;
            let _ = write!(shares, "{sampler} {:.3} [{lo:.3}, {hi:.3}], ", s.low_share);
            for ((f, p), (lo, hi)) in s.freq.iter().zip(&s.power).zip(&s.interval) {
                let _ = writeln!(
                    csv,
                    "{base},{sampler},{},{:.6e},{f:.6},{p:.6e},{lo:.6e},{hi:.6e}",
                    s.seeds, s.mse
                );
            }
        }
        let file = format!("spectrum-{}", base.replace(['/', ' '], "_"));
        write_chart(
            &o.dir.join(&file),
            &LogLogChart {
                title: format!("Error spectrum: {name} at {spp} spp"),
                x_label: "frequency (cycles per pixel)".into(),
                y_label: "error power / MSE".into(),
                lines: lines
                    .iter()
                    .map(|(sampler, s)| Line {
                        label: sampler.clone(),
                        points: s.freq.iter().copied().zip(s.power.clone()).collect(),
                        spread: s.interval.clone(),
                        colour: None,
                    })
                    .collect(),
                hline: Some((1.0, "white noise".into())),
            },
        )?;
        figs.push(Figure {
            file: format!("{file}.png"),
            caption: format!(
                "Error spectrum of {name} per sampler at {spp} spp ([SVG]({file}.svg)): the \
                 radially averaged power spectrum of each seed's deviation from the seeds' \
                 mean, averaged over {} seeds and divided by the MSE, so the lines compare \
                 how the error is spread over frequencies at equal MSE (1: white; rising: blue \
                 noise, finer grain); bars are 95 % bootstrap intervals over the seeds. Share \
                 of the error energy below {LOW} cycles per pixel (white noise: {:.3}), with \
                 its interval: {}. Data: `spectrum.csv`.",
                lines.first().map_or(0, |l| l.1.seeds),
                white_low_share(o.width as usize, o.height as usize),
                shares.trim_end_matches(", ")
            ),
        });
    }
    let path = o.dir.join("spectrum.csv");
    crate::output::write_atomic(&path, |tmp| {
        std::fs::write(tmp, &csv).map_err(|e| format!("{}: {e}", path.display()))
    })?;
    Ok(figs)
}
