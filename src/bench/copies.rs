//! The machine's own scaling limit: independent 1-thread renders run side by side, against
//! one alone. On a shared VM the cores need not add up (all-core turbo clocks below the
//! one-core clock, a neighbour's load, a shared cache), and no renderer's threads scale past
//! what independent copies of it reach at once: the thread speed-up is read against this.

use super::timing::throughput;
use crate::integrator::Strategy;
use crate::scene::Scene;
use std::time::Instant;

pub struct Copies {
    /// Samples per second of one 1-thread render alone, best of the repetitions.
    pub alone_per_s: f64,
    /// Samples per second of all the copies together (their samples over the wall-clock
    /// time until the last one finished), best of the repetitions.
    pub together_per_s: f64,
}

impl Copies {
    pub fn speed_up(&self) -> f64 {
        self.together_per_s / self.alone_per_s
    }
}

/// One 1-thread render of `spp` alone, then `copies` of it at once, `repeat` times: they take
/// turns within each repetition (as `bench::throughputs`), so a slow spell of the machine
/// hits both alike.
pub fn measure(scene: &Scene, strategy: Strategy, spp: u32, copies: usize, repeat: u32) -> Copies {
    let samples = scene.camera.width as f64 * scene.camera.height as f64 * spp as f64;
    let (mut alone_per_s, mut together_per_s) = (0.0f64, 0.0f64);
    for _ in 0..repeat.max(1) {
        alone_per_s = alone_per_s.max(throughput(scene, strategy, spp, 1, 1));
        let start = Instant::now();
        std::thread::scope(|s| {
            for _ in 0..copies {
                s.spawn(|| throughput(scene, strategy, spp, 1, 1));
            }
        });
        let seconds = start.elapsed().as_secs_f64().max(1e-9);
        together_per_s = together_per_s.max(copies as f64 * samples / seconds);
    }
    Copies {
        alone_per_s,
        together_per_s,
    }
}
