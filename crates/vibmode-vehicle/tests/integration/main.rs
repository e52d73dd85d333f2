//! The integration tests of `vibmode-vehicle`, in one test binary: one module per former test file
//! (`cargo test -p vibmode-vehicle --test integration <module>::` runs one of them). One binary instead of
//! one per file: linking each optimised test binary was a large share of a clean
//! `cargo test --workspace`.

mod model;
mod params;
mod realism;
mod reference;
mod sim;
mod update;
