//! Choosing which emitter to sample: uniformly, or in proportion to emitted power.

use super::Emitter;
use crate::sampling::discrete::bin_index;
use crate::sampling::AliasTable;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EmitterSelection {
    Uniform,
    Power,
}

/// A discrete distribution over the scene's emitters that can also report the pmf of a given
/// emitter, which MIS needs for BSDF-sampled hits.
#[derive(Clone, Debug)]
pub struct EmitterSelector {
    table: Option<AliasTable>,
    count: usize,
}

impl EmitterSelector {
    /// Power-proportional choice falls back to uniform when no emitter has positive power
    /// (the image is black either way, and the caller reports it).
    pub fn new(emitters: &[Emitter], mode: EmitterSelection) -> Self {
        let table = match mode {
            EmitterSelection::Uniform => None,
            EmitterSelection::Power => {
                let w: Vec<f64> = emitters.iter().map(Emitter::power).collect();
                AliasTable::new(&w)
            }
        };
        EmitterSelector {
            table,
            count: emitters.len(),
        }
    }

    #[inline]
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        if self.count == 0 {
            return None;
        }
        Some(match &self.table {
            Some(t) => {
                let i = t.sample(u);
                (i, t.pmf(i))
            }
            None => {
                let i = bin_index(u * self.count as f32, self.count);
                (i, 1.0 / self.count as f32)
            }
        })
    }

    /// With exactly one emitter, its pmf: `sample` then returns (0, this) for every u in
    /// [0, 1) (a one-bin alias table keeps its bin).
    #[inline]
    pub fn single(&self) -> Option<f32> {
        (self.count == 1).then(|| self.pmf(0))
    }

    /// Bin i of the choice as `sample` makes it: the probability of keeping the bin
    /// (against the fractional part of `u * count`) and its alias. Uniform choice keeps
    /// every bin.
    pub fn bin(&self, i: usize) -> (f32, u32) {
        match &self.table {
            Some(t) => t.bin(i),
            None => (f32::INFINITY, i as u32),
        }
    }

    pub fn len(&self) -> usize {
        self.count
    }

    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        match &self.table {
            Some(t) => t.pmf(i),
            None => 1.0 / self.count as f32,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emitter::{AreaLight, PointLight};
    use crate::math::Rgb;
    use crate::rng::Rng;
    use crate::stats::chi2::{chi2_sf, pearson};
    use glam::Vec3;

    fn emitters() -> Vec<Emitter> {
        let area = |area: f32, l: f32| {
            Emitter::Area(AreaLight {
                shape: 0,
                radiance: Rgb::splat(l),
                area,
                triangles: None,
            })
        };
        vec![
            area(0.01, 100.0),
            area(4.0, 0.5),
            area(1.0, 0.0),
            Emitter::Point(PointLight {
                position: Vec3::ZERO,
                intensity: Rgb::new(1.0, 2.0, 0.5),
            }),
            area(0.2, 3.0),
        ]
    }

    /// The count the lane tables check against their own, for both rules; none chooses
    /// nothing.
    #[test]
    fn len_counts_the_emitters() {
        for mode in [EmitterSelection::Uniform, EmitterSelection::Power] {
            let s = EmitterSelector::new(&emitters(), mode);
            assert_eq!((s.len(), s.is_empty()), (5, false));
            let one = EmitterSelector::new(&emitters()[..1], mode);
            assert_eq!((one.len(), one.is_empty()), (1, false));
            let none = EmitterSelector::new(&[], mode);
            assert_eq!((none.len(), none.is_empty()), (0, true));
            assert!(none.sample(0.5).is_none());
        }
    }

    #[test]
    fn power_pmf_is_proportional_to_power() {
        let e = emitters();
        let sel = EmitterSelector::new(&e, EmitterSelection::Power);
        let total: f64 = e.iter().map(Emitter::power).sum();
        for (i, em) in e.iter().enumerate() {
            assert!((sel.pmf(i) as f64 - em.power() / total).abs() < 1e-6);
        }
        // pi * A * L for area lights, 4 pi * luminance(I) for point lights.
        assert!((e[0].power() - std::f64::consts::PI * 0.01 * 100.0).abs() < 1e-4);
        assert_eq!(sel.pmf(2), 0.0);
    }

    /// `single` is `sample`'s answer for every u of one emitter, whatever its power, and
    /// None for more (or none).
    #[test]
    fn single_is_what_sample_returns_for_one_emitter() {
        let mut rng = Rng::new(8, 3);
        let below_one = f32::from_bits(1.0f32.to_bits() - 1);
        for (k, e) in emitters().into_iter().enumerate() {
            for mode in [EmitterSelection::Uniform, EmitterSelection::Power] {
                let sel = EmitterSelector::new(std::slice::from_ref(&e), mode);
                let single = sel.single().unwrap();
                for u in [0.0, 0.5, below_one]
                    .into_iter()
                    .chain((0..1000).map(|_| rng.next_f32()))
                {
                    assert_eq!(
                        sel.sample(u),
                        Some((0, single)),
                        "emitter {k}, {mode:?}, u {u}"
                    );
                }
            }
        }
        for mode in [EmitterSelection::Uniform, EmitterSelection::Power] {
            assert_eq!(EmitterSelector::new(&emitters(), mode).single(), None);
            assert_eq!(EmitterSelector::new(&[], mode).single(), None);
        }
    }

    /// Chi-square of 1M choices against the pmf, alpha = 0.01, for both selection modes; and
    /// the sampled pmf equals pmf(i).
    #[test]
    fn choice_frequencies_match_pmf() {
        let e = emitters();
        for mode in [EmitterSelection::Uniform, EmitterSelection::Power] {
            let sel = EmitterSelector::new(&e, mode);
            let n = 1_000_000;
            let mut counts = vec![0.0f64; e.len()];
            let mut rng = Rng::new(31, 7);
            for _ in 0..n {
                let (i, pmf) = sel.sample(rng.next_f32()).unwrap();
                assert_eq!(pmf, sel.pmf(i));
                counts[i] += 1.0;
            }
            let mut cells: Vec<(f64, f64)> = Vec::new();
            for (i, &c) in counts.iter().enumerate() {
                let expected = sel.pmf(i) as f64 * n as f64;
                if expected == 0.0 {
                    assert_eq!(c, 0.0, "emitter {i} has pmf 0 but was chosen");
                } else {
                    cells.push((c, expected));
                }
            }
            let p = pearson(&mut cells, 5.0).unwrap();
            let pv = chi2_sf(p.statistic, p.dof);
            assert!(
                pv > 0.01,
                "{mode:?}: chi2 {} dof {} p {pv}",
                p.statistic,
                p.dof
            );
        }
    }
}
