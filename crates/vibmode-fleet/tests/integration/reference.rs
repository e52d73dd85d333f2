//! The fleet's numeric routines against an independent implementation (scipy; the pinned scripts
//! in tools/reference/, their JSON committed).

use serde_json::Value;
use vibmode_fleet::suspension::{fiducial_z, fiducial_z_shared, t_as_normal, FIDUCIAL_DRAWS};

const T_AS_NORMAL: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tools/reference/data/t_as_normal.json"
));

/// A Student t score made a normal score with its tail probability, against
/// `-scipy.stats.norm.isf(scipy.stats.t.cdf(-|t|, df))` with t's sign
/// (tools/reference/t_as_normal.py, scipy 1.14.1): t in -40..8, 2-1000 degrees of freedom, to
/// 1e-7 absolute plus 1e-7 relative.
#[test]
fn t_as_normal_matches_scipy() {
    let r: Value = serde_json::from_str(T_AS_NORMAL).unwrap();
    assert_eq!(r["versions"]["scipy"], "1.14.1");
    let cases = r["cases"].as_array().unwrap();
    assert!(cases.len() >= 150);
    for c in cases {
        let (t, df, want) = (
            c["t"].as_f64().unwrap(),
            c["df"].as_f64().unwrap(),
            c["z"].as_f64().unwrap(),
        );
        let got = t_as_normal(t, df);
        assert!(
            (got - want).abs() <= 1e-7 + 1e-7 * want.abs(),
            "t {t} df {df}: {got} vs scipy {want}"
        );
    }
}

const FIDUCIAL_Z: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tools/reference/data/fiducial_z.json"
));

/// The Behrens-Fisher fiducial score of a difference over two estimated variance parts, against
/// scipy's nested quadrature of the same expectation (tools/reference/fiducial_z.py, scipy
/// 1.14.1): a drive against a baseline, against a precise reference, two equal parts, a trend
/// against a baseline; |z| from 0.8 to 5; and a part that shares a factor of its own degrees of
/// freedom (a drive's spring variance as its scale times the reference's proportion,
/// `fiducial_z_shared`: scipy's triple quadrature); to 0.03 (vibmode's Monte Carlo of 32768
/// draws).
#[test]
fn fiducial_z_matches_scipy_quadrature() {
    let r: Value = serde_json::from_str(FIDUCIAL_Z).unwrap();
    assert_eq!(r["versions"]["scipy"], "1.14.1");
    let cases = r["cases"].as_array().unwrap();
    assert!(cases.len() >= 36);
    assert!(cases.iter().filter(|c| c.get("shared").is_some()).count() >= 8);
    for c in cases {
        let d = c["d"].as_f64().unwrap();
        let parts: Vec<(f64, f64)> = c["parts"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
            .collect();
        let want = c["z"].as_f64().unwrap();
        let got = match c.get("shared") {
            Some(shared) => {
                let shared: Vec<bool> = shared
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|b| b.as_bool().unwrap())
                    .collect();
                let k = c["shared_df"].as_f64().unwrap();
                fiducial_z_shared(d, &parts, &shared, k, FIDUCIAL_DRAWS)
            }
            None => fiducial_z(d, &parts),
        };
        assert!(
            (got - want).abs() <= 0.03,
            "d {d} parts {parts:?}: {got} vs scipy {want}"
        );
    }
}

const RATE_UPPER_BOUND: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tools/reference/data/rate_upper_bound.json"
));

/// The Clopper-Pearson upper bound of a false-alarm rate from k flagged of n held-out drives,
/// against `scipy.stats.beta.ppf(confidence, k + 1, n - k)` (tools/reference/rate_upper_bound.py,
/// scipy 1.14.1): n 1..2000, k from 0 to n, confidence 0.8..0.999, to 1e-9 absolute plus 1e-7
/// relative.
#[test]
fn rate_upper_bound_matches_scipy() {
    let r: Value = serde_json::from_str(RATE_UPPER_BOUND).unwrap();
    assert_eq!(r["versions"]["scipy"], "1.14.1");
    let cases = r["cases"].as_array().unwrap();
    assert!(cases.len() >= 200, "{}", cases.len());
    for c in cases {
        let (k, n, conf, want) = (
            c["k"].as_u64().unwrap() as usize,
            c["n"].as_u64().unwrap() as usize,
            c["confidence"].as_f64().unwrap(),
            c["bound"].as_f64().unwrap(),
        );
        let got = vibmode_fleet::stats::rate_upper_bound(k, n, conf).unwrap_or(f64::NAN);
        assert!(
            (got - want).abs() <= 1e-9 + 1e-7 * want.abs(),
            "{k} of {n} at {conf}: {got} vs scipy {want}"
        );
    }
}
