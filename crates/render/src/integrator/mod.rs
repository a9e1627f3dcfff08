//! Direct-illumination estimators: light sampling, BSDF sampling and their MIS combinations
//! (`Direct`, one camera ray at a time), and the lane kernel that runs the same estimator on
//! eight camera samples at once (`LaneKernel`).

mod direct;
mod lanes;
pub mod optimal;
mod strategies;
mod strategy;

pub use direct::Direct;
#[cfg(test)]
pub(crate) use lanes::Paths;
pub use lanes::{LaneKernel, LaneScratch};
pub use strategies::Record;
pub use strategy::{Strategy, StrategyOverrides};

#[cfg(test)]
mod coated_tests;
#[cfg(test)]
#[cfg(test)]
pub(crate) mod tests;
