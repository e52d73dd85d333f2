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

const ESTIMATE_VARIANCE: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tools/reference/data/estimate_variance.json"
));

/// The variances a record's own estimate gives its level ratios and transmissibility, against
/// scipy.signal's welch and csd over 4000 seeded draws each (tools/reference/estimate_variance.py,
/// numpy 2.1.3, scipy 1.14.1; one 10.24 s record at 50 Hz, Hann, nperseg 256, 3 segments): a
/// band sum's relative variance is `1 / welch_band_cells` within 10 % (8-20, 2-5 and 12-20 Hz),
/// the noise-free level's `noise_free_level_variance` and the H1 estimate's `h1_log_variance`
/// within 15 % (noise shares 9 and 31 %, coherences 0.2 and 0.8). The Monte Carlo's own
/// standard error is about 2-3 %; the tolerances are the formulas' (approximations).
#[test]
fn estimate_variances_match_scipy_monte_carlo() {
    use vibmode_fleet::model::{h1_log_variance, noise_free_level_variance, welch_band_cells};
    let r: Value = serde_json::from_str(ESTIMATE_VARIANCE).unwrap();
    assert_eq!(r["versions"]["scipy"], "1.14.1");
    let segments = r["segments"].as_u64().unwrap() as usize;
    assert_eq!(segments, 3);
    let within = |got: f64, want: f64, tol: f64, what: &str| {
        assert!(
            (got / want - 1.0).abs() < tol,
            "{what}: formula {got}, scipy {want}"
        );
    };
    for c in r["band_sum"].as_array().unwrap() {
        let bins = c["bins"].as_u64().unwrap() as usize;
        let got = 1.0 / welch_band_cells(bins, segments);
        within(
            got,
            c["relative_variance"].as_f64().unwrap(),
            0.10,
            "band sum",
        );
    }
    let cells = welch_band_cells(62, segments);
    for c in r["noise_free_level"].as_array().unwrap() {
        assert_eq!(c["kept"].as_u64(), r["draws"].as_u64());
        let level = c["mean_measured_power"].as_f64().unwrap().sqrt();
        let pn = c["noise_power"].as_f64().unwrap();
        let got = noise_free_level_variance(level, pn, cells).unwrap();
        within(
            got,
            c["log_level_variance"].as_f64().unwrap(),
            0.15,
            "noise-free level",
        );
    }
    for c in r["h1"].as_array().unwrap() {
        let bins = c["bins"].as_u64().unwrap() as usize;
        let g = c["coherence"].as_f64().unwrap();
        let got = h1_log_variance(g, segments, welch_band_cells(bins, segments)).unwrap();
        within(got, c["log_variance"].as_f64().unwrap(), 0.15, "H1");
    }
}
