//! The analysis pipeline: records -> resampled channels -> spectra and sweeps -> invariant modes.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use crate::config::{AnalysisConfig, Role, SweepModel};
use crate::AnalysisError;
use vibmode_ident::{ArMethod, ArmaParams, Robust};
use vibmode_modal::{ClusterParams, InvariantMode, ModeMatch, PoleObservation, ReferenceMode};
use vibmode_signal::{Recording, ResampleParams};
use vibmode_spectra::{PeriodogramParams, WelchParams, Window};

/// One record to analyse, with a name for tables (usually the file name and segment).
#[derive(Clone, Debug)]
pub struct RecordInput {
    /// Display name, e.g. `record_03.csv` or `drive.wav [20.48-30.72 s]`.
    pub name: String,
    /// The samples, at their original rate.
    pub recording: Recording,
}

/// Cuts a long recording into consecutive records of `record_length_s` seconds (the remainder
/// shorter than one record is dropped). A recording shorter than one record is returned whole.
pub fn cut_records(name: &str, rec: &Recording, record_length_s: f64) -> Vec<RecordInput> {
    let n_per = (record_length_s * rec.fs_hz).round() as usize;
    let n = rec.len();
    if n_per == 0 || n < 2 * n_per {
        return vec![RecordInput {
            name: name.to_string(),
            recording: rec.clone(),
        }];
    }
    (0..n / n_per)
        .map(|k| {
            let mut r = rec.clone();
            for ch in &mut r.channels {
                ch.samples = ch.samples[k * n_per..(k + 1) * n_per].to_vec();
            }
            r.time_axis = None;
            RecordInput {
                name: format!(
                    "{name} [{:.2}-{:.2} s]",
                    k as f64 * record_length_s,
                    (k + 1) as f64 * record_length_s
                ),
                recording: r,
            }
        })
        .collect()
}

/// Facts about one analysed record.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RecordSummary {
    /// Display name.
    pub name: String,
    /// Original sampling rate, Hz.
    pub fs_hz: f64,
    /// Original number of samples.
    pub n_samples: usize,
    /// Duration, s.
    pub duration_s: f64,
    /// Activity per channel: RMS of the acceleration in `activity_min_hz..cutoff_hz`, from the
    /// record's Welch PSD at the analysis rate (square root of its integral over the band), in
    /// the channel's unit.
    pub activity_rms: Vec<f64>,
    /// Activity relative to the other records: per channel `activity_rms` divided by its median
    /// over all records, then the median over channels (1 = a typical record).
    pub activity_ratio: f64,
    /// True when `activity_ratio < stop_rms_ratio`: the vehicle was (mostly) at rest, the record
    /// is left out of the invariant-mode statistics (its poles are still in `poles`).
    pub stationary: bool,
    /// Why the record is left out of the mode statistics (None = used).
    pub excluded_reason: Option<String>,
}

/// One pole pair of one fit.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct PoleOut {
    /// Record index.
    pub record: usize,
    /// Model order p.
    pub order: usize,
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
}

/// Summary of one fit of the sweep.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct FitSummary {
    /// Record index.
    pub record: usize,
    /// Model order p.
    pub order: usize,
    /// Criterion value at the optimum.
    pub loss: f64,
    /// Innovation variance estimate.
    pub noise_variance: f64,
    /// Whether the search converged.
    pub converged: bool,
    /// Number of poles outside the unit circle.
    pub n_unstable: usize,
    /// Whether the fit failed outright (then the other fields are NaN/0).
    pub failed: bool,
}

/// A model PSD of one order on a frequency grid (for the paper's Fig. 6-7).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ModelPsd {
    /// Model order p.
    pub order: usize,
    /// One-sided density in (unit)^2/Hz on `ChannelAnalysis::model_freq_hz`.
    pub psd: Vec<f64>,
}

/// Everything found for one channel.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ChannelAnalysis {
    /// Channel name.
    pub name: String,
    /// Unit of the samples.
    pub unit: String,
    /// Role on the vehicle.
    pub role: Role,
    /// Welch frequencies, Hz.
    pub welch_freq_hz: Vec<f64>,
    /// Welch PSD averaged over the records used for the modes (stops left out), (unit)^2/Hz.
    pub welch_psd: Vec<f64>,
    /// Periodogram frequencies of the first record, Hz.
    pub periodogram_freq_hz: Vec<f64>,
    /// Periodogram (boxcar, density) of the first record, (unit)^2/Hz.
    pub periodogram_psd: Vec<f64>,
    /// Welch PSD of the first record, (unit)^2/Hz, on `welch_freq_hz`.
    pub welch_psd_first: Vec<f64>,
    /// Frequency grid of the model PSDs, Hz.
    pub model_freq_hz: Vec<f64>,
    /// Model PSDs of the first record at the orders `psd_orders`.
    pub model_psd_first: Vec<ModelPsd>,
    /// Every pole pair of every fit.
    pub poles: Vec<PoleOut>,
    /// Every fit's summary.
    pub fits: Vec<FitSummary>,
    /// Invariant modes of this channel alone.
    pub invariant_modes: Vec<InvariantMode>,
}

/// Modes pooled over all channels of one role.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RoleAnalysis {
    /// The role.
    pub role: Role,
    /// Channels pooled.
    pub channels: Vec<String>,
    /// Invariant modes of the pool.
    pub invariant_modes: Vec<InvariantMode>,
    /// Reference (physical model) modes matched to the invariant structural modes.
    pub matches: Vec<ModeMatch>,
}

/// The whole analysis: every number the report shows.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AnalysisResults {
    /// Settings used.
    pub config: AnalysisConfig,
    /// Records analysed.
    pub records: Vec<RecordSummary>,
    /// Per channel results.
    pub channels: Vec<ChannelAnalysis>,
    /// Per role results.
    pub roles: Vec<RoleAnalysis>,
    /// Physical model modes used for matching (empty without a vehicle model).
    pub reference_modes: Vec<ReferenceMode>,
    /// Number of records marked `stationary` (stops), left out of the mode statistics; the
    /// invariant modes' `record_share` and `order_share` are relative to the other records.
    pub n_stationary: usize,
    /// Number of model fits run.
    pub n_fits: usize,
    /// Number of fits that did not converge.
    pub n_not_converged: usize,
    /// Wall-clock time of the analysis, s.
    pub elapsed_s: f64,
}

struct TaskOut {
    record: usize,
    channel: usize,
    welch: Vec<f64>,
    welch_freq: Vec<f64>,
    periodogram: Option<(Vec<f64>, Vec<f64>)>,
    model_grid: Vec<f64>,
    model_psd: Vec<ModelPsd>,
    poles: Vec<PoleOut>,
    fits: Vec<FitSummary>,
}

/// Highest pole frequency clustered, Hz (see `ClusterConfig::freq_max_hz`), at analysis rate `fs`.
fn freq_max_hz(cfg: &AnalysisConfig, fs: f64) -> f64 {
    let cutoff = cfg.cutoff_hz.min(fs / 2.0);
    cfg.cluster
        .freq_max_hz
        .unwrap_or(if cutoff < 0.95 * fs / 2.0 {
            0.8 * cutoff
        } else {
            cutoff
        })
}

fn cluster_params(cfg: &AnalysisConfig, fs: f64) -> ClusterParams {
    ClusterParams {
        freq_tol_rel: cfg.cluster.freq_tol_rel,
        freq_tol_per_damping: cfg.cluster.freq_tol_per_damping,
        log_damping_tol: cfg.cluster.log_damping_tol,
        min_record_share: cfg.cluster.min_record_share,
        min_order_share: cfg.cluster.min_order_share,
        disturbance_damping_max: cfg.cluster.disturbance_damping_max,
        max_damping_ratio: cfg.cluster.max_damping_ratio,
        freq_min_hz: cfg.cluster.freq_min_hz,
        freq_max_hz: freq_max_hz(cfg, fs),
        disturbance_freq_spread_max: cfg.cluster.disturbance_freq_spread_max,
        ..ClusterParams::default()
    }
}

/// Runs the analysis. `progress(done, total)` is called after each (record, channel) task.
///
/// All records must have the same channel names and sampling rate.
pub fn analyze(
    records: &[RecordInput],
    cfg: &AnalysisConfig,
    reference: &[ReferenceMode],
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<AnalysisResults, AnalysisError> {
    let t0 = Instant::now();
    cfg.validate()?;
    let first = records.first().ok_or_else(|| {
        AnalysisError::Records("no records to analyse; give at least one input file".into())
    })?;
    let names: Vec<String> = first
        .recording
        .channels
        .iter()
        .map(|c| c.name.clone())
        .collect();
    for r in records {
        let rn: Vec<String> = r
            .recording
            .channels
            .iter()
            .map(|c| c.name.clone())
            .collect();
        if rn != names {
            return Err(AnalysisError::Records(format!(
                "record '{}' has channels {:?} but '{}' has {:?}; give files with the same channels or select them with --channel",
                r.name, rn, first.name, names
            )));
        }
        if (r.recording.fs_hz - first.recording.fs_hz).abs() > 1e-9 * first.recording.fs_hz {
            return Err(AnalysisError::Records(format!(
                "record '{}' is sampled at {} Hz but '{}' at {} Hz; resample them to one rate first",
                r.name, r.recording.fs_hz, first.name, first.recording.fs_hz
            )));
        }
    }
    // Resample every record once (all channels), in parallel.
    let rp = ResampleParams {
        to_hz: cfg.analysis_fs_hz,
        cutoff_hz: Some(cfg.cutoff_hz.min(first.recording.fs_hz / 2.0)),
        filter: true,
    };
    // With a non-integer rate ratio the output rate is n_out / duration, which can fall a hair
    // below analysis_fs_hz (e.g. 425.08 Hz -> 49.998 Hz); keep the cutoff below its Nyquist.
    let resampled: Vec<Recording> = records
        .par_iter()
        .map(|r| {
            let planned = vibmode_signal::Resampler::new(r.recording.len(), r.recording.fs_hz, &rp)
                .or_else(|_| {
                    let loose = ResampleParams {
                        cutoff_hz: None,
                        ..rp.clone()
                    };
                    vibmode_signal::Resampler::new(r.recording.len(), r.recording.fs_hz, &loose)
                })?;
            let rp_r = ResampleParams {
                cutoff_hz: rp.cutoff_hz.map(|c| c.min(planned.fs_out_hz() / 2.0)),
                ..rp.clone()
            };
            r.recording.resample(&rp_r)
        })
        .collect::<Result<_, _>>()?;
    let fs = resampled.first().map_or(cfg.analysis_fs_hz, |r| r.fs_hz);
    let n_ch = names.len();
    let tasks: Vec<(usize, usize)> = (0..records.len())
        .flat_map(|r| (0..n_ch).map(move |c| (r, c)))
        .collect();
    let total = tasks.len();
    let done = AtomicUsize::new(0);
    let orders = cfg.orders();
    let outs: Vec<TaskOut> = tasks
        .par_iter()
        .map(|&(r, c)| {
            let y = &resampled[r].channels[c].samples;
            let out = run_task(y, fs, r, c, cfg, &orders);
            let d = done.fetch_add(1, Ordering::SeqCst) + 1;
            progress(d, total);
            out
        })
        .collect::<Result<_, _>>()?;

    // Stops: activity per record and channel, relative to the median over records.
    let activity_rms: Vec<Vec<f64>> = (0..records.len())
        .map(|r| {
            (0..n_ch)
                .map(|c| {
                    outs.iter()
                        .find(|o| o.record == r && o.channel == c)
                        .map_or(f64::NAN, |o| {
                            band_rms(&o.welch_freq, &o.welch, cfg.activity_min_hz, cfg.cutoff_hz)
                        })
                })
                .collect()
        })
        .collect();
    let activity_ratio = activity_ratios(&activity_rms, n_ch);
    let mut stationary: Vec<bool> = activity_ratio
        .iter()
        .map(|&a| cfg.stop_rms_ratio > 0.0 && a < cfg.stop_rms_ratio)
        .collect();
    if stationary.iter().all(|&s| s) {
        // cannot happen with a median reference and a ratio < 1; never drop everything
        stationary.iter_mut().for_each(|s| *s = false);
    }
    // Records used for the modes, renumbered 0..n_active for the clustering.
    let active: Vec<Option<usize>> = {
        let mut k = 0;
        stationary
            .iter()
            .map(|&s| {
                if s {
                    None
                } else {
                    k += 1;
                    Some(k - 1)
                }
            })
            .collect()
    };
    let n_active = active.iter().flatten().count();

    // Assemble per channel.
    let mut channels = Vec::with_capacity(n_ch);
    for (c, name) in names.iter().enumerate() {
        let mine: Vec<&TaskOut> = outs.iter().filter(|o| o.channel == c).collect();
        let welch_freq = mine
            .first()
            .map(|o| o.welch_freq.clone())
            .unwrap_or_default();
        // Averaged over the records used for the modes (stops left out).
        let used: Vec<&&TaskOut> = mine.iter().filter(|o| !stationary[o.record]).collect();
        let mut welch_mean = vec![0.0; welch_freq.len()];
        for o in &used {
            for (m, v) in welch_mean.iter_mut().zip(&o.welch) {
                *m += v / used.len() as f64;
            }
        }
        let first_out = mine.iter().find(|o| o.record == 0);
        let (pf, pp) = first_out
            .and_then(|o| o.periodogram.clone())
            .unwrap_or_default();
        let poles: Vec<PoleOut> = mine.iter().flat_map(|o| o.poles.iter().copied()).collect();
        let fits: Vec<FitSummary> = mine.iter().flat_map(|o| o.fits.iter().copied()).collect();
        let obs = to_observations(&poles, name, cfg.role_of(name), &active);
        let invariant =
            vibmode_modal::find_invariant_modes(&obs, n_active, &orders, &cluster_params(cfg, fs))?;
        channels.push(ChannelAnalysis {
            name: name.clone(),
            unit: first.recording.channels[c].unit.clone(),
            role: cfg.role_of(name),
            welch_freq_hz: welch_freq,
            welch_psd: welch_mean,
            periodogram_freq_hz: pf,
            periodogram_psd: pp,
            welch_psd_first: first_out.map(|o| o.welch.clone()).unwrap_or_default(),
            model_freq_hz: first_out.map(|o| o.model_grid.clone()).unwrap_or_default(),
            model_psd_first: first_out.map(|o| o.model_psd.clone()).unwrap_or_default(),
            poles,
            fits,
            invariant_modes: invariant,
        });
    }
    // Pool per role.
    let mut roles = Vec::new();
    for role in [Role::Sprung, Role::Unsprung, Role::Other] {
        let chans: Vec<&ChannelAnalysis> = channels.iter().filter(|c| c.role == role).collect();
        if chans.is_empty() {
            continue;
        }
        let mut obs = Vec::new();
        for ch in &chans {
            obs.extend(to_observations(&ch.poles, &ch.name, role, &active));
        }
        let invariant =
            vibmode_modal::find_invariant_modes(&obs, n_active, &orders, &cluster_params(cfg, fs))?;
        let matches = if reference.is_empty() {
            Vec::new()
        } else {
            vibmode_modal::match_reference(&invariant, reference, 0.25)
        };
        roles.push(RoleAnalysis {
            role,
            channels: chans.iter().map(|c| c.name.clone()).collect(),
            invariant_modes: invariant,
            matches,
        });
    }
    let n_fits = channels.iter().map(|c| c.fits.len()).sum();
    let n_not_converged = channels
        .iter()
        .flat_map(|c| c.fits.iter())
        .filter(|f| !f.converged)
        .count();
    Ok(AnalysisResults {
        config: cfg.clone(),
        records: records
            .iter()
            .enumerate()
            .map(|(i, r)| RecordSummary {
                name: r.name.clone(),
                fs_hz: r.recording.fs_hz,
                n_samples: r.recording.len(),
                duration_s: r.recording.duration_s(),
                activity_rms: activity_rms[i].clone(),
                activity_ratio: activity_ratio[i],
                stationary: stationary[i],
                excluded_reason: stationary[i].then(|| {
                    format!(
                        "stationary: activity {:.3} x the median record < stop_rms_ratio {}",
                        activity_ratio[i], cfg.stop_rms_ratio
                    )
                }),
            })
            .collect(),
        channels,
        roles,
        reference_modes: reference.to_vec(),
        n_stationary: stationary.iter().filter(|&&s| s).count(),
        n_fits,
        n_not_converged,
        elapsed_s: t0.elapsed().as_secs_f64(),
    })
}

/// Poles of the records in use, with record indices renumbered by `active` (None = left out).
fn to_observations(
    poles: &[PoleOut],
    channel: &str,
    role: Role,
    active: &[Option<usize>],
) -> Vec<PoleObservation> {
    poles
        .iter()
        .filter_map(|p| {
            let record = active.get(p.record).copied().flatten()?;
            Some(PoleObservation {
                frequency_hz: p.frequency_hz,
                damping_ratio: p.damping_ratio,
                order: p.order,
                record,
                channel: channel.to_string(),
                role: Some(role.to_string()),
            })
        })
        .collect()
}

/// RMS in `[f_lo, f_hi]` Hz from a one-sided PSD (unit^2/Hz) on a uniform grid: the square root
/// of the sum of the bins in the band times the bin width. NaN for an empty grid.
pub(crate) fn band_rms(freq_hz: &[f64], psd: &[f64], f_lo: f64, f_hi: f64) -> f64 {
    if freq_hz.len() < 2 {
        return f64::NAN;
    }
    let df = freq_hz[1] - freq_hz[0];
    let power: f64 = freq_hz
        .iter()
        .zip(psd)
        .filter(|(f, _)| **f >= f_lo && **f <= f_hi)
        .map(|(_, p)| p * df)
        .sum();
    power.max(0.0).sqrt()
}

/// Per record: the median over channels of (activity / that channel's median over records).
/// A channel whose median is zero or not finite gives no information and is skipped; a record
/// with no informative channel gets 1 (never a stop).
pub(crate) fn activity_ratios(rms: &[Vec<f64>], n_ch: usize) -> Vec<f64> {
    let medians: Vec<f64> = (0..n_ch)
        .map(|c| {
            let v: Vec<f64> = rms
                .iter()
                .filter_map(|r| r.get(c).copied())
                .filter(|x| x.is_finite())
                .collect();
            if v.is_empty() {
                f64::NAN
            } else {
                vibmode_modal::stats::median(&v)
            }
        })
        .collect();
    rms.iter()
        .map(|r| {
            let ratios: Vec<f64> = r
                .iter()
                .zip(&medians)
                .filter(|(x, m)| x.is_finite() && m.is_finite() && **m > 0.0)
                .map(|(x, m)| x / m)
                .collect();
            if ratios.is_empty() {
                1.0
            } else {
                vibmode_modal::stats::median(&ratios)
            }
        })
        .collect()
}

/// Whether the pole (re, im) has a zero within `tol * (1 - |pole|)` of it.
fn cancelled(re: f64, im: f64, zeros: &[vibmode_ident::Complex64], tol: f64) -> bool {
    let r = (re * re + im * im).sqrt();
    let radius = tol * (1.0 - r).max(0.0);
    zeros
        .iter()
        .any(|z| ((z.re - re).powi(2) + (z.im - im).powi(2)).sqrt() < radius)
}

fn run_task(
    y: &[f64],
    fs: f64,
    record: usize,
    channel: usize,
    cfg: &AnalysisConfig,
    orders: &[usize],
) -> Result<TaskOut, AnalysisError> {
    let wp = WelchParams {
        window: Window::Hann,
        nperseg: Some(cfg.welch_nperseg.min(y.len())),
        ..WelchParams::default()
    };
    let w = vibmode_spectra::welch(y, fs, &wp)?;
    let periodogram = if record == 0 {
        let p = vibmode_spectra::periodogram(y, fs, &PeriodogramParams::default())?;
        Some((p.freq_hz, p.psd))
    } else {
        None
    };
    let model_grid: Vec<f64> = (1..=400).map(|i| i as f64 * fs / 2.0 / 400.0).collect();
    let params = ArmaParams {
        robust: if cfg.robust_factor > 0.0 {
            Robust::Huber {
                factor: cfg.robust_factor,
            }
        } else {
            Robust::Off
        },
        max_iter: cfg.max_iterations,
        tol: cfg.tolerance,
        ..ArmaParams::default()
    };
    let fits: Vec<Result<vibmode_ident::ArmaModel, vibmode_ident::IdentError>> = match cfg.model {
        SweepModel::Arma => vibmode_ident::sweep_arma(y, orders, &params),
        SweepModel::Ar => orders
            .iter()
            .map(|&p| vibmode_ident::fit_ar(y, p, ArMethod::Burg))
            .collect(),
    };
    let mut poles = Vec::new();
    let mut sums = Vec::new();
    let mut model_psd = Vec::new();
    for (&order, fit) in orders.iter().zip(fits) {
        match fit {
            Ok(m) => {
                let ms = m.modes(fs);
                let zeros = if cfg.cluster.pole_zero_tol > 0.0 {
                    m.zeros()
                } else {
                    Vec::new()
                };
                for md in &ms.modes {
                    if cancelled(md.pole_re, md.pole_im, &zeros, cfg.cluster.pole_zero_tol) {
                        continue;
                    }
                    poles.push(PoleOut {
                        record,
                        order,
                        frequency_hz: md.frequency_hz,
                        damping_ratio: md.damping_ratio,
                    });
                }
                if record == 0 && cfg.psd_orders.contains(&order) {
                    model_psd.push(ModelPsd {
                        order,
                        psd: m.model_psd(&model_grid, fs),
                    });
                }
                sums.push(FitSummary {
                    record,
                    order,
                    loss: m.loss,
                    noise_variance: m.noise_variance,
                    converged: m.converged,
                    n_unstable: ms.unstable_poles.len(),
                    failed: false,
                });
            }
            Err(_) => sums.push(FitSummary {
                record,
                order,
                loss: f64::NAN,
                noise_variance: f64::NAN,
                converged: false,
                n_unstable: 0,
                failed: true,
            }),
        }
    }
    Ok(TaskOut {
        record,
        channel,
        welch: w.psd,
        welch_freq: w.freq_hz,
        periodogram,
        model_grid,
        model_psd,
        poles,
        fits: sums,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn band_rms_of_a_flat_psd() {
        // 2 unit^2/Hz on 0, 0.5, ..., 25 Hz; band 1..3 Hz holds bins 1.0..3.0 = 5 bins x 0.5 Hz.
        let f: Vec<f64> = (0..=50).map(|k| k as f64 * 0.5).collect();
        let p = vec![2.0; f.len()];
        assert!((band_rms(&f, &p, 1.0, 3.0) - (2.0f64 * 5.0 * 0.5).sqrt()).abs() < 1e-12);
        assert!(band_rms(&[], &[], 1.0, 3.0).is_nan());
    }

    #[test]
    fn activity_ratio_is_median_over_channels_of_relative_rms() {
        // 3 records x 2 channels; channel medians 2.0 and 10.0.
        let rms = vec![vec![2.0, 10.0], vec![4.0, 30.0], vec![0.2, 1.0]];
        let a = activity_ratios(&rms, 2);
        // record 0: (1, 1) -> 1; record 1: (2, 3) -> 2.5; record 2: (0.1, 0.1) -> 0.1
        assert_eq!(a, vec![1.0, 2.5, 0.1]);
        // A dead channel (all zero) is ignored, not a stop everywhere.
        let rms = vec![vec![2.0, 0.0], vec![0.5, 0.0], vec![2.0, 0.0]];
        assert_eq!(activity_ratios(&rms, 2), vec![1.0, 0.25, 1.0]);
        let rms = vec![vec![0.0], vec![0.0]];
        assert_eq!(activity_ratios(&rms, 1), vec![1.0, 1.0]);
    }
}
