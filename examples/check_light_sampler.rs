//! Test a light sampler you wrote: directions towards a spherical light by uniform sampling
//! of the cone it subtends, checked by chi-square and by the mean of an estimator of the
//! light's irradiance (a t-test against the closed form).
//!
//!     cargo run --release --example check_light_sampler

use directlab::check::{chi2_directions, ttest_mean, DirectionSampler, Options};
use glam::{Vec2, Vec3};
use std::f32::consts::TAU;

/// A sphere of `radius` at `centre`, seen from the origin: uniform in its cone.
struct Cone {
    centre: Vec3,
    radius: f32,
}

impl Cone {
    fn cos_max(&self) -> f32 {
        let d2 = self.centre.length_squared();
        (1.0 - self.radius * self.radius / d2).max(0.0).sqrt()
    }
}

impl DirectionSampler for Cone {
    fn sample(&self, u: Vec2) -> Option<Vec3> {
        let c = 1.0 - u.x * (1.0 - self.cos_max());
        let s = (1.0 - c * c).max(0.0).sqrt();
        let w = self.centre.normalize();
        let a = if w.x.abs() > 0.9 { Vec3::Y } else { Vec3::X };
        let t = w.cross(a).normalize();
        let b = w.cross(t);
        let phi = TAU * u.y;
        Some(s * phi.cos() * t + s * phi.sin() * b + c * w)
    }
    fn pdf(&self, d: Vec3) -> f64 {
        let inside = d.dot(self.centre.normalize()) >= self.cos_max();
        if inside {
            1.0 / (TAU as f64 * (1.0 - self.cos_max() as f64))
        } else {
            0.0
        }
    }
}

fn main() {
    let light = Cone {
        centre: Vec3::new(0.3, -0.2, 2.0),
        radius: 0.5,
    };
    let o = chi2_directions(&light, &Options::default());
    println!("chi-square: {}", o.summary());
    // cos / pdf of each sample estimates the irradiance of a unit-radiance sphere at a
    // receiver facing +z: pi sin^2(theta_max) times the cosine of the sphere's centre.
    let c = light.cos_max() as f64;
    let irradiance = std::f64::consts::PI * (1.0 - c * c) * light.centre.normalize().z as f64;
    let t = ttest_mean(100_000, 1, irradiance, |r| {
        let d = light.sample(r.next_2d()).unwrap();
        d.z.max(0.0) as f64 / light.pdf(d)
    });
    println!(
        "irradiance {irradiance:.6}: t = {:.3}, p = {:.3}",
        t.t, t.p_value
    );
    if !o.passed() || !t.passes(0.01) {
        eprintln!("the light sampler is wrong");
        std::process::exit(1);
    }
    println!("the cone sampler matches its pdf and the irradiance");
}
