//! The in-memory recording: channels of equally long sample vectors at one sampling rate.

use crate::error::RecordingError;
use crate::placement::Placement;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// One measured signal.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct Channel {
    /// Channel name, e.g. `FL` or `Z-Axis` (without the unit).
    pub name: String,
    /// Unit of the samples, e.g. `m/s^2`; empty if unknown.
    pub unit: String,
    /// The samples, in `unit`, equally spaced at the recording's `fs_hz`.
    pub samples: Vec<f64>,
    /// Where the sensor sits on the vehicle (role, corner, direction); all unknown by default.
    #[serde(default)]
    pub placement: Placement,
}

impl Channel {
    /// A channel with an unknown placement.
    pub fn new(name: impl Into<String>, unit: impl Into<String>, samples: Vec<f64>) -> Channel {
        Channel {
            name: name.into(),
            unit: unit.into(),
            samples,
            placement: Placement::default(),
        }
    }

    /// The same channel with a placement.
    pub fn with_placement(mut self, placement: Placement) -> Channel {
        self.placement = placement;
        self
    }
}

/// Where the sampling rate of a delimited file came from, when it had a time column; for a WAV
/// or raw file whose sidecar gives its `start_time`, that start (`column` `start_time`, the
/// header's rate, `origin_unix_s`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TimeAxis {
    /// Name of the time column in the file (e.g. `Time`).
    pub column: String,
    /// Mean sampling rate derived from the time column, Hz: (n - 1) / (t_last - t_first).
    pub fs_hz: f64,
    /// Relative jitter of the time steps in the file: max |dt - mean dt| / mean dt (dimensionless).
    pub jitter_rel: f64,
    /// Time of the first sample, s.
    pub start_s: f64,
    /// When the time column holds date-times: the Unix time (s, UTC) of its zero, so the first
    /// sample was taken at `origin_unix_s + start_s`. `None` for a time column of numbers.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub origin_unix_s: Option<f64>,
}

impl TimeAxis {
    /// Unix time (s, UTC) of the first sample, when the time column told it.
    pub fn start_unix_s(&self) -> Option<f64> {
        self.origin_unix_s.map(|o| o + self.start_s)
    }
}

/// Checks that no two channel names are equal ([`RecordingError::SameName`] names the first
/// pair, by 0-based index).
pub fn check_unique_names<'a>(
    names: impl IntoIterator<Item = &'a str>,
) -> Result<(), RecordingError> {
    let mut seen: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
    for (k, n) in names.into_iter().enumerate() {
        if let Some(&first) = seen.get(n) {
            return Err(RecordingError::SameName {
                name: n.to_string(),
                first,
                second: k,
            });
        }
        seen.insert(n, k);
    }
    Ok(())
}

/// A multichannel recording at one uniform sampling rate.
///
/// Invariant (checked by [`Recording::new`] and by the readers): `fs_hz` is positive and finite,
/// all channels have the same number of samples, every sample is finite, and no two channels
/// have the same name.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Recording {
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// The channels (the time column of a text file is not a channel).
    pub channels: Vec<Channel>,
    /// Present when the rate was derived from a time column (delimited files).
    pub time_axis: Option<TimeAxis>,
}

/// Selects a channel by 0-based index or by name.
///
/// Parsing (`"2".parse()`): a string of decimal digits is an [`ChannelSelector::Index`]
/// (0-based: `"0"` is the first channel), anything else a [`ChannelSelector::Name`]. A channel
/// literally named `2` can therefore only be selected by its index.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ChannelSelector {
    /// 0-based position among the channels (the time column does not count).
    Index(usize),
    /// Channel name; matched exactly first, then case-insensitively if that is unambiguous.
    Name(String),
}

impl FromStr for ChannelSelector {
    type Err = RecordingError;
    fn from_str(s: &str) -> Result<Self, RecordingError> {
        let t = s.trim();
        if t.is_empty() {
            return Err(RecordingError::EmptySelector);
        }
        if t.bytes().all(|b| b.is_ascii_digit()) {
            if let Ok(i) = t.parse::<usize>() {
                return Ok(ChannelSelector::Index(i));
            }
        }
        Ok(ChannelSelector::Name(t.to_string()))
    }
}

impl fmt::Display for ChannelSelector {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ChannelSelector::Index(i) => write!(f, "{i}"),
            ChannelSelector::Name(n) => write!(f, "{n}"),
        }
    }
}

/// Checks that a sampling rate is positive and finite; `what` names where it came from.
/// Rates outside [`FS_HZ_MIN`](crate::limits::FS_HZ_MIN) to
/// [`FS_HZ_MAX`](crate::limits::FS_HZ_MAX) are refused as well (a unit mistake, and a resource
/// bomb downstream).
pub fn check_fs(fs_hz: f64, what: &str) -> Result<(), RecordingError> {
    if !(fs_hz.is_finite() && fs_hz > 0.0) {
        Err(RecordingError::InvalidSampleRate {
            what: what.to_string(),
            fs_hz,
        })
    } else if !(crate::limits::FS_HZ_MIN..=crate::limits::FS_HZ_MAX).contains(&fs_hz) {
        Err(RecordingError::SampleRateOutOfRange {
            what: what.to_string(),
            fs_hz,
        })
    } else {
        Ok(())
    }
}

impl Recording {
    /// Builds a recording, checking the invariants: `fs_hz` positive and finite, equal channel
    /// lengths, finite samples. `time_axis` is `None`.
    pub fn new(fs_hz: f64, channels: Vec<Channel>) -> Result<Recording, RecordingError> {
        check_fs(fs_hz, "fs_hz")?;
        check_unique_names(channels.iter().map(|c| c.name.as_str()))?;
        if let Some(first) = channels.first() {
            for c in &channels {
                if c.samples.len() != first.samples.len() {
                    return Err(RecordingError::LengthMismatch {
                        channel: c.name.clone(),
                        found: c.samples.len(),
                        first: first.name.clone(),
                        expected: first.samples.len(),
                    });
                }
            }
        }
        check_finite(&channels)?;
        Ok(Recording {
            fs_hz,
            channels,
            time_axis: None,
        })
    }

    /// Number of samples per channel (0 if there are no channels).
    pub fn len(&self) -> usize {
        self.channels.first().map_or(0, |c| c.samples.len())
    }

    /// True if there are no samples (or no channels).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of channels.
    pub fn n_channels(&self) -> usize {
        self.channels.len()
    }

    /// Duration in seconds, `len() / fs_hz` (204 800 samples at 20 kHz: 10.24 s).
    pub fn duration_s(&self) -> f64 {
        self.len() as f64 / self.fs_hz
    }

    /// Time of sample `i` in seconds: `start_s + i / fs_hz` (`start_s` from the time column, else 0).
    pub fn time_s(&self, i: usize) -> f64 {
        self.time_axis.as_ref().map_or(0.0, |t| t.start_s) + i as f64 / self.fs_hz
    }

    /// The channel names, in order.
    pub fn names(&self) -> Vec<&str> {
        self.channels.iter().map(|c| c.name.as_str()).collect()
    }

    /// `"; did you mean 'X'?"` when exactly one channel name starts with `name` (ignoring case).
    fn prefix_hint(&self, name: &str) -> String {
        let lower = name.to_lowercase();
        let hits: Vec<&str> = self
            .channels
            .iter()
            .map(|c| c.name.as_str())
            .filter(|c| !lower.is_empty() && c.to_lowercase().starts_with(&lower))
            .collect();
        match hits.as_slice() {
            [one] => format!("; did you mean '{}'?", crate::limits::quoted(one)),
            _ => String::new(),
        }
    }

    /// Finds a channel by name (exact match first, then unambiguous case-insensitive match).
    pub fn channel(&self, name: &str) -> Option<&Channel> {
        self.position(name).map(|i| &self.channels[i])
    }

    fn position(&self, name: &str) -> Option<usize> {
        if let Some(i) = self.channels.iter().position(|c| c.name == name) {
            return Some(i);
        }
        let lower = name.to_lowercase();
        let hits: Vec<usize> = self
            .channels
            .iter()
            .enumerate()
            .filter(|(_, c)| c.name.to_lowercase() == lower)
            .map(|(i, _)| i)
            .collect();
        if hits.len() == 1 {
            Some(hits[0])
        } else {
            None
        }
    }

    /// A new recording with the selected channels, in the order given (repeats allowed).
    /// An empty selection returns a copy of all channels.
    ///
    /// Errors: unknown name (lists the available names), index out of range.
    pub fn select(&self, sel: &[ChannelSelector]) -> Result<Recording, RecordingError> {
        if sel.is_empty() {
            return Ok(self.clone());
        }
        let mut channels = Vec::with_capacity(sel.len());
        let mut picked: Vec<usize> = Vec::with_capacity(sel.len());
        for s in sel {
            let i = match s {
                ChannelSelector::Index(i) => {
                    if *i >= self.channels.len() {
                        return Err(RecordingError::ChannelIndex {
                            index: *i,
                            count: self.channels.len(),
                            available: self
                                .channels
                                .iter()
                                .enumerate()
                                .map(|(k, c)| format!("{k}={}", c.name))
                                .collect::<Vec<_>>()
                                .join(", "),
                        });
                    }
                    *i
                }
                ChannelSelector::Name(n) => {
                    self.position(n)
                        .ok_or_else(|| RecordingError::UnknownChannel {
                            name: n.clone(),
                            available: self.names().join(", "),
                            hint: self.prefix_hint(n),
                        })?
                }
            };
            if picked.contains(&i) {
                return Err(RecordingError::DuplicateChannel {
                    name: self.channels[i].name.clone(),
                    index: i,
                });
            }
            picked.push(i);
            channels.push(self.channels[i].clone());
        }
        Ok(Recording {
            fs_hz: self.fs_hz,
            channels,
            time_axis: self.time_axis.clone(),
        })
    }

    /// A new recording with samples `start..end` of every channel (e.g. to drop the first 2000
    /// samples of a record). The time axis start moves accordingly.
    ///
    /// Errors: `start >= end` or `end > len()`.
    pub fn slice(&self, start: usize, end: usize) -> Result<Recording, RecordingError> {
        if start >= end || end > self.len() {
            return Err(RecordingError::InvalidRange {
                start,
                end,
                len: self.len(),
            });
        }
        Ok(Recording {
            fs_hz: self.fs_hz,
            channels: self
                .channels
                .iter()
                .map(|c| Channel {
                    name: c.name.clone(),
                    unit: c.unit.clone(),
                    samples: c.samples[start..end].to_vec(),
                    placement: c.placement,
                })
                .collect(),
            time_axis: self.time_axis.as_ref().map(|t| TimeAxis {
                start_s: t.start_s + start as f64 / self.fs_hz,
                ..t.clone()
            }),
        })
    }
}

/// Checks the samples against [`crate::limits`]: every sample finite and at most
/// `SAMPLE_ABS_MAX` in magnitude, a channel not all zeros peaking at `SAMPLE_PEAK_MIN` or more,
/// at most `CHANNELS_MAX` channels. The first bad sample is named.
pub fn check_finite(channels: &[Channel]) -> Result<(), RecordingError> {
    use crate::limits::{CHANNELS_MAX, SAMPLE_ABS_MAX, SAMPLE_PEAK_MIN};
    if channels.len() > CHANNELS_MAX {
        return Err(RecordingError::TooManyChannels {
            what: "the recording".into(),
            count: channels.len(),
            max: CHANNELS_MAX,
        });
    }
    /// Samples per block of the scan: a block is checked without a branch per sample (its
    /// lanes' peaks and one flag), and only a bad block is looked at sample by sample.
    const BLOCK: usize = 8;
    for c in channels {
        let mut lanes = [0.0f64; BLOCK];
        let mut blocks = c.samples.chunks_exact(BLOCK);
        let mut bad_from = None;
        for (b, block) in blocks.by_ref().enumerate() {
            // `!(|v| <= max)` holds for a NaN as well as for an infinity or a huge value.
            let mut ok = true;
            for (lane, &v) in lanes.iter_mut().zip(block) {
                ok &= v.abs() <= SAMPLE_ABS_MAX;
                *lane = lane.max(v.abs());
            }
            if !ok {
                bad_from = Some(b * BLOCK);
                break;
            }
        }
        let tail_from = c.samples.len() - blocks.remainder().len();
        // The first bad sample, in the bad block or the tail (maximum is exact in any order, so
        // the peak is the same as one running maximum's).
        let mut peak = lanes.iter().fold(0.0f64, |m, &v| m.max(v));
        let from = bad_from.unwrap_or(tail_from);
        for (i, &v) in c.samples.iter().enumerate().skip(from) {
            if !v.is_finite() {
                return Err(RecordingError::NonFinite {
                    channel: c.name.clone(),
                    index: i,
                    value: v,
                });
            }
            if v.abs() > SAMPLE_ABS_MAX {
                return Err(RecordingError::SampleTooLarge {
                    channel: c.name.clone(),
                    index: i,
                    value: v,
                });
            }
            peak = peak.max(v.abs());
        }
        if peak > 0.0 && peak < SAMPLE_PEAK_MIN {
            return Err(RecordingError::SamplesTooSmall {
                channel: c.name.clone(),
                peak,
            });
        }
    }
    Ok(())
}

/// A borrowed view of a recording: a sample range of every channel, without copying.
///
/// Record sources hand these to the analysis so that cutting a long recording into records costs
/// no copy of the samples.
#[derive(Clone, Copy, Debug)]
pub struct RecordingView<'a> {
    /// The recording viewed.
    pub recording: &'a Recording,
    /// First sample of the view.
    pub start: usize,
    /// One past the last sample of the view.
    pub end: usize,
}

impl<'a> RecordingView<'a> {
    /// Sampling rate, Hz.
    pub fn fs_hz(&self) -> f64 {
        self.recording.fs_hz
    }

    /// Number of samples per channel in the view.
    pub fn len(&self) -> usize {
        self.end - self.start
    }

    /// True if the view holds no samples.
    pub fn is_empty(&self) -> bool {
        self.end == self.start
    }

    /// Duration of the view in seconds.
    pub fn duration_s(&self) -> f64 {
        self.len() as f64 / self.recording.fs_hz
    }

    /// The samples of channel `i` in the view (`None` for an index out of range).
    pub fn samples(&self, i: usize) -> Option<&'a [f64]> {
        self.recording
            .channels
            .get(i)
            .map(|c| &c.samples[self.start..self.end])
    }

    /// An owned copy of the view (the time axis start moved to the view's first sample).
    pub fn to_recording(&self) -> Recording {
        Recording {
            fs_hz: self.recording.fs_hz,
            channels: self
                .recording
                .channels
                .iter()
                .map(|c| Channel {
                    samples: c.samples[self.start..self.end].to_vec(),
                    ..Channel::new(c.name.clone(), c.unit.clone(), Vec::new())
                        .with_placement(c.placement)
                })
                .collect(),
            time_axis: self.recording.time_axis.as_ref().map(|t| TimeAxis {
                start_s: t.start_s + self.start as f64 / self.recording.fs_hz,
                ..t.clone()
            }),
        }
    }
}

impl Recording {
    /// A borrowed view of samples `start..end` of every channel.
    ///
    /// Errors: `start >= end` or `end > len()`.
    pub fn view(&self, start: usize, end: usize) -> Result<RecordingView<'_>, RecordingError> {
        if start >= end || end > self.len() {
            return Err(RecordingError::InvalidRange {
                start,
                end,
                len: self.len(),
            });
        }
        Ok(RecordingView {
            recording: self,
            start,
            end,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The check one sample at a time, in order: what the blocked scan must give.
    fn check_one_by_one(c: &Channel) -> Result<(), RecordingError> {
        use crate::limits::{SAMPLE_ABS_MAX, SAMPLE_PEAK_MIN};
        let mut peak = 0.0f64;
        for (i, &v) in c.samples.iter().enumerate() {
            let (channel, index, value) = (c.name.clone(), i, v);
            if !v.is_finite() {
                return Err(RecordingError::NonFinite {
                    channel,
                    index,
                    value,
                });
            }
            if v.abs() > SAMPLE_ABS_MAX {
                return Err(RecordingError::SampleTooLarge {
                    channel,
                    index,
                    value,
                });
            }
            peak = peak.max(v.abs());
        }
        if peak > 0.0 && peak < SAMPLE_PEAK_MIN {
            return Err(RecordingError::SamplesTooSmall {
                channel: c.name.clone(),
                peak,
            });
        }
        Ok(())
    }

    /// The blocked scan of `check_finite` names the first bad sample (NaN, infinity, too large)
    /// wherever it lies (in a block, the tail, before a second bad one) and the peak of a
    /// too-small channel, as one sample at a time does: 400 seeded channels of 0 to 40 samples.
    #[test]
    fn blocked_scan_names_the_first_bad_sample_as_one_at_a_time() {
        let mut next = crate::stats::xorshift(0x9e37_79b9_7f4a_7c15);
        let bad = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 2e60, -1e61];
        let (mut errors, mut small) = (0, 0);
        for _ in 0..400 {
            let n = (next() % 41) as usize;
            let scale = if next() % 4 == 0 { 1e-64 } else { 1.0 };
            let mut x: Vec<f64> = (0..n)
                .map(|_| scale * ((next() % 2001) as f64 - 1000.0) / 7.0)
                .collect();
            for _ in 0..(next() % 3) {
                if n > 0 {
                    let i = (next() as usize) % n;
                    x[i] = bad[(next() as usize) % bad.len()];
                }
            }
            let c = Channel::new("z", "m/s^2", x);
            let want = check_one_by_one(&c);
            let got = check_finite(std::slice::from_ref(&c));
            // NaN != NaN: compare the messages, which carry index and value.
            assert_eq!(
                got.as_ref().map_err(|e| e.to_string()),
                want.as_ref().map_err(|e| e.to_string()),
                "{:?}",
                c.samples
            );
            errors += usize::from(want.is_err());
            small += usize::from(matches!(want, Err(RecordingError::SamplesTooSmall { .. })));
        }
        // The draw covers every branch.
        assert!(errors > 100 && small > 20, "{errors} {small}");
    }

    /// Issue 28: `-c 0 -c 0` analysed the same channel twice without a word.
    #[test]
    fn a_channel_selected_twice_is_refused() {
        let rec = Recording::new(
            50.0,
            vec![
                Channel::new("z", "m/s^2", vec![0.0; 4]),
                Channel::new("y\u{1b}[31m", "m/s^2", vec![0.0; 4]),
            ],
        )
        .unwrap();
        for sel in [
            vec![ChannelSelector::Index(0), ChannelSelector::Index(0)],
            vec![ChannelSelector::Index(0), ChannelSelector::Name("z".into())],
            vec![ChannelSelector::Name("Z".into()), ChannelSelector::Index(0)],
        ] {
            let e = rec.select(&sel).unwrap_err();
            assert_eq!(
                e,
                RecordingError::DuplicateChannel {
                    name: "z".into(),
                    index: 0
                }
            );
            assert!(e.to_string().contains("'z' (index 0) is selected twice"));
        }
        let e = rec
            .select(&[ChannelSelector::Index(1), ChannelSelector::Index(1)])
            .unwrap_err()
            .to_string();
        assert!(!e.contains('\u{1b}') && e.contains("'y?[31m'"), "{e}");
        assert!(rec
            .select(&[ChannelSelector::Index(1), ChannelSelector::Index(0)])
            .is_ok());
    }
}
