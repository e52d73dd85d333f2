//! The one median every layer uses (spectra, identification, clustering, lines, segmentation,
//! fleet): mean of the two middle values for an even count, NaN for no value; and the high
//! median (the larger middle value) where the level must be an observed value; and the dot
//! product the fits' inner loops share ([`dot`]).
//!
//! Values are ordered by [`f64::total_cmp`]; callers pass NaN-free values (every input is checked
//! to be finite where it is read) or filter them first.

/// Median of `v`, reordering `v` in place (O(n): `select_nth_unstable`). NaN when `v` is empty.
pub fn median_in_place(v: &mut [f64]) -> f64 {
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    let mid = n / 2;
    let (lower, m, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    let upper = *m;
    if n % 2 == 1 {
        upper
    } else {
        let below = lower.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (below + upper) / 2.0
    }
}

/// Median of `values` (copied). NaN when `values` is empty.
pub fn median(values: &[f64]) -> f64 {
    median_in_place(&mut values.to_vec())
}

/// The high median of `v` (Python's `statistics.median_high`): the middle value for an odd
/// count, the larger of the two middle values for an even count, always one of the values.
/// Reorders `v` in place (O(n)). NaN when `v` is empty. For a level that must be one of the
/// observed values (a peak's surrounding level, a noise density).
pub fn median_high_in_place(v: &mut [f64]) -> f64 {
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    *v.select_nth_unstable_by(n / 2, f64::total_cmp).1
}

/// Dot product of the common length of `x` and `z`, with four accumulators (accumulator k sums
/// the products at indices `4 i + k`; the chunks of four share SIMD registers): about 4x faster
/// than one running sum, whose every addition waits for the previous one, and no less accurate.
/// The ARMA fits' filters and SSI-cov's lag sums use it.
#[inline]
pub fn dot(x: &[f64], z: &[f64]) -> f64 {
    let n = x.len().min(z.len());
    let (xc, zc) = (x[..n].chunks_exact(4), z[..n].chunks_exact(4));
    let (xr, zr) = (xc.remainder(), zc.remainder());
    let mut s = [0.0f64; 4];
    for (a, b) in xc.zip(zc) {
        for k in 0..4 {
            s[k] += a[k] * b[k];
        }
    }
    let mut tail = 0.0;
    for (a, b) in xr.iter().zip(zr) {
        tail += a * b;
    }
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

/// The value of a channel that carries no vibration: `Some(0.0)` when every sample is 0 (a dead
/// sensor: its peak magnitude at most [`crate::limits::SAMPLE_PEAK_MIN`]), `Some(v)` when every
/// sample is `v` to within 1e-9 of the peak (a stuck sensor; rounding of a resampled constant
/// stays far inside this), `None` otherwise (and for an empty slice). The analysis refuses such
/// a channel, the fleet calls it `dead` or `flat`. `None` for fewer than 2 samples (too short
/// is another fault).
pub fn constant_value(x: &[f64]) -> Option<f64> {
    if x.len() < 2 {
        return None;
    }
    let first = x[0];
    let (min, max) = x
        .iter()
        .fold((first, first), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let peak = max.abs().max(min.abs());
    if peak <= crate::limits::SAMPLE_PEAK_MIN {
        return Some(0.0);
    }
    (max - min <= 1e-9 * peak).then_some(max)
}

/// Share of the samples at one extreme of a channel above which it counts as clipped (a
/// continuous signal reaches its extreme once or, quantised, a few times).
pub const CLIPPED_SHARE: f64 = 0.01;
/// Fewest samples at one extreme that count as clipped, however short the record.
pub const CLIPPED_MIN_SAMPLES: usize = 10;

/// Whether a channel is clipped: more than [`CLIPPED_SHARE`] of its samples (and at least
/// [`CLIPPED_MIN_SAMPLES`]) at its largest or its smallest value, to within 1e-9 of its range,
/// in stretches of two or more consecutive samples (a saturated sensor or amplifier holds its
/// extreme; a pure tone whose period is a whole number of samples touches it once per period).
/// `Some((count, value))` of the extreme held more often, `count` every sample at it (held or
/// not); `None` for a channel that is not clipped or is constant ([`constant_value`]).
pub fn clipped(x: &[f64]) -> Option<(usize, f64)> {
    if constant_value(x).is_some() || x.len() < 2 {
        return None;
    }
    let max = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let min = x.iter().copied().fold(f64::INFINITY, f64::min);
    let tol = 1e-9 * (max - min);
    // Samples satisfying `at` that have a neighbour satisfying it too.
    let held = |at: &dyn Fn(f64) -> bool| {
        (0..x.len())
            .filter(|&i| at(x[i]) && ((i > 0 && at(x[i - 1])) || (i + 1 < x.len() && at(x[i + 1]))))
            .count()
    };
    let is_max = |v: f64| v >= max - tol;
    let is_min = |v: f64| v <= min + tol;
    let (held_max, held_min) = (held(&is_max), held(&is_min));
    let need = CLIPPED_MIN_SAMPLES.max((CLIPPED_SHARE * x.len() as f64).ceil() as usize);
    // Judged by the held samples, reported with every sample at that extreme.
    let (n, value, at): (usize, f64, &dyn Fn(f64) -> bool) = if held_max >= held_min {
        (held_max, max, &is_max)
    } else {
        (held_min, min, &is_min)
    };
    (n >= need).then(|| (x.iter().filter(|&&v| at(v)).count(), value))
}

/// Stretches of a channel that hold one value: `(samples, stretches, longest)` over the runs of
/// at least `min_run` (>= 2) consecutive samples that are exactly equal, skipping runs at
/// `skip` (the extremes of a clipped channel, which [`clipped`] reports). A live sensor's
/// signal, dithered by its own noise, changes from sample to sample (the longest run in the
/// shipped real recordings is 4 samples at 500 Hz); a data logger's dropout, filled with the
/// last value or with 0, holds it.
pub fn held_runs(x: &[f64], min_run: usize, skip: &[f64]) -> (usize, usize, usize) {
    let min_run = min_run.max(2);
    let (mut samples, mut stretches, mut longest) = (0, 0, 0);
    let mut i = 0;
    while i < x.len() {
        let mut j = i + 1;
        while j < x.len() && x[j] == x[i] {
            j += 1;
        }
        let run = j - i;
        if run >= min_run && !skip.contains(&x[i]) {
            samples += run;
            stretches += 1;
            longest = longest.max(run);
        }
        i = j;
    }
    (samples, stretches, longest)
}

/// The jackknife standard deviation of an estimate from its leave-one-out values `theta`
/// (`m >= 2` of them): `sqrt((m - 1) / m * sum (theta_s - mean)^2)`. 0 for fewer than two.
/// SSI-cov's modes, the model update's parameters and the fleet's suspension scores use it.
pub fn jackknife_std(theta: &[f64]) -> f64 {
    let m = theta.len();
    if m < 2 {
        return 0.0;
    }
    let mean = theta.iter().sum::<f64>() / m as f64;
    let ss: f64 = theta.iter().map(|t| (t - mean) * (t - mean)).sum();
    ((m as f64 - 1.0) / m as f64 * ss).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn held_stretches_are_counted() {
        // 0, 1, 1, 1, 2, 0, 0, 0, 0, 3 with runs of 3 and 4.
        let x = [0.0, 1.0, 1.0, 1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 3.0];
        assert_eq!(held_runs(&x, 3, &[]), (7, 2, 4));
        assert_eq!(held_runs(&x, 4, &[]), (4, 1, 4));
        assert_eq!(held_runs(&x, 5, &[]), (0, 0, 0));
        assert_eq!(held_runs(&x, 3, &[0.0]), (3, 1, 3));
        // A run at the end counts; min_run below 2 is 2.
        assert_eq!(held_runs(&[1.0, 2.0, 2.0], 0, &[]), (2, 1, 2));
        assert_eq!(held_runs(&[], 2, &[]), (0, 0, 0));
    }

    #[test]
    fn a_channel_held_at_an_extreme_is_clipped() {
        // A sine of 1000 samples cut at 0.9: about 29 % of its samples at each extreme.
        let sine: Vec<f64> = (0..1000)
            .map(|i| (2.0 * std::f64::consts::PI * i as f64 / 100.0).sin())
            .collect();
        assert_eq!(clipped(&sine), None);
        let cut: Vec<f64> = sine.iter().map(|v| v.clamp(-2.0, 0.9)).collect();
        let (n, value) = clipped(&cut).unwrap();
        assert_eq!(value, 0.9);
        assert_eq!(n, sine.iter().filter(|&&v| v >= 0.9).count());
        // Ten samples held at the top of 1000 (1 %) are clipped; nine are not; ten at the top
        // but never two in a row are a tone's peaks, not clipping.
        let mut x: Vec<f64> = (0..1000).map(|i| ((i * 37) % 101) as f64 / 200.0).collect();
        for v in x.iter_mut().skip(1).take(10) {
            *v = 1.0;
        }
        assert_eq!(clipped(&x), Some((10, 1.0)));
        x[10] = 0.4;
        assert_eq!(clipped(&x), None);
        let mut y: Vec<f64> = (0..1000).map(|i| ((i * 37) % 101) as f64 / 200.0).collect();
        for i in 0..10 {
            y[1 + 50 * i] = 1.0;
        }
        assert_eq!(clipped(&y), None);
        // Held ten times in a row as well: clipped, and every sample at the top is counted.
        for v in y.iter_mut().skip(700).take(10) {
            *v = 1.0;
        }
        assert_eq!(clipped(&y), Some((20, 1.0)));
        // A constant channel is not "clipped" (it is dead or stuck).
        assert_eq!(clipped(&[2.0; 50]), None);
    }

    #[test]
    fn a_dead_or_stuck_channel_has_a_constant_value_and_a_moving_one_none() {
        assert_eq!(constant_value(&[]), None);
        assert_eq!(constant_value(&[1.0]), None);
        assert_eq!(constant_value(&[0.0; 5]), Some(0.0));
        assert_eq!(constant_value(&[1e-70, -1e-70]), Some(0.0));
        assert_eq!(constant_value(&[9.81; 4]), Some(9.81));
        // Rounding-level wobble of a resampled constant is still constant...
        assert_eq!(
            constant_value(&[1.0, 1.0 + 1e-15, 1.0 - 1e-15]),
            Some(1.0 + 1e-15)
        );
        // ...a micro-g vibration on gravity is not, nor is one sign change.
        assert_eq!(constant_value(&[9.81, 9.81 + 1e-6, 9.81]), None);
        assert_eq!(constant_value(&[1.0, -1.0]), None);
        assert_eq!(constant_value(&[0.0, 0.0, 1e-3]), None);
    }

    #[test]
    fn by_hand() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(median(&[-1.0]), -1.0);
        assert_eq!(median(&[5.0, 5.0, 1.0, 9.0]), 5.0);
        assert!(median(&[]).is_nan());
        assert_eq!(median_high_in_place(&mut [4.0, 1.0, 2.0, 3.0]), 3.0);
        assert_eq!(median_high_in_place(&mut [3.0, 1.0, 2.0]), 2.0);
        assert!(median_high_in_place(&mut []).is_nan());
    }

    /// Against the definition (sort, take the middle) on seeded random inputs of every length
    /// up to 64, with ties.
    #[test]
    fn equals_the_sorted_middle_over_seeds() {
        let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
        for n in 1..=64usize {
            for _ in 0..20 {
                let v: Vec<f64> = (0..n)
                    .map(|_| {
                        state = state
                            .wrapping_mul(6_364_136_223_846_793_005)
                            .wrapping_add(1_442_695_040_888_963_407);
                        ((state >> 33) % 17) as f64 - 8.0
                    })
                    .collect();
                let mut s = v.clone();
                s.sort_by(f64::total_cmp);
                let want = if n % 2 == 1 {
                    s[n / 2]
                } else {
                    (s[n / 2 - 1] + s[n / 2]) / 2.0
                };
                assert_eq!(median(&v), want, "{v:?}");
                assert_eq!(median_high_in_place(&mut v.clone()), s[n / 2], "{v:?}");
            }
        }
    }

    #[test]
    fn dot_by_hand_and_against_one_running_sum() {
        // 1 + 2 + 3 + 4 + 5 * 2 = 20; the shorter length counts.
        assert_eq!(
            dot(&[1.0, 2.0, 3.0, 4.0, 5.0], &[1.0, 1.0, 1.0, 1.0, 2.0, 9.0]),
            20.0
        );
        assert_eq!(dot(&[], &[1.0]), 0.0);
        let mut state = 12345u64;
        for n in 0..40 {
            let mut next = || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            };
            let x: Vec<f64> = (0..n).map(|_| next()).collect();
            let z: Vec<f64> = (0..n).map(|_| next()).collect();
            let naive: f64 = x.iter().zip(&z).map(|(a, b)| a * b).sum();
            let scale: f64 = x.iter().zip(&z).map(|(a, b)| (a * b).abs()).sum();
            assert!((dot(&x, &z) - naive).abs() <= 1e-15 * scale.max(1e-300) * n as f64);
        }
    }
}
