use super::*;
use crate::named::Named;

/// The closed forms against a midpoint rule on a 4000 x 4000 grid (edges cost it about
/// one cell row: 1e-3 is loose enough for them and tight for a wrong constant).
#[test]
fn exact_integrals_match_quadrature() {
    let m = 4000;
    for f in Integrand::ALL {
        let h = 1.0 / m as f64;
        let mut sum = 0.0;
        for j in 0..m {
            for i in 0..m {
                sum += f.eval((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
            }
        }
        let q = sum * h * h;
        let tol = if f.smooth() { 1e-7 } else { 1e-3 };
        assert!(
            (q - f.exact()).abs() < tol,
            "{}: {q} vs {}",
            f.name(),
            f.exact()
        );
    }
    let g = Integrand::Gaussian.exact();
    assert!((g - 0.557_746_285_351_033_5).abs() < 1e-15, "{g:.17}");
}

#[test]
fn counts_are_powers_of_two_and_off_grid() {
    assert_eq!(sample_counts(256), [16, 23, 32, 45, 64, 91, 128, 181, 256]);
    assert!(complete_count(SamplerKind::Stratified, 64));
    assert!(!complete_count(SamplerKind::Stratified, 32));
    assert!(complete_count(SamplerKind::Sobol, 32));
    assert!(!complete_count(SamplerKind::Sobol, 45));
}

/// Reduced size (64 seeds, N to 1024): every sampler is unbiased-looking in rate terms and
/// the structured ones beat N^-0.5 where theory says they must. The bounds are loose
/// compared with the published rates (the full run is `directlab integrands`), tight
/// enough that a sampler that lost its structure (a random point instead of its stratum)
/// fails.
#[test]
fn rates_at_reduced_size() {
    let counts = sample_counts(1024);
    let cells = measure(&SamplerKind::all(), &counts, 64).unwrap();
    let get = |k: SamplerKind, f: Integrand| {
        let i = Integrand::ALL.iter().position(|&g| g == f).unwrap();
        let mine: Vec<&Cell> = cells.iter().filter(|c| c.sampler == k).collect();
        slope(&mine, i, |n| complete_count(k, n)).unwrap()
    };
    for f in Integrand::ALL {
        let s = get(SamplerKind::Independent, f);
        let (a, b) = s.ci.unwrap();
        assert!(a < -0.5 && -0.5 < b, "independent {}: {s:?}", f.name());
        for k in [
            SamplerKind::Stratified,
            SamplerKind::Sobol,
            SamplerKind::ZSobol,
        ] {
            let s = get(k, f);
            assert!(s.slope < -0.65, "{} {}: {s:?}", k.name(), f.name());
        }
    }
    for k in [SamplerKind::Sobol, SamplerKind::ZSobol] {
        for f in [Integrand::Gaussian, Integrand::Bilinear] {
            let s = get(k, f);
            assert!(s.slope < -1.3, "{} {}: {s:?}", k.name(), f.name());
        }
        let s = get(k, Integrand::Step);
        assert!(s.slope < -0.9, "{} step: {s:?}", k.name());
    }
}
