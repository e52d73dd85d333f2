//! Command-line hints for library errors. The libraries name values (`fs_hz`), never flags; the
//! binary knows its flags and adds one short hint to the one-line message.

use vibmode_analysis::AnalysisError;
use vibmode_core::RecordingError;
use vibmode_segment::SegmentError;
use vibmode_signal::SignalError;

/// The flag that fixes `e`, if the error is one a flag fixes.
pub fn hint(e: &anyhow::Error) -> Option<&'static str> {
    for cause in e.chain() {
        if let Some(s) = cause.downcast_ref::<SignalError>() {
            return signal_hint(s);
        }
        if let Some(a) = cause.downcast_ref::<AnalysisError>() {
            return match a {
                AnalysisError::Signal(s) => signal_hint(s),
                AnalysisError::Recording(r) => recording_hint(r),
                AnalysisError::ChannelsDiffer { .. } => {
                    Some("--channel NAME for each channel to keep")
                }
                _ => None,
            };
        }
        if let Some(r) = cause.downcast_ref::<RecordingError>() {
            return recording_hint(r);
        }
        if let Some(s) = cause.downcast_ref::<SegmentError>() {
            return segment_hint(s);
        }
    }
    None
}

fn segment_hint(e: &SegmentError) -> Option<&'static str> {
    match e {
        SegmentError::InvalidParam { name, .. } => Some(match *name {
            "record_length_s" => "--record-length-s SECONDS",
            "gps_offset_s" => "--gps-offset-s SECONDS",
            _ => "set it in the --segment-config file",
        }),
        SegmentError::NoOverlap { .. } => Some("--gps-offset-s SECONDS"),
        SegmentError::Signal(s) => signal_hint(s),
        _ => None,
    }
}

fn signal_hint(e: &SignalError) -> Option<&'static str> {
    match e {
        SignalError::NoSampleRate { .. } => Some("--fs HZ"),
        SignalError::SampleRateMismatch { .. } => Some("drop --fs to use the file's rate"),
        SignalError::NonUniformTime { .. } => Some("--resample-nonuniform"),
        SignalError::Recording(r) => recording_hint(r),
        _ => None,
    }
}

fn recording_hint(e: &RecordingError) -> Option<&'static str> {
    match e {
        RecordingError::UnknownChannel { .. } | RecordingError::ChannelIndex { .. } => {
            Some("--channel NAME|INDEX")
        }
        RecordingError::EmptySelector => Some("e.g. --channel 0"),
        RecordingError::InvalidSampleRate { .. } => Some("e.g. --fs 500"),
        _ => None,
    }
}
