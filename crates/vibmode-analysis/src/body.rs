//! Stage 3c, body modes by SSI-cov beyond each record's wheelbase delay.
//!
//! A vehicle's rear wheels run over the road its front wheels met `wheelbase / speed` earlier,
//! so its excitation is correlated with itself at that delay, and SSI-cov from lag 1 merges
//! body heave and pitch (docs/ssi.md). Here every record's delay is measured (the peak of the
//! cross-correlation of a front and a rear wheel channel on the same side), the records are
//! resampled to a low rate that keeps the body band only, and each record's Toeplitz matrix
//! begins beyond its own delay: there the correlations are free decays of the modes. Records
//! driven at different speeds then excite heave and pitch in different proportions, and the
//! pooled correlations separate them; this needs hours of driving, not minutes.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use vibmode_core::{BodySsiParams, ClusterParams, Corner, Direction, PreprocessParams, Role};
use vibmode_signal::Preprocessed;

use crate::lines::{LineStage, LineTrack};
use crate::multichannel::{SsiAnalysis, SsiStage};
use crate::{AnalysisConfig, AnalysisError};

/// One record's front-to-rear delay.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordDelay {
    /// The measured delay, s (`None` when the record is left out).
    pub delay_s: Option<f64>,
    /// Peak of the normalised front/rear cross-correlation (mean over the pairs).
    pub correlation: f64,
    /// First lag of the record's Toeplitz matrix, samples at the body rate.
    pub first_lag: Option<usize>,
    /// Why the record is left out, when it is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub left_out: Option<String>,
}

/// What the body-band SSI-cov found.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BodySsi {
    /// Rate the records were resampled to, Hz.
    pub fs_hz: f64,
    /// The front/rear wheel channels whose cross-correlation gave the delays.
    pub delay_pairs: Vec<[String; 2]>,
    /// Per record (all records, in order; stationary ones left out).
    pub delays: Vec<RecordDelay>,
    /// Records used.
    pub n_records: usize,
    /// Their total duration, s.
    pub duration_s: f64,
    /// The identification, clusters and matches (every pole has record 0: one pooled
    /// identification).
    pub analysis: SsiAnalysis,
}

/// The pairs of vertical wheel channels (front, rear) on the same side, by index.
pub fn delay_pairs(pre: &Preprocessed, cfg: &AnalysisConfig) -> Vec<(usize, usize)> {
    let chans = &pre.recording.channels;
    let find = |corner: Corner| {
        chans.iter().position(|c| {
            let p = cfg.placement_of(c);
            p.role == Role::Unsprung
                && p.corner == Some(corner)
                && matches!(p.direction, None | Some(Direction::Z))
        })
    };
    [(Corner::FL, Corner::RL), (Corner::FR, Corner::RR)]
        .into_iter()
        .filter_map(|(f, r)| Some((find(f)?, find(r)?)))
        .collect()
}

/// The lag (s) at which `rear` best repeats `front` within `(0, max_delay_s]`, by the
/// phase-transform generalised cross-correlation (GCC-PHAT) in `band_hz`: each pair's
/// cross-spectrum (one Hann-windowed segment of the whole record, zero-padded to twice its
/// length) divided by its magnitude, so that the wheels' resonance and the engine lines do not
/// dominate, then `c(tau) = mean over bins and pairs of cos(phase + 2 pi f tau)` on a grid of
/// `1 / (4 fs_hz)`; `c` is 1 for an exact copy and near 0 for unrelated signals. Returns the
/// delay and `c` there; `None` when a channel is constant, too short or not finite.
pub fn front_rear_delay(
    pairs: &[(&[f64], &[f64])],
    fs_hz: f64,
    max_delay_s: f64,
    band_hz: [f64; 2],
) -> Option<(f64, f64)> {
    let n = pairs.first()?.0.len();
    if n < 16 || max_delay_s.is_nan() || max_delay_s <= 0.0 {
        return None;
    }
    let wp = vibmode_spectra::WelchParams {
        nperseg: Some(n),
        noverlap: Some(0),
        nfft: Some((2 * n).next_power_of_two()),
        ..Default::default()
    };
    let mut bins: Vec<(f64, f64)> = Vec::new(); // (frequency Hz, phase)
    for (f, r) in pairs {
        if f.len() != n || r.len() != n {
            return None;
        }
        let s = vibmode_spectra::csd(f, r, fs_hz, &wp).ok()?;
        let mut any = false;
        for (fr, c) in s.freq_hz.iter().zip(&s.csd) {
            if *fr >= band_hz[0] && *fr <= band_hz[1] && c.norm() > 0.0 && c.norm().is_finite() {
                bins.push((*fr, c.arg()));
                any = true;
            }
        }
        if !any {
            return None;
        }
    }
    // csd = conj(F) R: a rear that is the front `tau` later has the phase -2 pi f tau.
    let step = 1.0 / (4.0 * fs_hz);
    let n_tau = (max_delay_s / step).floor() as usize;
    let c = phase_sums(&bins, step, n_tau);
    let (k, best) = (1..=n_tau)
        .map(|k| (k, c[k] / bins.len() as f64))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    Some((k as f64 * step, best))
}

/// `c[k] = sum over bins of cos(phase + 2 pi f k step)` for `k = 1..=n_tau` (`c[0]` = 0): each
/// bin's phasor `exp(i (phase + 2 pi f k step))` turned by `exp(i 2 pi f step)` from one `k` to
/// the next (one complex product instead of a cosine), taken afresh from its angle every
/// `RESEED` steps so that rounding cannot build up.
fn phase_sums(bins: &[(f64, f64)], step: f64, n_tau: usize) -> Vec<f64> {
    const RESEED: usize = 64;
    let mut c = vec![0.0f64; n_tau + 1];
    let tau_step = 2.0 * std::f64::consts::PI * step;
    for &(f, ph) in bins {
        let (ws, wc) = (tau_step * f).sin_cos();
        let (mut zr, mut zi) = (0.0f64, 0.0f64);
        for (k, ck) in c.iter_mut().enumerate().skip(1) {
            if (k - 1) % RESEED == 0 {
                let (s, co) = (ph + tau_step * f * k as f64).sin_cos();
                (zr, zi) = (co, s);
            } else {
                (zr, zi) = (zr * wc - zi * ws, zr * ws + zi * wc);
            }
            *ck += zr;
        }
    }
    c
}

/// Lower edge of the band of the delay's cross-correlation, Hz: below it the body's own
/// motion, common to front and rear, dominates the wheels' channels.
pub const DELAY_BAND_LOW_HZ: f64 = 2.0;

/// Why the body-band SSI-cov did not run (`results.json`'s `body_ssi_not_run` is its text).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BodySsiNotRun {
    /// `[body_ssi] enabled = false`.
    #[error("switched off ([body_ssi] enabled = false)")]
    SwitchedOff,
    /// No record was given.
    #[error("no records")]
    NoRecords,
    /// No front and rear wheel channel on one side.
    #[error("no wheel channels at a front and a rear corner of one side (FL and RL, or FR and RR) to measure the wheelbase delay; give them the role unsprung and their corners")]
    NoWheelPair,
    /// No record has a measured delay; `example` is one record's reason.
    #[error("no record with a measured wheelbase delay (e.g. {example})")]
    NoDelay {
        /// Why one record was left out.
        example: String,
    },
    /// A record could not be resampled to the body rate.
    #[error("resampling to {fs_hz} Hz: {source}")]
    Resampling {
        /// The body rate, Hz.
        fs_hz: f64,
        /// The resampler's error.
        source: vibmode_signal::SignalError,
    },
}

pub(crate) struct BodyStage<'a> {
    pub pre: &'a [Preprocessed],
    pub active: &'a [Option<usize>],
    pub cfg: &'a AnalysisConfig,
    pub cluster: &'a ClusterParams,
}

impl BodyStage<'_> {
    /// Runs the stage; `Ok(Err(why))` when it cannot (no wheel pair, no record with a delay,
    /// too short records), which the analysis reports instead of the modes.
    pub fn run(
        &self,
        lines: &LineStage<'_>,
        tracks: &[LineTrack],
        other_tracks: &[LineTrack],
        reference: &[vibmode_core::ReferenceMode],
    ) -> Result<Result<BodySsi, BodySsiNotRun>, AnalysisError> {
        let p: &BodySsiParams = &self.cfg.body_ssi;
        let Some(first) = self.pre.first() else {
            return Ok(Err(BodySsiNotRun::NoRecords));
        };
        let pairs = delay_pairs(first, self.cfg);
        if pairs.is_empty() {
            return Ok(Err(BodySsiNotRun::NoWheelPair));
        }
        let names = |i: usize| first.recording.channels[i].name.clone();
        let delay_pairs: Vec<[String; 2]> =
            pairs.iter().map(|&(f, r)| [names(f), names(r)]).collect();
        let body_pre = PreprocessParams {
            cutoff_hz: 0.4 * p.fs_hz,
            analysis_fs_hz: p.fs_hz,
        };
        let i = p.block_rows;
        let mut delays = Vec::with_capacity(self.pre.len());
        // The records used (active ones), resampled to the body rate, and each one's first lag:
        // a stop is neither resampled nor identified.
        let mut low = Vec::with_capacity(self.pre.len());
        let mut lags = Vec::with_capacity(self.pre.len());
        let left = |why: String, corr: f64| RecordDelay {
            delay_s: None,
            correlation: corr,
            first_lag: None,
            left_out: Some(why),
        };
        // Each record's delay and resampling depend on that record only: in parallel, then
        // taken in record order (the first resampling failure in order is the one reported).
        type Outcome = (
            RecordDelay,
            Option<usize>,
            Result<vibmode_signal::Preprocessed, BodySsiNotRun>,
        );
        let outcomes: Vec<Option<Outcome>> = self
            .pre
            .par_iter()
            .enumerate()
            .map(|(r, pr)| {
                // A stop (no active index) is neither resampled nor identified.
                self.active.get(r).copied().flatten()?;
                let resampled = vibmode_signal::preprocess(&pr.recording, &body_pre).map_err(|e| {
                    BodySsiNotRun::Resampling {
                        fs_hz: p.fs_hz,
                        source: e,
                    }
                });
                let fs = pr.band.fs_hz;
                let sig: Vec<(&[f64], &[f64])> = pairs
                    .iter()
                    .map(|&(f, b)| {
                        (
                            pr.recording.channels[f].samples.as_slice(),
                            pr.recording.channels[b].samples.as_slice(),
                        )
                    })
                    .collect();
                let band = [DELAY_BAND_LOW_HZ, pr.band.valid_max_hz()];
                let (d, l) = match front_rear_delay(&sig, fs, p.max_delay_s, band) {
                    None => (
                        left("a wheel channel is constant or too short".into(), f64::NAN),
                        None,
                    ),
                    Some((_, corr)) if corr < p.min_delay_correlation => (
                        left(
                            format!(
                                "front/rear correlation {corr:.2} below min_delay_correlation {}",
                                p.min_delay_correlation
                            ),
                            corr,
                        ),
                        None,
                    ),
                    Some((delay, corr)) => {
                        let lag = p.first_lag(delay);
                        let n = resampled.as_ref().map_or(0, |x| x.recording.len());
                        if !vibmode_ssi::samples_needed(i, lag).is_some_and(|needed| n >= needed) {
                            (
                                left(
                                    format!(
                                        "{n} samples at {} Hz, too few for the lags {lag}..{} beyond its delay of {delay:.2} s",
                                        p.fs_hz,
                                        lag.saturating_add(2 * i - 2)
                                    ),
                                    corr,
                                ),
                                None,
                            )
                        } else {
                            (
                                RecordDelay {
                                    delay_s: Some(delay),
                                    correlation: corr,
                                    first_lag: Some(lag),
                                    left_out: None,
                                },
                                Some(lag),
                            )
                        }
                    }
                };
                Some((d, l, resampled))
            })
            .collect();
        for outcome in outcomes {
            let Some((d, l, resampled)) = outcome else {
                delays.push(left("stationary".into(), f64::NAN));
                continue;
            };
            let res = match resampled {
                Ok(x) => x,
                Err(why) => return Ok(Err(why)),
            };
            delays.push(d);
            lags.push(l);
            low.push(res);
        }
        let n_records = lags.iter().flatten().count();
        if n_records == 0 {
            let example = delays
                .iter()
                .find_map(|d| d.left_out.clone())
                .unwrap_or_default();
            return Ok(Err(BodySsiNotRun::NoDelay { example }));
        }
        // `low` holds the active records in order: the k-th is active record k.
        let low_active: Vec<Option<usize>> = (0..low.len()).map(Some).collect();
        let duration_s = low
            .iter()
            .zip(&lags)
            .filter(|(_, l)| l.is_some())
            .map(|(x, _)| x.recording.len() as f64 / p.fs_hz)
            .sum();
        let ssi = p.ssi_params();
        let cluster = ClusterParams {
            freq_max_hz: None,
            ..self.cluster.clone()
        }
        .for_band(&low[0].band);
        let pool_records = ssi.pool_records;
        let method = vibmode_ssi::SsiCovIdentifier { params: ssi };
        let stage = SsiStage {
            pre: &low,
            active: &low_active,
            n_active: n_records,
            method: &method,
            pool_records,
            cluster: &cluster,
            drop_band_edge: true,
            first_lags: Some(&lags),
        };
        // Only the model's modes in the body band are matched (the wheels' lie above it).
        let f_max = low[0].band.valid_max_hz();
        let in_band: Vec<vibmode_core::ReferenceMode> = reference
            .iter()
            .filter(|m| m.frequency_hz < f_max)
            .cloned()
            .collect();
        let analysis = stage.run(lines, Some(tracks), other_tracks, &in_band)?;
        Ok(Ok(BodySsi {
            fs_hz: p.fs_hz,
            delay_pairs,
            delays,
            n_records,
            duration_s,
            analysis,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phase_sums_are_the_cosines_summed() {
        // By hand: one bin at 1 Hz, phase 0, step 0.25 s: cos(pi/2 k) = 0, -1, 0, 1, ...
        let c = phase_sums(&[(1.0, 0.0)], 0.25, 4);
        let want = [0.0, 0.0, -1.0, 0.0, 1.0];
        assert!(
            c.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-14),
            "{c:?}"
        );
        // Seeded bins over many steps (past several re-seeds): the direct sum to 1e-12.
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..20 {
            let bins: Vec<(f64, f64)> = (0..50)
                .map(|_| {
                    (
                        2.0 + 20.0 * next(),
                        std::f64::consts::PI * (2.0 * next() - 1.0),
                    )
                })
                .collect();
            let (step, n_tau) = (1.0 / 200.0, 600);
            let c = phase_sums(&bins, step, n_tau);
            for (k, ck) in c.iter().enumerate().skip(1) {
                let direct: f64 = bins
                    .iter()
                    .map(|(f, ph)| (ph + 2.0 * std::f64::consts::PI * f * k as f64 * step).cos())
                    .sum();
                assert!((ck - direct).abs() < 1e-12, "k {k}: {ck} vs {direct}");
            }
        }
    }

    #[test]
    fn the_delay_of_a_copied_signal() {
        // rear = front 37 samples later (0.74 s at 50 Hz), plus a second pair 36 later
        let mut x = 0.3f64;
        let noise: Vec<f64> = (0..3000)
            .map(|_| {
                x = (x * 3.9 * (1.0 - x)).clamp(1e-6, 1.0 - 1e-6);
                x - 0.5
            })
            .collect();
        let front = &noise[100..2100];
        let rear = &noise[63..2063];
        let rear2 = &noise[64..2064];
        let band = [2.0, 20.0];
        let (d, c) = front_rear_delay(&[(front, rear)], 50.0, 3.0, band).unwrap();
        assert!((d - 0.74).abs() < 1e-9, "{d}");
        assert!(c > 0.6, "{c}");
        let (d, _) = front_rear_delay(&[(front, rear), (front, rear2)], 50.0, 3.0, band).unwrap();
        assert!((0.72..=0.74).contains(&d), "between the two: {d}");
        // unrelated signals: a low peak
        let other = &noise[900..2900];
        let (_, c0) = front_rear_delay(&[(front, other)], 50.0, 3.0, band).unwrap();
        assert!(c0 < 0.3, "{c0}");
        assert!(front_rear_delay(&[(&[1.0; 2000], rear)], 50.0, 3.0, band).is_none());
    }
}
