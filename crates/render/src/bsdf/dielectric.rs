//! Mitsuba `dielectric`: smooth interface between int_ior (below, -z) and ext_ior (above).
//! Two delta lobes, reflection chosen with probability R (Fresnel) and refraction with 1 - R,
//! so each lobe's weight is its throughput / probability: 1 for reflection.
//!
//! Radiance transport (as Mitsuba's TransportMode::Radiance): refraction multiplies radiance
//! by eta_ti^2 = (n_incident / n_transmitted)^2, the solid-angle compression across the
//! interface. Hence the albedo is R + T eta_ti^2, not 1; energy (R + T) is conserved exactly.
//! Naturally two-sided: `wi` below the surface sees the interface from inside.

use super::fresnel::fresnel_dielectric;
use super::mirror::reflect_z;
use super::params::{self, Params};
use super::Bsdf;
use super::BsdfSample;
use crate::math::Rgb;
use glam::Vec2;
use glam::Vec3;

/// A smooth dielectric interface (Mitsuba's `dielectric`): Fresnel-weighted choice between
/// mirror reflection and refraction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    /// int_ior / ext_ior.
    pub eta: f32,
}

impl Dielectric {
    /// Reflection or refraction of `wi`, chosen with `u1` in proportion to the Fresnel
    /// reflectance (a delta sample).
    #[inline]
    pub fn sample(&self, wi: Vec3, u1: f32) -> Option<BsdfSample> {
        if wi.z == 0.0 {
            return None;
        }
        let (r, cos_t, eta_ti) = fresnel_dielectric(wi.z, self.eta);
        // u1 < R: with R = 1 (total internal reflection) refraction is never chosen.
        Some(if u1 < r {
            BsdfSample {
                wo: reflect_z(wi),
                weight: Rgb::ONE,
                pdf: r,
                delta: true,
            }
        } else {
            BsdfSample {
                wo: Vec3::new(-eta_ti * wi.x, -eta_ti * wi.y, cos_t),
                weight: Rgb::splat(eta_ti * eta_ti),
                pdf: 1.0 - r,
                delta: true,
            }
        })
    }
}

impl Bsdf for Dielectric {
    const DELTA: bool = true;
    // As Mitsuba: the inside is meaningful, so mirroring it to the outside would turn
    // refraction into nonsense.
    const TWO_SIDED: bool = false;

    /// `int_ior` and `ext_ior`, numbers or Mitsuba's names (default BK7 in air).
    fn from_params<P: Params>(p: &mut P) -> Result<Self, P::Error> {
        let int_ior = params::ior(p, "int_ior", params::DEFAULT_INT_IOR)?;
        let ext_ior = params::ior(p, "ext_ior", params::DEFAULT_EXT_IOR)?;
        p.reject("specular_reflectance")?;
        p.reject("specular_transmittance")?;
        Ok(Dielectric {
            eta: int_ior / ext_ior,
        })
    }
    #[inline]
    fn sample(&self, wi: Vec3, u1: f32, _: Vec2) -> Option<BsdfSample> {
        Dielectric::sample(self, wi, u1)
    }
}

#[cfg(test)]
mod tests {
    use super::super::fresnel::*;
    use super::super::testing::*;
    use super::super::*;
    use crate::rng::Rng;

    fn glass(eta: f32) -> Material {
        Material {
            kind: BsdfKind::Dielectric(Dielectric { eta }),
            two_sided: false,
        }
    }

    fn dir(c: f32, phi: f32) -> Vec3 {
        let s = (1.0 - c * c).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), c)
    }

    #[test]
    fn lobes_snell_and_reversibility() {
        let m = glass(1.5046 / 1.000277);
        check_sample_consistency(&m, 20_000);
        assert!(m.is_delta());
        for c in [1.0f32, 0.7, 0.3, 0.01, -0.01, -0.3, -0.7, -1.0] {
            let wi = dir(c, 0.8);
            let (r, _, _) = fresnel_dielectric(c, 1.5046 / 1.000277);
            let refl = m.sample(wi, r * 0.999, Vec2::ZERO).unwrap();
            if r > 0.0 {
                assert!(refl.delta && refl.pdf == r && refl.wo == Vec3::new(-wi.x, -wi.y, c));
            }
            let Some(t) = m.sample(wi, 0.999_999, Vec2::ZERO) else {
                panic!()
            };
            if r == 1.0 {
                assert_eq!(t.wo.z, wi.z); // total internal reflection
                continue;
            }
            assert!(t.wo.z * wi.z < 0.0 && (t.wo.length() - 1.0).abs() < 1e-6);
            assert!((t.pdf - (1.0 - r)).abs() < 1e-7);
            // Snell (n_i sin_i = n_t sin_t), and light paths are reversible: refracting the
            // refracted direction leads back to wi, with reciprocal radiance scaling.
            let (n_i, n_t) = if c > 0.0 {
                (1.0, 1.5046 / 1.000277)
            } else {
                (1.5046 / 1.000277, 1.0)
            };
            let sin = |w: Vec3| (w.x * w.x + w.y * w.y).sqrt();
            assert!((n_i * sin(wi) - n_t * sin(t.wo)).abs() < 1e-5);
            // In the plane of incidence, on the far side of the normal (both directions
            // point away from the surface): wo_xy = -(n_i / n_t) wi_xy.
            let want = -(n_i / n_t) * wi.truncate();
            assert!(
                (t.wo.truncate() - want).length() < 1e-5,
                "{} vs {want}",
                t.wo
            );
            let back = m.sample(t.wo, 0.999_999, Vec2::ZERO).unwrap();
            assert!((back.wo - wi).length() < 1e-4, "{} vs {wi}", back.wo);
            assert!((t.weight.x * back.weight.x - 1.0).abs() < 1e-5);
        }
    }

    /// The Fresnel reflectance against the textbook formula, written here in f64 without the
    /// renderer's code: R = (Rs + Rp) / 2 with Rs = ((n1 c_i - n2 c_t) / (n1 c_i + n2 c_t))^2
    /// and Rp = ((n2 c_i - n1 c_t) / (n2 c_i + n1 c_t))^2; 0.04 at normal incidence on glass
    /// (1.5) from either side; total internal reflection past the critical angle.
    #[test]
    fn fresnel_matches_the_textbook_formula() {
        let eta = 1.5f64;
        let textbook = |c: f64| {
            let (n1, n2, ci) = if c > 0.0 {
                (1.0, eta, c)
            } else {
                (eta, 1.0, -c)
            };
            let s2 = (n1 / n2).powi(2) * (1.0 - ci * ci);
            if s2 >= 1.0 {
                return 1.0;
            }
            let ct = (1.0 - s2).sqrt();
            let rs = ((n1 * ci - n2 * ct) / (n1 * ci + n2 * ct)).powi(2);
            let rp = ((n2 * ci - n1 * ct) / (n2 * ci + n1 * ct)).powi(2);
            (rs + rp) / 2.0
        };
        assert!((textbook(1.0) - 0.04).abs() < 1e-12 && (textbook(-1.0) - 0.04).abs() < 1e-12);
        for c in [
            1.0, 0.9, 0.7, 0.3, 0.05, -1.0, -0.9, -0.8, -0.75, -0.5, -0.1,
        ] {
            let (r, _, _) = fresnel_dielectric(c as f32, eta as f32);
            assert!(
                (r as f64 - textbook(c)).abs() < 1e-5,
                "cos {c}: {r} vs {}",
                textbook(c)
            );
        }
    }

    /// 200k samples per direction: the reflected fraction is binomial, std error
    /// sqrt(R(1-R)/n) <= 1.1e-3; we allow 4.5 standard errors.
    #[test]
    fn furnace_energy_is_conserved() {
        let eta = 1.5f32;
        let m = glass(eta);
        for c in [1.0f32, 0.7, 0.3, 0.01, -0.01, -0.3, -0.7, -0.9, -1.0] {
            let wi = dir(c, 2.0);
            let (r, _, eta_ti) = fresnel_dielectric(c, eta);
            let n = 200_000;
            let mut rng = Rng::new(3, 9);
            let (mut energy, mut reflected, mut radiance) = (0.0f64, 0usize, 0.0f64);
            for _ in 0..n {
                let s = m.sample(wi, rng.next_f32(), rng.next_2d()).unwrap();
                let refracted = s.wo.z * wi.z < 0.0;
                // Undo the radiance scaling to count energy.
                let scale = if refracted { eta_ti * eta_ti } else { 1.0 };
                energy += (s.weight.x / scale) as f64;
                radiance += s.weight.x as f64;
                reflected += usize::from(!refracted);
            }
            let n = n as f64;
            assert!((energy / n - 1.0).abs() < 1e-6, "cos {c}: {}", energy / n);
            let se = ((r * (1.0 - r)) as f64 / n).sqrt().max(1.0 / n);
            assert!((reflected as f64 / n - r as f64).abs() < 4.5 * se);
            let want = r as f64 + (1.0 - r as f64) * (eta_ti * eta_ti) as f64;
            let (a, _) = albedo(&m, wi, 200_000);
            assert!((radiance / n - want).abs() < 4.5 * se * 2.25, "cos {c}");
            assert!(
                (a.x as f64 - want).abs() < 4.5 * se * 2.25,
                "cos {c}: {a} vs {want}"
            );
        }
    }
}
