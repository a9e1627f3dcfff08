//! What a render did, counted per technique: the rays traced, the BSDF rays that ended at
//! the light-bounds test, and the evaluations of BSDFs, light densities and the emitter
//! choice. The counts are a property of the estimator and the samples, not of the machine
//! or of the code path: the lane kernel counts each sample exactly as the scalar estimator
//! does (a test), so renders on different nodes, shards and thread counts compare, and a
//! per-machine linear model (`directlab bench`) turns them into time.

/// The counts of some samples; sums of counts are the counts of the union.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Camera rays (one per sample).
    pub camera_rays: u64,
    /// Light technique: samples drawn (an emitter chosen and a point on it sampled).
    pub light_samples: u64,
    /// Light technique: shadow rays traced.
    pub shadow_rays: u64,
    /// BSDF technique: samples drawn.
    pub bsdf_samples: u64,
    /// BSDF technique: rays traced past the light-bounds test.
    pub bsdf_rays: u64,
    /// BSDF technique: rays that ended at the light-bounds test (no light in their way).
    pub bsdf_rejected: u64,
    /// BSDF evaluations (value and density) at a light sample's direction.
    pub bsdf_evals: u64,
    /// Light densities evaluated at a BSDF sample's hit of an emitter (MIS weights).
    pub light_pdf_evals: u64,
    /// Emitters weighed by the emitter choice, in draws and in pmf evaluations: one per
    /// choice for the table rules, every emitter for the exhaustive one, each node's two
    /// children on the light tree's path.
    pub choice_evals: u64,
}

impl Counts {
    /// The counters, in field order.
    pub fn values(&self) -> [u64; 9] {
        [
            self.camera_rays,
            self.light_samples,
            self.shadow_rays,
            self.bsdf_samples,
            self.bsdf_rays,
            self.bsdf_rejected,
            self.bsdf_evals,
            self.light_pdf_evals,
            self.choice_evals,
        ]
    }

    /// The counts with the values `v` in field order (`values`).
    pub fn from_values(v: [u64; 9]) -> Counts {
        let [camera_rays, light_samples, shadow_rays, bsdf_samples, bsdf_rays, bsdf_rejected, bsdf_evals, light_pdf_evals, choice_evals] =
            v;
        Counts {
            camera_rays,
            light_samples,
            shadow_rays,
            bsdf_samples,
            bsdf_rays,
            bsdf_rejected,
            bsdf_evals,
            light_pdf_evals,
            choice_evals,
        }
    }

    /// Rays traced of every technique (camera, shadow and BSDF rays past the bounds test).
    pub fn rays(&self) -> u64 {
        self.camera_rays + self.shadow_rays + self.bsdf_rays
    }
}

impl std::ops::AddAssign for Counts {
    fn add_assign(&mut self, o: Counts) {
        let (a, b) = (self.values(), o.values());
        *self = Counts::from_values(std::array::from_fn(|i| a[i] + b[i]));
    }
}

impl std::ops::Add for Counts {
    type Output = Counts;
    fn add(mut self, o: Counts) -> Counts {
        self += o;
        self
    }
}

impl std::iter::Sum for Counts {
    fn sum<I: Iterator<Item = Counts>>(it: I) -> Counts {
        it.fold(Counts::default(), |a, b| a + b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_round_trip_and_sums_add_each_counter() {
        let a = Counts::from_values([1, 2, 3, 4, 5, 6, 7, 8, 9]);
        assert_eq!(a.values(), [1, 2, 3, 4, 5, 6, 7, 8, 9]);
        assert_eq!(a.bsdf_rejected, 6);
        let b = Counts::from_values([10, 20, 30, 40, 50, 60, 70, 80, 90]);
        assert_eq!((a + b).values(), [11, 22, 33, 44, 55, 66, 77, 88, 99]);
        assert_eq!([a, b].into_iter().sum::<Counts>(), a + b);
        assert_eq!(a.rays(), 1 + 3 + 5);
    }
}
