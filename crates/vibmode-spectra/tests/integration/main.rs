//! The integration tests of `vibmode-spectra`, in one test binary: one module per former test file
//! (`cargo test -p vibmode-spectra --test integration <module>::` runs one of them). One binary instead of
//! one per file: linking each optimised test binary was a large share of a clean
//! `cargo test --workspace`.

mod custom_window;
mod errors;
mod hand;
mod harmonic;
mod lines;
mod physics;
mod scipy_reference;
