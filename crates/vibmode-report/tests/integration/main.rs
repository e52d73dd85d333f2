//! The integration tests of `vibmode-report`, in one test binary: one module per former test file
//! (`cargo test -p vibmode-report --test integration <module>::` runs one of them). One binary instead of
//! one per file: linking each optimised test binary was a large share of a clean
//! `cargo test --workspace`.

mod axes;
mod figures;
mod html;
mod reference;
mod update_section;
