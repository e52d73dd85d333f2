//! The integration tests of `vibmode-fleet`, in one test binary: one module per former test file
//! (`cargo test -p vibmode-fleet --test integration <module>::` runs one of them). One binary instead of
//! one per file: linking each optimised test binary was a large share of a clean
//! `cargo test --workspace`.

mod acceptance;
mod body_measure;
mod common;
mod config_props;
mod end_to_end;
mod ingest_files;
mod level_ratios;
mod reference;
mod suspension;
