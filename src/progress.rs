//! The progress bar of the commands that work through many records (`analyze`, `demo`,
//! `fleet ingest`, `fleet check`, `resample`): records done, records per second and the time
//! left. Drawn on standard error only when it is a terminal and `-q` was not given; otherwise
//! nothing of it is written.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};

/// `-q`: a global option (any command takes it, before or after the command's name), set once
/// by `main` before the command runs.
static QUIET: AtomicBool = AtomicBool::new(false);

/// Records the global `-q`.
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

/// Whether a bar is drawn: not with `-q`, and only on a terminal.
pub fn shown() -> bool {
    !QUIET.load(Ordering::Relaxed) && std::io::stderr().is_terminal()
}

/// A bar counting records: with a known total (`len`), a bar, `done/total`, the rate and the
/// time left; without, a spinner, the count and the rate. `what` says what is counted (e.g.
/// "records identified"), `unit` its unit in the rate ("records", "files"): records (files or
/// records cut from them), never channels.
pub fn records_bar(len: Option<u64>, what: &str, unit: &'static str) -> ProgressBar {
    let target = if shown() {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let pb = ProgressBar::with_draw_target(len, target);
    set_phase(&pb, len, what, unit);
    pb
}

/// Starts a new phase on `pb`: a new total (or none), the count and the rate estimate from 0,
/// and what is counted.
pub fn set_phase(pb: &ProgressBar, len: Option<u64>, what: &str, unit: &'static str) {
    let template = if len.is_some() {
        "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}  {rate}  {left}"
    } else {
        "{spinner} [{elapsed_precise}] {pos} {msg}  {rate}"
    };
    if let Ok(style) = ProgressStyle::with_template(template) {
        let rate = move |s: &ProgressState, w: &mut dyn std::fmt::Write| {
            let _ = write!(w, "{:.1} {unit}/s", s.per_sec());
        };
        pb.set_style(style.with_key("rate", rate).with_key("left", left));
    }
    match len {
        Some(n) => pb.set_length(n),
        None => pb.unset_length(),
    }
    pb.set_position(0);
    pb.reset_eta();
    pb.set_message(what.to_string());
}

/// The time left, once a record is done (before, there is no rate to tell it from).
fn left(state: &ProgressState, w: &mut dyn std::fmt::Write) {
    if state.pos() == 0 {
        let _ = write!(w, "ETA -");
    } else {
        let _ = write!(w, "ETA {:#}", indicatif::HumanDuration(state.eta()));
    }
}
