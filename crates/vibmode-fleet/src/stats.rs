//! Robust statistics of the nominal model set: median, MAD, robust z-scores, and the control
//! limit from a false-alarm rate.

/// Factor that makes the MAD of normal data an estimate of its standard deviation
/// (1 / Phi^-1(3/4)).
pub const MAD_TO_SIGMA: f64 = 1.482_602_218_505_602;

/// Median of the finite values (mean of the two middle ones for an even count); `None` when
/// there is no finite value.
pub fn median(values: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    (!v.is_empty()).then(|| vibmode_core::stats::median_in_place(&mut v))
}

/// Median absolute deviation from the median (unscaled); `None` when there is no finite value.
pub fn mad(values: &[f64]) -> Option<f64> {
    let m = median(values)?;
    let dev: Vec<f64> = values
        .iter()
        .filter(|x| x.is_finite())
        .map(|x| (x - m).abs())
        .collect();
    median(&dev)
}

/// Robust spread: `max(MAD_TO_SIGMA * MAD, floor)`; `None` without finite values.
pub fn robust_sigma(values: &[f64], floor: f64) -> Option<f64> {
    Some((MAD_TO_SIGMA * mad(values)?).max(floor))
}

/// Robust z-score `(x - centre) / sigma`.
pub fn z_score(x: f64, centre: f64, sigma: f64) -> f64 {
    (x - centre) / sigma
}

/// The standard normal quantile Phi^-1(p) for 0 < p < 1 (Acklam's rational approximation,
/// relative error below 1.2e-9); NaN outside (0, 1).
pub fn normal_quantile(p: f64) -> f64 {
    if !(p > 0.0 && p < 1.0) {
        return f64::NAN;
    }
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let p_low = 0.02425;
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < p_low {
        tail((-2.0 * p.ln()).sqrt())
    } else if p <= 1.0 - p_low {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    }
}

/// Two-sided Bonferroni control limit on |z| for `n_features` scores so that a nominal record
/// raises an alarm with probability at most `false_alarm_rate` (normal scores):
/// `Phi^-1(1 - alpha / (2 m))`. `n_features = 0` counts as 1.
///
/// Computed as `-Phi^-1(alpha / (2 m))` (the normal is symmetric): `1 - alpha / (2 m)` rounds
/// to 1 below alpha / (2 m) = 1.1e-16, where the quantile would be NaN; the lower tail stays
/// finite for every positive rate.
pub fn bonferroni_limit(false_alarm_rate: f64, n_features: usize) -> f64 {
    let m = n_features.max(1) as f64;
    -normal_quantile(false_alarm_rate / (2.0 * m))
}

/// The one-sided upper confidence bound of a rate from `hits` events in `trials`
/// (Clopper-Pearson: the rate `p` at which `P(X <= hits) = 1 - confidence` for `X ~
/// Binomial(trials, p)`, the `confidence` quantile of `Beta(hits + 1, trials - hits)`). `None`
/// without trials, with more hits than trials, or with `confidence` outside (0, 1); 1 when every
/// trial was a hit. With no hit it is `1 - (1 - confidence)^(1 / trials)`: 0 of 40 drives flagged
/// bound a drive's false-alarm rate by 7.2 % at 95 %.
pub fn rate_upper_bound(hits: usize, trials: usize, confidence: f64) -> Option<f64> {
    use statrs::distribution::{Beta, ContinuousCDF};
    if trials == 0 || hits > trials || !(confidence > 0.0 && confidence < 1.0) {
        return None;
    }
    if hits == trials {
        return Some(1.0);
    }
    if hits == 0 {
        return Some(1.0 - (1.0 - confidence).powf(1.0 / trials as f64));
    }
    let beta = Beta::new(hits as f64 + 1.0, (trials - hits) as f64).ok()?;
    Some(beta.inverse_cdf(confidence))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rate_upper_bound_by_hand() {
        // No hit: 1 - 0.05^(1/n). n = 1: 0.95; n = 40: 0.0721; n = 300: 0.00994.
        let b = |k, n| rate_upper_bound(k, n, 0.95).unwrap_or(f64::NAN);
        assert!((b(0, 1) - 0.95).abs() < 1e-12);
        assert!((b(0, 40) - 0.072_158).abs() < 1e-6, "{}", b(0, 40));
        assert!((b(0, 300) - 0.009_936).abs() < 1e-6, "{}", b(0, 300));
        // One hit of two: P(X <= 1) = 1 - p^2 = 0.05 -> p = sqrt(0.95).
        assert!((b(1, 2) - 0.95f64.sqrt()).abs() < 1e-9, "{}", b(1, 2));
        // n - 1 hits of n: P(X <= n - 1) = 1 - p^n -> p = 0.95^(1/n).
        assert!((b(4, 5) - 0.95f64.powf(0.2)).abs() < 1e-9, "{}", b(4, 5));
        assert_eq!(b(3, 3), 1.0);
        assert_eq!(rate_upper_bound(0, 0, 0.95), None);
        assert_eq!(rate_upper_bound(3, 2, 0.95), None);
        assert_eq!(rate_upper_bound(0, 5, 1.0), None);
        assert_eq!(rate_upper_bound(0, 5, f64::NAN), None);
    }

    /// At the bound the binomial's lower tail is `1 - confidence` (the bound's definition), over
    /// seeded counts.
    #[test]
    fn rate_upper_bound_puts_the_lower_tail_at_one_minus_the_confidence() {
        use statrs::distribution::{Binomial, DiscreteCDF};
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = |m: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % m
        };
        for _ in 0..300 {
            let n = 1 + next(400) as usize;
            let k = next(n as u64) as usize;
            let conf = [0.8, 0.9, 0.95, 0.99][next(4) as usize];
            let p = rate_upper_bound(k, n, conf).unwrap_or(f64::NAN);
            let tail = Binomial::new(p, n as u64).map_or(f64::NAN, |d| d.cdf(k as u64));
            assert!(
                (tail - (1.0 - conf)).abs() < 1e-6,
                "{k} of {n} at {conf}: bound {p}, P(X <= k) {tail}"
            );
            // More hits, a higher bound.
            if k + 1 < n {
                assert!(rate_upper_bound(k + 1, n, conf).unwrap_or(0.0) > p);
            }
        }
    }

    #[test]
    fn median_and_mad_by_hand() {
        // Sorted 1 2 3 4 100: median 3; deviations 2 1 0 1 97 -> sorted 0 1 1 2 97 -> MAD 1.
        let v = [3.0, 1.0, 100.0, 2.0, 4.0];
        assert_eq!(median(&v), Some(3.0));
        assert_eq!(mad(&v), Some(1.0));
        // Even count: 1 2 4 7 -> median 3; deviations 2 1 1 4 -> sorted 1 1 2 4 -> MAD 1.5.
        let w = [7.0, 1.0, 4.0, 2.0];
        assert_eq!(median(&w), Some(3.0));
        assert_eq!(mad(&w), Some(1.5));
        // Non-finite values are ignored; none left is None.
        assert_eq!(median(&[f64::NAN, 5.0]), Some(5.0));
        assert_eq!(median(&[f64::NAN]), None);
        assert_eq!(mad(&[]), None);
    }

    #[test]
    fn sigma_has_a_floor_and_z_is_in_sigmas() {
        let v = [10.0, 10.0, 10.0, 10.0, 11.0];
        // MAD 0 -> the floor.
        assert_eq!(robust_sigma(&v, 0.5), Some(0.5));
        let s = robust_sigma(&[1.0, 2.0, 3.0, 4.0, 5.0], 0.0).unwrap_or(f64::NAN);
        assert!((s - 1.482_602_218_505_602).abs() < 1e-12, "{s}");
        assert_eq!(z_score(13.0, 10.0, 0.5), 6.0);
        assert_eq!(z_score(9.0, 10.0, 0.5), -2.0);
    }

    #[test]
    fn normal_quantiles_match_tables() {
        // Textbook values of the standard normal quantile.
        for (p, q) in [
            (0.5, 0.0),
            (0.975, 1.959_963_985),
            (0.995, 2.575_829_304),
            (0.999_9, 3.719_016_485),
            (0.01, -2.326_347_874),
            (1e-6, -4.753_424_309),
        ] {
            let got = normal_quantile(p);
            assert!((got - q).abs() < 1e-7, "p {p}: {got} vs {q}");
        }
        assert!(normal_quantile(0.0).is_nan() && normal_quantile(1.0).is_nan());
        // alpha 0.01 over 50 features: Phi^-1(1 - 1e-4) = 3.719.
        assert!((bonferroni_limit(0.01, 50) - 3.719_016_485).abs() < 1e-7);
        assert!((bonferroni_limit(0.05, 1) - 1.959_963_985).abs() < 1e-7);
        // Tiny rates (1e-15 made 1 - alpha / 2m round to 1: a NaN limit) stay finite and
        // grow: Phi^-1(1 - 5e-16) = 8.0269 (bisection of erfc).
        assert!(
            (bonferroni_limit(1e-15, 1) - 8.026_859).abs() < 1e-4,
            "{}",
            bonferroni_limit(1e-15, 1)
        );
        let mut last = 0.0;
        for rate in [1e-9, 1e-15, 1e-100, 1e-300] {
            let l = bonferroni_limit(rate, 1000);
            assert!(l.is_finite() && l > last, "{rate}: {l}");
            last = l;
        }
    }
}
