//! Checks of an experiment file beyond its syntax, each naming the file and the key at fault,
//! and the expansion of its `scene` or `[[case]]`s into runnable cases.

use super::cases::{merge_defines, Case, CaseReferenceSpec, CaseSpec, MIN_BATCHES};
use super::schema::ErrorMetric;
use super::schema::Experiment;
use crate::limits;
use std::collections::BTreeMap;
use std::path::Path;

/// The cases of a file: its `[[case]]`s, or its single `scene` as an unnamed case. A case's
/// own defines win over the file's (which `--quick` has already updated).
pub(crate) fn cases(exp: &Experiment, file: &Path) -> Result<Vec<Case>, String> {
    let dir = file.parent().unwrap_or(Path::new("."));
    let single;
    let specs: &[CaseSpec] = match (&exp.scene, exp.cases.is_empty()) {
        (Some(scene), true) => {
            single = [CaseSpec {
                name: String::new(),
                scene: scene.clone(),
                defines: BTreeMap::new(),
                reference: CaseReferenceSpec::default(),
                group: String::new(),
                about: String::new(),
                warning: None,
                blind: Vec::new(),
            }];
            &single
        }
        (None, false) => &exp.cases,
        (Some(_), false) => {
            return Err(format!(
                "{}: give either `scene` or [[case]] entries, not both",
                file.display()
            ))
        }
        (None, true) => {
            return Err(format!(
                "{}: missing `scene` (or [[case]] entries)",
                file.display()
            ))
        }
    };
    let v: Vec<Case> = specs
        .iter()
        .map(|c| Case {
            name: c.name.clone(),
            scene: dir.join(&c.scene),
            defines: merge_defines(&[&exp.defines, &c.defines]),
            integrator: exp.integrator,
            value: c.reference.value.or(exp.reference.value),
            closed_form: c.reference.closed_form.or(exp.reference.closed_form),
            group: c.group.clone(),
            about: c.about.clone(),
            warning: c.warning.clone(),
            blind: c.blind.clone(),
        })
        .collect();
    Ok(v)
}

/// The longest equal-time budget accepted: anything longer is a typo, not an experiment.
const MAX_EQUAL_TIME_SECONDS: f64 = 7.0 * 86400.0;

pub(crate) fn validate(exp: &Experiment, file: &Path) -> Result<(), String> {
    let fail = |m: String| Err(format!("{}: {m}", file.display()));
    if exp.spp.is_empty() || exp.spp.contains(&0) {
        return fail("`spp` needs at least one value, all positive".into());
    }
    if exp.seeds == 0 {
        return fail("`seeds` must be at least 1".into());
    }
    let spps = exp.spp.iter().map(|&s| ("spp", s));
    for (what, s) in spps.chain(exp.reference.spp.map(|s| ("reference.spp", s))) {
        if let Err(e) = limits::count(s as u64, what, limits::SPP) {
            return fail(e);
        }
    }
    if let Err(e) = limits::count(exp.seeds as u64, "seeds", limits::SEEDS) {
        return fail(e);
    }
    for (what, v) in [
        ("figures.equal_spp", exp.figures.equal_spp),
        ("figures.variance_spp", exp.figures.variance_spp),
    ] {
        if let Some(v) = v.filter(|v| !exp.spp.contains(v)) {
            return fail(format!(
                "{what} = {v} is not one of the sweep's spp {:?}",
                exp.spp
            ));
        }
    }
    if exp.strategies.is_empty() {
        return fail("at least one [[strategy]] is needed".into());
    }
    if exp.reference.spp.is_some_and(|s| s < 2) {
        return fail("reference.spp must be at least 2 (its noise is measured from it)".into());
    }
    if exp.reference.spp.is_some() && exp.reference.seed < exp.seeds as u64 {
        return fail(format!(
            "reference.seed {} is one of the sweep's seeds 0..{}; the reference must be independent",
            exp.reference.seed, exp.seeds
        ));
    }
    // A closed-form reference may be 0, where relMSE then falls back to the MSE.
    let eps = exp.metrics.relmse_epsilon;
    if !(eps > 0.0 && eps.is_finite() || (eps == 0.0 && exp.probe.is_some())) {
        return fail(format!(
            "metrics.relmse_epsilon = {eps}: expected a finite positive number (0 is allowed in \
             probe mode); an infinite one makes every relMSE 0"
        ));
    }
    let m = &exp.metrics;
    if !matches!(m.primary, ErrorMetric::Mse | ErrorMetric::Relmse) {
        return fail(format!(
            "metrics.primary = \"{}\": expected \"mse\" or \"relmse\" (the errors corrected for the \
             reference's noise); list \"{0}\" in metrics.report to have it reported beside them",
            m.primary.slug()
        ));
    }
    if !(m.mape_epsilon > 0.0 && m.mape_epsilon.is_finite()) {
        return fail(format!(
            "metrics.mape_epsilon = {}: expected a positive number",
            m.mape_epsilon
        ));
    }
    if let Some(x) = m
        .report
        .iter()
        .find(|x| matches!(x, ErrorMetric::Mse | ErrorMetric::Relmse))
    {
        return fail(format!(
            "metrics.report lists \"{}\", which is always reported; list only {}",
            x.slug(),
            ErrorMetric::extra()
                .iter()
                .map(|e| format!("\"{}\"", e.slug()))
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    if let Some((i, x)) = m
        .report
        .iter()
        .enumerate()
        .find(|(i, x)| m.report[..*i].contains(x))
    {
        return fail(format!(
            "metrics.report lists \"{}\" twice (entries {} and {})",
            x.slug(),
            m.report.iter().position(|y| y == x).expect("found") + 1,
            i + 1
        ));
    }
    let mut names: Vec<&str> = exp.strategies.iter().map(|s| s.name.as_str()).collect();
    names.sort();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        return fail(format!("strategy name '{}' is used twice", w[0]));
    }
    if exp.samplers.is_empty() {
        return fail(
            "samplers = []: at least one sampler is needed (the default is [\"independent\"])"
                .into(),
        );
    }
    let mut samplers = exp.samplers.clone();
    samplers.sort_by_key(|s| s.to_string());
    if let Some(w) = samplers.windows(2).find(|w| w[0] == w[1]) {
        return fail(format!("sampler '{}' is listed twice", w[0]));
    }
    if let Some(et) = &exp.equal_time {
        if let Some(s) = et
            .seconds
            .iter()
            .find(|s| !(**s > 0.0 && **s <= MAX_EQUAL_TIME_SECONDS))
        {
            return fail(format!(
                "equal_time.seconds = {s}: expected a budget in (0, {MAX_EQUAL_TIME_SECONDS}] \
                 seconds (a week)"
            ));
        }
        if et.seeds == 0 {
            return fail("equal_time.seeds must be at least 1".into());
        }
    }
    if let Some(v) = exp
        .figures
        .exposure
        .filter(|v| !(v.is_finite() && *v > 0.0))
    {
        return fail(format!(
            "figures.exposure = {v}: expected a finite positive multiplier (1 shows radiance as \
             rendered)"
        ));
    }
    if let Some(v) = exp
        .figures
        .page_mb
        .filter(|v| !(v.is_finite() && *v >= 0.1))
    {
        return fail(format!(
            "figures.page_mb = {v}: expected the viewer's page budget in MB, at least 0.1"
        ));
    }
    if let Some(v) = exp
        .figures
        .progression
        .iter()
        .find(|v| !exp.spp.contains(v))
    {
        return fail(format!(
            "figures.progression: {v} is not one of the sweep's spp {:?}",
            exp.spp
        ));
    }
    for c in &exp.figures.crops {
        let ok = c.x >= 0.0
            && c.y >= 0.0
            && c.width > 0.0
            && c.height > 0.0
            && c.x + c.width <= 1.0
            && c.y + c.height <= 1.0;
        if !ok {
            return fail(format!(
                "crop '{}' must lie inside the image (fractions in [0, 1])",
                c.name
            ));
        }
    }
    Ok(())
}

/// Checks that depend on the mode: an image sweep has one scene and a rendered or constant
/// reference; probe mode has named cases with closed-form values, and its own keys.
pub(crate) fn validate_cases(exp: &Experiment, cases: &[Case], file: &Path) -> Result<(), String> {
    let fail = |m: String| Err(format!("{}: {m}", file.display()));
    let r = &exp.reference;
    let Some(p) = &exp.probe else {
        if cases.len() > 1 {
            return fail(
                "several [[case]] entries need [probe]; an image sweep renders one scene per file"
                    .into(),
            );
        }
        let probe_only = [
            ("[[invalid]]", !exp.invalid.is_empty()),
            ("[accumulation]", exp.accumulation.is_some()),
            ("figures.panels", !exp.figures.panels.is_empty()),
            ("reference.closed_form", cases[0].closed_form.is_some()),
        ];
        if let Some((key, _)) = probe_only.iter().find(|(_, set)| *set) {
            return fail(format!("{key} is only used in probe mode ([probe])"));
        }
        return match (r.spp, cases[0].value) {
            (Some(_), Some(_)) => fail(
                "give reference.spp (a rendered reference) or reference.value (a constant), not both"
                    .into(),
            ),
            (None, None) => fail("[reference] needs spp (rendered) or value (a constant)".into()),
            (_, Some(v)) if !v.is_finite() => fail(format!("reference.value {v} is not finite")),
            _ => Ok(()),
        };
    };
    if r.spp.is_some() {
        return fail("reference.spp: probe mode measures against closed-form values only".into());
    }
    // A probe's batches are consecutive samples of one pixel: with a sequence sampler they
    // are not independent randomisations, so its batch statistics would not hold.
    if let Some(s) = exp
        .samplers
        .iter()
        .find(|s| s.kind != crate::sampler::SamplerKind::Independent)
    {
        return fail(format!(
            "samplers: probe mode draws its batches from one pixel's stream and takes the \
             independent sampler only ('{s}' listed); compare samplers in an image sweep"
        ));
    }
    let image_only = [
        ("[equal_time]", exp.equal_time.is_some()),
        ("figures.equal_spp", exp.figures.equal_spp.is_some()),
        ("figures.variance_spp", exp.figures.variance_spp.is_some()),
        ("figures.progression", !exp.figures.progression.is_empty()),
        ("figures.crops", !exp.figures.crops.is_empty()),
        ("figures.exposure", exp.figures.exposure.is_some()),
        ("figures.seed_images", exp.figures.seed_images),
        ("figures.page_mb", exp.figures.page_mb.is_some()),
    ];
    if let Some((key, _)) = image_only.iter().find(|(_, set)| *set) {
        return fail(format!("{key} needs images; probe mode draws none"));
    }
    let mut seen = std::collections::BTreeSet::new();
    for (i, c) in cases.iter().enumerate() {
        if c.name.is_empty() {
            return fail(format!("case[{i}].name: probe mode needs named [[case]]s"));
        }
        if !seen.insert(c.name.as_str()) {
            return fail(format!("case[{i}].name '{}' is used twice", c.name));
        }
        match c.value {
            None => {
                return fail(format!(
                "case '{}': reference.value is needed (probe mode measures against a closed form)",
                c.name
            ))
            }
            Some(v) if !v.is_finite() => {
                return fail(format!(
                    "case '{}': reference.value {v} is not finite",
                    c.name
                ))
            }
            _ => {}
        }
    }
    let max = *exp.spp.iter().max().expect("validated non-empty");
    if (p.samples / max) < MIN_BATCHES {
        return fail(format!(
            "probe.samples = {} leaves fewer than {MIN_BATCHES} batches at spp {max}",
            p.samples
        ));
    }
    if let Some(t) = p.table_spp.filter(|t| !exp.spp.contains(t)) {
        return fail(format!(
            "probe.table_spp = {t} is not one of the sweep's spp {:?}",
            exp.spp
        ));
    }
    if !(p.alpha > 0.0 && p.alpha < 1.0) {
        return fail(format!("probe.alpha = {} must lie in (0, 1)", p.alpha));
    }
    let is_case = |n: &str| cases.iter().any(|c| c.name == n);
    if let Some(n) = exp.figures.panels.iter().find(|n| !is_case(n)) {
        return fail(format!("figures.panels: no [[case]] is named '{n}'"));
    }
    if let Some(a) = &exp.accumulation {
        if !is_case(&a.case) {
            return fail(format!(
                "accumulation.case: no [[case]] is named '{}'",
                a.case
            ));
        }
        if let Some(n) = a
            .strategies
            .iter()
            .find(|n| !exp.strategies.iter().any(|s| &s.name == *n))
        {
            return fail(format!(
                "accumulation.strategies: no [[strategy]] is named '{n}'"
            ));
        }
        if a.spp < 2 {
            return fail("accumulation.spp must be at least 2".into());
        }
    }
    for (i, v) in exp.invalid.iter().enumerate() {
        if v.error.is_some() == v.warning.is_some() {
            return fail(format!(
                "invalid[{i}] ({}): give exactly one of `error` and `warning`",
                v.scene.display()
            ));
        }
    }
    Ok(())
}
