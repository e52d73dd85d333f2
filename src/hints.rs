//! Command-line hints for library errors. The libraries name values (`fs_hz`), never flags; the
//! binary knows its flags and adds one short hint to the one-line message. A hint is given only
//! when the command that failed accepts every flag it names (`analyze` has no
//! `--resample-nonuniform`, `simulate` no `--channel`): the test below walks every hint against
//! every command.

use vibmode_analysis::AnalysisError;
use vibmode_core::{ParamError, RecordingError};
use vibmode_fleet::FleetError;
use vibmode_segment::SegmentError;
use vibmode_signal::SignalError;
use vibmode_ssi::SsiError;

/// A fix a flag gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hint {
    /// The sampling rate is missing.
    Fs,
    /// `--fs` disagrees with the file.
    DropFs,
    /// A non-uniform time column.
    ResampleNonuniform,
    /// An unknown channel name or index.
    Channel,
    /// An empty channel selector.
    ChannelExample,
    /// A channel selected twice.
    ChannelOnce,
    /// An invalid sampling rate.
    FsExample,
    /// Files with different channels.
    KeepChannels,
    /// Too few samples for the SSI lags.
    BlockRowsOrFirstLag,
    /// A Toeplitz matrix too large.
    BlockRowsOrChannels,
    /// A first lag out of range.
    FirstLag,
    /// Block rows out of range.
    BlockRows,
    /// Orders out of range or not identifiable.
    Orders,
    /// A reference channel that does not exist or repeats.
    References,
    /// Uncertainty blocks out of range.
    UncertaintyBlocks,
    /// A record length out of range.
    RecordLength,
    /// A GPS offset out of range, or a track that misses the recording.
    GpsOffset,
    /// Another segmentation setting out of range.
    SegmentConfig,
}

impl Hint {
    /// Every hint (for the test that walks them against every command).
    #[cfg(test)]
    pub const ALL: [Hint; 18] = [
        Hint::Fs,
        Hint::DropFs,
        Hint::ResampleNonuniform,
        Hint::Channel,
        Hint::ChannelExample,
        Hint::ChannelOnce,
        Hint::FsExample,
        Hint::KeepChannels,
        Hint::BlockRowsOrFirstLag,
        Hint::BlockRowsOrChannels,
        Hint::FirstLag,
        Hint::BlockRows,
        Hint::Orders,
        Hint::References,
        Hint::UncertaintyBlocks,
        Hint::RecordLength,
        Hint::GpsOffset,
        Hint::SegmentConfig,
    ];

    /// The text appended to the message.
    pub fn text(self) -> &'static str {
        match self {
            Hint::Fs => "--fs HZ",
            Hint::DropFs => "drop --fs to use the file's rate",
            Hint::ResampleNonuniform => "--resample-nonuniform",
            Hint::Channel => "--channel NAME|INDEX",
            Hint::ChannelExample => "e.g. --channel 0",
            Hint::ChannelOnce => "give each --channel once",
            Hint::FsExample => "e.g. --fs 500",
            Hint::KeepChannels => "--channel NAME for each channel to keep",
            Hint::BlockRowsOrFirstLag => "a lower --block-rows or --first-lag",
            Hint::BlockRowsOrChannels => "a lower --block-rows, or fewer --channel",
            Hint::FirstLag => "--first-lag N",
            Hint::BlockRows => "--block-rows N",
            Hint::Orders => "--orders",
            Hint::References => "--references",
            Hint::UncertaintyBlocks => "--uncertainty-blocks N",
            Hint::RecordLength => "--record-length-s SECONDS",
            Hint::GpsOffset => "--gps-offset-s SECONDS",
            Hint::SegmentConfig => "set it in the --segment-config file",
        }
    }
}

/// The long flags a hint's text names (`"--fs HZ"` names `fs`).
pub fn flags(text: &str) -> Vec<&str> {
    text.split(|c: char| c.is_whitespace() || c == ',')
        .filter_map(|w| w.strip_prefix("--"))
        .map(|w| w.trim_end_matches(|c: char| !(c.is_ascii_alphanumeric() || c == '-')))
        .collect()
}

/// Whether `cmd` accepts the long flag `--flag`.
pub fn accepts(cmd: &clap::Command, flag: &str) -> bool {
    cmd.get_arguments().any(|a| a.get_long() == Some(flag))
}

/// The hint for `e` as `cmd` (the subcommand that ran) can give it: `None` when no flag fixes
/// the error or `cmd` lacks a flag the hint names.
pub fn hint(e: &anyhow::Error, cmd: &clap::Command) -> Option<&'static str> {
    for_command(key(e)?, cmd)
}

/// `h`'s text when `cmd` accepts every flag it names.
pub fn for_command(h: Hint, cmd: &clap::Command) -> Option<&'static str> {
    let text = h.text();
    flags(text).iter().all(|f| accepts(cmd, f)).then_some(text)
}

/// The hint for `e`, whatever the command.
fn key(e: &anyhow::Error) -> Option<Hint> {
    for cause in e.chain() {
        if let Some(s) = cause.downcast_ref::<SignalError>() {
            return signal_hint(s);
        }
        if let Some(a) = cause.downcast_ref::<AnalysisError>() {
            return match a {
                AnalysisError::Signal(s) => signal_hint(s),
                AnalysisError::Recording(r) => recording_hint(r),
                AnalysisError::ChannelsDiffer { .. }
                | AnalysisError::ChannelConstant { .. }
                | AnalysisError::ChannelMostlyRepeated { .. } => Some(Hint::KeepChannels),
                _ => None,
            };
        }
        if let Some(r) = cause.downcast_ref::<RecordingError>() {
            return recording_hint(r);
        }
        if let Some(s) = cause.downcast_ref::<SsiError>() {
            return ssi_hint(s);
        }
        if let Some(p) = cause.downcast_ref::<ParamError>() {
            return param_hint(p);
        }
        if let Some(s) = cause.downcast_ref::<SegmentError>() {
            return segment_hint(s);
        }
        if let Some(f) = cause.downcast_ref::<FleetError>() {
            return match f {
                FleetError::Signal(s) => signal_hint(s),
                FleetError::Analysis(AnalysisError::Signal(s)) => signal_hint(s),
                _ => None,
            };
        }
    }
    None
}

fn segment_hint(e: &SegmentError) -> Option<Hint> {
    match e {
        SegmentError::Param(
            ParamError::OutOfRange { name, .. } | ParamError::OutOfRangeHere { name, .. },
        ) => Some(match *name {
            "record_length_s" => Hint::RecordLength,
            "gps_offset_s" => Hint::GpsOffset,
            _ => Hint::SegmentConfig,
        }),
        SegmentError::Param(_) => Some(Hint::SegmentConfig),
        SegmentError::NoOverlap { .. } => Some(Hint::GpsOffset),
        SegmentError::Signal(s) => signal_hint(s),
        _ => None,
    }
}

fn signal_hint(e: &SignalError) -> Option<Hint> {
    match e {
        SignalError::NoSampleRate { .. } | SignalError::NpyNoSampleRate { .. } => Some(Hint::Fs),
        SignalError::SampleRateMismatch { .. } => Some(Hint::DropFs),
        SignalError::NonUniformTime { .. } => Some(Hint::ResampleNonuniform),
        SignalError::Recording(r) => recording_hint(r),
        _ => None,
    }
}

fn recording_hint(e: &RecordingError) -> Option<Hint> {
    match e {
        RecordingError::UnknownChannel { .. } | RecordingError::ChannelIndex { .. } => {
            Some(Hint::Channel)
        }
        RecordingError::EmptySelector => Some(Hint::ChannelExample),
        RecordingError::DuplicateChannel { .. } => Some(Hint::ChannelOnce),
        RecordingError::InvalidSampleRate { .. } => Some(Hint::FsExample),
        _ => None,
    }
}

fn ssi_hint(e: &SsiError) -> Option<Hint> {
    match e {
        SsiError::TooFewSamples { .. } => Some(Hint::BlockRowsOrFirstLag),
        SsiError::MatrixTooLarge { .. } => Some(Hint::BlockRowsOrChannels),
        SsiError::LagsTooLarge { .. } => Some(Hint::FirstLag),
        SsiError::TooManyBlocks { .. }
        | SsiError::TooFewBlocks { .. }
        | SsiError::BlocksTooShort { .. } => Some(Hint::UncertaintyBlocks),
        SsiError::OrderList { .. }
        | SsiError::NoOrder { .. }
        | SsiError::OrderTooHigh { .. }
        | SsiError::OrderAboveRank { .. } => Some(Hint::Orders),
        SsiError::ReferenceChannel { .. } => Some(Hint::References),
        SsiError::Param(p) => param_hint(p),
        _ => None,
    }
}

/// The SSI parameters' names (the libraries' errors name these) and their flags.
fn param_hint(e: &ParamError) -> Option<Hint> {
    match e {
        ParamError::OutOfRange { name, .. } => match *name {
            "block_rows" => Some(Hint::BlockRows),
            "first_lag" => Some(Hint::FirstLag),
            "order_min" | "order_max" | "order_step" => Some(Hint::Orders),
            "reference_channels" => Some(Hint::References),
            _ => None,
        },
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    /// Every command that runs (subcommands of subcommands included), with its path.
    fn leaves(cmd: &clap::Command, path: String, out: &mut Vec<(String, clap::Command)>) {
        let subs: Vec<&clap::Command> = cmd
            .get_subcommands()
            .filter(|s| s.get_name() != "help")
            .collect();
        if subs.is_empty() {
            out.push((path.clone(), cmd.clone()));
        }
        for s in subs {
            leaves(s, format!("{path} {}", s.get_name()), out);
        }
    }

    fn commands() -> Vec<(String, clap::Command)> {
        let mut cli = crate::Cli::command();
        cli.build();
        let mut out = Vec::new();
        leaves(&cli, "vibmode".into(), &mut out);
        out
    }

    #[test]
    fn flags_are_read_from_the_hint_texts() {
        assert_eq!(flags("--fs HZ"), ["fs"]);
        assert_eq!(flags("drop --fs to use the file's rate"), ["fs"]);
        assert_eq!(flags("--channel NAME|INDEX"), ["channel"]);
        assert_eq!(
            flags("a lower --block-rows, or fewer --channel"),
            ["block-rows", "channel"]
        );
        for h in Hint::ALL {
            assert!(!flags(h.text()).is_empty(), "{h:?} names no flag");
        }
    }

    /// Issue 29 item 5: every hint the binary gives names flags the command accepts. A hint a
    /// command cannot act on is not given there; the reading hints are given by every command
    /// that reads recordings, since they all share the same input options.
    #[test]
    fn every_hint_names_a_flag_of_the_command_that_gives_it() {
        let commands = commands();
        assert!(commands.len() >= 15, "{}", commands.len());
        for h in Hint::ALL {
            let mut given = 0;
            for (path, cmd) in &commands {
                if let Some(text) = for_command(h, cmd) {
                    given += 1;
                    for f in flags(text) {
                        assert!(
                            accepts(cmd, f),
                            "{path}: hint {text:?} names --{f}, which it does not accept"
                        );
                    }
                }
            }
            // Every hint is of use to at least one command (`vibmode ssi` for the SSI ones).
            assert!(given > 0, "{h:?} is given by no command");
        }
        let find = |name: &str| {
            commands
                .iter()
                .find(|(p, _)| p == name)
                .map(|(_, c)| c.clone())
                .unwrap_or_else(|| panic!("no command {name}"))
        };
        for reader in [
            "vibmode psd",
            "vibmode fit",
            "vibmode sweep",
            "vibmode ssi",
            "vibmode resample",
            "vibmode segment",
            "vibmode analyze",
            "vibmode fleet ingest",
            "vibmode fleet check",
        ] {
            let cmd = find(reader);
            for h in [
                Hint::ResampleNonuniform,
                Hint::Fs,
                Hint::DropFs,
                Hint::FsExample,
            ] {
                assert!(for_command(h, &cmd).is_some(), "{reader}: {h:?}");
            }
            for flag in ["scale", "unit", "time-unit"] {
                assert!(accepts(&cmd, flag), "{reader} lacks --{flag}");
            }
        }
        for selects in ["vibmode psd", "vibmode segment", "vibmode analyze"] {
            assert!(
                for_command(Hint::Channel, &find(selects)).is_some(),
                "{selects}"
            );
        }
        assert!(for_command(Hint::Channel, &find("vibmode simulate")).is_none());
        assert!(for_command(Hint::BlockRows, &find("vibmode ssi")).is_some());
        assert!(for_command(Hint::BlockRows, &find("vibmode analyze")).is_none());
    }

    /// The errors reach the hints: a library error of each kind gives the flag that fixes it.
    #[test]
    fn library_errors_map_to_their_hints() {
        let e = anyhow::Error::from(RecordingError::DuplicateChannel {
            name: "z".into(),
            index: 0,
        });
        assert_eq!(key(&e), Some(Hint::ChannelOnce));
        let e = anyhow::Error::from(SsiError::MatrixTooLarge {
            block_rows: 600,
            n_channels: 2,
            max_rows: 1024,
            max_block_rows: 512,
        });
        assert_eq!(key(&e), Some(Hint::BlockRowsOrChannels));
        let e = anyhow::Error::from(ParamError::out_of_range("first_lag", 0, "must be >= 1", 1));
        assert_eq!(key(&e), Some(Hint::FirstLag));
        let e = anyhow::Error::from(ParamError::out_of_range("nperseg", 0, "must be >= 1", 1));
        assert_eq!(key(&e), None);
        let e = anyhow::Error::from(FleetError::Signal(SignalError::NoSampleRate {
            path: "a.csv".into(),
        }));
        assert_eq!(key(&e), Some(Hint::Fs));
    }
}
