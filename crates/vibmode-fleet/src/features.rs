//! Features of one record: band levels per channel (and the level at and above wheel hop for
//! the unsprung level ratios), transmissibility per corner, and the modes identified per
//! channel. See docs/fleet.md for the formulas.

use serde::{Deserialize, Serialize};
use vibmode_analysis::{
    analyze_prepared, cut_records, preprocess_recordings, AnalysisConfig, Corner, CutRecords,
    RecordFacts, Role, SweepIdentifier,
};
use vibmode_core::stats::ChannelHealth;
use vibmode_core::{ModeClass, Recording};
use vibmode_signal::ChannelSpectrum;
use vibmode_spectra::{band_rms, SpectraError, WelchParams, Window};

use crate::body::{body_spectra, BodySpectra};

use crate::config::FleetConfig;
use crate::error::{FleetError, Result};

/// One identified mode of a channel.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModeEstimate {
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
}

/// Features of one channel.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChannelFeatures {
    /// Channel name.
    pub name: String,
    /// Sprung, unsprung or other.
    pub role: Role,
    /// Corner, if known.
    pub corner: Option<Corner>,
    /// RMS in each band of [`RecordFeatures::bands_hz`] (units of the channel), `None` where the
    /// band holds no power or no bin.
    pub band_rms: Vec<Option<f64>>,
    /// Structural invariant modes of the file in this channel.
    pub modes: Vec<ModeEstimate>,
    /// RMS in `ratio_band_hz` (units of the channel), for the unsprung level ratios; absent in
    /// records stored before it existed (their model sets then lack the ratios).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ratio_band_rms: Option<f64>,
}

/// Transmissibility of one corner: sprung over unsprung.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CornerTransmissibility {
    /// The corner.
    pub corner: Corner,
    /// The sprung channel.
    pub sprung: String,
    /// The unsprung channel.
    pub unsprung: String,
    /// `sqrt(sum_band S_sprung / sum_band S_unsprung)` per band; `None` where the unsprung band
    /// holds no power.
    pub values: Vec<Option<f64>>,
    /// The same from the cross-spectrum (H1): `sqrt(sum_band |S_us|^2 / S_uu / sum_band S_uu)`
    /// per band, the sprung power coherent with the unsprung channel over the unsprung power,
    /// which the sprung sensor's noise does not raise. Used instead of `values` when present;
    /// empty in records stored before it existed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub h1: Vec<Option<f64>>,
}

/// Everything the fleet store keeps of one record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordFeatures {
    /// Rate of the analysed signals, Hz.
    pub analysis_fs_hz: f64,
    /// Duration of the file, s.
    pub duration_s: f64,
    /// Records of `record_length_s` the file was cut into.
    pub n_segments: usize,
    /// The bands, Hz.
    pub bands_hz: Vec<[f64; 2]>,
    /// Per channel.
    pub channels: Vec<ChannelFeatures>,
    /// Per corner with a sprung and an unsprung channel.
    pub transmissibility: Vec<CornerTransmissibility>,
    /// Why some features are missing.
    pub notes: Vec<String>,
    /// Cross-spectra of the sprung and unsprung channels in `body_band_hz`, for the body's
    /// response to the wheel motions; absent in records stored before it existed and in records
    /// without both a sprung and an unsprung channel with a corner.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body_spectra: Option<BodySpectra>,
    /// Channels with a role whose sensor failed (dead, stuck, clipped or held); they give no feature,
    /// and a check of the record is classed `sensor`. Empty in records stored before it existed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sensor_faults: Vec<SensorFault>,
    /// The transmissibility and the unsprung levels of the level ratios with the bins of the
    /// record's periodic lines (engine and driveline orders) left out; absent in records stored
    /// before it existed (a model set is line-free only when all its nominal records are).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_free: Option<LineFree>,
    /// The record's body equations for the suspension fitted per drive, made with the
    /// vehicle's registered model file ([`crate::suspension`]); absent without one, in records
    /// stored before it existed or registered, and when the record cannot give them (`notes`
    /// says why).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub suspension: Option<crate::suspension::StoredEquations>,
    /// When the record started: Unix time (s, UTC), where the file tells it (a time column of
    /// date-times); it puts the record into the drive of its day ([`crate::drive_of_day`]).
    /// Absent in records stored before it existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_unix_s: Option<f64>,
}

impl RecordFeatures {
    /// True when the record lacks the body equations of the model file with this SHA-256 (none,
    /// or another file's) and could have them (no failed sensor): a stored record that gets them
    /// when it is ingested or checked again.
    pub fn lacks_equations_of(&self, model_sha256: &str) -> bool {
        let current = self
            .suspension
            .as_ref()
            .is_some_and(|e| e.model_sha256 == model_sha256);
        !current && self.sensor_faults.is_empty()
    }
}

/// A record's transmissibility with the bins of its periodic lines left out of the band sums
/// (and its unsprung levels with them replaced by the continuum under them): a line
/// (an engine or driveline order entering at the engine mounts or the axle) moves the body and,
/// through the suspension, the wheel at one frequency, so it is coherent between the sprung and
/// the unsprung channel and pulls the transmissibility towards the path from the body to the
/// wheel; on a smooth road at low speed it dominated the 5-12 Hz bands of busgen buses.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LineFree {
    /// Centre frequencies of the left-out bins, Hz: those around the periodic lines the
    /// analysis of the file found steady in any channel with a role.
    pub line_bins_hz: Vec<f64>,
    /// Per entry of [`RecordFeatures::transmissibility`] (same order): the cross-spectral (H1)
    /// value per band without the line bins; `None` where the band keeps no unsprung power.
    pub h1: Vec<Vec<Option<f64>>>,
    /// Per entry of [`RecordFeatures::channels`] (same order): the RMS in `ratio_band_hz` with
    /// the bins of the lines found in an unsprung channel replaced by their neighbours'
    /// continuum ([`continuum`]), for the unsprung level ratios.
    #[serde(default)]
    pub ratio_band_rms: Vec<Option<f64>>,
    /// Per entry of [`RecordFeatures::channels`] (same order): the one-sided density (unit^2/Hz)
    /// of the unsprung channel's white noise floor, measured at the file's own rate above the
    /// ratio band ([`noise_range_hz`], [`vibmode_vehicle::update::noise_floor_density`] of each
    /// record's first [`NOISE_SAMPLES_MAX`] samples; the median over the file's records), 0
    /// where the rate leaves no such range, the floor is not flat (motion, not noise) or the
    /// channel is not unsprung. Its power in the band is taken out of the band's
    /// before the unsprung level ratios (by model sets built from records that have it,
    /// [`crate::model::ModelSet::noise_free`]). Empty in records stored before it existed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub noise_density: Vec<f64>,
    /// The transmissibility's parts per Welch bin, lines in: a model set leaves out of every
    /// record the bins of the vehicle's own lines ([`crate::model::ModelSet::vehicle_line_bins_hz`])
    /// besides the record's, so that a line found in some records and not in others does not
    /// move the feature. Absent in records stored before it existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bins: Option<TransmissibilityBins>,
}

/// A record's cross-spectral transmissibility per Welch bin (within the bands), from which a
/// band's value with any set of bins left out is `sqrt(sum coherent / sum input)` over the
/// band's other bins ([`TransmissibilityBins::band_value`]): the H1 estimate's power over the
/// input power, as [`h1_band_values`] computes it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TransmissibilityBins {
    /// Bin centres, Hz.
    pub freq_hz: Vec<f64>,
    /// Per entry of [`RecordFeatures::transmissibility`] (same order): `|S_us|^2 / S_uu` per bin,
    /// the unsprung input's power coherent with the sprung output, scaled by the output (0 where
    /// `S_uu` is 0).
    pub coherent: Vec<Vec<f64>>,
    /// Per entry of [`RecordFeatures::transmissibility`]: `S_uu` per bin, the unsprung PSD.
    pub input: Vec<Vec<f64>>,
    /// Per entry of [`RecordFeatures::transmissibility`]: `S_ss` per bin, the sprung PSD (empty in
    /// records stored before it existed).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub output: Vec<Vec<f64>>,
    /// The Welch segments averaged into these spectra (over the file's records; 0 where not
    /// known).
    #[serde(default)]
    pub segments: usize,
}

impl TransmissibilityBins {
    /// The transmissibility of entry `entry` in `band` (Hz, edges included as in
    /// [`vibmode_spectra::band_rms`]) with the bins at the frequencies of `left_out` (either
    /// list, Hz) left out of both sums; `None` where no input power is left or the entry is
    /// absent.
    pub fn band_value(&self, entry: usize, band: [f64; 2], left_out: &[&[f64]]) -> Option<f64> {
        let (num, den) = self.band_sums(self.input.get(entry)?, entry, band, left_out)?;
        (den > 0.0)
            .then(|| (num / den).sqrt())
            .filter(|v| v.is_finite())
    }

    /// The coherence of entry `entry` over `band` with the bins of `left_out` left out, weighted
    /// by the output's power: `sum coherent / sum output`, the share of the sprung channel's power
    /// coherent with its wheel, as estimated (biased up by about `(1 - gamma^2) / n` for `n`
    /// averages). `None` without the output spectra or power.
    pub fn band_coherence(&self, entry: usize, band: [f64; 2], left_out: &[&[f64]]) -> Option<f64> {
        let (num, den) = self.band_sums(self.output.get(entry)?, entry, band, left_out)?;
        (den > 0.0).then(|| num / den).filter(|v| v.is_finite())
    }

    /// The transmissibility of entry `entry` in `band` as [`TransmissibilityBins::band_value`]
    /// with the input's white noise of one-sided density `noise_density` (the unsprung sensor's
    /// floor, [`LineFree::noise_density`]) taken out: the H1 estimate's input power holds the
    /// noise and its coherent power is the output's over the noisy input, so each is divided by
    /// `1 - noise share` of the band's input power (`sum S_uu / (sum S_uu - m N)` over the `m`
    /// bins used): `|H|` itself where the noise share is the same in every bin of the band, not
    /// `|H|` lowered by the share, which grows as the road gets smoother. `None` where more than
    /// `max_share` of the band's input power is the noise, or as `band_value`.
    pub fn band_value_noise_free(
        &self,
        entry: usize,
        band: [f64; 2],
        left_out: &[&[f64]],
        noise_density: f64,
        max_share: f64,
    ) -> Option<f64> {
        let (num, den, m) =
            self.band_sums_counted(self.input.get(entry)?, entry, band, left_out)?;
        let share = Self::noise_share(den, m, noise_density)?;
        if share > max_share {
            return None;
        }
        let keep = den * (1.0 - share);
        let v = (num * den / keep / keep).sqrt();
        v.is_finite().then_some(v)
    }

    /// The share of entry `entry`'s input power in `band` (the bins of `left_out` left out) that
    /// is white noise of one-sided density `noise_density`: `m N / sum S_uu` over the `m` bins
    /// summed; `None` where the band holds no input power or the entry is absent.
    pub fn band_noise_share(
        &self,
        entry: usize,
        band: [f64; 2],
        left_out: &[&[f64]],
        noise_density: f64,
    ) -> Option<f64> {
        let (_, den, m) = self.band_sums_counted(self.input.get(entry)?, entry, band, left_out)?;
        Self::noise_share(den, m, noise_density)
    }

    /// `m N / power`, `None` without power.
    fn noise_share(power: f64, bins: usize, noise_density: f64) -> Option<f64> {
        (power > 0.0).then(|| noise_density.max(0.0) * bins as f64 / power)
    }

    /// The number of bins of `band` that the band sums use (those of `left_out` left out).
    pub fn band_bins(&self, band: [f64; 2], left_out: &[&[f64]]) -> usize {
        self.freq_hz
            .iter()
            .filter(|&&f| Self::kept(f, band, left_out))
            .count()
    }

    /// Whether the bin at `f` is summed over `band`: inside it (edges included) and not at a
    /// frequency of `left_out`.
    fn kept(f: f64, band: [f64; 2], left_out: &[&[f64]]) -> bool {
        f >= band[0]
            && f <= band[1]
            && !left_out
                .iter()
                .any(|l| l.iter().any(|&x| (x - f).abs() <= 1e-9 * f.abs().max(1.0)))
    }

    /// The sums over `band`'s bins, but those of `left_out`, of entry `entry`'s coherent power
    /// and of `other` (its input or output spectrum).
    fn band_sums(
        &self,
        other: &[f64],
        entry: usize,
        band: [f64; 2],
        left_out: &[&[f64]],
    ) -> Option<(f64, f64)> {
        self.band_sums_counted(other, entry, band, left_out)
            .map(|(num, den, _)| (num, den))
    }

    /// [`TransmissibilityBins::band_sums`] and the number of bins summed.
    fn band_sums_counted(
        &self,
        other: &[f64],
        entry: usize,
        band: [f64; 2],
        left_out: &[&[f64]],
    ) -> Option<(f64, f64, usize)> {
        let coherent = self.coherent.get(entry)?;
        let (mut num, mut den, mut m) = (0.0, 0.0, 0usize);
        for ((&f, &c), &p) in self.freq_hz.iter().zip(coherent).zip(other) {
            if Self::kept(f, band, left_out) {
                num += c;
                den += p;
                m += 1;
            }
        }
        Some((num, den, m))
    }
}

/// Where an unsprung channel's spectrum is taken as its sensor's noise floor, Hz: from
/// [`NOISE_FROM_BAND_EDGE`] times the band's upper edge (and at least 5 % of the rate) to 0.4
/// times the rate, two octaves at least (so that a spectrum still falling there, the wheel's
/// motion, is told from a flat floor: [`vibmode_vehicle::update::FLAT_FLOOR`]); `None` when the
/// rate is too low (below 100 times the edge: 2 kHz for the 20 Hz of the ratio band).
pub fn noise_range_hz(band_hz: [f64; 2], fs_hz: f64) -> Option<[f64; 2]> {
    vibmode_vehicle::update::noise_range_above(band_hz, fs_hz, NOISE_FROM_BAND_EDGE)
}

/// Most samples of a record the noise floor is measured from (its first ones): 16384 give
/// thousands of periodogram bins in each half of the range at any rate that has one (2400 at
/// 2 kHz over 200-800 Hz), so the medians scatter by about 2 %.
pub const NOISE_SAMPLES_MAX: usize = 16_384;

/// How far above the ratio band's upper edge the noise floor is measured: a wheel's response
/// above wheel hop falls at least as fast as `f^-2` in power, so at 10 times the edge it is a
/// hundredth of its level there; busgen's unsprung channels are at their noise floor from about
/// 40 Hz on.
pub const NOISE_FROM_BAND_EDGE: f64 = 10.0;

/// Half-width, in Welch bins, of the band left out around a detected periodic line: a Hann
/// window spreads a line over its main lobe of +-2 bins, and at 1.5 bins off the line its power
/// is down by 15 dB.
pub const LINE_HALF_WIDTH_BINS: f64 = 1.5;

/// The bins `freq` within [`LINE_HALF_WIDTH_BINS`] of a line's frequency range (`lines`: lowest
/// and highest frequency over the records where it was found, Hz).
pub fn line_bins(freq: &[f64], lines: &[(f64, f64)]) -> Vec<bool> {
    let df = if freq.len() > 1 {
        freq[1] - freq[0]
    } else {
        0.0
    };
    let w = LINE_HALF_WIDTH_BINS * df;
    freq.iter()
        .map(|f| lines.iter().any(|(lo, hi)| *f >= lo - w && *f <= hi + w))
        .collect()
}

/// Half-width, in bins, of the neighbourhood whose median replaces a line bin in
/// [`continuum`].
pub const CONTINUUM_HALF_BINS: usize = 4;

/// `psd` with each bin of `lines` replaced by the median of the bins within
/// [`CONTINUUM_HALF_BINS`] that are not lines (kept where there is none): the line's power
/// removed, the broadband response under it kept. For the unsprung level ratios, whose band
/// holds the wheel hop: zeroing the bins instead takes out part of a wheel-hop peak where a
/// line sits on it in one record and not the next (vibmode's simulator moves its engine lines
/// with the speed), which scattered the ratios and hid a damper at 50 %.
pub fn continuum(psd: &[f64], lines: &[bool]) -> Vec<f64> {
    let is_line = |j: usize| lines.get(j).copied().unwrap_or(false);
    (0..psd.len())
        .map(|i| {
            if !is_line(i) {
                return psd[i];
            }
            let lo = i.saturating_sub(CONTINUUM_HALF_BINS);
            let hi = (i + CONTINUUM_HALF_BINS + 1).min(psd.len());
            let mut w: Vec<f64> = (lo..hi)
                .filter(|j| !is_line(*j))
                .map(|j| psd[j])
                .filter(|x| x.is_finite())
                .collect();
            if w.is_empty() {
                return psd[i];
            }
            w.sort_by(f64::total_cmp);
            let n = w.len();
            if n % 2 == 1 {
                w[n / 2]
            } else {
                0.5 * (w[n / 2 - 1] + w[n / 2])
            }
        })
        .collect()
}

/// `psd` with the bins of `lines` set to 0 (left out of band sums).
fn without_lines(psd: &[f64], lines: &[bool]) -> Vec<f64> {
    psd.iter()
        .zip(lines.iter().chain(std::iter::repeat(&false)))
        .map(|(p, l)| if *l { 0.0 } else { *p })
        .collect()
}

/// What is wrong with a sensor.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FaultKind {
    /// Every sample is 0 (a dead logger channel, a broken cable).
    Dead,
    /// Every sample has one value other than 0 (a stuck sensor).
    Flat,
    /// More than [`CLIPPED_SHARE`] of the samples sit at the channel's largest or smallest
    /// value (a saturated sensor or amplifier).
    Clipped,
    /// [`vibmode_analysis::HELD_SHARE_MIN`] of the samples or more hold one value over
    /// stretches of [`vibmode_analysis::HELD_MIN_S`] (a logger's dropouts filled with the last
    /// value or 0).
    Held,
}

/// A channel whose sensor failed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SensorFault {
    /// The channel.
    pub channel: String,
    /// What is wrong.
    pub fault: FaultKind,
    /// In words, e.g. `every sample is 0`, `12.5 % of the samples at 9.81`.
    pub detail: String,
}

impl std::fmt::Display for SensorFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kind = match self.fault {
            FaultKind::Dead => "dead",
            FaultKind::Flat => "flat",
            FaultKind::Clipped => "clipped",
            FaultKind::Held => "held",
        };
        write!(
            f,
            "channel {} is {kind} ({})",
            vibmode_core::quoted(&self.channel),
            self.detail
        )
    }
}

pub use crate::config::MIN_PERIODS;
pub use vibmode_core::stats::{CLIPPED_MIN_SAMPLES, CLIPPED_SHARE};

/// The sensor faults of the channels of `rec` that have a role (sprung or unsprung; other
/// columns, such as a speed, are not sensors of the features).
pub fn sensor_faults(rec: &Recording, acfg: &AnalysisConfig) -> Vec<SensorFault> {
    sensor_faults_of(rec, acfg, &channel_healths(rec))
}

/// The [`vibmode_core::stats::channel_health`] of every channel of `rec`, as the analysis
/// takes it (runs held at [`vibmode_core::stats::held_min_run`] of the rate).
fn channel_healths(rec: &Recording) -> Vec<ChannelHealth> {
    let min_run = vibmode_core::stats::held_min_run(rec.fs_hz);
    rec.channels
        .iter()
        .map(|ch| vibmode_core::stats::channel_health(&ch.samples, min_run))
        .collect()
}

/// [`sensor_faults`] from each channel's health (`health[i]` of `rec.channels[i]`).
fn sensor_faults_of(
    rec: &Recording,
    acfg: &AnalysisConfig,
    health: &[ChannelHealth],
) -> Vec<SensorFault> {
    let mut out = Vec::new();
    for (ch, h) in rec.channels.iter().zip(health) {
        if acfg.placement_of(ch).role == Role::Other || ch.samples.is_empty() {
            continue;
        }
        let x = &ch.samples;
        let fault = |fault, detail| SensorFault {
            channel: ch.name.clone(),
            fault,
            detail,
        };
        if let Some(v) = h.constant {
            out.push(if v == 0.0 {
                fault(FaultKind::Dead, "every sample is 0".into())
            } else {
                fault(
                    FaultKind::Flat,
                    format!("every sample is {}", vibmode_core::Num(v)),
                )
            });
        } else if let Some((n, value)) = h.clipped {
            out.push(fault(
                FaultKind::Clipped,
                format!(
                    "{:.1} % of the samples at {}",
                    100.0 * n as f64 / x.len() as f64,
                    vibmode_core::Num(value)
                ),
            ));
        } else if h.is_held() {
            out.push(fault(
                FaultKind::Held,
                format!(
                    "{:.1} % of the samples hold one value, in {} stretch(es) up to {:.3} s",
                    100.0 * h.held_share(),
                    h.held.1,
                    h.held.2 as f64 / rec.fs_hz
                ),
            ));
        }
    }
    out
}

/// A record must be sampled fast enough for the highest band of the features and long enough
/// for the lowest: its Nyquist frequency at least the highest band edge (`bands_hz`,
/// `ratio_band_hz`, `body_band_hz`), its duration at least [`MIN_PERIODS`] periods of the
/// lowest band edge of `bands_hz` and one Welch segment at the analysis rate. Else an error
/// stating the minimum.
pub fn check_sampling(name: &str, rec: &Recording, cfg: &FleetConfig) -> Result<()> {
    let min_fs = cfg.min_fs_hz();
    if rec.fs_hz.is_nan() || rec.fs_hz < min_fs {
        return Err(FleetError::RecordUnderSampled {
            record: name.to_string(),
            fs_hz: rec.fs_hz,
            min_fs_hz: min_fs,
        });
    }
    let min_s = cfg.min_record_s();
    let duration = rec.duration_s();
    if duration.is_nan() || duration < min_s {
        return Err(FleetError::RecordTooShort {
            record: name.to_string(),
            duration_s: duration,
            min_duration_s: min_s,
            periods: MIN_PERIODS,
            lowest_band_edge_hz: cfg.lowest_band_edge_hz().unwrap_or(0.0),
        });
    }
    Ok(())
}

fn finite(x: f64) -> Option<f64> {
    (x.is_finite() && x > 0.0).then_some(x)
}

/// Computes the features of `rec` (a file's recording, named `name` in messages).
///
/// The record's sampling is checked first ([`check_sampling`]); channels whose sensor failed
/// ([`sensor_faults`]) are left out of the features and listed in
/// [`RecordFeatures::sensor_faults`] (a record of only failed sensors has no feature at all).
///
/// Errors: too short or too slowly sampled a record, the analysis fails (bad settings), or no
/// feature can be computed (no channel with a role: name channels like `FL_unsprung`,
/// `RR_sprung`).
pub fn compute_features(name: &str, rec: &Recording, cfg: &FleetConfig) -> Result<RecordFeatures> {
    compute_features_spectra(name, rec, cfg, None)
}

/// [`compute_features`] with each channel's forward transform taken from `spectra[i]` (of
/// `rec.channels[i]`) where given and where the pre-processing resamples the whole recording:
/// the same features bit for bit.
pub(crate) fn compute_features_spectra(
    name: &str,
    rec: &Recording,
    cfg: &FleetConfig,
    spectra: Option<&[ChannelSpectrum]>,
) -> Result<RecordFeatures> {
    let mut features = compute_features_of(name, rec, cfg, spectra)?;
    features.start_unix_s = rec.time_axis.as_ref().and_then(|t| t.start_unix_s());
    Ok(features)
}

fn compute_features_of(
    name: &str,
    rec: &Recording,
    cfg: &FleetConfig,
    spectra: Option<&[ChannelSpectrum]>,
) -> Result<RecordFeatures> {
    cfg.validate()?;
    check_sampling(name, rec, cfg)?;
    let health = channel_healths(rec);
    let faults = sensor_faults_of(rec, &cfg.analysis, &health);
    if faults.is_empty() {
        return features_of(name, rec, Some((&health, spectra)), cfg);
    }
    let mut healthy = rec.clone();
    healthy
        .channels
        .retain(|c| !faults.iter().any(|f| f.channel == c.name));
    let only_faults = |note: String| RecordFeatures {
        analysis_fs_hz: cfg.analysis.preprocess.analysis_fs_hz,
        duration_s: rec.duration_s(),
        n_segments: 0,
        bands_hz: cfg.bands_hz.clone(),
        channels: Vec::new(),
        transmissibility: Vec::new(),
        notes: vec![note],
        body_spectra: None,
        sensor_faults: faults.clone(),
        line_free: Some(LineFree::default()),
        suspension: None,
        start_unix_s: None,
    };
    if healthy.channels.is_empty() {
        return Ok(only_faults("no working sensor: no feature".into()));
    }
    // The working channels alone may give no feature (or the analysis fails on them): the
    // record is still one with failed sensors, not an error.
    let mut f = match features_of(name, &healthy, None, cfg) {
        Ok(f) => f,
        Err(e) => {
            return Ok(only_faults(format!(
                "the working sensors give no feature: {e}"
            )))
        }
    };
    f.sensor_faults = faults;
    Ok(f)
}

/// A record of [`features_of`]: its name and samples, borrowed.
struct Borrowed<'a> {
    name: &'a str,
    recording: &'a Recording,
}

/// The features of `rec`; `whole`, where given, is [`channel_healths`] of `rec` and the
/// spectra of its channels, if taken.
fn features_of(
    name: &str,
    rec: &Recording,
    whole: Option<(&[ChannelHealth], Option<&[ChannelSpectrum]>)>,
    cfg: &FleetConfig,
) -> Result<RecordFeatures> {
    let health = whole.map(|w| w.0);
    let acfg: &AnalysisConfig = &cfg.analysis;
    // A recording of one record's length is that record, borrowed (`cut_records` would copy
    // its samples); a longer one is cut.
    let cuts = if CutRecords::new(name, rec, acfg.record_length_s).len() > 1 {
        cut_records(name, rec, acfg.record_length_s)
    } else {
        Vec::new()
    };
    let records: Vec<Borrowed> = if cuts.is_empty() {
        vec![Borrowed {
            name,
            recording: rec,
        }]
    } else {
        cuts.iter()
            .map(|r| Borrowed {
                name: &r.name,
                recording: &r.recording,
            })
            .collect()
    };
    let analysis = |source: vibmode_analysis::AnalysisError| FleetError::FeaturesAnalysis {
        record: name.to_string(),
        source,
    };
    let spectra = |source: SpectraError| FleetError::FeaturesSpectra {
        record: name.to_string(),
        source,
    };
    let bins_differ = |first_bins: usize, other_bins: usize| FleetError::SpectraBinsDiffer {
        record: name.to_string(),
        first_bins,
        other_bins,
    };
    let mut notes = Vec::new();
    // Mean Welch PSD over the records, per channel, at the analysis rate.
    let mut psd: Vec<Vec<f64>> = Vec::new();
    let mut freq: Vec<f64> = Vec::new();
    let mut fs = acfg.preprocess.analysis_fs_hz;
    // Sprung and unsprung channels with a corner, in corner order: the body's outputs and
    // inputs.
    let by_role = |role: Role| -> Vec<usize> {
        Corner::ALL
            .iter()
            .filter_map(|corner| {
                rec.channels.iter().position(|ch| {
                    let p = acfg.placement_of(ch);
                    p.role == role && p.corner == Some(*corner)
                })
            })
            .collect()
    };
    let (body_u, body_y) = (by_role(Role::Unsprung), by_role(Role::Sprung));
    // (corner, sprung, unsprung) channel indices of the corners with both, for the
    // cross-spectral transmissibility; the mean cross-spectrum `conj(U) S` of each, (re, im).
    let place = |c: &vibmode_core::Channel| acfg.placement_of(c);
    let pairs: Vec<(Corner, usize, usize)> = Corner::ALL
        .iter()
        .filter_map(|corner| {
            let find = |role: Role| {
                rec.channels.iter().position(|ch| {
                    let p = place(ch);
                    p.role == role && p.corner == Some(*corner)
                })
            };
            Some((*corner, find(Role::Sprung)?, find(Role::Unsprung)?))
        })
        .collect();
    let mut cross: Vec<Vec<(f64, f64)>> = vec![Vec::new(); pairs.len()];
    // Welch segments averaged into the cross-spectra, over the records.
    let mut csd_segments = 0usize;
    let mut body: Option<BodySpectra> = None;
    // Each record pre-processed once (in parallel): the spectra here and the analysis below
    // share it.
    // (The records cut from one recording share its channels and rate: no layout check.)
    acfg.validate().map_err(analysis)?;
    let pres = match (whole.and_then(|w| w.1), cuts.is_empty()) {
        // The record is the recording whose channels' spectra were taken.
        (Some(spectra), true) => {
            vec![
                vibmode_signal::preprocess_with_spectra(rec, &acfg.preprocess, Some(spectra))
                    .map_err(|e| analysis(e.into()))?,
            ]
        }
        _ => {
            let recordings: Vec<&Recording> = records.iter().map(|r| r.recording).collect();
            preprocess_recordings(&recordings, acfg).map_err(analysis)?
        }
    };
    for pre in &pres {
        fs = pre.band.fs_hz;
        if !body_u.is_empty() && !body_y.is_empty() {
            let samples = |idx: &[usize]| -> Vec<&[f64]> {
                idx.iter()
                    .map(|&c| pre.recording.channels[c].samples.as_slice())
                    .collect()
            };
            let names = |idx: &[usize]| -> Vec<String> {
                idx.iter().map(|&c| rec.channels[c].name.clone()).collect()
            };
            let s = body_spectra(
                &samples(&body_u),
                &samples(&body_y),
                names(&body_u),
                names(&body_y),
                fs,
                cfg.body_band_hz,
            )
            .map_err(spectra)?;
            body = Some(match body.take() {
                None => s.scaled(1.0 / records.len() as f64),
                Some(acc) => {
                    let (first_bins, other_bins) = (acc.freq_hz.len(), s.freq_hz.len());
                    acc.add_scaled(&s, 1.0 / records.len() as f64)
                        .ok_or_else(|| bins_differ(first_bins, other_bins))?
                }
            });
        }
        for (c, ch) in pre.recording.channels.iter().enumerate() {
            let wp = WelchParams {
                window: Window::Hann,
                nperseg: Some(acfg.spectra.nperseg.min(ch.samples.len())),
                ..WelchParams::default()
            };
            let w = vibmode_spectra::welch(&ch.samples, pre.band.fs_hz, &wp).map_err(spectra)?;
            if psd.len() <= c {
                psd.push(vec![0.0; w.psd.len()]);
                freq = w.freq_hz.clone();
            }
            if psd[c].len() != w.psd.len() {
                return Err(bins_differ(psd[c].len(), w.psd.len()));
            }
            for (a, b) in psd[c].iter_mut().zip(&w.psd) {
                *a += b / records.len() as f64;
            }
        }
        for (k, &(_, s, u)) in pairs.iter().enumerate() {
            let (xs, xu) = (
                &pre.recording.channels[s].samples,
                &pre.recording.channels[u].samples,
            );
            let wp = WelchParams {
                window: Window::Hann,
                nperseg: Some(acfg.spectra.nperseg.min(xu.len())),
                ..WelchParams::default()
            };
            let c = vibmode_spectra::csd(xu, xs, pre.band.fs_hz, &wp).map_err(spectra)?;
            if k == 0 {
                csd_segments += c.n_segments;
            }
            if cross[k].is_empty() {
                cross[k] = vec![(0.0, 0.0); c.csd.len()];
            }
            if cross[k].len() != c.csd.len() {
                return Err(bins_differ(cross[k].len(), c.csd.len()));
            }
            let n = records.len() as f64;
            for (a, b) in cross[k].iter_mut().zip(&c.csd) {
                a.0 += b.re / n;
                a.1 += b.im / n;
            }
        }
    }
    let identifier = SweepIdentifier {
        sweep: acfg.sweep.clone(),
        poles: acfg.poles.clone(),
    };
    let facts = match (health, cuts.is_empty()) {
        // The record is the recording whose health was taken.
        (Some(h), true) => vec![RecordFacts::of_recording_health(name, rec, h)],
        _ => records
            .iter()
            .map(|r| RecordFacts::of_recording(r.name, r.recording))
            .collect(),
    };
    let results = analyze_prepared(
        facts,
        pres,
        acfg,
        &identifier,
        &[],
        &|_, _| {},
        std::time::Instant::now(),
    )
    .map_err(analysis)?;
    let mut channels = Vec::new();
    for (c, ch) in rec.channels.iter().enumerate() {
        let placement = acfg.placement_of(ch);
        let levels: Vec<Option<f64>> = cfg
            .bands_hz
            .iter()
            .map(|b| {
                psd.get(c)
                    .and_then(|p| finite(band_rms(&freq, p, b[0], b[1])))
            })
            .collect();
        let modes = results
            .channels
            .iter()
            .find(|a| a.name == ch.name)
            .map(|a| {
                a.invariant_modes
                    .iter()
                    .filter(|m| m.class == ModeClass::Structural)
                    .map(|m| ModeEstimate {
                        frequency_hz: m.frequency_hz,
                        damping_ratio: m.damping_ratio,
                    })
                    .collect()
            })
            .unwrap_or_default();
        let [rlo, rhi] = cfg.ratio_band_hz;
        channels.push(ChannelFeatures {
            name: ch.name.clone(),
            role: placement.role,
            corner: placement.corner,
            band_rms: levels,
            modes,
            ratio_band_rms: psd
                .get(c)
                .and_then(|p| finite(band_rms(&freq, p, rlo, rhi))),
        });
    }
    let mut transmissibility = Vec::new();
    for corner in Corner::ALL {
        let find = |role: Role| {
            channels
                .iter()
                .find(|c| c.corner == Some(corner) && c.role == role)
        };
        match (find(Role::Sprung), find(Role::Unsprung)) {
            (Some(s), Some(u)) => {
                let values = s
                    .band_rms
                    .iter()
                    .zip(&u.band_rms)
                    .map(|(a, b)| match (a, b) {
                        (Some(a), Some(b)) => finite(a / b),
                        _ => None,
                    })
                    .collect();
                let uidx = channels.iter().position(|c| c.name == u.name);
                let h1 = pairs
                    .iter()
                    .position(|(c, _, _)| *c == corner)
                    .and_then(|k| Some((&cross[k], psd.get(uidx?)?)))
                    .map(|(sx, suu)| h1_band_values(&freq, sx, suu, &cfg.bands_hz))
                    .unwrap_or_default();
                transmissibility.push(CornerTransmissibility {
                    corner,
                    sprung: s.name.clone(),
                    unsprung: u.name.clone(),
                    values,
                    h1,
                });
            }
            (Some(s), None) => notes.push(format!(
                "corner {corner}: sprung channel {} has no unsprung partner, no transmissibility",
                s.name
            )),
            (None, Some(u)) => notes.push(format!(
                "corner {corner}: unsprung channel {} has no sprung partner, no transmissibility",
                u.name
            )),
            (None, None) => {}
        }
    }
    // The periodic lines the analysis found steady in a channel with a role (engine and
    // driveline orders: narrow-band kurtosis and F-test, so a lightly damped mode is not one).
    let line_ranges: Vec<(f64, f64)> = results
        .channels
        .iter()
        .filter(|a| a.role != Role::Other)
        .flat_map(|a| a.lines.iter())
        .filter(|l| l.has_steady_record())
        .map(|l| l.frequency_range_hz)
        .collect();
    let lines = line_bins(&freq, &line_ranges);
    // For the unsprung level ratios: the lines found in an unsprung channel (an order entering
    // at the axle), replaced by the continuum under them.
    let unsprung_ranges: Vec<(f64, f64)> = results
        .channels
        .iter()
        .filter(|a| a.role == Role::Unsprung)
        .flat_map(|a| a.lines.iter())
        .filter(|l| l.has_steady_record())
        .map(|l| l.frequency_range_hz)
        .collect();
    let unsprung_lines = line_bins(&freq, &unsprung_ranges);
    // The unsprung sensors' noise floors, measured at the file's rate on each record (the median
    // over the records: a record with a knock or a tone in the range counts once).
    let noise_range = noise_range_hz(cfg.ratio_band_hz, rec.fs_hz);
    let mut noise_density = Vec::with_capacity(channels.len());
    for (c, ch) in channels.iter().enumerate() {
        let Some(range) = noise_range.filter(|_| ch.role == Role::Unsprung) else {
            noise_density.push(0.0);
            continue;
        };
        let mut per: Vec<f64> = Vec::with_capacity(records.len());
        for r in &records {
            let Some(x) = r.recording.channels.get(c) else {
                continue;
            };
            // The floor needs a few thousand bins, not the whole record (an FFT of 200 000
            // samples per channel and record at 20 kHz would cost a fifth of the ingest).
            let head = &x.samples[..x.samples.len().min(NOISE_SAMPLES_MAX)];
            match vibmode_vehicle::update::noise_floor_density(head, r.recording.fs_hz, range) {
                Ok(d) if d.is_finite() && d >= 0.0 => per.push(d),
                _ => notes.push(format!(
                    "channel {}: the noise floor of {} could not be measured; its level ratios keep the noise",
                    ch.name, r.name
                )),
            }
        }
        noise_density.push(crate::stats::median(&per).unwrap_or(0.0));
    }
    let [rlo, rhi] = cfg.ratio_band_hz;
    let line_free = LineFree {
        line_bins_hz: freq
            .iter()
            .zip(&lines)
            .filter(|(_, l)| **l)
            .map(|(f, _)| *f)
            .collect(),
        h1: transmissibility
            .iter()
            .map(|t| {
                let uidx = channels.iter().position(|c| c.name == t.unsprung);
                pairs
                    .iter()
                    .position(|(c, _, _)| *c == t.corner)
                    .and_then(|k| Some((&cross[k], psd.get(uidx?)?)))
                    .map(|(sx, suu)| {
                        let sx: Vec<(f64, f64)> = sx
                            .iter()
                            .zip(lines.iter().chain(std::iter::repeat(&false)))
                            .map(|(v, l)| if *l { (0.0, 0.0) } else { *v })
                            .collect();
                        h1_band_values(&freq, &sx, &without_lines(suu, &lines), &cfg.bands_hz)
                    })
                    .unwrap_or_default()
            })
            .collect(),
        ratio_band_rms: psd
            .iter()
            .take(channels.len())
            .map(|p| finite(band_rms(&freq, &continuum(p, &unsprung_lines), rlo, rhi)))
            .collect(),
        noise_density,
        bins: transmissibility_bins(
            &freq,
            &transmissibility,
            &channels,
            &pairs,
            &cross,
            &psd,
            &cfg.bands_hz,
        )
        .map(|b| TransmissibilityBins {
            segments: csd_segments,
            ..b
        }),
    };
    if !channels.iter().any(|c| c.role == Role::Unsprung) {
        notes.push("no unsprung channel: no excitation levels".into());
    }
    let n_modes: usize = channels.iter().map(|c| c.modes.len()).sum();
    if transmissibility.is_empty() && n_modes == 0 {
        return Err(FleetError::NoRecordFeature {
            record: name.to_string(),
            channels: rec.names().iter().map(|c| c.to_string()).collect(),
        });
    }
    Ok(RecordFeatures {
        analysis_fs_hz: fs,
        duration_s: rec.duration_s(),
        n_segments: records.len(),
        bands_hz: cfg.bands_hz.clone(),
        channels,
        transmissibility,
        notes,
        body_spectra: body,
        sensor_faults: Vec::new(),
        line_free: Some(line_free),
        suspension: None,
        start_unix_s: None,
    })
}

/// The transmissibility's parts per bin within the bands ([`TransmissibilityBins`]), in the
/// order of `transmissibility`; `None` when a corner's spectra are missing or of another length.
fn transmissibility_bins(
    freq: &[f64],
    transmissibility: &[CornerTransmissibility],
    channels: &[ChannelFeatures],
    pairs: &[(Corner, usize, usize)],
    cross: &[Vec<(f64, f64)>],
    psd: &[Vec<f64>],
    bands_hz: &[[f64; 2]],
) -> Option<TransmissibilityBins> {
    let lo = bands_hz.iter().map(|b| b[0]).fold(f64::INFINITY, f64::min);
    let hi = bands_hz
        .iter()
        .map(|b| b[1])
        .fold(f64::NEG_INFINITY, f64::max);
    let keep: Vec<usize> = (0..freq.len())
        .filter(|&k| freq[k] >= lo && freq[k] <= hi)
        .collect();
    let mut out = TransmissibilityBins {
        freq_hz: keep.iter().map(|&k| freq[k]).collect(),
        ..TransmissibilityBins::default()
    };
    for t in transmissibility {
        let uidx = channels.iter().position(|c| c.name == t.unsprung)?;
        let sidx = channels.iter().position(|c| c.name == t.sprung)?;
        let k = pairs.iter().position(|(c, _, _)| *c == t.corner)?;
        let (sx, suu, sss) = (cross.get(k)?, psd.get(uidx)?, psd.get(sidx)?);
        if sx.len() != freq.len() || suu.len() != freq.len() || sss.len() != freq.len() {
            return None;
        }
        out.output.push(keep.iter().map(|&j| sss[j]).collect());
        out.coherent.push(
            keep.iter()
                .map(|&j| {
                    let (re, im) = sx[j];
                    if suu[j] > 0.0 {
                        (re * re + im * im) / suu[j]
                    } else {
                        0.0
                    }
                })
                .collect(),
        );
        out.input.push(keep.iter().map(|&j| suu[j]).collect());
    }
    Some(out)
}

/// Per band, `sqrt(sum_band |S_us|^2 / S_uu / sum_band S_uu)` from the mean cross-spectrum
/// `S_us` (re, im) and the unsprung PSD `S_uu` on the bins `freq`: the H1 estimate's output
/// power over the input power. `None` where the band holds no unsprung power.
pub fn h1_band_values(
    freq: &[f64],
    s_us: &[(f64, f64)],
    s_uu: &[f64],
    bands_hz: &[[f64; 2]],
) -> Vec<Option<f64>> {
    if s_us.len() != s_uu.len() || freq.len() != s_uu.len() {
        return vec![None; bands_hz.len()];
    }
    let coherent: Vec<f64> = s_us
        .iter()
        .zip(s_uu)
        .map(|(&(re, im), &p)| {
            if p > 0.0 {
                (re * re + im * im) / p
            } else {
                0.0
            }
        })
        .collect();
    bands_hz
        .iter()
        .map(|b| {
            let num = band_rms(freq, &coherent, b[0], b[1]);
            let den = band_rms(freq, s_uu, b[0], b[1]);
            if den > 0.0 {
                finite(num / den)
            } else {
                None
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use vibmode_core::{Channel, Num};

    /// A band's transmissibility from the per-bin parts by hand: bins 1-4 Hz, coherent power
    /// 1, 4, 9, 16 and input 4, 4, 4, 4; 1-3 Hz: sqrt(14 / 12); with 2 Hz left out by either
    /// list: sqrt(10 / 8); 4 Hz only: sqrt(16 / 4) = 2; nothing left or no such entry: none.
    #[test]
    fn band_value_leaves_out_the_given_bins_by_hand() {
        let b = TransmissibilityBins {
            freq_hz: vec![1.0, 2.0, 3.0, 4.0],
            coherent: vec![vec![1.0, 4.0, 9.0, 16.0]],
            input: vec![vec![4.0; 4]],
            ..TransmissibilityBins::default()
        };
        let v = |band, out: &[&[f64]]| b.band_value(0, band, out).unwrap_or(f64::NAN);
        assert!((v([1.0, 3.0], &[]) - (14.0f64 / 12.0).sqrt()).abs() < 1e-15);
        assert!((v([1.0, 3.0], &[&[2.0]]) - (10.0f64 / 8.0).sqrt()).abs() < 1e-15);
        assert!((v([1.0, 3.0], &[&[], &[2.0, 9.0]]) - (10.0f64 / 8.0).sqrt()).abs() < 1e-15);
        assert_eq!(v([3.5, 4.0], &[]), 2.0);
        assert_eq!(b.band_value(0, [3.5, 4.0], &[&[4.0]]), None);
        assert_eq!(b.band_value(1, [1.0, 4.0], &[]), None);
        // Coherence: coherent power over output power (8 each): 1-3 Hz 14 / 24, without 2 Hz
        // 10 / 16; without the output spectra, none.
        let mut c = b.clone();
        assert_eq!(c.band_coherence(0, [1.0, 3.0], &[]), None);
        c.output = vec![vec![8.0; 4]];
        assert!(
            (c.band_coherence(0, [1.0, 3.0], &[]).unwrap_or(f64::NAN) - 14.0 / 24.0).abs() < 1e-15
        );
        assert!(
            (c.band_coherence(0, [1.0, 3.0], &[&[2.0]])
                .unwrap_or(f64::NAN)
                - 10.0 / 16.0)
                .abs()
                < 1e-15
        );
    }

    /// H1 band value by hand: a cross-spectrum `0.5 e^(i theta) S_uu` gives 0.5 in every band
    /// whatever the phase and the weights; a band without unsprung power gives none.
    #[test]
    fn h1_band_values_by_hand() {
        let freq = [0.0, 1.0, 2.0, 3.0, 4.0];
        let suu = [1.0, 2.0, 3.0, 4.0, 0.0];
        let sus: Vec<(f64, f64)> = suu
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let th = 0.7 * k as f64;
                (0.5 * p * th.cos(), 0.5 * p * th.sin())
            })
            .collect();
        let bands = [[0.5, 3.5], [1.5, 2.5], [3.8, 4.2]];
        let v = h1_band_values(&freq, &sus, &suu, &bands);
        assert!((v[0].unwrap() - 0.5).abs() < 1e-12, "{v:?}");
        assert!((v[1].unwrap() - 0.5).abs() < 1e-12, "{v:?}");
        assert_eq!(v[2], None);
    }

    /// Over 20 seeds: y = 0.5 u + noise as strong as u. The band-RMS ratio is sqrt(0.25 + 1)
    /// = 1.12 (the noise raises it); the cross-spectral value's power is biased only by the
    /// noise power over the effective number of averaged segments (39 Hann segments at 50 %
    /// overlap, about 28 independent): expected sqrt(0.25 + 1 / 28) = 0.535, each seed within
    /// 0.09 of 0.5 and the mean over seeds within 0.51..0.56.
    #[test]
    fn h1_is_not_raised_by_output_noise_over_seeds() {
        let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut normal = move || {
            let (a, b) = (uniform().max(1e-300), uniform());
            (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
        };
        let fs = 50.0;
        let wp = WelchParams {
            window: Window::Hann,
            nperseg: Some(256),
            ..WelchParams::default()
        };
        let mut sum = 0.0;
        for seed in 0..20 {
            let u: Vec<f64> = (0..5120).map(|_| normal()).collect();
            let y: Vec<f64> = u.iter().map(|x| 0.5 * x + normal()).collect();
            let pu = vibmode_spectra::welch(&u, fs, &wp).unwrap();
            let py = vibmode_spectra::welch(&y, fs, &wp).unwrap();
            let c = vibmode_spectra::csd(&u, &y, fs, &wp).unwrap();
            let sus: Vec<(f64, f64)> = c.csd.iter().map(|z| (z.re, z.im)).collect();
            let band = [[2.0, 20.0]];
            let h1 = h1_band_values(&pu.freq_hz, &sus, &pu.psd, &band)[0].unwrap();
            let rms = band_rms(&pu.freq_hz, &py.psd, 2.0, 20.0)
                / band_rms(&pu.freq_hz, &pu.psd, 2.0, 20.0);
            assert!((h1 - 0.5).abs() < 0.09, "seed {seed}: H1 {h1}");
            sum += h1;
            assert!(rms > 1.0, "seed {seed}: RMS ratio {rms}");
        }
        let mean = sum / 20.0;
        assert!((0.51..0.56).contains(&mean), "mean H1 {mean}");
    }

    /// A smooth, non-repeating signal (no two samples equal, one at each extreme).
    fn wave(n: usize, scale: f64) -> Vec<f64> {
        (0..n)
            .map(|i| {
                let t = i as f64 / 200.0;
                scale * ((7.3 * t).sin() + 0.5 * (2.9 * t + 0.4).sin() + 0.01 * t)
            })
            .collect()
    }

    fn recording(fs: f64, channels: Vec<(&str, Vec<f64>)>) -> Recording {
        Recording::new(
            fs,
            channels
                .into_iter()
                .map(|(n, s)| Channel::new(n, "m/s^2", s))
                .collect(),
        )
        .expect("recording")
    }

    /// By hand with the default settings: a record at half the rate the bands need, and one a
    /// sample shorter than the shortest allowed, are refused naming their rate and duration.
    #[test]
    fn a_slow_or_short_record_is_refused_naming_its_rate_or_duration() {
        let cfg = FleetConfig::default();
        let (min_fs, min_s) = (cfg.min_fs_hz(), cfg.min_record_s());
        let slow = recording(min_fs / 2.0, vec![("FL_unsprung", vec![0.0; 4096])]);
        match check_sampling("a.csv", &slow, &cfg) {
            Err(e @ FleetError::RecordUnderSampled { .. }) => {
                let m = e.to_string();
                let want = format!("sampled at {} Hz", Num(min_fs / 2.0));
                assert!(m.contains(&want) && m.contains("a.csv"), "{m}");
            }
            other => panic!("{other:?}"),
        }
        let fs = min_fs * 2.0;
        let n = (min_s * fs).ceil() as usize - 2;
        let short = recording(fs, vec![("FL_unsprung", vec![0.0; n])]);
        match check_sampling("b.csv", &short, &cfg) {
            Err(FleetError::RecordTooShort {
                duration_s,
                min_duration_s,
                ..
            }) => {
                assert!(duration_s < min_duration_s && min_duration_s == min_s);
            }
            other => panic!("{other:?}"),
        }
        let fine = recording(fs, vec![("FL_unsprung", vec![0.0; n + 4])]);
        assert!(check_sampling("c.csv", &fine, &cfg).is_ok());
    }

    #[test]
    fn dead_flat_and_clipped_channels_are_found_healthy_and_unplaced_ones_not() {
        let n = 2048;
        let clipped: Vec<f64> = wave(n, 1.0).iter().map(|x| x.clamp(-1.0, 1.0)).collect();
        // 0.25 s of dropouts (50 samples at 200 Hz) filled with the last value.
        let mut held = wave(n, 2.0);
        let last = held[999];
        held[1000..1050].fill(last);
        let rec = recording(
            200.0,
            vec![
                ("FL_unsprung", wave(n, 3.0)),
                ("FR_unsprung", vec![0.0; n]),
                ("RL_unsprung", vec![9.81; n]),
                ("RR_unsprung", clipped),
                ("FR_sprung", held),
                // Not a sensor of the features: a constant speed column is no fault.
                ("speed", vec![40.0; n]),
            ],
        );
        let f = sensor_faults(&rec, &FleetConfig::default().analysis);
        let got: Vec<(&str, FaultKind)> = f.iter().map(|f| (f.channel.as_str(), f.fault)).collect();
        assert_eq!(
            got,
            vec![
                ("FR_unsprung", FaultKind::Dead),
                ("RL_unsprung", FaultKind::Flat),
                ("RR_unsprung", FaultKind::Clipped),
                ("FR_sprung", FaultKind::Held),
            ],
            "{f:?}"
        );
        assert!(
            f[3].to_string()
                .contains("2.5 % of the samples hold one value, in 1 stretch(es) up to 0.255 s"),
            "{}",
            f[3]
        );
        assert!(f[1].to_string().contains("9.81"), "{}", f[1]);
    }

    #[test]
    fn too_short_and_too_slowly_sampled_records_are_refused_with_the_minimum() {
        let cfg = FleetConfig::default();
        assert_eq!(cfg.min_fs_hz(), 40.0);
        assert_eq!(cfg.min_record_s(), 8.0);
        let short = recording(200.0, vec![("FL_unsprung", wave(300, 1.0))]);
        let e = check_sampling("short.csv", &short, &cfg).expect_err("1.5 s");
        assert!(e.to_string().contains("at least 8 s"), "{e}");
        let slow = recording(20.0, vec![("FL_unsprung", wave(400, 1.0))]);
        let e = check_sampling("slow.csv", &slow, &cfg).expect_err("20 Hz");
        assert!(e.to_string().contains("at least 40 Hz"), "{e}");
        let fine = recording(200.0, vec![("FL_unsprung", wave(1600, 1.0))]);
        assert!(check_sampling("fine.csv", &fine, &cfg).is_ok());
    }

    /// The bins within 1.5 bins of a line's range, by hand: bins of 0.5 Hz, a line at 7.1 Hz
    /// (6.35-7.85 Hz: bins 6.5, 7.0, 7.5) and one that wandered over 10.0-10.2 Hz (9.25-10.95
    /// Hz: bins 9.5, 10.0, 10.5).
    #[test]
    fn line_bins_by_hand() {
        let freq: Vec<f64> = (0..30).map(|i| 0.5 * i as f64).collect();
        let hits: Vec<f64> = line_bins(&freq, &[(7.1, 7.1), (10.0, 10.2)])
            .iter()
            .zip(&freq)
            .filter(|(l, _)| **l)
            .map(|(_, f)| *f)
            .collect();
        assert_eq!(hits, vec![6.5, 7.0, 7.5, 9.5, 10.0, 10.5]);
        assert!(line_bins(&freq, &[]).iter().all(|l| !l));
    }

    /// The continuum by hand: line bins 3 and 4 of `[1, 2, 3, 50, 60, 4, 5, 6, 7]` become the
    /// median of the other bins within 4 (bins 0-2 and 5-8: 1, 2, 3, 4, 5, 6, 7, 8 minus the
    /// ends as the window allows); other bins are kept.
    #[test]
    fn continuum_by_hand() {
        let p = [1.0, 2.0, 3.0, 50.0, 60.0, 4.0, 5.0, 6.0, 7.0];
        let lines = [false, false, false, true, true, false, false, false, false];
        let c = continuum(&p, &lines);
        // Bin 3: bins 0..=7 without 3, 4: 1, 2, 3, 4, 5, 6 -> median 3.5.
        // Bin 4: bins 0..=8 without 3, 4: 1, 2, 3, 4, 5, 6, 7 -> median 4.
        assert_eq!(c, vec![1.0, 2.0, 3.0, 3.5, 4.0, 4.0, 5.0, 6.0, 7.0]);
    }

    /// White noise `u` at the wheel, `y = 0.5 u` on the body, and a line at 7.0 Hz entering at
    /// the body (amplitude 0.2 there, 0.06 at the wheel, so coherent between both; about 18 dB
    /// above the noise in its Welch bin, as busgen's orders on a smooth road): with the line the
    /// cross-spectral transmissibility in 5-8 Hz is pulled far above 0.5 (the line's ratio is
    /// 1 / 0.3); with the line bins left out it is 0.5 within 10 %, and 8-12 Hz (no line) is the
    /// same both ways. (A line 32 dB above the noise, amplitude 1, leaks past the left-out bins
    /// through the Hann window's side lobes: 0.557.)
    #[test]
    fn a_line_coherent_in_both_channels_is_left_out_of_the_transmissibility() {
        let fs = 200.0;
        let n = 2048; // 10.24 s
        let mut state: u64 = 0x2545_f491_4f6c_dd1d;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let u: Vec<f64> = (0..n).map(|_| uniform()).collect();
        let line = |a: f64| -> Vec<f64> {
            (0..n)
                .map(|i| a * (2.0 * std::f64::consts::PI * 7.0 * i as f64 / fs).sin())
                .collect()
        };
        let (lu, ly) = (line(0.06), line(0.2));
        let wheel: Vec<f64> = u.iter().zip(&lu).map(|(a, b)| a + b).collect();
        let body: Vec<f64> = u.iter().zip(&ly).map(|(a, b)| 0.5 * a + b).collect();
        let rec = recording(fs, vec![("FL_unsprung", wheel), ("FL_sprung", body)]);
        let f = compute_features("line.csv", &rec, &FleetConfig::default()).expect("features");
        let lf = f.line_free.as_ref().expect("line-free values");
        assert!(
            lf.line_bins_hz.iter().any(|h| (h - 7.0).abs() < 0.4),
            "{:?}",
            lf.line_bins_hz
        );
        let band = |lo: f64| f.bands_hz.iter().position(|b| b[0] == lo).expect("band");
        let (b58, b812) = (band(5.0), band(8.0));
        let with = f.transmissibility[0].h1[b58].expect("h1");
        let without = lf.h1[0][b58].expect("line-free h1");
        assert!(with > 1.0, "with the line {with}");
        assert!(
            (without / 0.5 - 1.0).abs() < 0.1,
            "without the line {without}"
        );
        let (a, b) = (
            f.transmissibility[0].h1[b812].expect("h1"),
            lf.h1[0][b812].expect("line-free h1"),
        );
        assert!((a / b - 1.0).abs() < 1e-9, "8-12 Hz {a} vs {b}");
        // The per-bin parts give the same values: with the record's lines left out, the
        // line-free ones; with none left out, those with the line.
        let bins = lf.bins.as_ref().expect("per-bin parts");
        for (k, band) in f.bands_hz.iter().enumerate() {
            let pairs = [
                (bins.band_value(0, *band, &[&lf.line_bins_hz]), lf.h1[0][k]),
                (bins.band_value(0, *band, &[]), f.transmissibility[0].h1[k]),
            ];
            for (got, want) in pairs {
                match (got, want) {
                    (Some(g), Some(w)) => {
                        assert!((g / w - 1.0).abs() < 1e-9, "{band:?}: {g} vs {w}")
                    }
                    (g, w) => assert_eq!(g, w, "{band:?}"),
                }
            }
        }
    }
}
