//! Numeric helpers against the numpy reference in tools/reference/report_plot.py
//! (tools/reference/data/report_plot.json). Tolerances are stated in the script's docstring.

use serde_json::Value;
use vibmode_report::axes::{auto_range, decimate_minmax, nice_ticks, rescale_to};
use vibmode_report::Scale;

const REF: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tools/reference/data/report_plot.json"
));

fn data() -> Value {
    serde_json::from_str(REF).expect("reference JSON parses")
}

fn num(v: &Value) -> f64 {
    match v {
        Value::Number(n) => n.as_f64().expect("number"),
        Value::String(s) => match s.as_str() {
            "nan" => f64::NAN,
            "inf" => f64::INFINITY,
            "-inf" => f64::NEG_INFINITY,
            other => panic!("unexpected string {other}"),
        },
        Value::Null => f64::NAN,
        other => panic!("unexpected value {other}"),
    }
}

fn vec_of(v: &Value) -> Vec<f64> {
    v.as_array().expect("array").iter().map(num).collect()
}

fn scale_of(v: &Value) -> Scale {
    v.as_str().expect("scale").parse().expect("valid scale")
}

#[test]
fn decimation_matches_numpy_m4_exactly() {
    let d = data();
    let cases = d["decimate"].as_array().unwrap();
    assert_eq!(cases.len(), 4);
    for (k, c) in cases.iter().enumerate() {
        let x = vec_of(&c["x"]);
        let y = vec_of(&c["y"]);
        let kept = decimate_minmax(
            &x,
            &y,
            num(&c["x_lo"]),
            num(&c["x_hi"]),
            c["n_columns"].as_u64().unwrap() as usize,
        );
        let expected: Vec<usize> = c["kept"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap() as usize)
            .collect();
        assert!(expected.len() < x.len() / 2, "case {k} should compress");
        assert_eq!(kept, expected, "case {k}");
    }
}

#[test]
fn nice_ticks_match_brute_force_reference() {
    let d = data();
    let cases = d["nice_ticks"].as_array().unwrap();
    assert!(cases.len() >= 50);
    for c in cases {
        let (lo, hi) = (num(&c["lo"]), num(&c["hi"]));
        let m = c["max_ticks"].as_u64().unwrap() as usize;
        let step = num(&c["step"]);
        let expected = vec_of(&c["ticks"]);
        let got = nice_ticks(lo, hi, m);
        assert_eq!(
            got.len(),
            expected.len(),
            "lo {lo} hi {hi} max {m}: {got:?} vs {expected:?}"
        );
        for (g, e) in got.iter().zip(&expected) {
            assert!((g - e).abs() <= 1e-12 * step, "lo {lo} hi {hi}: {g} vs {e}");
        }
    }
}

#[test]
fn auto_range_matches_numpy() {
    let d = data();
    let cases = d["auto_range"].as_array().unwrap();
    assert_eq!(cases.len(), 20);
    for c in cases {
        let v = vec_of(&c["values"]);
        let scale = scale_of(&c["scale"]);
        let (lo, hi) = auto_range(&v, scale);
        let (elo, ehi) = (num(&c["lo"]), num(&c["hi"]));
        let tol = |e: f64| 1e-12 * e.abs().max(1e-300);
        assert!(
            (lo - elo).abs() <= tol(elo),
            "{scale} {v:?}: lo {lo} vs {elo}"
        );
        assert!(
            (hi - ehi).abs() <= tol(ehi),
            "{scale} {v:?}: hi {hi} vs {ehi}"
        );
    }
}

#[test]
fn rescale_matches_numpy() {
    let d = data();
    for c in d["rescale"].as_array().unwrap() {
        let v = vec_of(&c["values"]);
        let scale = scale_of(&c["scale"]);
        let t = vec_of(&c["target"]);
        let got = rescale_to(&v, scale, (t[0], t[1]));
        let expected: Vec<Option<f64>> = c["expected"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e.as_f64())
            .collect();
        assert_eq!(got.len(), expected.len());
        for (g, e) in got.iter().zip(&expected) {
            match e {
                None => assert!(g.is_nan(), "{g} should be NaN"),
                Some(e) => assert!((g - e).abs() <= 1e-12 * (t[1] - t[0]).abs(), "{g} vs {e}"),
            }
        }
    }
}
