//! Property test of the fleet settings parser (issue 28): any TOML with arbitrary finite or
//! non-finite values is either refused with a short error naming a key or the file, or gives
//! settings whose derived limits are all finite and which read back unchanged from the JSON a
//! store keeps (so no later command can find the store's settings unreadable).

use proptest::prelude::*;
use vibmode_fleet::stats::bonferroni_limit;
use vibmode_fleet::FleetConfig;

/// A number as TOML: finite ones in Rust's round-trip form, the non-finite as TOML spells them.
fn toml_number(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.into()
    } else {
        format!("{x:?}")
    }
}

fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<f64>().prop_map(toml_number),
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        (-30.0f64..30.0).prop_map(toml_number),
        (-320i32..2).prop_map(|e| toml_number(10f64.powi(e))),
        (0.0f64..1.0).prop_map(toml_number),
        (-5i64..100).prop_map(|i| i.to_string()),
    ]
}

const SCALARS: &[&str] = &[
    "false_alarm_rate",
    "min_nominal",
    "floor_level",
    "floor_transmissibility",
    "transmissibility_min_hz",
    "transmissibility_min_coherence",
    "floor_frequency",
    "floor_damping",
    "mode_group_tol",
    "mode_match_tol",
    "mode_min_share",
    "floor_side_ratio",
    "floor_track_ratio",
    "floor_body_response",
];

const PAIRS: &[&str] = &["ratio_band_hz", "body_band_hz"];
const BAND_LISTS: &[&str] = &["bands_hz", "body_response_bands_hz"];

/// One `key = value` line of the fleet settings, or of `[analysis]` (kept apart).
fn line() -> impl Strategy<Value = (bool, String)> {
    prop_oneof![
        (prop::sample::select(SCALARS), number()).prop_map(|(k, v)| (false, format!("{k} = {v}"))),
        (prop::sample::select(PAIRS), number(), number())
            .prop_map(|(k, a, b)| (false, format!("{k} = [{a}, {b}]"))),
        (
            prop::sample::select(BAND_LISTS),
            prop::collection::vec((number(), number()), 0..4)
        )
            .prop_map(|(k, bands)| {
                let b: Vec<String> = bands.iter().map(|(a, b)| format!("[{a}, {b}]")).collect();
                (false, format!("{k} = [{}]", b.join(", ")))
            }),
        (
            prop::sample::select(&["record_length_s", "analysis_fs_hz", "cutoff_hz"][..]),
            number()
        )
            .prop_map(|(k, v)| (true, format!("{k} = {v}"))),
    ]
}

fn document() -> impl Strategy<Value = String> {
    prop::collection::vec(line(), 0..6).prop_map(|lines| {
        let mut top = Vec::new();
        let mut analysis = Vec::new();
        for (in_analysis, l) in lines {
            // One value per key (a repeated key is a TOML error, not what is tested here).
            let key = l.split(" = ").next().unwrap_or("").to_string();
            let list = if in_analysis { &mut analysis } else { &mut top };
            if !list
                .iter()
                .any(|x: &String| x.split(" = ").next() == Some(key.as_str()))
            {
                list.push(l);
            }
        }
        let mut text = top.join("\n");
        if !analysis.is_empty() {
            text.push_str("\n[analysis]\n");
            text.push_str(&analysis.join("\n"));
        }
        text.push('\n');
        text
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn settings_are_refused_or_give_finite_limits(text in document()) {
        match FleetConfig::from_toml_str(&text, "fleet.toml") {
            Err(e) => {
                let msg = e.to_string();
                prop_assert!(msg.len() < 400, "long message ({} bytes): {msg}", msg.len());
                prop_assert!(!msg.contains('\n'), "not one line: {msg}");
            }
            Ok(cfg) => {
                for m in [0usize, 1, 7, 1000, 1_000_000] {
                    let l = bonferroni_limit(cfg.false_alarm_rate, m);
                    prop_assert!(l.is_finite() && l > 0.0, "limit {l} for m {m}: {text}");
                }
                let fs = cfg.min_fs_hz();
                let s = cfg.min_record_s();
                prop_assert!(fs.is_finite() && fs > 0.0, "min fs {fs}: {text}");
                prop_assert!(s.is_finite() && s > 0.0, "min record {s}: {text}");
                for floor in [
                    cfg.floor_level,
                    cfg.floor_transmissibility,
                    cfg.floor_frequency,
                    cfg.floor_damping,
                    cfg.floor_side_ratio,
                    cfg.floor_track_ratio,
                    cfg.floor_body_response,
                ] {
                    prop_assert!(floor.is_finite() && (1.0 / floor).is_finite(), "{text}");
                }
                // What a store keeps reads back, valid, with finite limits (serde_json may read
                // a float one unit in the last place off: compared within 1e-12).
                let json = serde_json::to_string(&cfg).expect("serialise");
                let back: FleetConfig = serde_json::from_str(&json)
                    .map_err(|e| TestCaseError::fail(format!("{e}: {text}")))?;
                prop_assert!(back.validate().is_ok(), "{text}");
                let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs());
                prop_assert!(close(back.false_alarm_rate, cfg.false_alarm_rate), "{text}");
                prop_assert!(close(back.min_record_s(), cfg.min_record_s()), "{text}");
                prop_assert!(close(back.min_fs_hz(), cfg.min_fs_hz()), "{text}");
                prop_assert_eq!(back.bands_hz.len(), cfg.bands_hz.len());
                prop_assert_eq!(back.min_nominal, cfg.min_nominal);
            }
        }
    }
}

/// The cases of the issue, by hand: each refused naming its key.
#[test]
fn the_settings_of_the_issue_are_refused() {
    for (text, key) in [
        ("false_alarm_rate = 1e-15", "false_alarm_rate"),
        ("false_alarm_rate = 1e-300", "false_alarm_rate"),
        ("transmissibility_min_hz = nan", "transmissibility_min_hz"),
        (
            "transmissibility_min_coherence = 1",
            "transmissibility_min_coherence",
        ),
        (
            "transmissibility_min_coherence = -0.1",
            "transmissibility_min_coherence",
        ),
        ("bands_hz = [[1e-300, 2]]", "bands_hz"),
        ("floor_damping = inf", "floor_damping"),
    ] {
        let e = FleetConfig::from_toml_str(text, "fleet.toml").expect_err(text);
        assert!(e.to_string().contains(key), "{text}: {e}");
    }
    let ok = FleetConfig::from_toml_str("false_alarm_rate = 1e-9", "fleet.toml").expect("1e-9");
    assert!(bonferroni_limit(ok.false_alarm_rate, 100).is_finite());
}

/// An `[analysis]` table overrides the fleet's analysis key by key: one sweep key leaves the
/// fleet's ARMA-only method and model-update band (before, any `[analysis]` key brought back a
/// standalone analysis's defaults: SSI-cov too and no band). A preset key takes that preset
/// under the fleet's own choices; a misspelt key is refused, naming it.
#[test]
fn an_analysis_table_keeps_the_fleets_other_defaults() {
    use vibmode_analysis::Preset;
    use vibmode_fleet::fleet_analysis;
    let cfg =
        FleetConfig::from_toml_str("[analysis.sweep]\norder_max = 20\n", "fleet.toml").unwrap();
    let want = {
        let mut a = fleet_analysis(Preset::Vibmode);
        a.sweep.order_max = 20;
        a
    };
    assert_eq!(cfg.analysis, want);
    assert_eq!(cfg.analysis.method, vibmode_core::IdentMethod::Arma.into());
    assert_eq!(
        cfg.analysis.model_update.band_hz,
        Some(vibmode_fleet::SUSPENSION_BAND_HZ)
    );
    assert_eq!(cfg, {
        let mut d = FleetConfig::default();
        d.analysis.sweep.order_max = 20;
        d
    });
    let paper =
        FleetConfig::from_toml_str("[analysis]\npreset = \"paper\"\n", "fleet.toml").unwrap();
    assert_eq!(paper.analysis, fleet_analysis(Preset::Paper));
    assert_ne!(paper.analysis.preprocess, cfg.analysis.preprocess);
    for (text, key) in [
        ("[analysis.sweep]\norder_maxx = 20\n", "order_maxx"),
        ("analysis = 3\n", "analysis"),
        ("[analysis.sweep]\norder_max = 0\n", "order_max"),
    ] {
        let e = FleetConfig::from_toml_str(text, "fleet.toml").expect_err(text);
        let msg = e.to_string();
        assert!(msg.contains(key) && !msg.contains('\n'), "{text}: {msg}");
    }
}
