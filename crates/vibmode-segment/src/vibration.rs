//! Records cut where the vibration says the vehicle drives steadily (no GPS).
//!
//! One pass over the stream: the signals are low-passed at 8 Hz and decimated by
//! `floor(fs / 20)` with the streaming FIR ([`vibmode_signal::FirDecimator`]; recordings below
//! 40 Hz are used as they are), then cut into windows of `window_s`. Per window and channel: the
//! mean (the content below about 1 / window_s Hz) and the RMS about the mean (the activity in
//! about 1-8 Hz, where road input moves body and axles; an idling engine's lines lie above).
//! - **Stop or idling**: the window's activity, per channel relative to that channel's median
//!   window and then the median over channels, is below `stop_activity_ratio`.
//! - **Strong manoeuvre**: on a longitudinal or lateral channel (named `x`, `y`, `*_x`, `*_y`,
//!   `x-*`, `y-*`, `long*`, `lat*`), the window mean departs from the channel's median window mean
//!   (its static offset: gravity, mounting) by more than `manoeuvre_mps2` (converted when the
//!   unit is `g`).
//! - Windows within `guard_s` of either are skipped too; the remaining runs of steady windows are
//!   cut into consecutive records (the rest of each run is a remainder).

use crate::plan::{check_length, empty_segmentation, record_at, recording_start};
use crate::{push_skip, SegmentError, SegmentParams, Segmentation, SkipReason};
use serde::{Deserialize, Serialize};
use vibmode_signal::{FirDecimator, FrameStream, StreamResampleParams, DEFAULT_BLOCK_FRAMES};

/// The vibration state of one window.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VibrationWindow {
    /// Start, s.
    pub start_s: f64,
    /// Broadband activity relative to the median window (median over channels).
    pub activity: f64,
    /// Largest departure of a longitudinal/lateral window mean from its median, m/s^2 (`None`
    /// without such channels).
    pub manoeuvre_mps2: Option<f64>,
    /// `None` when steady, else why the window is skipped.
    pub skip: Option<SkipReason>,
}

/// Upper edge of the activity band, Hz.
pub const ACTIVITY_MAX_HZ: f64 = 8.0;

fn is_longitudinal_or_lateral(name: &str) -> bool {
    let n = name.trim().to_ascii_lowercase();
    n == "x"
        || n == "y"
        || n.ends_with("_x")
        || n.ends_with("_y")
        || n.starts_with("x-")
        || n.starts_with("y-")
        || n.starts_with("x ")
        || n.starts_with("y ")
        || n.starts_with("long")
        || n.starts_with("lat")
}

use vibmode_core::stats::median_in_place as median;

/// Segments the recording read from `stream` by its vibration (see the module documentation);
/// also returns the state of every window.
pub fn by_vibration(
    stream: &mut FrameStream,
    record_length_s: f64,
    p: &SegmentParams,
) -> Result<(Segmentation, Vec<VibrationWindow>), SegmentError> {
    p.validate(record_length_s)?;
    // The record length against the rate first (no duration yet), then the window against it.
    p.check_work(record_length_s, stream.info().fs_hz, 0.0, false)?;
    if p.window_s > record_length_s {
        return Err(crate::invalid(
            "window_s",
            p.window_s,
            format!(
                "at most the record length ({} s; window_s defaults to 1): give a longer record length or a shorter window_s",
                vibmode_core::Num(record_length_s)
            ),
        ));
    }
    let info = stream.info().clone();
    let nch = info.n_channels();
    let check_cells = |n_windows: f64| {
        if n_windows * nch as f64 > crate::VIBRATION_CELLS_MAX {
            Err(crate::invalid(
                "window_s",
                p.window_s,
                format!(
                    "long enough for at most {} windows x channels ({} channels here; a window is at least 2 samples at about 20 Hz), e.g. 1",
                    crate::VIBRATION_CELLS_MAX,
                    nch
                ),
            ))
        } else {
            Ok(())
        }
    };
    if let Some(n) = info.n_frames {
        let duration_s = check_length(&info, n, record_length_s)?;
        p.check_work(record_length_s, info.fs_hz, duration_s, false)?;
    }
    // Road-induced body and axle motion lies below ~8 Hz; an idling engine's lines lie above
    // (Bratislava bus: 0.5-8 Hz RMS falls to 0.15-0.4 of the median at a stop, 8-40 Hz does not).
    let factor = (info.fs_hz / 20.0).floor().max(1.0);
    let mut fir = if factor >= 2.0 {
        FirDecimator::new(
            info.fs_hz,
            nch,
            &StreamResampleParams {
                fs_out_hz: info.fs_hz / factor,
                cutoff_hz: Some(ACTIVITY_MAX_HZ),
                ..StreamResampleParams::default()
            },
        )
        .ok()
    } else {
        None
    };
    let fs_d = fir.as_ref().map_or(info.fs_hz, FirDecimator::fs_out_hz);
    let win_n = ((p.window_s * fs_d).round() as usize).max(2);
    if let Some(n) = info.n_frames {
        // Windows of win_n decimated samples.
        check_cells(n as f64 / info.fs_hz * fs_d / win_n as f64)?;
    }
    let mut pending: Vec<Vec<f64>> = vec![Vec::new(); nch];
    // Per window: per channel (mean, rms about the mean).
    let mut stats: Vec<Vec<(f64, f64)>> = Vec::new();
    let consume = |pending: &mut Vec<Vec<f64>>, stats: &mut Vec<Vec<(f64, f64)>>| {
        let have = pending.first().map_or(0, Vec::len);
        let full = have / win_n;
        for w in 0..full {
            stats.push(
                pending
                    .iter()
                    .map(|d| {
                        let s = &d[w * win_n..(w + 1) * win_n];
                        let m = s.iter().sum::<f64>() / win_n as f64;
                        let r = (s.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / win_n as f64)
                            .sqrt();
                        (m, r)
                    })
                    .collect(),
            );
        }
        for d in pending.iter_mut() {
            d.drain(..full * win_n);
        }
    };
    while let Some(b) = stream.next_block(DEFAULT_BLOCK_FRAMES)? {
        let y = match fir.as_mut() {
            Some(f) => f.process(&b.channels)?,
            None => b.channels,
        };
        for (d, c) in pending.iter_mut().zip(y) {
            d.extend_from_slice(&c);
        }
        consume(&mut pending, &mut stats);
        check_cells(stats.len() as f64)?;
    }
    if let Some(f) = fir.as_mut() {
        for (d, c) in pending.iter_mut().zip(f.finish()) {
            d.extend_from_slice(&c);
        }
        consume(&mut pending, &mut stats);
    }
    let n_frames = stream.position();
    let duration_s = check_length(&info, n_frames, record_length_s)?;
    p.check_work(record_length_s, info.fs_hz, duration_s, false)?;
    let start_unix = recording_start(&info)?;
    let window_s = win_n as f64 / fs_d;
    let nw = stats.len();
    // Activity relative to each channel's median window.
    let med_rms: Vec<f64> = (0..nch)
        .map(|c| median(&mut stats.iter().map(|w| w[c].1).collect::<Vec<_>>()))
        .collect();
    let med_mean: Vec<f64> = (0..nch)
        .map(|c| median(&mut stats.iter().map(|w| w[c].0).collect::<Vec<_>>()))
        .collect();
    let xy: Vec<(usize, f64)> = info
        .names
        .iter()
        .enumerate()
        .filter(|(_, n)| is_longitudinal_or_lateral(n))
        .map(|(c, _)| {
            let unit = info.units[c].trim().to_ascii_lowercase();
            let to_mps2 = if unit == "g" { 9.80665 } else { 1.0 };
            (c, to_mps2)
        })
        .collect();
    let mut windows: Vec<VibrationWindow> = stats
        .iter()
        .enumerate()
        .map(|(w, s)| {
            let mut rel: Vec<f64> = (0..nch)
                .map(|c| {
                    if med_rms[c] > 0.0 {
                        s[c].1 / med_rms[c]
                    } else {
                        1.0
                    }
                })
                .collect();
            let activity = median(&mut rel);
            let man = xy
                .iter()
                .map(|&(c, k)| (s[c].0 - med_mean[c]).abs() * k)
                .fold(None, |a: Option<f64>, v| Some(a.map_or(v, |a| a.max(v))));
            let skip = if activity < p.stop_activity_ratio {
                Some(SkipReason::StopOrIdle)
            } else if man.is_some_and(|m| m > p.manoeuvre_mps2) {
                Some(SkipReason::Manoeuvre)
            } else {
                None
            };
            VibrationWindow {
                start_s: w as f64 * window_s,
                activity,
                manoeuvre_mps2: man,
                skip,
            }
        })
        .collect();
    // Guard windows next to stops and manoeuvres (a prefix count of the bad windows: one pass
    // whatever guard_s is).
    let guard = (p.guard_s / window_s).ceil().min(nw as f64) as usize;
    let mut n_bad = Vec::with_capacity(nw + 1);
    n_bad.push(0usize);
    for win in &windows {
        n_bad.push(n_bad[n_bad.len() - 1] + usize::from(win.skip.is_some()));
    }
    for (w, win) in windows.iter_mut().enumerate() {
        if win.skip.is_some() {
            continue;
        }
        let lo = w.saturating_sub(guard);
        let hi = (w + guard + 1).min(nw);
        if n_bad[hi] > n_bad[lo] {
            win.skip = Some(SkipReason::Transition);
        }
    }
    let mut seg = empty_segmentation(
        &info,
        crate::SegmentMethod::Vibration,
        duration_s,
        record_length_s,
        p,
        start_unix,
    );
    let mut w = 0;
    while w < nw {
        if let Some(r) = windows[w].skip {
            push_skip(
                &mut seg.skipped,
                w as f64 * window_s,
                (w + 1) as f64 * window_s,
                r,
            );
            w += 1;
            continue;
        }
        let a = w;
        while w < nw && windows[w].skip.is_none() {
            w += 1;
        }
        let (start, end) = (a as f64 * window_s, w as f64 * window_s);
        let mut t = start;
        while t + record_length_s <= end + 1e-9 {
            seg.records
                .push(record_at(info.fs_hz, t, record_length_s, start_unix));
            t += record_length_s;
        }
        push_skip(&mut seg.skipped, t, end, SkipReason::Remainder);
    }
    push_skip(
        &mut seg.skipped,
        nw as f64 * window_s,
        duration_s,
        SkipReason::Remainder,
    );
    seg.tally();
    Ok((seg, windows))
}
