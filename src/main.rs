//! `vibmode`: the command line over the vibmode library crates.
//!
//! The binary is thin: it parses arguments, reads files through `vibmode-signal`, calls the
//! numerical crates and writes JSON, CSV and figures. Every error is printed as one line on
//! standard error and exits with code 2.

mod cmd_analyze;
mod cmd_fit;
mod cmd_fleet;
mod cmd_psd;
mod cmd_resample;
mod cmd_segment;
mod cmd_ssi;
mod cmd_sweep;
mod cmd_vehicle;
mod hints;
mod input;
mod output;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Vibration modes of vehicle suspensions from in-service accelerations.
#[derive(Parser, Debug)]
#[command(name = "vibmode", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Power spectral density (Welch and/or periodogram) of one or more channels.
    #[command(allow_negative_numbers = true)]
    Psd(cmd_psd::PsdArgs),
    /// Ideal DFT anti-alias filter and resampling to a new rate.
    #[command(allow_negative_numbers = true)]
    Resample(cmd_resample::ResampleArgs),
    /// Cut a long recording into records where the vehicle drives steadily (by GPS or by the
    /// vibration), writing the records and segments.json.
    #[command(allow_negative_numbers = true)]
    Segment(cmd_segment::SegmentArgs),
    /// Fit an AR or ARMA model to each channel and report its modes.
    #[command(allow_negative_numbers = true)]
    Fit(cmd_fit::FitArgs),
    /// Fit every model order and collect every mode (stabilisation diagram).
    #[command(allow_negative_numbers = true)]
    Sweep(cmd_sweep::SweepArgs),
    /// Multichannel SSI-cov of one record: stabilisation diagram and modes with shapes.
    #[command(allow_negative_numbers = true)]
    Ssi(cmd_ssi::SsiArgs),
    /// The paper's whole analysis over many records, with an HTML report.
    #[command(allow_negative_numbers = true)]
    Analyze(cmd_analyze::AnalyzeArgs),
    /// Simulate a city bus and run the whole analysis, writing a report.
    #[command(allow_negative_numbers = true)]
    Demo(cmd_analyze::DemoArgs),
    /// Modes of a 7-DOF full-car model given by a TOML parameter file.
    #[command(allow_negative_numbers = true)]
    Fullcar(cmd_vehicle::FullcarArgs),
    /// Simulate in-service acceleration records of a vehicle on an ISO 8608 road.
    #[command(allow_negative_numbers = true)]
    Simulate(cmd_vehicle::SimulateArgs),
    /// Fleet monitoring: nominal model sets per vehicle in an SQLite store; records classified
    /// as normal, road, vehicle or both.
    #[command(allow_negative_numbers = true)]
    Fleet(cmd_fleet::FleetArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Psd(a) => cmd_psd::run(&a),
        Command::Resample(a) => cmd_resample::run(&a),
        Command::Segment(a) => cmd_segment::run(&a),
        Command::Fit(a) => cmd_fit::run(&a),
        Command::Sweep(a) => cmd_sweep::run(&a),
        Command::Ssi(a) => cmd_ssi::run(&a),
        Command::Analyze(a) => cmd_analyze::run(&a),
        Command::Demo(a) => cmd_analyze::run_demo(&a),
        Command::Fullcar(a) => cmd_vehicle::run_fullcar(&a),
        Command::Simulate(a) => cmd_vehicle::run_simulate(&a),
        Command::Fleet(a) => cmd_fleet::run(&a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // One line: the chain of causes joined (a cause already quoted by the message before
            // it is not repeated), never a backtrace.
            let mut msg = String::new();
            for cause in e.chain() {
                let text = cause.to_string();
                if msg.contains(&text) {
                    continue;
                }
                if !msg.is_empty() {
                    msg.push_str(": ");
                }
                msg.push_str(&text);
            }
            if let Some(h) = hints::hint(&e) {
                msg.push_str(&format!(" (on the command line: {h})"));
            }
            eprintln!("vibmode: error: {}", msg.replace('\n', " "));
            ExitCode::from(2)
        }
    }
}
