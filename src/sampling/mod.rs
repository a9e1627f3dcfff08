//! Sampling routines: warps of the unit square and discrete distributions.

pub mod discrete;
pub mod spherical;
pub mod warps;

pub use discrete::AliasTable;
