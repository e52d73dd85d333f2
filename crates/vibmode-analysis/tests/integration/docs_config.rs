//! The settings block of docs/analysis.md is a valid config and documents the defaults: parsed,
//! every section equals `AnalysisConfig::default()` (only the `[[channels]]` example differs).

use vibmode_analysis::AnalysisConfig;

const DOC: &str = include_str!("../../../../docs/analysis.md");

#[test]
fn documented_settings_are_the_defaults() {
    let start = DOC
        .find("```toml\npreset = ")
        .expect("the settings block of docs/analysis.md");
    let body = &DOC[start + "```toml\n".len()..];
    let end = body.find("```").expect("end of the block");
    let cfg = AnalysisConfig::from_toml_str(&body[..end]).expect("the documented block parses");
    let d = AnalysisConfig::default();
    assert_eq!(cfg.method, d.method);
    assert_eq!(cfg.record_length_s, d.record_length_s);
    assert_eq!(cfg.preprocess, d.preprocess);
    assert_eq!(cfg.spectra, d.spectra);
    assert_eq!(cfg.sweep, d.sweep);
    assert_eq!(cfg.ssi, d.ssi);
    assert_eq!(cfg.poles, d.poles);
    assert_eq!(cfg.stops, d.stops);
    assert_eq!(cfg.cluster, d.cluster);
    assert_eq!(cfg.lines, d.lines);
    assert_eq!(cfg.report, d.report);
    assert_eq!(cfg.model_update, d.model_update);
    assert_eq!(cfg.body_ssi, d.body_ssi);
    assert_eq!(cfg.channels.len(), 1);
}
