//! Unpolarised Fresnel reflectance for dielectric and conductor interfaces.

use crate::math::Rgb;

/// Dielectric Fresnel term (Mitsuba's `fresnel`). `eta` = n_inside / n_outside; `cos_i` is
/// signed, positive when the incident direction lies on the outside (normal) side.
/// Returns (R, cos_t, eta_ti): cos_t is the signed cosine of the refracted direction (on the
/// other side, 0 under total internal reflection) and eta_ti = n_incident / n_transmitted,
/// the factor by which tangential components scale on refraction.
#[inline]
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> (f32, f32, f32) {
    let eta_ti = if cos_i >= 0.0 { 1.0 / eta } else { eta };
    let cos_i_abs = cos_i.abs().min(1.0);
    let cos_t2 = 1.0 - eta_ti * eta_ti * (1.0 - cos_i_abs * cos_i_abs);
    if cos_t2 <= 0.0 {
        return (1.0, 0.0, eta_ti);
    }
    let cos_t_abs = cos_t2.sqrt();
    let cos_t = if cos_i >= 0.0 { -cos_t_abs } else { cos_t_abs };
    if eta == 1.0 {
        return (0.0, cos_t, eta_ti);
    }
    // eta_it = 1 / eta_ti; amplitudes multiplied through by eta_ti to avoid the division.
    let a_s = (cos_t_abs - eta_ti * cos_i_abs) / (cos_t_abs + eta_ti * cos_i_abs);
    let a_p = (cos_i_abs - eta_ti * cos_t_abs) / (cos_i_abs + eta_ti * cos_t_abs);
    (0.5 * (a_s * a_s + a_p * a_p), cos_t, eta_ti)
}

/// Conductor Fresnel for a complex index eta + i k per channel, relative to the outside medium
/// (Mitsuba's `fresnel_conductor`, the closed form of the complex-amplitude expression).
#[inline]
pub fn fresnel_conductor(cos_i: f32, eta: Rgb, k: Rgb) -> Rgb {
    let one = |eta, k| fresnel_conductor_channel(cos_i, eta, k);
    // Grey indices (Mitsuba's default "none" material among them) need one channel, not
    // three: the f64 square roots and divisions are most of a rough conductor's eval.
    if is_grey(eta, k) {
        return Rgb::splat(one(eta.x, k.x));
    }
    Rgb::new(one(eta.x, k.x), one(eta.y, k.y), one(eta.z, k.z))
}

/// Whether every channel of the index is the same, so that one channel is the whole
/// `fresnel_conductor`.
#[inline]
pub fn is_grey(eta: Rgb, k: Rgb) -> bool {
    eta.x == eta.y && eta.x == eta.z && k.x == k.y && k.x == k.z
}

/// One channel of `fresnel_conductor`; selects rather than branches, so that it runs in
/// vector lanes (`integrator::lanes`). In f32, as Mitsuba and pbrt evaluate it: within 1e-6
/// of the f64 closed form over the loader's range of indices (`conductor_f32_matches_f64`
/// measures 2e-7).
#[inline(always)]
pub fn fresnel_conductor_channel(cos_i: f32, eta: f32, k: f32) -> f32 {
    let c = cos_i.clamp(0.0, 1.0);
    let c2 = c * c;
    let s2 = 1.0 - c2;
    // eta^2 - k^2 - s2, with c2 added last: 1 - c2 rounds a grazing c2 away (an index of 1
    // then reflected everything at cos 1e-4).
    let t1 = (eta * eta - k * k - 1.0) + c2;
    let a2b2 = (t1 * t1 + 4.0 * eta * eta * k * k).sqrt();
    // Cancels where t1 < 0 (metals), but by less than the bound above: the form without
    // cancellation, eta k / sqrt((a2b2 - t1) / 2) there, measured the same worst case and
    // costs a division.
    let a = (0.5 * (a2b2 + t1)).max(0.0).sqrt();
    let (t_1, t_2) = (a2b2 + c2, 2.0 * c * a);
    let (t_3, t_4) = (a2b2 * c2 + s2 * s2, t_2 * s2);
    // (r_s + r_p) / 2 with r_p = r_s (t_3 - t_4) / (t_3 + t_4) is r_s t_3 / (t_3 + t_4): one
    // division. eta = k = 0 at normal incidence is 0/0 in r_p; its limit equals r_s.
    let q = t_3 + t_4;
    let (num, den) = if q > 0.0 {
        ((t_1 - t_2) * t_3, (t_1 + t_2) * q)
    } else {
        (t_1 - t_2, t_1 + t_2)
    };
    num / den
}

/// Mitsuba's diffuse Fresnel reflectance F_dr(eta): the fraction of uniformly diffuse light
/// that a smooth boundary of index ratio `eta` reflects. Egan and Hilgeman's fit below 1,
/// d'Eon and Irving's above (each where it is accurate to about 0.1 %).
pub fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    let inv = 1.0 / eta;
    if eta < 1.0 {
        0.0636 * inv + (eta * (eta * -1.4399 + 0.7099) + 0.6681)
    } else {
        let c = [0.919317, -3.4793, 6.75335, -7.80989, 4.98554, -1.36881];
        c.iter().rev().fold(0.0, |acc, &k| acc * inv + k)
    }
}

/// The largest index component the loader takes: the f32 form's squares and products stay
/// far from overflow (k^4 ~ 1e24).
pub const MAX_INDEX: f32 = 1e6;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_normal_incidence_and_symmetry() {
        for (n1, n2) in [
            (1.0f32, 1.5f32),
            (1.5, 1.0),
            (1.000277, 1.5046),
            (1.33, 2.4),
        ] {
            let eta = n2 / n1;
            let want = ((n1 - n2) / (n1 + n2)).powi(2);
            let (r, cos_t, _) = fresnel_dielectric(1.0, eta);
            assert!((r - want).abs() < 1e-6 && cos_t == -1.0, "{r} vs {want}");
            let (r, cos_t, _) = fresnel_dielectric(-1.0, 1.0 / eta);
            assert!((r - want).abs() < 1e-6 && cos_t == 1.0);
        }
        // Stokes relation: the same interface reflects equally from both sides along a
        // refracted pair of directions.
        for i in 1..100 {
            let ci = i as f32 / 100.0;
            let (r, cos_t, eta_ti) = fresnel_dielectric(ci, 1.5);
            let (r2, cos_back, eta_back) = fresnel_dielectric(cos_t, 1.5);
            // f32 cancellation in 1 - cos^2 near grazing limits this to ~1e-5.
            assert!(
                (r - r2).abs() < 1e-4 && (cos_back - ci).abs() < 1e-4,
                "{ci}"
            );
            assert!((eta_ti * eta_back - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn dielectric_total_internal_reflection() {
        // From glass (n = 1.5) the critical angle is asin(1/1.5): cos = sqrt(1 - 1/2.25).
        let crit = (1.0f32 - 1.0 / 2.25).sqrt();
        let (r, cos_t, _) = fresnel_dielectric(-(crit - 1e-3), 1.5);
        assert_eq!((r, cos_t), (1.0, 0.0));
        let (r, _, _) = fresnel_dielectric(-(crit + 1e-3), 1.5);
        assert!(r < 1.0 && r > 0.5, "{r}");
        assert_eq!(fresnel_dielectric(0.0, 1.5).0, 1.0);
    }

    /// Gold, rgb fit of Mitsuba's Au spectra (eta, k as widely used in rgb renderers).
    /// References from the complex-amplitude formulas (Python cmath), an independent route.
    #[test]
    fn conductor_gold_against_complex_amplitudes() {
        let eta = Rgb::new(0.143119, 0.374957, 1.44248);
        let k = Rgb::new(3.98316, 2.38572, 1.60322);
        let refs = [
            (1.0, [0.966_662_8, 0.802_190_05, 0.324_050_55]),
            (0.5, [0.962_191_8, 0.804_541_6, 0.371_098_76]),
            (0.1, [0.973_419_9, 0.919_570_9, 0.718_828_56]),
        ];
        for (c, want) in refs {
            let f = fresnel_conductor(c, eta, k);
            let d = (f - Rgb::from(want)).abs().max_element();
            assert!(d < 2e-6, "cos {c}: {f} vs {want:?}");
        }
        assert_eq!(fresnel_conductor(0.0, eta, k), Rgb::ONE);
    }

    /// The closed form in f64, as `fresnel_conductor_channel` was written before it moved
    /// to f32.
    fn channel_f64(cos_i: f32, eta: f32, k: f32) -> f64 {
        let c = cos_i.clamp(0.0, 1.0) as f64;
        let (eta, k) = (eta as f64, k as f64);
        let c2 = c * c;
        let s2 = 1.0 - c2;
        let t1 = eta * eta - k * k - s2;
        let a2b2 = (t1 * t1 + 4.0 * eta * eta * k * k).max(0.0).sqrt();
        let a = (0.5 * (a2b2 + t1)).max(0.0).sqrt();
        let (t_1, t_2) = (a2b2 + c2, 2.0 * c * a);
        let rs = (t_1 - t_2) / (t_1 + t_2);
        let (t_3, t_4) = (a2b2 * c2 + s2 * s2, t_2 * s2);
        let rp = if t_3 + t_4 > 0.0 {
            rs * (t_3 - t_4) / (t_3 + t_4)
        } else {
            rs
        };
        0.5 * (rs + rp)
    }

    /// Over indices from 0 to `MAX_INDEX` (log-spaced, with the metals table's and exact
    /// zeros) and cosines from grazing to normal, the f32 form stays within 1e-6 of the f64
    /// one: a few f32 roundings of a reflectance below 1.
    #[test]
    fn conductor_f32_matches_f64() {
        let mut values: Vec<f32> = vec![0.0, 1.0];
        values.extend((0..=60).map(|i| 10f32.powf(-3.0 + i as f32 * 0.15)));
        for (_, eta, k) in crate::bsdf::params::METALS {
            values.extend(eta.iter().chain(k.iter()));
        }
        let mut worst = (0.0f64, 0.0, 0.0, 0.0);
        for &eta in &values {
            for &k in &values {
                for i in 0..=200 {
                    let c = (i as f32 / 200.0).powi(2);
                    let d = (fresnel_conductor_channel(c, eta, k) as f64 - channel_f64(c, eta, k))
                        .abs();
                    if !(d <= worst.0) {
                        worst = (d, c, eta, k);
                    }
                }
            }
        }
        eprintln!(
            "worst |f32 - f64| {:.3e} at (cos, eta, k) {:?}",
            worst.0, &worst
        );
        assert!(worst.0 < 1e-6, "{worst:?}");
    }

    #[test]
    fn conductor_reduces_to_dielectric_and_to_perfect_mirror() {
        for i in 0..=100 {
            let c = i as f32 / 100.0;
            let f = fresnel_conductor(c, Rgb::splat(1.5), Rgb::ZERO);
            let d = fresnel_dielectric(c.max(1e-9), 1.5).0;
            assert!((f.x - d).abs() < 1e-5, "cos {c}: {f} vs {d}");
            // A purely imaginary index (Mitsuba's 'none': eta 0, k 1) reflects everything.
            let one = fresnel_conductor(c, Rgb::ZERO, Rgb::ONE);
            assert!((one - Rgb::ONE).abs().max_element() < 1e-6);
            assert!(
                (fresnel_conductor(c, Rgb::ZERO, Rgb::ZERO) - Rgb::ONE)
                    .abs()
                    .max_element()
                    < 1e-6
            );
        }
    }

    /// The grey shortcut is the per-channel formula, bit for bit: each channel of a coloured
    /// index equals the grey index made of that channel.
    #[test]
    fn conductor_grey_shortcut_matches_each_channel() {
        let (eta, k) = (Rgb::new(0.2, 0.92, 1.1), Rgb::new(3.9, 2.45, 2.14));
        for i in 0..=200 {
            let c = i as f32 / 200.0;
            let f = fresnel_conductor(c, eta, k);
            for ch in 0..3 {
                let grey = fresnel_conductor(c, Rgb::splat(eta[ch]), Rgb::splat(k[ch]));
                assert_eq!(grey, Rgb::splat(f[ch]), "cos {c}, channel {ch}");
            }
        }
    }

    /// The grey shortcut is taken exactly when all three channels of eta and of k agree:
    /// indices that agree in some channels only (each of the 16 patterns of which of
    /// eta.y, eta.z, k.y, k.z equal the x channel) keep their colour.
    #[test]
    fn grey_exactly_when_every_channel_agrees() {
        for pattern in 0..16u32 {
            let same = |bit: u32| pattern >> bit & 1 != 0;
            let pick = |bit: u32, x: f32, other: f32| if same(bit) { x } else { other };
            let eta = Rgb::new(0.2, pick(0, 0.2, 0.9), pick(1, 0.2, 1.3));
            let k = Rgb::new(3.0, pick(2, 3.0, 2.1), pick(3, 3.0, 1.7));
            assert_eq!(is_grey(eta, k), pattern == 15, "{eta} {k}");
            for c in [0.05f32, 0.5, 1.0] {
                let f = fresnel_conductor(c, eta, k);
                for ch in 0..3 {
                    let one = fresnel_conductor(c, Rgb::splat(eta[ch]), Rgb::splat(k[ch]));
                    assert_eq!(f[ch], one.x, "{eta} {k} cos {c} channel {ch}");
                }
            }
        }
    }
}
