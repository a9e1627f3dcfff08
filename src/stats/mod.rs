//! Statistics for proving estimators and samplers right: running moments, t-tests against
//! closed forms, chi-square tests of samplers against their pdfs, and heat maps of the latter.

pub mod chi2;
pub mod domain;
pub mod heatmap;
pub mod integrate;
pub mod ttest;
pub mod welford;

pub use chi2::{chi2_test, Chi2Config, Chi2Result, Grid, Verdict};
pub use domain::{Disk, Domain, Sphere, Triangle, UnitSquare};
pub use integrate::Integration;
pub use ttest::{one_sample, one_sample_welford, sidak, welch, Group, TTest};
pub use welford::Welford;
