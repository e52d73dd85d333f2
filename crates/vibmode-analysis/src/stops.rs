//! Stop detection: records in which the vehicle stood still carry no road input and are left out
//! of the mode statistics.

use vibmode_core::StopParams;

pub use vibmode_spectra::band_rms;

/// Per record: the median over channels of (activity / that channel's median over records).
/// A channel whose median is zero or not finite gives no information and is skipped; a record
/// with no informative channel gets 1 (never a stop).
pub fn activity_ratios(rms: &[Vec<f64>], n_ch: usize) -> Vec<f64> {
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

/// Which records are stops: activity ratio below `stop_rms_ratio` (never every record).
pub fn detect_stops(activity_ratio: &[f64], p: &StopParams) -> Vec<bool> {
    let mut stationary: Vec<bool> = activity_ratio
        .iter()
        .map(|&a| p.stop_rms_ratio > 0.0 && a < p.stop_rms_ratio)
        .collect();
    if stationary.iter().all(|&s| s) {
        // Cannot happen with a median reference and a ratio < 1; never drop everything.
        stationary.iter_mut().for_each(|s| *s = false);
    }
    stationary
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
        assert_eq!(
            detect_stops(&[1.0, 0.1, 0.5], &StopParams::default()),
            vec![false, true, false]
        );
    }
}
