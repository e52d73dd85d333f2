//! `vibmode`: the command line over the vibmode library crates.
//!
//! The binary is thin: it parses arguments, reads files through `vibmode-signal`, calls the
//! numerical crates and writes JSON, CSV and figures. Every error is printed as one line on
//! standard error and exits with code 2.

mod cmd_analyze;
mod cmd_fit;
mod cmd_fleet;
mod cmd_info;
mod cmd_psd;
mod cmd_resample;
mod cmd_segment;
mod cmd_ssi;
mod cmd_sweep;
mod cmd_vehicle;
mod hints;
mod input;
mod output;
mod progress;

use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::{ArgMatches, CommandFactory, FromArgMatches, Parser, Subcommand};
use std::ffi::OsString;
use std::process::ExitCode;
use vibmode_core::cap_message;
use vibmode_core::limits::MESSAGE_BYTES_MAX;

/// Vibration modes of vehicle suspensions from in-service accelerations.
#[derive(Parser, Debug)]
#[command(name = "vibmode", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// No progress bar (any command; only `analyze`, `demo`, `resample` and `fleet ingest` and
    /// `check` draw one, on a terminal). Before or after the command's name.
    #[arg(long, short = 'q', global = true)]
    quiet: bool,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// What each recording file holds: format, rate, channels, length, start time, and each
    /// channel's range, mean, std and RMS (dead, stuck and clipped sensors and held stretches
    /// marked).
    #[command(allow_negative_numbers = true)]
    Info(cmd_info::InfoArgs),
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
    let args: Vec<OsString> = std::env::args_os().collect();
    let mut cli_cmd = Cli::command();
    let matches = match cli_cmd.try_get_matches_from_mut(&args) {
        Ok(m) => m,
        Err(e) => return clap_failure(&e, &cli_cmd, &args),
    };
    let leaf = leaf_of_matches(&cli_cmd, &matches);
    if let Err(line) = refuse_empty_values(&cli_cmd, &matches) {
        return fail(&line, None);
    }
    let cli = match Cli::from_arg_matches(&matches) {
        Ok(c) => c,
        Err(e) => return clap_failure(&e, &cli_cmd, &args),
    };
    progress::set_quiet(cli.quiet);
    let result = match cli.command {
        Command::Info(a) => cmd_info::run(&a),
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
            fail(&msg, hints::hint(&e, &leaf))
        }
    }
}

/// Prints `vibmode: error: MESSAGE (on the command line: HINT)` as one line of at most
/// [`MESSAGE_BYTES_MAX`] bytes (control characters shown as `?`; the message, not the hint, is
/// cut where it is too long) and returns exit code 2.
fn fail(msg: &str, hint: Option<&str>) -> ExitCode {
    eprintln!("{}", one_line(msg, hint));
    ExitCode::from(2)
}

/// The line [`fail`] prints.
fn one_line(msg: &str, hint: Option<&str>) -> String {
    const PREFIX: &str = "vibmode: error: ";
    let clean = |s: &str| -> String {
        s.chars()
            .map(|c| {
                if c == '\n' || c == '\t' {
                    ' '
                } else if c.is_control() {
                    '?'
                } else {
                    c
                }
            })
            .collect()
    };
    let suffix = hint.map_or(String::new(), |h| {
        format!(" (on the command line: {})", clean(h))
    });
    let room = MESSAGE_BYTES_MAX.saturating_sub(PREFIX.len() + suffix.len());
    let line = format!("{PREFIX}{}{suffix}", cap_message(&clean(msg), room));
    cap_message(&line, MESSAGE_BYTES_MAX)
}

/// The subcommand that runs (`fleet check`, say).
fn leaf_of_matches(cmd: &clap::Command, m: &ArgMatches) -> clap::Command {
    let (mut cmd, mut m) = (cmd.clone(), m.clone());
    while let Some((name, sub_m)) = m.subcommand() {
        let Some(sub) = cmd.find_subcommand(name).cloned() else {
            break;
        };
        let sub_m = sub_m.clone();
        cmd = sub;
        m = sub_m;
    }
    cmd
}

/// The subcommand the words of `args` name, for a command line clap refused.
fn leaf_of_args(cmd: &clap::Command, args: &[OsString]) -> (String, clap::Command) {
    let mut path = cmd.get_name().to_string();
    let mut cmd = cmd.clone();
    for a in args.iter().skip(1) {
        let a = a.to_string_lossy();
        if a.starts_with('-') {
            continue;
        }
        match cmd.find_subcommand(a.as_ref()).cloned() {
            Some(sub) => {
                path = format!("{path} {a}");
                cmd = sub;
            }
            None => break,
        }
    }
    (path, cmd)
}

/// An empty value (`-o ''`, `--json ''`, an empty input path) is refused, naming the option:
/// no option of vibmode means anything when empty.
fn refuse_empty_values(cmd: &clap::Command, m: &ArgMatches) -> Result<(), String> {
    let mut path = cmd.get_name().to_string();
    let (mut cmd, mut m) = (cmd.clone(), m.clone());
    loop {
        for arg in cmd.get_arguments() {
            let id = arg.get_id().as_str();
            if m.value_source(id) != Some(clap::parser::ValueSource::CommandLine) {
                continue;
            }
            let Ok(Some(mut raw)) = m.try_get_raw(id) else {
                continue;
            };
            if raw.any(|v| v.is_empty()) {
                return Err(format!(
                    "empty value for {}: '' (give a value; see {path} --help)",
                    arg_display(arg)
                ));
            }
        }
        let Some((name, sub_m)) = m.subcommand() else {
            return Ok(());
        };
        let Some(sub) = cmd.find_subcommand(name).cloned() else {
            return Ok(());
        };
        path = format!("{path} {name}");
        let sub_m = sub_m.clone();
        cmd = sub;
        m = sub_m;
    }
}

/// `--name` for an option, `<NAME>` for a positional argument.
fn arg_display(arg: &clap::Arg) -> String {
    match arg.get_long() {
        Some(l) => format!("--{l}"),
        None => match arg.get_value_names().and_then(|v| v.first()) {
            Some(v) => format!("<{v}>"),
            None => format!("<{}>", arg.get_id().as_str().to_uppercase()),
        },
    }
}

/// A context value of a clap error as text.
fn context(e: &clap::Error, kind: ContextKind) -> Option<String> {
    match e.get(kind)? {
        ContextValue::String(s) => Some(s.clone()),
        ContextValue::Strings(v) => Some(v.join(", ")),
        ContextValue::StyledStr(s) => Some(s.to_string()),
        ContextValue::StyledStrs(v) => Some(
            v.iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", "),
        ),
        ContextValue::Number(n) => Some(n.to_string()),
        ContextValue::Bool(b) => Some(b.to_string()),
        _ => None,
    }
}

/// What values an argument of a whole-number or decimal type takes.
fn value_range(arg: &clap::Arg) -> Option<String> {
    use std::any::TypeId;
    let t = arg.get_value_parser().type_id();
    macro_rules! ints {
        ($($ty:ty),*) => {
            $(if t == TypeId::of::<$ty>() {
                return Some(format!("a whole number from {} to {}", <$ty>::MIN, <$ty>::MAX));
            })*
        };
    }
    ints!(u8, u16, u32, u64, usize, i8, i16, i32, i64, isize);
    if t == TypeId::of::<f64>() || t == TypeId::of::<f32>() {
        return Some("a decimal number, e.g. 2.5".into());
    }
    None
}

/// Prints a clap error: help and version as clap prints them (exit 0), every other error as
/// one line `vibmode: error: WHAT: VALUE (FIX)`, exit 2, without clap's usage block.
fn clap_failure(e: &clap::Error, cmd: &clap::Command, args: &[OsString]) -> ExitCode {
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        // `vibmode` or `vibmode fleet` alone: the list of commands, as clap prints it.
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let _ = e.print();
            return ExitCode::from(2);
        }
        _ => {}
    }
    let (path, leaf) = leaf_of_args(cmd, args);
    fail(&clap_line(e, &path, &leaf, args), None)
}

/// The one-line text of a clap error (without the `vibmode: error: ` prefix).
fn clap_line(e: &clap::Error, path: &str, leaf: &clap::Command, args: &[OsString]) -> String {
    let help = format!("see {path} --help");
    let arg_text = context(e, ContextKind::InvalidArg).unwrap_or_default();
    // "--seed <SEED>" -> "--seed"
    let flag = arg_text
        .split_whitespace()
        .next()
        .unwrap_or_default()
        .to_string();
    let quoted_value = |v: &str| format!("'{}'", vibmode_core::quoted(v));
    match e.kind() {
        ErrorKind::InvalidValue | ErrorKind::ValueValidation => {
            let value = context(e, ContextKind::InvalidValue).unwrap_or_default();
            let arg = leaf
                .get_arguments()
                .find(|a| a.get_long().is_some_and(|l| flag == format!("--{l}")));
            if value.is_empty() {
                return format!("empty value for {flag}: '' (give a value; {help})");
            }
            let mut fix = Vec::new();
            if let Some(src) = std::error::Error::source(e) {
                fix.push(src.to_string());
            }
            if let Some(valid) = context(e, ContextKind::ValidValue) {
                fix.push(format!("give one of: {valid}"));
            } else if let Some(range) = arg.and_then(value_range) {
                fix.push(format!("give {range}"));
            } else {
                fix.push(help);
            }
            format!(
                "invalid value for {flag}: {} ({})",
                quoted_value(&value),
                fix.join("; ")
            )
        }
        ErrorKind::UnknownArgument => {
            let mut fix = Vec::new();
            if let Some(s) = context(e, ContextKind::SuggestedArg) {
                fix.push(format!("did you mean {s}"));
            }
            // `--vehicle -bus`: the value starts with '-' and was read as a flag.
            let words: Vec<String> = args
                .iter()
                .map(|a| a.to_string_lossy().into_owned())
                .collect();
            if let Some(i) = words
                .iter()
                .position(|w| !flag.is_empty() && (*w == flag || w.starts_with(&flag)))
            {
                if let Some(prev) = i.checked_sub(1).map(|j| &words[j]) {
                    let takes_value = prev.strip_prefix("--").is_some_and(|l| {
                        !l.contains('=')
                            && leaf
                                .get_arguments()
                                .any(|a| a.get_long() == Some(l) && a.get_action().takes_values())
                    });
                    if takes_value {
                        fix.push(format!(
                            "for a value that starts with '-', write {prev}={}",
                            vibmode_core::quoted(&words[i])
                        ));
                    }
                }
            }
            fix.push(help);
            format!(
                "unexpected argument: {} ({})",
                quoted_value(&flag),
                fix.join("; ")
            )
        }
        ErrorKind::InvalidSubcommand => {
            let sub = context(e, ContextKind::InvalidSubcommand).unwrap_or_default();
            let names: Vec<&str> = leaf
                .get_subcommands()
                .map(clap::Command::get_name)
                .filter(|n| *n != "help")
                .collect();
            let mut fix = Vec::new();
            if let Some(s) = context(e, ContextKind::SuggestedSubcommand) {
                fix.push(format!("did you mean {s}"));
            }
            fix.push(format!("commands: {}", names.join(", ")));
            format!(
                "unknown command: {} ({})",
                quoted_value(&sub),
                fix.join("; ")
            )
        }
        ErrorKind::MissingRequiredArgument => {
            format!("missing required argument: {arg_text} ({help})")
        }
        _ => {
            // Clap's own first line, without its "error: " and usage block.
            let rendered = e.render().to_string();
            let first = rendered
                .lines()
                .find(|l| !l.trim().is_empty())
                .unwrap_or("invalid command line");
            let first = first.strip_prefix("error: ").unwrap_or(first);
            format!("{} ({help})", vibmode_core::cap_message(first, 200))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_line_is_capped_clean_and_keeps_the_hint() {
        let long = format!("bad \u{1b}[31m{}\nend", "x".repeat(5000));
        let line = one_line(&long, Some("--block-rows N"));
        assert!(line.len() <= MESSAGE_BYTES_MAX, "{}", line.len());
        assert!(!line.contains('\u{1b}') && !line.contains('\n'), "{line}");
        assert!(line.starts_with("vibmode: error: bad ?[31m"), "{line}");
        assert!(
            line.ends_with("... (on the command line: --block-rows N)"),
            "{line}"
        );
        assert_eq!(one_line("short", None), "vibmode: error: short");
    }
}
