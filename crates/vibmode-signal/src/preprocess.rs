//! The pre-processing stage: the paper's ideal DFT anti-alias filter and resampling of a whole
//! record to the analysis rate, returning the band the result carries as data.

use vibmode_core::{BandLimit, PreprocessParams, Recording};

use crate::error::Result;
use crate::resample::{planned_fs_out_hz, resample_recording, ChannelSpectrum, ResampleParams};

/// A record at the analysis rate and the band it carries.
#[derive(Clone, Debug, PartialEq)]
pub struct Preprocessed {
    /// The resampled record.
    pub recording: Recording,
    /// Its rate, the cutoff actually applied and whether an empty band lies above it: the one
    /// definition later stages (identification, pole filters, clustering) read.
    pub band: BandLimit,
}

/// Anti-alias filters (ideal DFT low-pass at `cutoff_hz`) and resamples `rec` to
/// `analysis_fs_hz`.
///
/// The cutoff is clamped to the Nyquist frequency of the input and of the actual output rate:
/// with a non-integer rate ratio the output rate is `n_out / duration`, which can fall a hair
/// below `analysis_fs_hz` (425.08 Hz -> 49.998 Hz). A record already at the analysis rate is
/// still low-passed at the cutoff.
///
/// Errors: invalid parameters, an analysis rate more than
/// [`UPSAMPLE_RATIO_MAX`](vibmode_core::limits::UPSAMPLE_RATIO_MAX) times the record's, non-finite
/// samples, a record too short to resample.
pub fn preprocess(rec: &Recording, p: &PreprocessParams) -> Result<Preprocessed> {
    preprocess_with_spectra(rec, p, None)
}

/// [`preprocess`] of `rec`, each channel's forward transform taken from `spectra[i]` (of
/// `rec.channels[i]`, [`ChannelSpectrum::of`]) where given (a caller that resamples the channels
/// to another rate too transforms them once): the same result bit for bit.
pub fn preprocess_with_spectra(
    rec: &Recording,
    p: &PreprocessParams,
    spectra: Option<&[ChannelSpectrum]>,
) -> Result<Preprocessed> {
    let ratio = p.analysis_fs_hz / rec.fs_hz;
    if ratio > vibmode_core::limits::UPSAMPLE_RATIO_MAX {
        return Err(crate::SignalError::InvalidParam {
            name: "analysis_fs_hz",
            value: vibmode_core::Num(p.analysis_fs_hz).to_string(),
            fix: format!(
                "it is {} times the record's rate of {} Hz (at most {} allowed); check the unit of the time column or of fs_hz, or lower analysis_fs_hz",
                vibmode_core::Num(ratio),
                vibmode_core::Num(rec.fs_hz),
                vibmode_core::limits::UPSAMPLE_RATIO_MAX
            ),
        });
    }
    let wanted = ResampleParams {
        fs_out_hz: p.analysis_fs_hz,
        cutoff_hz: Some(p.cutoff_hz.min(rec.fs_hz / 2.0)),
        filter: true,
    };
    // The rate the one planned resampler will have (it does not depend on the cutoff), so that
    // the cutoff is clamped to its Nyquist frequency before planning.
    let fs_out_hz = planned_fs_out_hz(rec.len(), rec.fs_hz, &wanted);
    let cutoff_hz = wanted
        .cutoff_hz
        .map_or(fs_out_hz / 2.0, |c| c.min(fs_out_hz / 2.0));
    let params = ResampleParams {
        cutoff_hz: Some(cutoff_hz),
        ..wanted
    };
    let recording = resample_recording(rec, &params, spectra)?;
    let band = BandLimit::ideal_lowpass(recording.fs_hz, cutoff_hz);
    Ok(Preprocessed { recording, band })
}
