//! The fleet's numeric routines against an independent implementation (scipy; the pinned scripts
//! in tools/reference/, their JSON committed).

use serde_json::Value;
use vibmode_fleet::suspension::t_as_normal;

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
