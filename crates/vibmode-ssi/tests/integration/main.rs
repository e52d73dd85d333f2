//! The integration tests of `vibmode-ssi`, in one test binary: one module per former test file
//! (`cargo test -p vibmode-ssi --test integration <module>::` runs one of them). One binary instead of
//! one per file: linking each optimised test binary was a large share of a clean
//! `cargo test --workspace`.

mod errors;
mod hand;
mod physics;
mod reference;
