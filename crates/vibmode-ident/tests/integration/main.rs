//! The integration tests of `vibmode-ident`, in one test binary: one module per former test file
//! (`cargo test -p vibmode-ident --test integration <module>::` runs one of them). One binary instead of
//! one per file: linking each optimised test binary was a large share of a clean
//! `cargo test --workspace`.

mod behaviour;
mod outliers;
mod reference;
