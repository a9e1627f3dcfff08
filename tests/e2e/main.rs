//! The end-to-end tests, through the command line, in one test binary: as fifteen binaries,
//! each linked with the release profile's thin LTO, their linking was most of a fresh
//! `cargo test --release`.

mod common;

mod bad_counts;
mod bad_input;
mod bench_cli;
mod browser;
mod check_sampler;
mod check_sampler_cpp;
mod compare_cli;
mod experiment_cli;
mod extreme;
mod html_page;
mod integrands_cli;
mod layout;
mod mitsuba_cli;
mod noritest_cli;
mod quick_figures;
mod readme;
mod reference_cache;
mod render_cli;
mod seeded_bugs;
mod shard_cli;
mod shard_damage;
mod slurm_e2e;
mod small_films;
mod strategies_agree;
