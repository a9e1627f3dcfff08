use super::*;

#[test]
fn hand_computed_ratios_and_degenerate_inputs() {
    // mean(a) = 2, mean(b) = 2: ratio 1, an interval around it that does not rank them.
    let r = ratio_of_means(&[1.0, 2.0, 3.0], &[2.0, 2.0, 2.0], true, 1000).unwrap();
    assert_eq!(r.value, 1.0);
    assert!(
        r.lo > 0.0 && r.lo < 1.0 && r.hi > 1.0 && r.hi.is_finite(),
        "{r:?}"
    );
    assert!(!r.ranks());
    // The delta-method standard error of log(2 / 2) by hand: paired relative differences
    // a_i / 2 - b_i / 2 = -0.5, 0, 0.5, variance 0.25, over 3 pairs.
    let (theta, se) = log_ratio(
        &[1.0, 2.0, 3.0],
        &[2.0, 2.0, 2.0],
        true,
        &[0, 1, 2],
        &[0, 1, 2],
    );
    assert_eq!(theta, 0.0);
    assert!((se - (0.25f64 / 3.0).sqrt()).abs() < 1e-15);
    // Unpaired: var(a / 2) / 3 + var(b / 4) / 2 = 0.25 / 3 + 0.125 / 2.
    let (theta, se) = log_ratio(&[1.0, 2.0, 3.0], &[3.0, 5.0], false, &[0, 1, 2], &[0, 1]);
    assert!((theta - (0.5f64).ln()).abs() < 1e-15);
    assert!((se - (0.25f64 / 3.0 + 0.125 / 2.0).sqrt()).abs() < 1e-15);
    // No spread: the interval is the value itself.
    let c = ratio_of_means(&[2.0, 2.0], &[1.0, 1.0], true, 1000).unwrap();
    assert_eq!((c.value, c.lo, c.hi), (2.0, 2.0, 2.0));
    assert!(c.ranks());
    let inv = c.inverse();
    assert_eq!((inv.value, inv.lo, inv.hi), (0.5, 0.5, 0.5));
    assert_eq!(
        Ratio {
            value: 2.3149,
            lo: 1.8712,
            hi: 29.04,
            paired: true,
            seeds: (3, 3)
        }
        .show(),
        "2.31x [1.87, 29.0]"
    );
    // Two seeds: the value, without a bound.
    let two = ratio_of_means(&[1.0, 3.0], &[1.0, 1.5], true, 1000).unwrap();
    assert_eq!((two.value, two.lo, two.hi), (1.6, 0.0, f64::INFINITY));
    assert_eq!(two.show(), "1.60x [0, inf]");
    let wide = Ratio {
        value: 0.0612,
        lo: 2e-7,
        hi: 7687.0,
        paired: false,
        seeds: (4, 4),
    };
    assert_eq!(wide.show(), "0.0612x [2.00e-7, 7687]");
    // Refused: one seed, unequal pairs, a negative or NaN value, a zero denominator.
    assert!(ratio_of_means(&[1.0], &[1.0], false, 1000).is_none());
    assert!(ratio_of_means(&[1.0, 2.0], &[1.0, 2.0, 3.0], true, 1000).is_none());
    assert!(ratio_of_means(&[1.0, -2.0], &[1.0, 2.0], false, 1000).is_none());
    assert!(ratio_of_means(&[1.0, f64::NAN], &[1.0, 2.0], false, 1000).is_none());
    assert!(ratio_of_means(&[1.0, 2.0], &[0.0, 0.0], false, 1000).is_none());
    // The same data give the same interval (a fixed stream).
    let x = [0.3, 0.9, 0.5, 0.7];
    assert_eq!(
        ratio_of_means(&x, &[0.2, 0.4, 0.1, 0.3], false, 1000),
        ratio_of_means(&x, &[0.2, 0.4, 0.1, 0.3], false, 1000)
    );
}

/// The MSE of a k-pixel image whose pixels have noise sigma: a scaled chi-square (k dof).
fn mse(rng: &mut Rng, normal: &mut impl FnMut(&mut Rng) -> f64, sigma: f64, k: usize) -> f64 {
    (0..k).map(|_| (sigma * normal(rng)).powi(2)).sum::<f64>() / k as f64
}

/// Calibration, as the experiments use it: two estimators with a known variance ratio (4,
/// so the true ratio of their expected MSEs is 4), 8 seeds each, images of 16 pixels (per-seed
/// MSEs skewed as chi-square with 16 dof). Over 1,000 repetitions the 95 % interval must
/// cover the true ratio at least 93 % of the time (binomial sd of the rate 0.7 %), unpaired,
/// and paired with the two methods' errors correlated through shared seeds (rho 0.8).
#[test]
fn the_interval_covers_a_known_ratio() {
    let mut normal = |rng: &mut Rng| {
        // Box-Muller.
        let (u, v) = (1.0 - rng.next_f64(), rng.next_f64());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    let (seeds, k, reps) = (8usize, 16usize, 1000usize);
    for (paired, rho) in [(false, 0.0), (true, 0.8)] {
        let mut rng = Rng::new(77, paired as u64);
        let mut covered = 0;
        let mut ranked = 0;
        for _ in 0..reps {
            let (mut a, mut b) = (Vec::new(), Vec::new());
            for _ in 0..seeds {
                if paired {
                    // Pixel noises correlated between the methods.
                    let (mut sa, mut sb) = (0.0, 0.0);
                    for _ in 0..k {
                        let (z1, z2) = (normal(&mut rng), normal(&mut rng));
                        sa += (2.0 * z1).powi(2);
                        sb += (rho * z1 + (1.0 - rho * rho).sqrt() * z2).powi(2);
                    }
                    a.push(sa / k as f64);
                    b.push(sb / k as f64);
                } else {
                    a.push(mse(&mut rng, &mut normal, 2.0, k));
                    b.push(mse(&mut rng, &mut normal, 1.0, k));
                }
            }
            let r = ratio_of_means(&a, &b, paired, 1000).unwrap();
            covered += (r.lo <= 4.0 && 4.0 <= r.hi) as usize;
            ranked += r.ranks() as usize;
        }
        let rate = covered as f64 / reps as f64;
        eprintln!("paired {paired}: coverage {rate}, ranked {ranked} of {reps}");
        assert!(
            rate >= 0.93,
            "paired {paired}: coverage {rate} of the true ratio 4"
        );
        // A fourfold difference at 8 seeds is almost always ranked.
        assert!(ranked > reps * 9 / 10, "paired {paired}: ranked {ranked}");
    }
}
