//! What a recording file holds, from one or two streamed passes: format, rate, channels, length, start
//! time, and each channel's range, mean, standard deviation and RMS (`vibmode info`).
//!
//! The file is read block by block ([`open_stream`]), so an hour of 20 kHz data needs the memory
//! of one block: the statistics first, then each channel's sensor checks against its extremes
//! ([`HealthScan`]: exactly what the analysis notes per record), over the first pass's blocks
//! kept in memory up to [`KEEP_PARSED_MAX_VALUES`] samples, else over the file read again. Every check of the
//! readers applies (a NaN or Inf sample is refused, naming its file, channel and frame). A
//! channel whose samples are all one value ([`constant_value`]: a dead or stuck sensor) is
//! marked, and so are a clipped channel and one with held stretches (a logger's dropouts filled
//! with one value); the analysis refuses a constant channel and one that repeats a value over
//! 90 % of its samples.
//!
//! Statistics: `mean` and `std` are the population mean and standard deviation (`numpy.mean`,
//! `numpy.std` with `ddof = 0`), `rms` is `sqrt(mean(x^2))`, each merged over the blocks with
//! Chan's pairwise update (no cancellation of a large mean). Units are the channel's own.
//!
//! [`constant_value`]: vibmode_core::stats::constant_value
//! [`HealthScan`]: vibmode_core::stats::HealthScan

use std::fmt;
use std::path::Path;

use serde::Serialize;

use vibmode_core::stats::{ChannelHealth, HealthScan};

use crate::error::Result;
use crate::read::{Format, ReadOptions};
use crate::stream::{open_stream, FrameBlock, KEEP_PARSED_MAX_VALUES};

/// Frames read per block.
const BLOCK_FRAMES: usize = 65_536;

/// One channel's statistics over the whole file.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct ChannelSummary {
    /// Name, as the readers give it.
    pub name: String,
    /// Unit (empty when the file does not say and none was given).
    pub unit: String,
    /// Smallest sample, in `unit`.
    pub min: f64,
    /// Largest sample, in `unit`.
    pub max: f64,
    /// Mean, in `unit`.
    pub mean: f64,
    /// Population standard deviation (`ddof = 0`), in `unit`.
    pub std: f64,
    /// Root mean square, in `unit`.
    pub rms: f64,
    /// The channel's one value when it carries no vibration (a dead sensor reads 0, a stuck one
    /// a constant), `None` when it varies.
    pub constant: Option<f64>,
    /// Samples at the clipped extreme ([`vibmode_core::stats::clipped`]), 0 when not clipped.
    pub clipped_samples: usize,
    /// The clipped extreme, in `unit`; `None` when not clipped.
    pub clipped_value: Option<f64>,
    /// Samples in held stretches ([`vibmode_core::stats::ChannelHealth::held`], runs of at least
    /// [`vibmode_core::stats::HELD_MIN_S`]), the stretches and the longest, in samples.
    pub held_samples: usize,
    /// Number of held stretches.
    pub held_stretches: usize,
    /// The longest held stretch, samples.
    pub held_longest: usize,
    /// Whether the analysis refuses the channel: constant, or a value repeated (clipped or
    /// held) over [`vibmode_core::stats::REPEATED_SHARE_MAX`] of its samples.
    pub refused_by_analysis: bool,
}

/// What a recording file holds ([`summarize`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct FileSummary {
    /// The file as given.
    pub path: String,
    /// Its format.
    pub format: Format,
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Number of frames (samples per channel).
    pub frames: u64,
    /// `frames / fs_hz`, s.
    pub duration_s: f64,
    /// Time of the first frame on the file's own time axis, s (a time column's first value).
    pub start_s: f64,
    /// The absolute start time from the sidecar (`"start_time"`), as written.
    pub start_time: Option<String>,
    /// The channels, in file order.
    pub channels: Vec<ChannelSummary>,
}

/// Running statistics of one channel.
#[derive(Clone, Copy, Debug)]
struct Acc {
    n: u64,
    min: f64,
    max: f64,
    mean: f64,
    /// Sum of squared deviations from `mean`.
    m2: f64,
}

impl Acc {
    fn new() -> Acc {
        Acc {
            n: 0,
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            mean: 0.0,
            m2: 0.0,
        }
    }

    /// Merges one block (two passes over it, then Chan's update).
    fn add(&mut self, x: &[f64]) {
        if x.is_empty() {
            return;
        }
        let nb = x.len() as f64;
        let mb = x.iter().sum::<f64>() / nb;
        let m2b: f64 = x.iter().map(|v| (v - mb) * (v - mb)).sum();
        let (lo, hi) = vibmode_core::stats::extremes(x);
        self.min = self.min.min(lo);
        self.max = self.max.max(hi);
        let na = self.n as f64;
        let n = na + nb;
        let d = mb - self.mean;
        self.mean += d * nb / n;
        self.m2 += m2b + d * d * na * nb / n;
        self.n += x.len() as u64;
    }

    fn summary(&self, name: String, unit: String, h: &ChannelHealth) -> ChannelSummary {
        let n = self.n.max(1) as f64;
        let var = (self.m2 / n).max(0.0);
        ChannelSummary {
            name,
            unit,
            min: self.min,
            max: self.max,
            mean: self.mean,
            std: var.sqrt(),
            rms: (var + self.mean * self.mean).sqrt(),
            constant: h.constant,
            clipped_samples: h.clipped.map_or(0, |c| c.0),
            clipped_value: h.clipped.map(|c| c.1),
            held_samples: h.held.0,
            held_stretches: h.held.1,
            held_longest: h.held.2,
            refused_by_analysis: h.constant.is_some() || h.is_mostly_repeated(),
        }
    }
}

/// Reads `path` block by block and summarises it (see the module documentation). The sensor
/// checks need each channel's extremes, so they are a second pass: over the blocks of the first,
/// kept in memory when they hold at most [`KEEP_PARSED_MAX_VALUES`] samples (128 MiB, as a text
/// file's stream keeps its parsed blocks), else over the file read again. The options are those
/// of [`crate::read_path`].
///
/// Errors: every error of [`open_stream`] and of reading its blocks (a missing or unreadable
/// file, a malformed row, a NaN or Inf sample, no sampling rate where the file has none).
pub fn summarize(path: &Path, opts: &ReadOptions) -> Result<FileSummary> {
    summarize_keeping(path, opts, KEEP_PARSED_MAX_VALUES)
}

/// [`summarize`], keeping the first pass's blocks for the second when they hold at most
/// `keep_max` samples.
fn summarize_keeping(path: &Path, opts: &ReadOptions, keep_max: usize) -> Result<FileSummary> {
    let mut s = open_stream(path, opts)?;
    let info = s.info().clone();
    let mut acc = vec![Acc::new(); info.n_channels()];
    let mut frames = 0u64;
    let mut kept: Option<Vec<FrameBlock>> = Some(Vec::new());
    let mut kept_values = 0usize;
    while let Some(block) = s.next_block(BLOCK_FRAMES)? {
        frames += block.n_frames() as u64;
        for (a, ch) in acc.iter_mut().zip(&block.channels) {
            a.add(ch);
        }
        if let Some(k) = &mut kept {
            kept_values = kept_values.saturating_add(block.n_frames() * block.channels.len());
            if kept_values <= keep_max {
                k.push(block);
            } else {
                kept = None;
            }
        }
    }
    // The second pass: clipping and held stretches need the channel's extremes.
    let n = usize::try_from(frames).unwrap_or(usize::MAX);
    let min_run = vibmode_core::stats::held_min_run(info.fs_hz);
    let mut scans: Vec<HealthScan> = acc
        .iter()
        .map(|a| HealthScan::new(n, a.min, a.max, min_run))
        .collect();
    let mut push = |block: &FrameBlock| {
        for (h, ch) in scans.iter_mut().zip(&block.channels) {
            h.push(ch);
        }
    };
    match kept {
        Some(blocks) => blocks.iter().for_each(&mut push),
        None => {
            let mut s = open_stream(path, opts)?;
            while let Some(block) = s.next_block(BLOCK_FRAMES)? {
                push(&block);
            }
        }
    }
    let channels = acc
        .iter()
        .zip(scans)
        .zip(info.names.iter().zip(&info.units))
        .map(|((a, h), (name, unit))| a.summary(name.clone(), unit.clone(), &h.finish()))
        .collect();
    Ok(FileSummary {
        path: path.display().to_string(),
        format: info.format,
        fs_hz: info.fs_hz,
        frames,
        duration_s: frames as f64 / info.fs_hz,
        start_s: info.start_s,
        start_time: info.start_time,
        channels,
    })
}

fn format_name(f: Format) -> &'static str {
    match f {
        Format::Delimited => "delimited text",
        Format::Wav => "WAV",
        Format::Raw => "raw samples with a sidecar",
        Format::Npy => "NumPy array",
    }
}

/// `v` with 4 significant digits (plain below 1e5 and from 1e-3, else scientific).
fn num(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if (1e-3..1e5).contains(&a) {
        let digits = (3 - a.log10().floor() as i32).max(0) as usize;
        format!("{v:.digits$}")
    } else {
        format!("{v:.3e}")
    }
}

impl fmt::Display for FileSummary {
    /// A heading line (format, channels, frames, rate, duration, start), then one row per
    /// channel: name, unit, min, max, mean, std, rms, and a note for a constant channel.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // The path whole (a table's heading, not an error's quote), control characters as `?`.
        let path: String = self
            .path
            .chars()
            .map(|c| if c.is_control() { '?' } else { c })
            .collect();
        write!(
            f,
            "{path}: {}, {} channel{}, {} frames at {} Hz ({} s)",
            format_name(self.format),
            self.channels.len(),
            if self.channels.len() == 1 { "" } else { "s" },
            self.frames,
            vibmode_core::num(&self.fs_hz),
            vibmode_core::num(&self.duration_s),
        )?;
        if self.start_s != 0.0 {
            write!(f, ", time axis from {} s", vibmode_core::num(&self.start_s))?;
        }
        match &self.start_time {
            Some(t) => writeln!(f, ", starts {}", vibmode_core::quoted(t))?,
            None => writeln!(f, ", no absolute start time")?,
        }
        let w = self
            .channels
            .iter()
            .map(|c| vibmode_core::quoted(&c.name).to_string().chars().count())
            .max()
            .unwrap_or(0)
            .max("channel".len());
        let u = self
            .channels
            .iter()
            .map(|c| vibmode_core::quoted(&c.unit).to_string().chars().count())
            .max()
            .unwrap_or(0)
            .max("unit".len());
        writeln!(
            f,
            "  {:<w$}  {:<u$}  {:>11} {:>11} {:>11} {:>11} {:>11}",
            "channel", "unit", "min", "max", "mean", "std", "rms"
        )?;
        for c in &self.channels {
            write!(
                f,
                "  {:<w$}  {:<u$}  {:>11} {:>11} {:>11} {:>11} {:>11}",
                vibmode_core::quoted(&c.name).to_string(),
                vibmode_core::quoted(&c.unit).to_string(),
                num(c.min),
                num(c.max),
                num(c.mean),
                num(c.std),
                num(c.rms),
            )?;
            let share = |k: usize| 100.0 * k as f64 / self.frames.max(1) as f64;
            match c.constant {
                Some(0.0) => write!(f, "  all 0: a dead sensor")?,
                Some(v) => write!(f, "  constant {}: a stuck sensor", num(v))?,
                None => {}
            }
            if let Some(v) = c.clipped_value {
                write!(
                    f,
                    "  clipped at {}: {} % of samples",
                    num(v),
                    num(share(c.clipped_samples))
                )?;
            }
            if c.held_stretches > 0 {
                write!(
                    f,
                    "  held: {} stretch{}, {} % of samples, longest {} s",
                    c.held_stretches,
                    if c.held_stretches == 1 { "" } else { "es" },
                    num(share(c.held_samples)),
                    num(c.held_longest as f64 / self.fs_hz)
                )?;
            }
            if c.refused_by_analysis {
                write!(f, " (the analysis refuses it)")?;
            }
            writeln!(f)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_merging_by_hand() {
        // x = 1, 2, 3, 4 in blocks [1, 2] and [3, 4]: mean 2.5, squared deviations 2.25 + 0.25
        // + 0.25 + 2.25 = 5, population variance 1.25, rms sqrt((1 + 4 + 9 + 16) / 4) = sqrt(7.5).
        let mut a = Acc::new();
        a.add(&[1.0, 2.0]);
        a.add(&[]);
        a.add(&[3.0, 4.0]);
        let live = vibmode_core::stats::channel_health(&[1.0, 2.0, 3.0, 4.0], 2);
        let s = a.summary("x".into(), "g".into(), &live);
        assert_eq!((s.min, s.max, s.mean), (1.0, 4.0, 2.5));
        assert!((s.std - 1.25f64.sqrt()).abs() < 1e-15, "{}", s.std);
        assert!((s.rms - 7.5f64.sqrt()).abs() < 1e-15, "{}", s.rms);
        assert_eq!(s.constant, None);
        let dead = vibmode_core::stats::channel_health(&[0.0; 5], 2);
        let mut z = Acc::new();
        z.add(&[0.0; 5]);
        let d = z.summary("d".into(), String::new(), &dead);
        assert_eq!((d.constant, d.refused_by_analysis), (Some(0.0), true));
    }

    #[test]
    fn the_second_pass_from_memory_or_from_the_file_is_the_same() {
        // A clipped channel, a held one and a live one over 200 000 frames (four blocks): the
        // sensor checks over the kept blocks and over the file read again agree.
        let dir = tempfile::tempdir().unwrap();
        let n = 200_000;
        let live: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let clip: Vec<f64> = live.iter().map(|v| v.min(0.8)).collect();
        let mut held = live.clone();
        let v = held[70_000];
        held[65_000..70_000].iter_mut().for_each(|s| *s = v);
        let rec = vibmode_core::Recording {
            fs_hz: 1000.0,
            channels: vec![
                vibmode_core::Channel::new("live", "g", live),
                vibmode_core::Channel::new("clip", "g", clip),
                vibmode_core::Channel::new("held", "g", held),
            ],
            time_axis: None,
        };
        let path = dir.path().join("r.f64");
        crate::write_path(&path, &rec).unwrap();
        let opts = ReadOptions::default();
        let kept = summarize_keeping(&path, &opts, usize::MAX).unwrap();
        let again = summarize_keeping(&path, &opts, 0).unwrap();
        assert_eq!(kept, again);
        assert_eq!(kept, summarize(&path, &opts).unwrap());
        let c = &kept.channels;
        assert_eq!((c[0].clipped_value, c[0].held_stretches), (None, 0));
        assert_eq!(c[1].clipped_value, Some(0.8));
        assert_eq!((c[2].held_stretches, c[2].held_longest), (1, 5001));
    }

    #[test]
    fn numbers_print_with_four_significant_digits() {
        assert_eq!(num(0.0), "0");
        assert_eq!(num(20000.0), "20000");
        assert_eq!(num(10.24), "10.24");
        assert_eq!(num(-0.0123456), "-0.01235");
        assert_eq!(num(1.5e-6), "1.500e-6");
        assert_eq!(num(2.5e7), "2.500e7");
    }
}
