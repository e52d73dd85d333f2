//! Errors of the core types. Messages name the offending value and the fix, never a
//! command-line flag: the front end (CLI, Python) adds its own hints.

use crate::limits::{num, quoted, FS_HZ_MAX, FS_HZ_MIN, SAMPLE_ABS_MAX, SAMPLE_PEAK_MIN};

/// A recording that breaks its invariants, or a channel that cannot be found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RecordingError {
    /// A NaN or infinite sample.
    #[error("channel '{}' sample {index} is {}; clean the data first (remove or interpolate the bad samples)", quoted(.channel), num(.value))]
    NonFinite {
        /// Channel name.
        channel: String,
        /// 0-based sample index.
        index: usize,
        /// The value (NaN, inf or -inf).
        value: f64,
    },
    /// A sampling rate that is not a positive finite number.
    #[error("sampling rate {} Hz ({}) must be a positive finite number", num(.fs_hz), quoted(.what))]
    InvalidSampleRate {
        /// Where the rate came from.
        what: String,
        /// The value.
        fs_hz: f64,
    },
    /// A sampling rate outside [`FS_HZ_MIN`, `FS_HZ_MAX`].
    #[error("sampling rate {} Hz ({}) is outside {} to {} Hz; check its unit (a time column in ms read as s, say)", num(.fs_hz), quoted(.what), num(&FS_HZ_MIN), num(&FS_HZ_MAX))]
    SampleRateOutOfRange {
        /// Where the rate came from.
        what: String,
        /// The value.
        fs_hz: f64,
    },
    /// A sample whose magnitude exceeds [`SAMPLE_ABS_MAX`]: its powers would overflow.
    #[error("channel '{}' sample {index} is {}, beyond the largest magnitude vibmode accepts ({}); rescale the data (another unit) or remove the bad samples", quoted(.channel), num(.value), num(&SAMPLE_ABS_MAX))]
    SampleTooLarge {
        /// Channel name.
        channel: String,
        /// 0-based sample index.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A channel whose largest magnitude is below [`SAMPLE_PEAK_MIN`] but not zero.
    #[error("channel '{}' peaks at {}, below the smallest magnitude vibmode accepts ({}); rescale the data (another unit)", quoted(.channel), num(.peak), num(&SAMPLE_PEAK_MIN))]
    SamplesTooSmall {
        /// Channel name.
        channel: String,
        /// Largest |sample|.
        peak: f64,
    },
    /// More channels than [`CHANNELS_MAX`](crate::limits::CHANNELS_MAX).
    #[error("{} has {count} channels; vibmode reads at most {max}: select the columns you need or split the file", quoted(.what))]
    TooManyChannels {
        /// Where.
        what: String,
        /// Number found.
        count: usize,
        /// The limit.
        max: usize,
    },
    /// A channel name not present in the recording.
    #[error("no channel named '{}'; available: {}{hint}", quoted(.name), quoted(.available))]
    UnknownChannel {
        /// The requested name.
        name: String,
        /// Comma-separated list of the available names.
        available: String,
        /// `"; did you mean 'X'?"` when exactly one name starts with the requested one (ignoring
        /// case), else empty.
        hint: String,
    },
    /// A channel index out of range.
    #[error(
        "channel index {index} is out of range: there are {count} channels (0-based: {})",
        quoted(.available)
    )]
    ChannelIndex {
        /// The requested 0-based index.
        index: usize,
        /// Number of channels.
        count: usize,
        /// "0=x, 1=y, 2=z".
        available: String,
    },
    /// An empty channel selector string.
    #[error("empty channel selector; give a channel name or a 0-based index")]
    EmptySelector,
    /// A channel selected twice (by name or index): it would be analysed twice.
    #[error("channel '{}' (index {index}) is selected twice; select each channel once", quoted(.name))]
    DuplicateChannel {
        /// The channel's name.
        name: String,
        /// Its 0-based index.
        index: usize,
    },
    /// Two channels of one recording with the same name: selections and results are by name.
    #[error("channels {} and {} are both named '{}'; give each channel its own name (in the file's header or its sidecar)", .first + 1, .second + 1, quoted(.name))]
    SameName {
        /// The name.
        name: String,
        /// 0-based index of the first channel with it.
        first: usize,
        /// 0-based index of the second.
        second: usize,
    },
    /// Channels of different lengths in one recording.
    #[error("channel '{}' has {found} samples but '{}' has {expected}; all channels must have the same length", quoted(.channel), quoted(.first))]
    LengthMismatch {
        /// Offending channel.
        channel: String,
        /// Its length.
        found: usize,
        /// The first channel's name.
        first: String,
        /// The first channel's length.
        expected: usize,
    },
    /// A sample range outside the recording.
    #[error(
        "sample range {start}..{end} is invalid: need start < end <= {len} (the number of samples)"
    )]
    InvalidRange {
        /// First sample asked for.
        start: usize,
        /// One past the last sample asked for.
        end: usize,
        /// Number of samples in the recording.
        len: usize,
    },
}

/// A parameter outside its valid range, or a name that is not one of the valid ones.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParamError {
    /// A value out of range.
    #[error("{name} = {value} {requirement}; use e.g. {name} = {suggestion}")]
    OutOfRange {
        /// Parameter name as in the params struct (and the TOML key).
        name: &'static str,
        /// The offending value, formatted.
        value: String,
        /// The rule it breaks, e.g. "must be > 0".
        requirement: &'static str,
        /// A valid value (usually the default).
        suggestion: String,
    },
    /// A name that is not one of the valid ones (a preset, a model, a corner...).
    #[error("unknown {what} '{}'; valid: {valid}", quoted(.value))]
    UnknownName {
        /// What was being named.
        what: &'static str,
        /// The text given.
        value: String,
        /// The valid names.
        valid: &'static str,
    },
    /// A value out of a range that depends on the data (the record length, the rate, the
    /// channels), so that the rule and the valid example are worked out for it.
    #[error("{name} = {value} must be {rule}")]
    OutOfRangeHere {
        /// Parameter name as in the params struct (and the TOML key).
        name: &'static str,
        /// The offending value, formatted.
        value: String,
        /// The rule with the data's numbers and a valid value, e.g. "at least 0.02 s here
        /// (...), e.g. 10.24".
        rule: String,
    },
}

impl ParamError {
    /// Shorthand for [`ParamError::OutOfRange`].
    pub fn out_of_range(
        name: &'static str,
        value: impl ToString,
        requirement: &'static str,
        suggestion: impl ToString,
    ) -> ParamError {
        ParamError::OutOfRange {
            name,
            value: value.to_string(),
            requirement,
            suggestion: suggestion.to_string(),
        }
    }
}
