//! `analyze`: the stages composed. Record source -> pre-processing -> spectra and
//! identification -> pole store -> stops -> clustering and classification -> model matching.

use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use vibmode_core::stats::ChannelHealth;
use vibmode_core::{ClusterParams, Identifier, RecordInput, ReferenceMode, Role, SignalFits};
use vibmode_modal::{InvariantMode, MATCH_MAC_MIN, MATCH_MAX_FREQ_DIFF_REL};
use vibmode_signal::{preprocess, Preprocessed};
use vibmode_spectra::{WelchParams, Window};

use crate::body::BodySsiNotRun;
use crate::config::AnalysisConfig;
use crate::identify::SweepIdentifier;
use crate::lines::LineStage;
use crate::multichannel::SsiStage;
use crate::results::{
    sensor_notes, AnalysisResults, ChannelAnalysis, ClippedChannel, HeldChannel, RecordSummary,
    RoleAnalysis, Timing, SCHEMA_VERSION,
};
use crate::stops::{activity_ratios, band_rms, detect_stops};
use crate::store::PoleStore;
use crate::AnalysisError;

/// Welch spectrum and identification of one (record, channel) signal.
struct SignalOut {
    record: usize,
    channel: usize,
    welch_freq: Vec<f64>,
    welch: Vec<f64>,
    fits: SignalFits,
}

/// Checks that all records have the same channels and rate.
pub fn check_records(records: &[RecordInput]) -> Result<(), AnalysisError> {
    let first = records.first().ok_or(AnalysisError::NoRecords)?;
    for r in records {
        check_same_layout(first, r)?;
    }
    Ok(())
}

/// Checks that every channel of `r` varies: a dead or stuck sensor
/// ([`AnalysisError::ChannelConstant`]) would give the modes of the pre-processing's rounding
/// noise, and one that repeats a value over most of its samples
/// ([`AnalysisError::ChannelMostlyRepeated`]: a dead sensor with a spike) those of its glitches.
pub fn check_channels_vary(r: &RecordInput) -> Result<(), AnalysisError> {
    channels_checked(r).map(|_| ())
}

/// The health of every channel of `r`, refused ([`AnalysisError::ChannelConstant`],
/// [`AnalysisError::ChannelMostlyRepeated`]) where a channel carries no vibration.
fn channels_checked(r: &RecordInput) -> Result<Vec<ChannelHealth>, AnalysisError> {
    let min_run = vibmode_core::stats::held_min_run(r.recording.fs_hz);
    r.recording
        .channels
        .iter()
        .map(|ch| {
            let h = vibmode_core::stats::channel_health(&ch.samples, min_run);
            if let Some(value) = h.constant {
                return Err(AnalysisError::ChannelConstant {
                    record: r.name.clone(),
                    channel: ch.name.clone(),
                    value,
                });
            }
            if h.is_mostly_repeated() {
                return Err(AnalysisError::ChannelMostlyRepeated {
                    record: r.name.clone(),
                    channel: ch.name.clone(),
                    share: h.repeated_share(),
                });
            }
            Ok(h)
        })
        .collect()
}

/// Checks that `r` has the channels and rate of `first`.
pub fn check_same_layout(first: &RecordInput, r: &RecordInput) -> Result<(), AnalysisError> {
    let names = first.recording.names();
    if r.recording.names() != names {
        return Err(AnalysisError::ChannelsDiffer {
            record: r.name.clone(),
            channels: r.recording.names().join(", "),
            first: first.name.clone(),
            first_channels: names.join(", "),
        });
    }
    if (r.recording.fs_hz - first.recording.fs_hz).abs() > 1e-9 * first.recording.fs_hz {
        return Err(AnalysisError::RatesDiffer {
            record: r.name.clone(),
            fs_hz: r.recording.fs_hz,
            first: first.name.clone(),
            first_fs_hz: first.recording.fs_hz,
        });
    }
    Ok(())
}

/// Samples per model parameter a fit needs at least: ARMA(p, q) is fitted only when
/// `p + q <= N / 3` (`vibmode_ident::max_arma_order`).
const SAMPLES_PER_PARAMETER: usize = 3;

/// Checks that every pre-processed record is long enough for the lowest order of the sweep
/// (and for a Welch segment of 8 samples).
pub fn check_lengths(
    records: &[RecordInput],
    pre: &[Preprocessed],
    cfg: &AnalysisConfig,
) -> Result<(), AnalysisError> {
    check_lengths_named(records.iter().map(|r| r.name.as_str()), pre, cfg)
}

fn check_lengths_named<'n>(
    names: impl Iterator<Item = &'n str>,
    pre: &[Preprocessed],
    cfg: &AnalysisConfig,
) -> Result<(), AnalysisError> {
    let per_order = match cfg.sweep.model {
        vibmode_core::SweepModel::Arma => 2,
        vibmode_core::SweepModel::Ar => 1,
    };
    let needed = (SAMPLES_PER_PARAMETER * per_order * cfg.sweep.order_min).max(8);
    let names: Vec<&str> = names.collect();
    for (name, p) in names.iter().zip(pre) {
        let n = p.recording.len();
        if n < needed {
            return Err(AnalysisError::RecordTooShort {
                record: name.to_string(),
                n_samples: n,
                fs_hz: p.band.fs_hz,
                duration_s: n as f64 / p.band.fs_hz,
                order_min: cfg.sweep.order_min,
                needed,
                needed_s: needed as f64 / p.band.fs_hz,
            });
        }
    }
    // The highest order must be within reach of the longest record (a short last record only
    // fits the orders it can; orders no record can fit would make every fit above them fail and
    // no cluster reach its share of the orders).
    if let Some((name, p)) = names.iter().zip(pre).max_by_key(|(_, p)| p.recording.len()) {
        let n = p.recording.len();
        let needed_max = SAMPLES_PER_PARAMETER * per_order * cfg.sweep.order_max;
        if n < needed_max {
            return Err(AnalysisError::OrderMaxTooHigh {
                order_max: cfg.sweep.order_max,
                needed: needed_max,
                needed_s: needed_max as f64 / p.band.fs_hz,
                record: name.to_string(),
                n_samples: n,
                fs_hz: p.band.fs_hz,
                duration_s: n as f64 / p.band.fs_hz,
                highest: n / (SAMPLES_PER_PARAMETER * per_order),
            });
        }
    }
    Ok(())
}

/// Stage 2 over every record, in parallel.
pub fn preprocess_records(
    records: &[RecordInput],
    cfg: &AnalysisConfig,
) -> Result<Vec<Preprocessed>, AnalysisError> {
    let recordings: Vec<&vibmode_core::Recording> = records.iter().map(|r| &r.recording).collect();
    preprocess_recordings(&recordings, cfg)
}

/// [`preprocess_records`] of recordings borrowed (a record that is a whole recording needs no
/// [`RecordInput`] owning a copy of its samples).
pub fn preprocess_recordings(
    recordings: &[&vibmode_core::Recording],
    cfg: &AnalysisConfig,
) -> Result<Vec<Preprocessed>, AnalysisError> {
    recordings
        .par_iter()
        .map(|r| preprocess(r, &cfg.preprocess).map_err(AnalysisError::from))
        .collect()
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
    let identifier = SweepIdentifier {
        sweep: cfg.sweep.clone(),
        poles: cfg.poles.clone(),
    };
    analyze_with(records, cfg, &identifier, reference, progress)
}

/// [`analyze`] with another identification method.
pub fn analyze_with(
    records: &[RecordInput],
    cfg: &AnalysisConfig,
    identifier: &dyn Identifier,
    reference: &[ReferenceMode],
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<AnalysisResults, AnalysisError> {
    analyze_keeping_first(records, cfg, identifier, reference, progress).map(|(r, _)| r)
}

/// [`analyze_with`], also returning the first record at the analysis rate as the analysis
/// pre-processed it (what the report draws: [`crate::first_record_spectra`]).
pub fn analyze_keeping_first(
    records: &[RecordInput],
    cfg: &AnalysisConfig,
    identifier: &dyn Identifier,
    reference: &[ReferenceMode],
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<(AnalysisResults, Preprocessed), AnalysisError> {
    let t0 = Instant::now();
    cfg.validate()?;
    check_records(records)?;
    let pre = preprocess_records(records, cfg)?;
    // After the pre-processing's own checks (a rate or a length out of reach is the first thing
    // to fix).
    let facts = records
        .iter()
        .map(RecordFacts::checked)
        .collect::<Result<Vec<_>, _>>()?;
    let first = pre.first().cloned().ok_or(AnalysisError::NoRecords)?;
    let results = analyze_prepared(facts, pre, cfg, identifier, reference, progress, t0)?;
    Ok((results, first))
}

/// What the results keep of a record at its original rate (the samples themselves are not kept).
#[derive(Clone, Debug)]
pub struct RecordFacts {
    /// Display name.
    pub name: String,
    /// Original sampling rate, Hz.
    pub fs_hz: f64,
    /// Original number of samples.
    pub n_samples: usize,
    /// Where the record was cut from a long recording (segmentation), if it was.
    pub meta: Option<vibmode_core::RecordMeta>,
    /// Its channels held at an extreme, as read.
    pub clipped: Vec<ClippedChannel>,
    /// Its channels that hold one value over stretches, as read.
    pub held: Vec<HeldChannel>,
}

impl RecordFacts {
    /// The facts of `r` (no segmentation facts).
    pub fn of(r: &RecordInput) -> RecordFacts {
        Self::of_recording(&r.name, &r.recording)
    }

    /// The facts of the record `name` whose samples are `rec` (no segmentation facts): as
    /// [`RecordFacts::of`] without a [`RecordInput`] that owns them.
    pub fn of_recording(name: &str, rec: &vibmode_core::Recording) -> RecordFacts {
        let (clipped, held) = sensor_notes(rec);
        Self::of_recording_notes(name, rec, clipped, held)
    }

    /// As [`RecordFacts::of_recording`], from each channel's health already taken
    /// (`health[i]` the [`vibmode_core::stats::channel_health`] of `rec.channels[i]` at
    /// [`vibmode_core::stats::held_min_run`] of its rate): one look at the samples for the
    /// caller's checks and these facts.
    pub fn of_recording_health(
        name: &str,
        rec: &vibmode_core::Recording,
        health: &[vibmode_core::stats::ChannelHealth],
    ) -> RecordFacts {
        let (clipped, held) = crate::results::sensor_notes_of(rec, health);
        Self::of_recording_notes(name, rec, clipped, held)
    }

    fn of_recording_notes(
        name: &str,
        rec: &vibmode_core::Recording,
        clipped: Vec<ClippedChannel>,
        held: Vec<HeldChannel>,
    ) -> RecordFacts {
        RecordFacts {
            name: name.to_string(),
            fs_hz: rec.fs_hz,
            n_samples: rec.len(),
            meta: None,
            clipped,
            held,
        }
    }

    /// As [`RecordFacts::of`], refusing a channel that carries no vibration
    /// ([`check_channels_vary`]): one look at each channel for both.
    pub fn checked(r: &RecordInput) -> Result<RecordFacts, AnalysisError> {
        let health = channels_checked(r)?;
        Ok(Self::of_recording_health(&r.name, &r.recording, &health))
    }
}

/// Stages 3-7 on records already pre-processed (`pre[i]` is `facts[i]` at the analysis rate):
/// what [`analyze_with`] runs after stage 2, and what a streamed analysis runs once every record
/// has arrived and been pre-processed.
pub fn analyze_prepared(
    facts: Vec<RecordFacts>,
    pre: Vec<Preprocessed>,
    cfg: &AnalysisConfig,
    identifier: &dyn Identifier,
    reference: &[ReferenceMode],
    progress: &(dyn Fn(usize, usize) + Sync),
    t0: Instant,
) -> Result<AnalysisResults, AnalysisError> {
    if pre.is_empty() {
        return Err(AnalysisError::NoRecords);
    }
    check_lengths_named(facts.iter().map(|f| f.name.as_str()), &pre, cfg)?;
    // The spectra first, then the stops from them, then the identification of the records that
    // are used (and of the first record, whose models the report draws): a stop's sweep would be
    // thrown away.
    let mut outs = spectra_all(&pre, cfg)?;
    let n_ch = pre.first().map_or(0, |p| p.recording.n_channels());
    let activity_rms = record_activity(&outs, facts.len(), n_ch, cfg);
    let activity_ratio = activity_ratios(&activity_rms, n_ch);
    let stationary = detect_stops(&activity_ratio, &cfg.stops);
    let active = renumber_active(&stationary);
    let n_active = active.iter().flatten().count();
    let cluster = cfg.cluster.for_band(&pre[0].band);
    let ssi_method = vibmode_ssi::SsiCovIdentifier {
        params: cfg.ssi.clone(),
    };
    let ssi_stage = SsiStage {
        pre: &pre,
        active: &active,
        n_active,
        method: &ssi_method,
        pool_records: cfg.ssi.pool_records,
        cluster: &cluster,
        drop_band_edge: cfg.poles.drop_band_edge,
        first_lags: None,
    };
    // SSI-cov's identifications need nothing of the sweep: they run beside it (and fill the
    // cores the sweep's last channels leave idle); their clustering and classing come after.
    let ((), ssi_poles) = rayon::join(
        || {
            if cfg.method.runs_arma() {
                identify_used(&pre, &mut outs, &stationary, cfg, identifier, progress);
            }
        },
        || cfg.method.runs_ssi().then(|| ssi_stage.poles()),
    );
    let orders = cfg.orders();
    let support = Support {
        active: &active,
        n_active,
        orders: &orders,
        cluster: &cluster,
    };
    let lines = LineStage::new(&pre, stationary.iter().map(|s| !s).collect(), &cfg.lines);
    let mut store = PoleStore::new();
    let (channels, role_pools) = channel_modes(
        &pre[0].recording,
        &outs,
        &stationary,
        cfg,
        &support,
        &lines,
        &mut store,
    )?;
    let roles = role_modes(&channels, role_pools, &lines, reference);
    let role_tracks: Vec<crate::LineTrack> =
        roles.iter().flat_map(|r| r.lines.iter().cloned()).collect();
    let ssi = match ssi_poles {
        Some(poles) => Some(ssi_stage.finish(poles, &lines, None, &role_tracks, reference)?),
        None => None,
    };
    let (body_ssi, body_ssi_not_run) = match &ssi {
        Some(main) if cfg.body_ssi.enabled => {
            let stage = crate::body::BodyStage {
                pre: &pre,
                active: &active,
                cfg,
                cluster: &cluster,
            };
            match stage.run(&lines, &main.lines, &role_tracks, reference)? {
                Ok(b) => (Some(b), None),
                Err(why) => (None, Some(why.to_string())),
            }
        }
        Some(_) => (None, Some(BodySsiNotRun::SwitchedOff.to_string())),
        None => (None, None),
    };
    let fits = channels.iter().flat_map(|c| c.fits.iter());
    let n_fits = fits.clone().count();
    let n_not_converged = fits.clone().filter(|f| !f.converged).count();
    let n_failed = fits.filter(|f| f.failed).count();
    let records = facts
        .into_iter()
        .zip(&pre)
        .enumerate()
        .map(|(i, (r, p))| RecordSummary {
            name: r.name,
            fs_hz: r.fs_hz,
            n_samples: r.n_samples,
            duration_s: r.n_samples as f64 / r.fs_hz,
            segment: r.meta,
            clipped: r.clipped,
            held: r.held,
            band: p.band,
            activity_rms: activity_rms[i].clone(),
            activity_ratio: activity_ratio[i],
            stationary: stationary[i],
            excluded_reason: stationary[i].then(|| {
                format!(
                    "stationary: activity {:.3} x the median record < stop_rms_ratio {}",
                    activity_ratio[i], cfg.stops.stop_rms_ratio
                )
            }),
        })
        .collect();
    Ok(AnalysisResults {
        schema_version: SCHEMA_VERSION,
        drive_speed_trace: Vec::new(),
        config: cfg.clone(),
        records,
        channels,
        roles,
        reference_modes: reference.to_vec(),
        n_stationary: stationary.iter().filter(|&&s| s).count(),
        ssi,
        body_ssi,
        body_ssi_not_run,
        n_fits,
        n_not_converged,
        n_failed,
        timing: Timing {
            elapsed_s: t0.elapsed().as_secs_f64(),
        },
    })
}

/// The Welch spectrum of every (record, channel) in parallel, each record at its own band
/// (rate, cutoff): what the stops, the lines and the channel spectra need. `outs[r * n_ch + c]`
/// is record `r`, channel `c`.
fn spectra_all(
    pre: &[Preprocessed],
    cfg: &AnalysisConfig,
) -> Result<Vec<SignalOut>, AnalysisError> {
    let n_ch = pre.first().map_or(0, |p| p.recording.n_channels());
    let tasks: Vec<(usize, usize)> = (0..pre.len())
        .flat_map(|r| (0..n_ch).map(move |c| (r, c)))
        .collect();
    tasks
        .par_iter()
        .map(|&(r, c)| {
            let p = &pre[r];
            let y = &p.recording.channels[c].samples;
            let wp = WelchParams {
                window: Window::Hann,
                nperseg: Some(cfg.spectra.nperseg.min(y.len())),
                ..WelchParams::default()
            };
            let w = vibmode_spectra::welch(y, p.band.fs_hz, &wp)?;
            Ok(SignalOut {
                record: r,
                channel: c,
                welch_freq: w.freq_hz,
                welch: w.psd,
                fits: SignalFits::default(),
            })
        })
        .collect()
}

/// Stage 3: the identification of every channel of the records used for the modes (not the
/// stops) and of the first record (the report draws its models), in parallel.
fn identify_used(
    pre: &[Preprocessed],
    outs: &mut [SignalOut],
    stationary: &[bool],
    cfg: &AnalysisConfig,
    identifier: &dyn Identifier,
    progress: &(dyn Fn(usize, usize) + Sync),
) {
    let used: Vec<&mut SignalOut> = outs
        .iter_mut()
        .filter(|o| o.record == 0 || !stationary[o.record])
        .collect();
    let total = used.len();
    let done = AtomicUsize::new(0);
    used.into_par_iter().for_each(|o| {
        let p = &pre[o.record];
        let y = &p.recording.channels[o.channel].samples;
        let keep = if o.record == 0 {
            cfg.report.model_psd_orders.as_slice()
        } else {
            &[]
        };
        o.fits = identifier.identify(y, &p.band, o.record, keep);
        progress(done.fetch_add(1, Ordering::SeqCst) + 1, total);
    });
}

/// Activity per record and channel: band RMS of the Welch PSD.
fn record_activity(
    outs: &[SignalOut],
    n_rec: usize,
    n_ch: usize,
    cfg: &AnalysisConfig,
) -> Vec<Vec<f64>> {
    (0..n_rec)
        .map(|r| {
            (0..n_ch)
                .map(|c| {
                    outs.get(r * n_ch + c)
                        .filter(|o| o.record == r && o.channel == c)
                        .map_or(f64::NAN, |o| {
                            band_rms(
                                &o.welch_freq,
                                &o.welch,
                                cfg.stops.activity_min_hz,
                                cfg.preprocess.cutoff_hz,
                            )
                        })
                })
                .collect()
        })
        .collect()
}

/// Records used for the modes, renumbered 0..n_active for the clustering (stops: `None`).
fn renumber_active(stationary: &[bool]) -> Vec<Option<usize>> {
    let mut k = 0;
    stationary
        .iter()
        .map(|&s| {
            (!s).then(|| {
                k += 1;
                k - 1
            })
        })
        .collect()
}

/// The Welch PSD averaged over the records used for the modes (stops left out).
fn mean_welch(mine: &[&SignalOut], stationary: &[bool]) -> (Vec<f64>, Vec<f64>) {
    let freq = mine
        .first()
        .map(|o| o.welch_freq.clone())
        .unwrap_or_default();
    let used: Vec<&&SignalOut> = mine.iter().filter(|o| !stationary[o.record]).collect();
    let mut mean = vec![0.0; freq.len()];
    for o in &used {
        for (m, v) in mean.iter_mut().zip(&o.welch) {
            *m += v / used.len() as f64;
        }
    }
    (freq, mean)
}

/// What the clustering needs besides the poles: the records in use and the orders fitted.
struct Support<'a> {
    active: &'a [Option<usize>],
    n_active: usize,
    orders: &'a [usize],
    cluster: &'a ClusterParams,
}

impl Support<'_> {
    fn cluster(
        &self,
        store: &PoleStore,
        which: impl Fn(&str, Role) -> bool,
    ) -> Result<Vec<InvariantMode>, AnalysisError> {
        let obs = store.observations(which, self.active);
        Ok(vibmode_modal::find_invariant_modes(
            &obs,
            self.n_active,
            self.orders,
            self.cluster,
        )?)
    }
}

/// The roles whose channels are pooled, in the order they are reported.
const POOLED_ROLES: [Role; 2] = [Role::Sprung, Role::Unsprung];

/// A role and the invariant modes of its channels' pooled poles.
type RolePool = (Role, Vec<InvariantMode>);

/// Stages 4 and 6 per channel: each channel's poles stored and clustered alone; and the
/// clustering of stage 6 per role (the poles of all channels of a role together), returned
/// beside the channels for [`role_modes`]: `(role, its invariant modes)` for every role of
/// [`POOLED_ROLES`] that has channels. The clusterings depend on the store only, so they run
/// in parallel (each one as it would alone).
fn channel_modes(
    first: &vibmode_core::Recording,
    outs: &[SignalOut],
    stationary: &[bool],
    cfg: &AnalysisConfig,
    support: &Support<'_>,
    lines: &LineStage<'_>,
    store: &mut PoleStore,
) -> Result<(Vec<ChannelAnalysis>, Vec<RolePool>), AnalysisError> {
    struct Stored<'o> {
        placement: vibmode_core::Placement,
        mine: Vec<&'o SignalOut>,
        poles: Vec<vibmode_core::PoleOut>,
    }
    let mut stored = Vec::with_capacity(first.n_channels());
    for (c, ch) in first.channels.iter().enumerate() {
        let placement = cfg.placement_of(ch);
        let mine: Vec<&SignalOut> = outs.iter().filter(|o| o.channel == c).collect();
        let poles: Vec<_> = mine
            .iter()
            .flat_map(|o| o.fits.poles.iter().copied())
            .collect();
        store.add(&ch.name, placement.role, &poles);
        stored.push(Stored {
            placement,
            mine,
            poles,
        });
    }
    let roles: Vec<Role> = POOLED_ROLES
        .into_iter()
        .filter(|&role| stored.iter().any(|s| s.placement.role == role))
        .collect();
    // Each result in its own slot (the pools, then the channels). The tasks are started
    // largest first (by number of poles) and taken in that order by whichever thread is free,
    // so that the largest pool does not start last and run alone.
    enum Pool<'n> {
        Role(Role),
        Channel(&'n str),
    }
    let tasks: Vec<(Pool<'_>, usize)> = roles
        .iter()
        .map(|&r| {
            let n = stored
                .iter()
                .filter(|s| s.placement.role == r)
                .map(|s| s.poles.len())
                .sum();
            (Pool::Role(r), n)
        })
        .chain(
            first
                .channels
                .iter()
                .zip(&stored)
                .map(|(ch, s)| (Pool::Channel(&ch.name), s.poles.len())),
        )
        .collect();
    let store: &PoleStore = store;
    let mut slots: Vec<Option<Result<Vec<InvariantMode>, AnalysisError>>> =
        (0..tasks.len()).map(|_| None).collect();
    let mut jobs: Vec<_> = slots.iter_mut().zip(&tasks).collect();
    jobs.sort_by_key(|(_, (_, n_poles))| std::cmp::Reverse(*n_poles));
    rayon::scope_fifo(|scope| {
        for (slot, (task, _)) in jobs {
            scope.spawn_fifo(move |_| {
                *slot = Some(match *task {
                    Pool::Role(role) => support.cluster(store, |_, r| r == role),
                    Pool::Channel(name) => support.cluster(store, |n, _| n == name),
                });
            });
        }
    });
    // Every slot is filled once the scope ends.
    let mut clustered: Vec<Result<Vec<InvariantMode>, AnalysisError>> =
        slots.into_iter().flatten().collect();
    let per_channel = clustered.split_off(roles.len());
    let mut channels = Vec::with_capacity(first.n_channels());
    for (c, ((ch, s), modes)) in first
        .channels
        .iter()
        .zip(stored)
        .zip(per_channel)
        .enumerate()
    {
        let mut invariant_modes = modes?;
        let tracks = lines.tracks(&[c]);
        lines.classify(&mut invariant_modes, &[c], &tracks);
        let (welch_freq_hz, welch_psd) = mean_welch(&s.mine, stationary);
        channels.push(ChannelAnalysis {
            name: ch.name.clone(),
            unit: ch.unit.clone(),
            role: s.placement.role,
            placement: s.placement,
            welch_freq_hz,
            welch_psd,
            poles: s.poles,
            fits: s
                .mine
                .iter()
                .flat_map(|o| o.fits.fits.iter().cloned())
                .collect(),
            first_record_models: s
                .mine
                .iter()
                .find(|o| o.record == 0)
                .map(|o| o.fits.models.clone())
                .unwrap_or_default(),
            invariant_modes,
            lines: tracks,
        });
    }
    let pools = roles
        .into_iter()
        .zip(clustered)
        .map(|(role, modes)| modes.map(|m| (role, m)))
        .collect::<Result<_, _>>()?;
    Ok((channels, pools))
}

/// Stages 6 and 7 per role: the invariant modes of each role's pool (clustered by
/// [`channel_modes`]) classed against the lines, and the structural modes matched to the
/// physical model's. Channels without a role (`Role::Other`:
/// x, y and z of one sensor, or sensors of unknown place) are not pooled: their modes differ,
/// and each is analysed alone (`ChannelAnalysis::invariant_modes`).
fn role_modes(
    channels: &[ChannelAnalysis],
    pools: Vec<RolePool>,
    lines: &LineStage<'_>,
    reference: &[ReferenceMode],
) -> Vec<RoleAnalysis> {
    let mut roles = Vec::new();
    for (role, mut invariant) in pools {
        let names: Vec<String> = channels
            .iter()
            .filter(|c| c.role == role)
            .map(|c| c.name.clone())
            .collect();
        let idx: Vec<usize> = channels
            .iter()
            .enumerate()
            .filter(|(_, c)| c.role == role)
            .map(|(i, _)| i)
            .collect();
        let tracks = lines.tracks(&idx);
        lines.classify(&mut invariant, &idx, &tracks);
        let matches = if reference.is_empty() {
            Vec::new()
        } else {
            // One to one, the closest frequencies first: a single-channel pool cannot tell
            // heave from pitch, so one body cluster must not be reported as both.
            vibmode_modal::match_reference_shapes(
                &invariant,
                reference,
                &names,
                MATCH_MAX_FREQ_DIFF_REL,
                MATCH_MAC_MIN,
            )
        };
        roles.push(RoleAnalysis {
            role,
            channels: names,
            invariant_modes: invariant,
            matches,
            lines: tracks,
        });
    }
    roles
}
