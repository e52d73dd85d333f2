//! Every `SsiError` variant from bad input, with its message naming the offending value.
//! (`NotConverged` is produced by a unit test of the eigen-decomposition in `src/eig.rs`: finite
//! input data cannot reach it through the public functions.)

use vibmode_ssi::{ssi_cov, SsiCov, SsiError, SsiParams};

fn noise(n: usize, seed: u64) -> Vec<f64> {
    // A small linear congruential generator: deterministic, no RNG crate needed.
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect()
}

fn params(block_rows: usize) -> SsiParams {
    SsiParams {
        block_rows,
        order_min: 2,
        order_max: 4,
        order_step: 2,
        reference_channels: None,
        pool_records: false,
        first_lag: 1,
    }
}

fn msg(r: Result<impl std::fmt::Debug, SsiError>) -> (SsiError, String) {
    let e = r.expect_err("expected an error");
    let m = e.to_string();
    assert!(!m.contains('\n'), "one line: {m}");
    assert!(!m.contains("--"), "no command-line flag: {m}");
    (e, m)
}

#[test]
fn no_channels() {
    let (e, m) = msg(ssi_cov(&[], 50.0, &params(5)));
    assert_eq!(e, SsiError::NoChannels);
    assert!(m.contains("at least one channel"), "{m}");
}

#[test]
fn too_short() {
    let a = noise(1, 1);
    let (e, m) = msg(ssi_cov(&[&a], 50.0, &params(5)));
    assert!(
        matches!(
            e,
            SsiError::TooShort {
                channel: 0,
                n_samples: 1
            }
        ),
        "{e:?}"
    );
    assert!(m.contains("1 samples") && m.contains("at least 2"), "{m}");
}

#[test]
fn length_mismatch() {
    let (a, b) = (noise(100, 1), noise(99, 2));
    let (e, m) = msg(ssi_cov(&[&a, &b], 50.0, &params(5)));
    assert!(
        matches!(
            e,
            SsiError::LengthMismatch {
                channel: 1,
                found: 99,
                expected: 100
            }
        ),
        "{e:?}"
    );
    assert!(m.contains("channel 1 has 99") && m.contains("100"), "{m}");
}

#[test]
fn non_finite() {
    let a = noise(100, 1);
    let mut b = noise(100, 2);
    b[37] = f64::NAN;
    let (e, m) = msg(ssi_cov(&[&a, &b], 50.0, &params(5)));
    assert!(
        matches!(
            e,
            SsiError::NonFinite {
                channel: 1,
                index: 37,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(m.contains("channel 1 sample 37 is NaN"), "{m}");
    b[37] = f64::NEG_INFINITY;
    let (_, m) = msg(ssi_cov(&[&a, &b], 50.0, &params(5)));
    assert!(m.contains("is -inf"), "{m}");
}

#[test]
fn invalid_sample_rate() {
    let a = noise(100, 1);
    for fs in [0.0, -50.0, f64::NAN, f64::INFINITY] {
        let (e, m) = msg(ssi_cov(&[&a], fs, &params(5)));
        assert!(matches!(e, SsiError::InvalidSampleRate { .. }), "{e:?}");
        assert!(m.contains(&format!("{fs} Hz")), "{m}");
    }
}

#[test]
fn too_few_samples_for_the_block_rows() {
    // 20 block rows: 39 lags, each averaged over at least 39 products: 78 samples.
    let a = noise(77, 1);
    let (e, m) = msg(ssi_cov(&[&a], 50.0, &params(20)));
    assert_eq!(
        e,
        SsiError::TooFewSamples {
            n_samples: 77,
            block_rows: 20,
            first_lag: 1,
            max_lag: 39,
            min_samples: 78
        }
    );
    assert!(
        m.contains("77 samples") && m.contains("block_rows = 20") && m.contains("at least 78"),
        "{m}"
    );
    // Exactly 2 (2 i - 1) samples is accepted.
    let a = noise(78, 1);
    assert!(SsiCov::new(&[&a], 50.0, &params(20)).is_ok());
    // A later first lag needs as many more samples: lags 11..=49 need 88.
    let p = SsiParams {
        first_lag: 11,
        ..params(20)
    };
    let (e, m) = msg(ssi_cov(&[&a], 50.0, &p));
    assert_eq!(
        e,
        SsiError::TooFewSamples {
            n_samples: 78,
            block_rows: 20,
            first_lag: 11,
            max_lag: 49,
            min_samples: 88
        }
    );
    assert!(
        m.contains("lags 11..=49") && m.contains("at least 88"),
        "{m}"
    );
    assert!(SsiCov::new(&[&noise(88, 1)], 50.0, &p).is_ok());
    let (_, m) = msg(ssi_cov(
        &[&a],
        50.0,
        &SsiParams {
            first_lag: 0,
            ..params(5)
        },
    ));
    assert!(m.contains("first_lag = 0") && m.contains(">= 1"), "{m}");
}

#[test]
fn invalid_params() {
    let a = noise(100, 1);
    let p = SsiParams {
        order_min: 1,
        ..params(5)
    };
    let (e, m) = msg(ssi_cov(&[&a], 50.0, &p));
    assert!(matches!(e, SsiError::Param(_)), "{e:?}");
    assert!(
        m.contains("order_min = 1") && m.contains("order_min = 2"),
        "{m}"
    );
    let p = SsiParams {
        block_rows: 0,
        ..params(5)
    };
    let (_, m) = msg(ssi_cov(&[&a], 50.0, &p));
    assert!(m.contains("block_rows = 0"), "{m}");
}

#[test]
fn zero_order() {
    let a = noise(200, 1);
    let cov = SsiCov::new(&[&a], 50.0, &params(5)).unwrap();
    let (e, m) = msg(cov.poles_at(0));
    assert_eq!(e, SsiError::ZeroOrder);
    assert!(m.contains("order 0") && m.contains(">= 1"), "{m}");
}

#[test]
fn order_too_high_for_the_block_rows() {
    let (a, b) = (noise(500, 1), noise(500, 2));
    let cov = SsiCov::new(&[&a, &b], 50.0, &params(5)).unwrap();
    assert_eq!(cov.max_order(), 8);
    assert!(cov.poles_at(8).is_ok());
    let (e, m) = msg(cov.poles_at(10));
    assert_eq!(
        e,
        SsiError::OrderTooHigh {
            order: 10,
            block_rows: 5,
            n_channels: 2,
            n_references: 2,
            max_order: 8,
            needed_block_rows: 6
        }
    );
    assert!(
        m.contains("order 10") && m.contains("= 8") && m.contains("block_rows to 6"),
        "{m}"
    );
    // Through ssi_cov: the sweep stops at the first order it cannot identify.
    let p = SsiParams {
        order_max: 12,
        ..params(5)
    };
    let (e, _) = msg(ssi_cov(&[&a, &b], 50.0, &p));
    assert!(
        matches!(e, SsiError::OrderTooHigh { order: 10, .. }),
        "{e:?}"
    );
    // One block row leaves no shift: every order is too high.
    let (e, _) = msg(ssi_cov(&[&a, &b], 50.0, &params(1)));
    assert!(
        matches!(
            e,
            SsiError::OrderTooHigh {
                order: 2,
                max_order: 0,
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn order_above_the_rank() {
    // A tone at the Nyquist frequency (+1, -1, ...): every lag's correlation is +-1 times the
    // same value, so the Toeplitz matrix has rank 1 and order 2 is above it.
    let a: Vec<f64> = (0..200)
        .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
        .collect();
    let (e, m) = msg(ssi_cov(&[&a], 50.0, &params(5)));
    assert!(
        matches!(
            e,
            SsiError::OrderAboveRank {
                order: 2,
                rank: 1,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(m.contains("order 2") && m.contains("rank 1"), "{m}");
}

#[test]
fn a_constant_channel_is_named() {
    // A stuck sensor (or a dead one) carries no vibration; its mean removed it would be
    // rank 0, and scaled to unit RMS it would be rounding noise.
    let a = noise(200, 1);
    for value in [3.5, 0.0] {
        let b = vec![value; 200];
        let (e, m) = msg(ssi_cov(&[&a, &b], 50.0, &params(5)));
        assert_eq!(e, SsiError::ConstantChannel { channel: 1, value });
        assert!(
            m.contains("channel 1 is constant") && m.contains(&format!("every sample is {value}")),
            "{m}"
        );
    }
}

#[test]
fn reference_channel_out_of_range() {
    let (a, b) = (noise(200, 1), noise(200, 2));
    let p = SsiParams {
        reference_channels: Some(vec![0, 2]),
        ..params(5)
    };
    let (e, m) = msg(ssi_cov(&[&a, &b], 50.0, &p));
    assert_eq!(
        e,
        SsiError::ReferenceChannel {
            index: 2,
            n_channels: 2,
            last: 1
        }
    );
    assert!(
        m.contains("reference channel 2") && m.contains("0..=1"),
        "{m}"
    );
}

#[test]
fn order_limited_by_the_references() {
    // 3 channels, 1 reference, 4 block rows: the Toeplitz matrix is 12 x 4, so at most order 4
    // (and (4 - 1) x 3 = 9 from the shift).
    let ch: Vec<Vec<f64>> = (0..3).map(|s| noise(500, s)).collect();
    let refs: Vec<&[f64]> = ch.iter().map(Vec::as_slice).collect();
    let p = SsiParams {
        reference_channels: Some(vec![1]),
        ..params(4)
    };
    let cov = SsiCov::new(&refs, 50.0, &p).unwrap();
    assert_eq!(cov.n_references(), 1);
    assert_eq!(cov.singular_values().len(), 4);
    let (e, m) = msg(cov.poles_at(6));
    assert!(
        matches!(
            e,
            SsiError::OrderTooHigh {
                order: 6,
                max_order: 4,
                n_references: 1,
                needed_block_rows: 6,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(
        m.contains("1 references") && m.contains("= 4") && m.contains("block_rows to 6"),
        "{m}"
    );
}

#[test]
fn overflowing_correlations() {
    let a: Vec<f64> = noise(200, 1).iter().map(|v| v * 1e300).collect();
    let (e, m) = msg(ssi_cov(&[&a], 50.0, &params(5)));
    assert!(matches!(e, SsiError::Overflow { lag: 1, .. }), "{e:?}");
    assert!(m.contains("lag 1") && m.contains("e299"), "{m}");
}

#[test]
fn jackknife_needs_two_segments() {
    let a = noise(100, 1);
    let e = SsiCov::jackknife(&[vec![a.as_slice()]], 50.0, &params(5), 2).unwrap_err();
    assert_eq!(
        e,
        SsiError::TooFewSegments {
            n_segments: 1,
            groups: 2
        }
    );
    let m = e.to_string();
    assert!(m.contains("2 groups over 1 segments"), "{m}");
    let two = [vec![a.as_slice()], vec![a.as_slice()]];
    assert!(SsiCov::jackknife(&two, 50.0, &params(5), 2).is_ok());
    assert!(SsiCov::jackknife(&two, 50.0, &params(5), 1).is_err());
    assert!(SsiCov::jackknife(&two, 50.0, &params(5), 3).is_err());
}

#[test]
fn one_record_pipeline_with_no_identifiable_order() {
    let y: Vec<Vec<f64>> = (0..2).map(|c| noise(400, c)).collect();
    let chans: Vec<&[f64]> = y.iter().map(Vec::as_slice).collect();
    // 2 channels, 3 block rows: the highest order is 4, below order_min 10.
    let p = SsiParams {
        block_rows: 3,
        order_min: 10,
        order_max: 20,
        ..SsiParams::default()
    };
    let (e, m) = msg(vibmode_ssi::identify_record(
        &chans,
        50.0,
        &p,
        &vibmode_ssi::RecordSsiOptions::default(),
    ));
    assert!(matches!(e, SsiError::NoOrder { max_order: 4, .. }), "{e:?}");
    assert!(
        m.contains("highest is 4") && m.contains("block_rows"),
        "{m}"
    );
}

#[test]
fn perturbation_blocks_too_short_or_too_few() {
    // 5 block rows: lags up to 9, so a block needs 10 samples; 95 samples allow 9 blocks.
    let (a, b) = (noise(95, 1), noise(95, 2));
    let (e, m) = msg(SsiCov::perturbation(&[&a, &b], 50.0, &params(5), 10));
    assert_eq!(
        e,
        SsiError::BlocksTooShort {
            n_samples: 95,
            n_blocks: 10,
            block_len: 9,
            min_block_len: 10,
            max_blocks: 9
        }
    );
    assert!(
        m.contains("10 blocks") && m.contains("at most 9 blocks") && !m.contains('\n'),
        "{m}"
    );
    assert!(SsiCov::perturbation(&[&a, &b], 50.0, &params(5), 9).is_ok());
    let (e, m) = msg(SsiCov::perturbation(&[&a, &b], 50.0, &params(5), 1));
    assert_eq!(e, SsiError::TooFewBlocks { n_blocks: 1 });
    assert!(m.contains("at least 2 blocks"), "{m}");
    // Non-finite data is named as for SsiCov::new.
    let mut c = a.clone();
    c[40] = f64::NAN;
    let (e, _) = msg(SsiCov::perturbation(&[&c, &b], 50.0, &params(5), 4));
    assert!(
        matches!(
            e,
            SsiError::NonFinite {
                channel: 0,
                index: 40,
                ..
            }
        ),
        "{e:?}"
    );
}

/// Issue 28: `--first-lag 18446744073709551615` panicked (a range start out of range) and a huge
/// `block_rows` wrapped around; the library refuses both, naming the value, on every entry point.
#[test]
fn huge_first_lag_and_block_rows_are_refused_not_wrapped() {
    let (a, b) = (noise(2048, 1), noise(2048, 2));
    for (p, needle) in [
        (
            SsiParams {
                first_lag: usize::MAX,
                ..params(20)
            },
            "first_lag = 18446744073709551615",
        ),
        (
            SsiParams {
                block_rows: usize::MAX,
                ..params(20)
            },
            "block_rows = 18446744073709551615",
        ),
        (
            SsiParams {
                block_rows: usize::MAX / 2 + 1,
                ..params(20)
            },
            "block_rows = 9223372036854775808",
        ),
    ] {
        let (e, m) = msg(ssi_cov(&[&a, &b], 50.0, &p));
        assert!(matches!(e, SsiError::Param(_)), "{e:?}");
        assert!(m.contains(needle), "{m}");
        let segs = [vec![a.as_slice(), b.as_slice()]];
        let (_, m) = msg(vibmode_ssi::SsiCorrelations::new(&segs, 50.0, &p));
        assert!(m.contains(needle), "{m}");
        let (_, m) = msg(SsiCov::perturbation(&[&a, &b], 50.0, &p, 4));
        assert!(m.contains(needle), "{m}");
    }
    // Per-segment first lags are checked as well.
    let segs = [vec![a.as_slice(), b.as_slice()]];
    let (e, m) = msg(vibmode_ssi::SsiCorrelations::with_first_lags(
        &segs,
        50.0,
        &params(20),
        &[usize::MAX],
    ));
    assert!(matches!(e, SsiError::LagsTooLarge { .. }), "{e:?}");
    assert!(m.contains("first_lag = 18446744073709551615"), "{m}");
    // A first lag within the bound but beyond the record: too few samples, named.
    let p = SsiParams {
        first_lag: 1 << 30,
        ..params(20)
    };
    let (e, m) = msg(ssi_cov(&[&a, &b], 50.0, &p));
    assert!(
        matches!(
            e,
            SsiError::TooFewSamples {
                n_samples: 2048,
                first_lag: 1073741824,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(m.contains("at least 1073741901"), "{m}");
}

/// Issue 28: 1000 block rows on a 2048-sample record ran for minutes (a 1000 x 1000 SVD from
/// correlations of a few products each). The record's length bounds the block rows, and the
/// Toeplitz matrix's size is bounded whatever the length.
#[test]
fn block_rows_are_bounded_by_the_record_and_the_matrix_size() {
    let a = noise(2048, 1);
    let (e, m) = msg(ssi_cov(&[&a], 50.0, &params(1000)));
    assert_eq!(
        e,
        SsiError::TooFewSamples {
            n_samples: 2048,
            block_rows: 1000,
            first_lag: 1,
            max_lag: 1999,
            min_samples: 3998
        }
    );
    assert!(m.contains("block_rows = 1000") && m.contains("3998"), "{m}");
    // The largest block rows this record allows: 2 (2 i - 1) <= 2048.
    let one = [vec![a.as_slice()]];
    assert!(vibmode_ssi::SsiCorrelations::new(&one, 50.0, &params(512)).is_ok());
    assert!(matches!(
        vibmode_ssi::SsiCorrelations::new(&one, 50.0, &params(513)).unwrap_err(),
        SsiError::TooFewSamples { .. }
    ));
    // 600 block rows of 2 channels: 1200 rows, above the 1024 the SVD is allowed, however long
    // the record.
    let (c, d) = (noise(5000, 3), noise(5000, 4));
    let (e, m) = msg(SsiCov::new(&[&c, &d], 50.0, &params(600)));
    assert_eq!(
        e,
        SsiError::MatrixTooLarge {
            block_rows: 600,
            n_channels: 2,
            max_rows: 1024,
            max_block_rows: 512
        }
    );
    assert!(
        m.contains("block_rows = 600 with 2 channels") && m.contains("block_rows = 512"),
        "{m}"
    );
    let (e, _) = msg(SsiCov::perturbation(&[&c, &d], 50.0, &params(600), 2));
    assert!(matches!(e, SsiError::MatrixTooLarge { .. }), "{e:?}");
}

/// Uncertainty blocks cost two SVDs each: their number is bounded by the matrix size.
#[test]
fn uncertainty_blocks_are_bounded_by_the_svd_work() {
    let (a, b) = (noise(40_000, 1), noise(40_000, 2));
    // 256 block rows of 2 channels: a 512 x 512 matrix, 2^27 work per SVD: at most 31 blocks.
    let p = SsiParams {
        block_rows: 256,
        ..params(256)
    };
    let (e, m) = msg(SsiCov::perturbation(&[&a, &b], 50.0, &p, 40));
    assert_eq!(
        e,
        SsiError::TooManyBlocks {
            n_blocks: 40,
            rows: 512,
            cols: 512,
            max_blocks: 31
        }
    );
    assert!(m.contains("at most 31 blocks"), "{m}");
}

/// Issue 28: an order list is identified as listed (`10, 20, 35` once ran 10, 20, 30), and a
/// list that is not increasing orders within the bound is refused.
#[test]
fn order_lists_are_taken_as_listed() {
    let y: Vec<Vec<f64>> = (0..4).map(|c| noise(4000, c)).collect();
    let chans: Vec<&[f64]> = y.iter().map(Vec::as_slice).collect();
    let p = SsiParams {
        block_rows: 12,
        ..SsiParams::default()
    };
    let options = vibmode_ssi::RecordSsiOptions {
        orders: Some(vec![10, 20, 35]),
        ..Default::default()
    };
    let r = vibmode_ssi::identify_record(&chans, 50.0, &p, &options).unwrap();
    let got: Vec<usize> = r.result.orders.iter().map(|o| o.order).collect();
    assert_eq!(got, vec![10, 20, 35]);
    for bad in [vec![], vec![0, 2], vec![4, 2], vec![2, 2], vec![2, 5000]] {
        let options = vibmode_ssi::RecordSsiOptions {
            orders: Some(bad.clone()),
            ..Default::default()
        };
        let (e, m) = msg(vibmode_ssi::identify_record(&chans, 50.0, &p, &options));
        assert!(matches!(e, SsiError::OrderList { .. }), "{bad:?}: {e:?}");
        assert!(m.contains("increasing orders from 1 to 1024"), "{m}");
    }
    // A list of 10^5 orders is quoted in at most 60 characters.
    let long: Vec<usize> = (1..100_000).rev().collect();
    let options = vibmode_ssi::RecordSsiOptions {
        orders: Some(long),
        ..Default::default()
    };
    let (_, m) = msg(vibmode_ssi::identify_record(&chans, 50.0, &p, &options));
    assert!(m.len() < 200, "{m}");
}
