//! Direct-illumination estimators: light sampling, BSDF sampling and their MIS combinations.

mod direct;
mod lane_tables;
mod lanes;
mod lanes_light;
mod lanes_rough;
mod strategy;

pub use direct::Direct;
pub use lanes::LaneScratch;
pub use strategy::{Strategy, StrategyOverrides};

#[cfg(test)]
pub(crate) mod tests;
