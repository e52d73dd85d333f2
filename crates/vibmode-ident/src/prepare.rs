//! Preparation of a signal for a prediction-error fit: additive-outlier cleaning, demeaning and
//! scaling to unit mean square, and the numerical noise floor for signals with an empty band
//! (see [`ArmaParams::noise_floor`]).

use std::borrow::Cow;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::outliers::{clean_additive_outliers, OutlierCleaning};
use crate::params::{ArmaParams, Robust};
use crate::IdentError;

/// The signal a robust fit works on: cleaned when `params.robust` is Huber and cleaning is on
/// (returns the signal, its mean and the number of replaced samples), else `y` and `mean` as given.
pub(crate) fn cleaned<'a>(
    y: &'a [f64],
    mean: f64,
    params: &ArmaParams,
) -> Result<(Cow<'a, [f64]>, f64, usize), IdentError> {
    let OutlierCleaning::RobustFilter(cp) = params.outlier_cleaning else {
        return Ok((Cow::Borrowed(y), mean, 0));
    };
    cp.validate()?;
    if params.robust == Robust::Off {
        return Ok((Cow::Borrowed(y), mean, 0));
    }
    let c = clean_additive_outliers(y, &cp)?;
    if c.replaced.is_empty() {
        return Ok((Cow::Borrowed(y), mean, 0));
    }
    let mean = c.y.iter().sum::<f64>() / c.y.len() as f64;
    Ok((Cow::Owned(c.y), mean, c.replaced.len()))
}

/// Shortest signal checked for an empty band: a shorter periodogram has too few bins for a 1 %
/// share to mean anything.
const EMPTY_BAND_MIN_LEN: usize = 16;

/// A periodogram bin is "empty" below this fraction of the largest bin: about the square of
/// double-precision rounding (1e-16) relative to the signal, times a margin of 1e12, so only what
/// an ideal DFT low-pass leaves above its cutoff falls below it, never a genuinely weak band.
const EMPTY_BIN_LEVEL: f64 = 1e-20;

/// A signal has an empty band when more than this percentage of its periodogram bins are empty
/// (1 %: a band wide enough to make the predictor's gain unbounded there).
const EMPTY_BAND_PERCENT: usize = 1;

/// Whether `y` has a numerically empty band: more than [`EMPTY_BAND_PERCENT`] % of its periodogram
/// bins below [`EMPTY_BIN_LEVEL`] of the largest bin (what an ideal DFT low-pass leaves above its
/// cutoff).
fn has_empty_band(y: &[f64]) -> bool {
    let n = y.len();
    if n < EMPTY_BAND_MIN_LEN {
        return false;
    }
    let mut planner = vibmode_fft::Planner::new();
    let fft = planner.forward(n);
    let mut input = y.to_vec();
    let mut spec = fft.make_output_vec();
    if fft.process(&mut input, &mut spec).is_err() {
        return false;
    }
    let power: Vec<f64> = spec.iter().map(|z| z.norm_sqr()).collect();
    let max = power.iter().cloned().fold(0.0, f64::max);
    if !(max > 0.0 && max.is_finite()) {
        return false;
    }
    let empty = power.iter().filter(|&&p| p < EMPTY_BIN_LEVEL * max).count();
    empty * 100 > EMPTY_BAND_PERCENT * power.len()
}

/// Seed of the noise-floor generator.
const FLOOR_SEED: u64 = 0x0076_6962_6d6f_6465;

/// The signal the search works on, and what it takes to map its results back to signal units.
pub(crate) struct Prepared {
    /// Cleaned, centred signal divided by `scale` (unit mean square), plus the noise floor when
    /// `floor_added`.
    pub(crate) ys: Vec<f64>,
    /// Root mean square of the centred signal (signal units).
    pub(crate) scale: f64,
    /// Value subtracted before scaling: the (cleaned) signal's mean, or 0 without `demean`.
    pub(crate) offset: f64,
    /// Samples replaced by the outlier cleaner.
    pub(crate) outliers_replaced: usize,
    /// Whether the numerical noise floor was added (the signal has an empty band).
    pub(crate) floor_added: bool,
}

/// Cleans `y` (mean `mean`) as [`cleaned`] does, centres it (when `params.demean`), scales it to
/// unit mean square and adds the numerical noise floor when it has an empty band.
///
/// Errors: invalid cleaner settings, a cleaner error, or a signal with zero or non-finite mean
/// square after centring ([`IdentError::Constant`]).
pub(crate) fn for_search(
    y: &[f64],
    mean: f64,
    params: &ArmaParams,
) -> Result<Prepared, IdentError> {
    let n = y.len();
    let (y, mean, outliers_replaced) = cleaned(y, mean, params)?;
    let y: &[f64] = &y;
    let offset = if params.demean { mean } else { 0.0 };
    let centred: Vec<f64> = y.iter().map(|v| v - offset).collect();
    let scale = (centred.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
    if !(scale > 0.0 && scale.is_finite()) {
        return Err(IdentError::Constant { value: y[0] });
    }
    let ys: Vec<f64> = centred.iter().map(|v| v / scale).collect();
    // The search works on the signal plus the numerical noise floor (ys has unit mean square).
    let floored: Option<Vec<f64>> = (params.noise_floor > 0.0
        && params
            .band
            .map_or_else(|| has_empty_band(&ys), |b| b.empty_band))
    .then(|| {
        let sd = params.noise_floor.sqrt();
        let mut rng = ChaCha8Rng::seed_from_u64(FLOOR_SEED);
        ys.iter()
            .map(|&v| {
                let w: f64 = StandardNormal.sample(&mut rng);
                v + sd * w
            })
            .collect()
    });
    let floor_added = floored.is_some();
    Ok(Prepared {
        ys: floored.unwrap_or(ys),
        scale,
        offset,
        outliers_replaced,
        floor_added,
    })
}
