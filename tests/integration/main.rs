//! The integration tests of `vibmode`, in one test binary: one module per former test file
//! (`cargo test -p vibmode --test integration <module>::` runs one of them). One binary instead of
//! one per file: linking each optimised test binary was a large share of a clean
//! `cargo test --workspace`.

mod cli;
mod cli_analysis;
mod cli_fleet;
mod cli_fleet_drive;
mod cli_fleet_robust;
mod cli_fleet_suspension;
mod cli_gps;
mod cli_hardening;
mod cli_input;
mod cli_names;
mod cli_progress;
mod cli_ssi_bounds;
mod cli_stream;
mod cli_vocabulary;
mod common;
mod mutation_fuzz;
mod report_browser;
