//! Tests of experiment files: parsing, `--quick`, and the checks that name file and key.

use super::*;
use crate::experiment::resolve::{parse, resolve};

const EXAMPLE: &str = r#"
    title = "demo"
    scene = "../scenes/cbox/cbox.xml"
    defines = { res = "64" }
    spp = [1, 4, 16]
    seeds = 2
    [reference]
    spp = 256
    strategy = { strategy = "mis", heuristic = "balance" }
    [metrics]
    relmse_epsilon = 0.001
    [[strategy]]
    name = "light"
    strategy = "light"
    emitter_selection = "power"
    light_sampling = "solid-angle"
    [[strategy]]
    name = "one-sample"
    strategy = "mis-onesample"
    [equal_time]
    seconds = [0.5]
    [figures]
    crops = [{ name = "corner", x = 0.0, y = 0.0, width = 0.25, height = 0.25 }]
    [quick]
    defines = { res = "16" }
    spp = [1, 2]
    reference_spp = 8
"#;

fn file() -> PathBuf {
    PathBuf::from("experiments/demo.toml")
}

#[test]
fn parses_the_example_and_applies_quick() {
    let exp = parse(EXAMPLE, &file()).unwrap();
    assert_eq!(exp.strategies.len(), 2);
    assert!(matches!(
        exp.strategies[0].strategy,
        Some(StrategyKind::Light)
    ));
    assert!(matches!(
        exp.strategies[0].light_sampling,
        Some(LightSampling::SolidAngle)
    ));
    assert!(matches!(
        exp.strategies[1].strategy,
        Some(StrategyKind::MisOneSample)
    ));
    assert!(matches!(
        exp.reference.strategy.heuristic,
        Some(Heuristic::Balance)
    ));
    assert_eq!(exp.metrics.relmse_epsilon, 0.001);

    let full = resolve(exp.clone(), &file(), false).unwrap();
    assert_eq!(full.name, "demo");
    assert_eq!(
        full.scene(),
        Path::new("experiments/../scenes/cbox/cbox.xml")
    );
    assert_eq!(full.defines(), [("res".into(), "64".into())]);
    assert_eq!(full.equal_spp(), 4);
    assert_eq!(full.variance_spp(), 16);

    let quick = resolve(exp, &file(), true).unwrap();
    assert_eq!(quick.name, "demo-quick");
    assert_eq!(quick.exp.spp, vec![1, 2]);
    assert_eq!(quick.exp.reference.spp, Some(8));
    assert_eq!(quick.defines(), [("res".into(), "16".into())]);
}

#[test]
fn rejects_typos_and_bad_values() {
    let typo = EXAMPLE.replace("seeds = 2", "sedes = 2");
    assert!(parse(&typo, &file()).unwrap_err().contains("sedes"));
    let bad_name = EXAMPLE.replace("\"solid-angle\"", "\"solid_angle\"");
    assert!(parse(&bad_name, &file()).is_err());
    let zero = EXAMPLE.replace("spp = [1, 4, 16]", "spp = [0, 4]");
    let e = resolve(parse(&zero, &file()).unwrap(), &file(), false).unwrap_err();
    assert!(e.contains("spp"), "{e}");
    let shared_seed = EXAMPLE.replace("spp = 256", "spp = 256\nseed = 1");
    let e = resolve(parse(&shared_seed, &file()).unwrap(), &file(), false).unwrap_err();
    assert!(e.contains("independent"), "{e}");
    let off = EXAMPLE.replace("[figures]", "[figures]\nequal_spp = 8");
    let e = resolve(parse(&off, &file()).unwrap(), &file(), false).unwrap_err();
    assert!(e.contains("equal_spp = 8 is not one of"), "{e}");
    let crop = EXAMPLE.replace("width = 0.25", "width = 1.25");
    let e = resolve(parse(&crop, &file()).unwrap(), &file(), false).unwrap_err();
    assert!(e.contains("crop"), "{e}");
    // The samplers axis: names, duplicates, an empty list.
    let with = |list: &str| EXAMPLE.replace("seeds = 2", &format!("seeds = 2\nsamplers = {list}"));
    let ok = parse(&with(r#"["sobol", "stratified"]"#), &file()).unwrap();
    assert_eq!(ok.samplers.len(), 2);
    assert_eq!(
        parse(EXAMPLE, &file()).unwrap().samplers,
        [Default::default()]
    );
    let e = parse(&with(r#"["sobol", "halton"]"#), &file()).unwrap_err();
    assert!(e.contains("unknown sampler 'halton'"), "{e}");
    for (list, says) in [
        (
            r#"["sobol", "sobol:joint"]"#,
            "sampler 'sobol' is listed twice",
        ),
        ("[]", "at least one sampler"),
    ] {
        let e = resolve(parse(&with(list), &file()).unwrap(), &file(), false).unwrap_err();
        assert!(e.contains(says), "{list}: {e}");
    }
}

const PROBE: &str = r#"
    spp = [1, 2, 4]
    seeds = 1
    defines = { res = "1" }
    [probe]
    samples = 256
    [metrics]
    relmse_epsilon = 0
    [[strategy]]
    name = "light"
    strategy = "light"
    [[strategy]]
    name = "bsdf"
    strategy = "bsdf"
    [figures]
    panels = ["a"]
    [accumulation]
    case = "a"
    defines = { res = "2" }
    spp = 1000
    strategies = ["light"]
    [[invalid]]
    scene = "bad.xml"
    error = "not finite"
    [[case]]
    name = "a"
    scene = "../scenes/a.xml"
    reference = { value = 0.5, closed_form = "lambert" }
    blind = [{ strategy = "bsdf", why = "small light" }]
    [[case]]
    name = "b"
    scene = "../scenes/a.xml"
    defines = { res = "3", x = "0.5" }
    reference = { value = 0.25 }
    warning = "zero radiance"
    [quick]
    probe_samples = 128
    accumulation_spp = 10
"#;

fn probe(text: &str, quick: bool) -> Result<Resolved, String> {
    resolve(parse(text, &file())?, &file(), quick)
}

#[test]
fn probe_mode_cases_resolve_with_their_defines_references_and_quick_counts() {
    let full = probe(PROBE, false).unwrap();
    assert_eq!(full.cases.len(), 2);
    let (a, b) = (&full.cases[0], &full.cases[1]);
    assert_eq!(a.scene, Path::new("experiments/../scenes/a.xml"));
    assert_eq!(a.defines, [("res".into(), "1".into())]);
    assert_eq!(
        (a.value, a.closed_form),
        (Some(0.5), Some(ClosedForm::Lambert))
    );
    assert_eq!(a.reference_from(), "Lambert");
    assert_eq!(b.reference_from(), "given");
    // The case's own defines win over the file's.
    assert_eq!(
        b.defines,
        [("res".into(), "3".into()), ("x".into(), "0.5".into())]
    );
    assert_eq!(b.warning.as_deref(), Some("zero radiance"));
    assert_eq!(full.exp.probe.as_ref().unwrap().samples, 256);
    let quick = probe(PROBE, true).unwrap();
    assert_eq!(quick.name, "demo-quick");
    assert_eq!(quick.exp.probe.as_ref().unwrap().samples, 128);
    assert_eq!(quick.exp.accumulation.as_ref().unwrap().spp, 10);
}

#[test]
fn probe_mode_rejects_missing_references_and_image_keys_naming_the_key() {
    let err = |from: &str, to: &str| {
        let text = PROBE.replacen(from, to, 1);
        assert_ne!(text, PROBE, "the edit must apply: {from}");
        probe(&text, false).unwrap_err()
    };
    let e = err("reference = { value = 0.25 }", "");
    assert!(
        e.contains("experiments/demo.toml: case 'b': reference.value is needed"),
        "{e}"
    );
    let e = err(
        "reference = { value = 0.25 }",
        "refrence = { value = 0.25 }",
    );
    assert!(e.contains("refrence"), "unknown keys in a case: {e}");
    let e = err(
        "seeds = 1",
        "seeds = 1\n    samplers = [\"independent\", \"sobol\"]",
    );
    assert!(
        e.contains("probe mode") && e.contains("independent sampler only ('sobol' listed)"),
        "{e}"
    );
    let e = err("samples = 256", "samples = 100");
    assert!(
        e.contains("probe.samples = 100 leaves fewer than 32 batches"),
        "{e}"
    );
    let e = err("panels = [\"a\"]", "panels = [\"c\"]");
    assert!(
        e.contains("figures.panels: no [[case]] is named 'c'"),
        "{e}"
    );
    let e = err("strategies = [\"light\"]", "strategies = [\"mis\"]");
    assert!(e.contains("accumulation.strategies"), "{e}");
    let e = err("error = \"not finite\"", "");
    assert!(e.contains("invalid[0] (bad.xml): give exactly one"), "{e}");
    let e = err("[figures]", "[equal_time]\nseconds = [1.0]\n[figures]");
    assert!(e.contains("[equal_time] needs images"), "{e}");
    let e = err("[metrics]", "[reference]\nspp = 64\n[metrics]");
    assert!(e.contains("reference.spp: probe mode"), "{e}");
    let e = err("name = \"b\"", "name = \"a\"");
    assert!(e.contains("case[1].name 'a' is used twice"), "{e}");
    let e = err("seeds = 1", "seeds = 1\nscene = \"x.xml\"");
    assert!(e.contains("either `scene` or [[case]]"), "{e}");
}

#[test]
fn image_sweeps_take_one_scene_and_a_rendered_or_constant_reference() {
    let two = PROBE
        .replace("[probe]", "")
        .replace("samples = 256", "")
        .replace("relmse_epsilon = 0", "relmse_epsilon = 0.01");
    let e = probe(&two, false).unwrap_err();
    assert!(e.contains("several [[case]] entries need [probe]"), "{e}");
    let constant = EXAMPLE.replace("spp = 256", "value = 1.5");
    let r = resolve(parse(&constant, &file()).unwrap(), &file(), false).unwrap();
    assert_eq!(r.cases[0].value, Some(1.5));
    let both = EXAMPLE.replace("spp = 256", "spp = 256\nvalue = 1.5");
    let e = resolve(parse(&both, &file()).unwrap(), &file(), false).unwrap_err();
    assert!(e.contains("not both"), "{e}");
    let none = EXAMPLE.replace("spp = 256", "");
    let e = resolve(parse(&none, &file()).unwrap(), &file(), false).unwrap_err();
    assert!(e.contains("[reference] needs spp"), "{e}");
    let eps0 = EXAMPLE.replace("relmse_epsilon = 0.001", "relmse_epsilon = 0");
    let e = resolve(parse(&eps0, &file()).unwrap(), &file(), false).unwrap_err();
    assert!(
        e.contains("relmse_epsilon = 0: expected a finite positive"),
        "{e}"
    );
    let inf = EXAMPLE.replace("relmse_epsilon = 0.001", "relmse_epsilon = inf");
    let e = resolve(parse(&inf, &file()).unwrap(), &file(), false).unwrap_err();
    assert!(e.contains("relmse_epsilon = inf"), "{e}");
}

#[test]
fn metrics_report_defaults_to_every_extra_and_checks_its_choices() {
    let r = resolve(parse(EXAMPLE, &file()).unwrap(), &file(), false).unwrap();
    assert_eq!(r.exp.metrics.report, ErrorMetric::extra());
    assert_eq!(r.exp.metrics.mape_epsilon, 0.01);
    let some = EXAMPLE.replace(
        "relmse_epsilon = 0.001",
        "relmse_epsilon = 0.001\nreport = [\"ssim\", \"flip\"]\nmape_epsilon = 0.1",
    );
    let r = resolve(parse(&some, &file()).unwrap(), &file(), false).unwrap();
    assert_eq!(r.exp.metrics.report, [ErrorMetric::Ssim, ErrorMetric::Flip]);
    assert_eq!(r.exp.metrics.mape_epsilon, 0.1);
    let err = |from: &str, to: &str| {
        let text = EXAMPLE.replace(from, to);
        match parse(&text, &file()) {
            Ok(e) => resolve(e, &file(), false).unwrap_err(),
            Err(e) => e,
        }
    };
    let e = err("relmse_epsilon = 0.001", "primary = \"ssim\"");
    assert!(
        e.contains("metrics.primary = \"ssim\"") && e.contains("metrics.report"),
        "{e}"
    );
    let e = err("relmse_epsilon = 0.001", "report = [\"relmse\"]");
    assert!(e.contains("always reported"), "{e}");
    let e = err("relmse_epsilon = 0.001", "report = [\"psnr\"]");
    assert!(e.contains("psnr") && e.contains("trimmed-relmse"), "{e}");
    let e = err("relmse_epsilon = 0.001", "mape_epsilon = 0");
    assert!(e.contains("mape_epsilon = 0"), "{e}");
}
