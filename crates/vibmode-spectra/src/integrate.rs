//! Integrals of one-sided spectra: RMS over a band, total RMS, the peak. One definition, used by
//! `vibmode psd`'s table and the analysis' stop detection.

use crate::params::Scaling;

/// RMS in `[f_lo, f_hi]` Hz of a one-sided density (units^2/Hz) on a uniform grid `freq_hz`:
/// the square root of the sum of the bins in the band times the bin width, in units. NaN for a
/// grid of fewer than two frequencies.
pub fn band_rms(freq_hz: &[f64], psd: &[f64], f_lo: f64, f_hi: f64) -> f64 {
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

/// Total RMS (units) of a one-sided spectrum: `sqrt(sum psd * df)` for a density,
/// `sqrt(sum psd)` for a power spectrum. For a boxcar periodogram with the mean removed this is
/// the signal's standard deviation (Parseval). NaN for an empty spectrum.
pub fn rms(freq_hz: &[f64], psd: &[f64], scaling: Scaling) -> f64 {
    if psd.is_empty() {
        return f64::NAN;
    }
    let sum: f64 = psd.iter().sum();
    let power = match scaling {
        Scaling::Density => {
            let df = if freq_hz.len() > 1 {
                freq_hz[1] - freq_hz[0]
            } else {
                0.0
            };
            sum * df
        }
        Scaling::Spectrum => sum,
    };
    power.max(0.0).sqrt()
}

/// The largest bin above 0 Hz: `(frequency_hz, value)`; `None` when there is none.
pub fn peak(freq_hz: &[f64], psd: &[f64]) -> Option<(f64, f64)> {
    freq_hz
        .iter()
        .zip(psd)
        .filter(|(f, v)| **f > 0.0 && v.is_finite())
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(f, v)| (*f, *v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_cases() {
        // 2 units^2/Hz on 0, 0.5, ..., 25 Hz; band 1..3 Hz holds 5 bins x 0.5 Hz.
        let f: Vec<f64> = (0..=50).map(|k| k as f64 * 0.5).collect();
        let p = vec![2.0; f.len()];
        assert!((band_rms(&f, &p, 1.0, 3.0) - 5.0f64.sqrt()).abs() < 1e-12);
        assert!(band_rms(&[], &[], 1.0, 3.0).is_nan());
        assert!((rms(&f, &p, Scaling::Density) - (2.0f64 * 51.0 * 0.5).sqrt()).abs() < 1e-12);
        assert!((rms(&f, &[4.0, 5.0], Scaling::Spectrum) - 3.0).abs() < 1e-12);
        assert_eq!(peak(&[0.0, 1.0, 2.0], &[9.0, 1.0, 3.0]), Some((2.0, 3.0)));
        assert_eq!(peak(&[0.0], &[9.0]), None);
    }
}
