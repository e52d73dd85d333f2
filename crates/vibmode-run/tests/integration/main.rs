//! The integration tests of `vibmode-run`, in one test binary: one module per former test file
//! (`cargo test -p vibmode-run --test integration <module>::` runs one of them). One binary instead of
//! one per file: linking each optimised test binary was a large share of a clean
//! `cargo test --workspace`.

mod commands;
mod run;
