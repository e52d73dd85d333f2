//! What the report draws of the first record (the paper's Fig. 5-7), computed from the record
//! as the analysis pre-processed it ([`FirstRecord::prepared`]) and the model coefficients kept in
//! the results, so the results carry no report-only arrays.

use serde::{Deserialize, Serialize};
use vibmode_signal::Preprocessed;
use vibmode_spectra::{PeriodogramParams, WelchParams, Window};

use crate::results::AnalysisResults;
use crate::AnalysisError;
use vibmode_core::RecordInput;

/// The first record of an analysis as read and as pre-processed (the analysis rate): what the
/// report draws, kept by the analysis so that it is not pre-processed twice.
#[derive(Clone, Debug)]
pub struct FirstRecord {
    /// The record at its own rate.
    pub record: RecordInput,
    /// The record at the analysis rate, as the analysis used it.
    pub prepared: Preprocessed,
}

/// Number of points of the model-PSD grid, from Nyquist/N to Nyquist.
pub const MODEL_GRID_POINTS: usize = 400;

/// A model PSD of one order on a frequency grid.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ModelPsd {
    /// Model order p.
    pub order: usize,
    /// One-sided density in (unit)^2/Hz.
    pub psd: Vec<f64>,
}

/// The first record's spectra of one channel, at the analysis rate.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FirstRecordSpectra {
    /// Channel name.
    pub channel: String,
    /// Periodogram (boxcar, density) frequencies, Hz.
    pub periodogram_freq_hz: Vec<f64>,
    /// Periodogram, (unit)^2/Hz.
    pub periodogram_psd: Vec<f64>,
    /// Welch (Hann, `spectra.nperseg`) frequencies, Hz.
    pub welch_freq_hz: Vec<f64>,
    /// Welch PSD, (unit)^2/Hz.
    pub welch_psd: Vec<f64>,
    /// Frequency grid of the model PSDs, Hz.
    pub model_freq_hz: Vec<f64>,
    /// Model PSDs at the orders of `report.model_psd_orders`.
    pub models: Vec<ModelPsd>,
}

/// The spectra of the first record, `pre` (at the analysis rate, as the analysis pre-processed
/// it), for every channel of `results`.
pub fn first_record_spectra(
    pre: &Preprocessed,
    results: &AnalysisResults,
) -> Result<Vec<FirstRecordSpectra>, AnalysisError> {
    let cfg = &results.config;
    let fs = pre.band.fs_hz;
    let grid: Vec<f64> = (1..=MODEL_GRID_POINTS)
        .map(|i| i as f64 * fs / 2.0 / MODEL_GRID_POINTS as f64)
        .collect();
    results
        .channels
        .iter()
        .zip(&pre.recording.channels)
        .map(|(ch, samples)| {
            let y = &samples.samples;
            let p = vibmode_spectra::periodogram(y, fs, &PeriodogramParams::default())?;
            let wp = WelchParams {
                window: Window::Hann,
                nperseg: Some(cfg.spectra.nperseg.min(y.len())),
                ..WelchParams::default()
            };
            let w = vibmode_spectra::welch(y, fs, &wp)?;
            let models = ch
                .first_record_models
                .iter()
                .map(|m| ModelPsd {
                    order: m.order,
                    psd: vibmode_ident::arma_psd(&m.a, &m.c, m.noise_variance, &grid, m.fs_hz),
                })
                .collect();
            Ok(FirstRecordSpectra {
                channel: ch.name.clone(),
                periodogram_freq_hz: p.freq_hz,
                periodogram_psd: p.psd,
                welch_freq_hz: w.freq_hz,
                welch_psd: w.psd,
                model_freq_hz: grid.clone(),
                models,
            })
        })
        .collect()
}
