//! Sampling routines: warps of the unit square and discrete distributions.

pub mod discrete;
pub(crate) mod elementary;
pub(crate) mod erf;
pub mod gauss_legendre;
pub mod microfacet;
pub mod piecewise;
#[cfg(test)]
pub(crate) mod quadrature;
pub mod spherical;
pub mod warps;

pub use discrete::AliasTable;
