//! The in-memory recording: channels of equally long sample vectors at one sampling rate.

use crate::error::{Result, SignalError};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// One measured signal.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Channel {
    /// Channel name, e.g. `FL` or `Z-Axis` (without the unit).
    pub name: String,
    /// Unit of the samples, e.g. `m/s^2`; empty if unknown.
    pub unit: String,
    /// The samples, in `unit`, equally spaced at the recording's `fs_hz`.
    pub samples: Vec<f64>,
}

/// Where the sampling rate of a delimited file came from, when it had a time column.
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
}

/// A multichannel recording at one uniform sampling rate.
///
/// Invariant (checked by [`Recording::new`] and by the readers): `fs_hz` is positive and finite,
/// all channels have the same number of samples, and every sample is finite.
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
    type Err = SignalError;
    fn from_str(s: &str) -> Result<Self> {
        let t = s.trim();
        if t.is_empty() {
            return Err(SignalError::EmptySelector);
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

pub(crate) fn check_fs(fs_hz: f64, what: &str) -> Result<()> {
    if fs_hz.is_finite() && fs_hz > 0.0 {
        Ok(())
    } else {
        Err(SignalError::InvalidSampleRate {
            what: what.to_string(),
            fs_hz,
        })
    }
}

impl Recording {
    /// Builds a recording, checking the invariants: `fs_hz` positive and finite, equal channel
    /// lengths, finite samples. `time_axis` is `None`.
    pub fn new(fs_hz: f64, channels: Vec<Channel>) -> Result<Recording> {
        check_fs(fs_hz, "fs_hz")?;
        if let Some(first) = channels.first() {
            for c in &channels {
                if c.samples.len() != first.samples.len() {
                    return Err(SignalError::LengthMismatch {
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
            [one] => format!("; did you mean '{one}'?"),
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
    pub fn select(&self, sel: &[ChannelSelector]) -> Result<Recording> {
        if sel.is_empty() {
            return Ok(self.clone());
        }
        let mut channels = Vec::with_capacity(sel.len());
        for s in sel {
            let i = match s {
                ChannelSelector::Index(i) => {
                    if *i >= self.channels.len() {
                        return Err(SignalError::ChannelIndex {
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
                        .ok_or_else(|| SignalError::UnknownChannel {
                            name: n.clone(),
                            available: self.names().join(", "),
                            hint: self.prefix_hint(n),
                        })?
                }
            };
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
    pub fn slice(&self, start: usize, end: usize) -> Result<Recording> {
        if start >= end || end > self.len() {
            return Err(SignalError::InvalidParam {
                name: "sample range",
                value: format!("{start}..{end}"),
                fix: format!("need start < end <= {} (the number of samples)", self.len()),
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
                })
                .collect(),
            time_axis: self.time_axis.as_ref().map(|t| TimeAxis {
                start_s: t.start_s + start as f64 / self.fs_hz,
                ..t.clone()
            }),
        })
    }
}

pub(crate) fn check_finite(channels: &[Channel]) -> Result<()> {
    for c in channels {
        if let Some(i) = c.samples.iter().position(|v| !v.is_finite()) {
            return Err(SignalError::NonFinite {
                channel: c.name.clone(),
                index: i,
                value: c.samples[i],
            });
        }
    }
    Ok(())
}
