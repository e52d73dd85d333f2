//! The integration tests of `vibmode-analysis`, in one test binary: one module per former test file
//! (`cargo test -p vibmode-analysis --test integration <module>::` runs one of them). One binary instead of
//! one per file: linking each optimised test binary was a large share of a clean
//! `cargo test --workspace`.

mod body_ssi_acceptance;
mod common;
mod demo_acceptance;
mod docs_config;
mod errors;
mod lines_acceptance;
mod real_data;
mod ssi_acceptance;
mod stops;
mod stream;
