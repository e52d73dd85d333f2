//! Small order statistics used for the cluster summaries.

/// Percentile `q` in [0, 1] of an ascending-sorted, non-empty slice, with linear interpolation
/// between closest ranks (numpy's default `method="linear"`: position `q * (n - 1)`).
/// Returns NaN for an empty slice.
pub fn percentile_sorted(sorted: &[f64], q: f64) -> f64 {
    let n = sorted.len();
    if n == 0 {
        return f64::NAN;
    }
    let pos = q.clamp(0.0, 1.0) * (n - 1) as f64;
    let lo = pos.floor() as usize;
    let hi = (lo + 1).min(n - 1);
    let frac = pos - lo as f64;
    sorted[lo] + (sorted[hi] - sorted[lo]) * frac
}

pub use vibmode_core::stats::median;

/// Mean and sample standard deviation (n - 1 denominator; 0 when n = 1). NaN for an empty slice.
pub fn mean_std(values: &[f64]) -> (f64, f64) {
    let n = values.len();
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    if n == 1 {
        return (mean, 0.0);
    }
    let ss: f64 = values.iter().map(|x| (x - mean) * (x - mean)).sum();
    (mean, (ss / (n - 1) as f64).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_percentiles() {
        let v = [1.0, 2.0, 3.0, 4.0];
        // positions 0.75, 1.5, 2.25
        assert!((percentile_sorted(&v, 0.25) - 1.75).abs() < 1e-15);
        assert!((percentile_sorted(&v, 0.5) - 2.5).abs() < 1e-15);
        assert!((percentile_sorted(&v, 0.75) - 3.25).abs() < 1e-15);
        assert_eq!(percentile_sorted(&[7.0], 0.3), 7.0);
        assert!(percentile_sorted(&[], 0.5).is_nan());
        assert_eq!(median(&[5.0, 1.0, 3.0]), 3.0);
    }

    #[test]
    fn hand_mean_std() {
        let (m, s) = mean_std(&[2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]);
        assert!((m - 5.0).abs() < 1e-15);
        // sum of squares 32, n-1 = 7
        assert!((s - (32.0f64 / 7.0).sqrt()).abs() < 1e-14);
        assert_eq!(mean_std(&[3.0]), (3.0, 0.0));
    }
}
