//! The integration tests of `vibmode-modal`, in one test binary: one module per former test file
//! (`cargo test -p vibmode-modal --test integration <module>::` runs one of them). One binary instead of
//! one per file: linking each optimised test binary was a large share of a clean
//! `cargo test --workspace`.

mod bandwidth;
mod common;
mod hand;
mod reference;
mod shapes;
mod support;
mod synthetic;
