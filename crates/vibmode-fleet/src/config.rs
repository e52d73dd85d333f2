//! Settings of feature extraction and scoring, kept in every model set.

use serde::{Deserialize, Serialize};
use vibmode_analysis::AnalysisConfig;
use vibmode_core::Num;

use crate::error::{FleetError, Result};

/// The band of the suspension fitted per drive, Hz: the fleet's default `[analysis.model_update]
/// band_hz`.
pub const SUSPENSION_BAND_HZ: [f64; 2] = [0.7, 5.0];

/// Periods of the lowest band edge a record must span (4 periods of 0.5 Hz: 8 s).
pub const MIN_PERIODS: f64 = 4.0;

/// Feature bands, statistics floors and the false-alarm rate. Every model set stores the
/// settings it was built with; checks use the model set's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FleetConfig {
    /// The per-record analysis (pre-processing, spectra, order sweep, clustering).
    pub analysis: AnalysisConfig,
    /// Bands of levels and transmissibility, Hz (default 0.5-2, 2-5, 5-8, 8-12, 12-20).
    pub bands_hz: Vec<[f64; 2]>,
    /// Family-wise false-alarm probability per record and feature group (default 0.01).
    pub false_alarm_rate: f64,
    /// Nominal records a baseline needs (default 5).
    pub min_nominal: usize,
    /// Scale of the excitation score, ln units (default 0.15: the road level of a band, averaged
    /// over the unsprung channels, scatters by about 15 % between 10 s records at constant
    /// conditions).
    pub floor_level: f64,
    /// How far above the nominal range of the road level, ln units, a record's level must lie
    /// before its excitation is scored (default 0.69 = ln 2: one ISO 8608 road class, a factor
    /// 2 in amplitude, as between a class B baseline and a class C road). A road the baseline's
    /// roads or up to one class rougher drive is normal; a smoother road is never an alarm.
    /// The same margin below the range's bottom is too little road input: the vehicle
    /// features that input biases are not judged in that band (docs/fleet.md, "Little road
    /// input").
    pub road_margin: f64,
    /// Floor of the spread of ln(transmissibility) (default 0.10).
    pub floor_transmissibility: f64,
    /// Bands of `bands_hz` starting below this frequency, Hz, give no transmissibility feature
    /// (default 2: at 0.5-2 Hz the body modes' response to the front and rear wheels' inputs,
    /// which the wheelbase delays by a speed-dependent time, made healthy records' sprung over
    /// unsprung ratio scatter by 30-40 % and caused every false alarm of the acceptance; the
    /// body response to wheel motion covers the body instead).
    pub transmissibility_min_hz: f64,
    /// A corner's transmissibility in a band is left out of the model set when its sprung
    /// channel's coherence with its wheel there, over the nominal records (median, the H1
    /// estimate's finite-average bias taken out: [`crate::model::corrected_coherence`]), is below
    /// this (default 0.2; 0 keeps every band). Where the wheel explains little of the body's
    /// motion the H1 estimate's own bias, `(1 - gamma^2) / (n gamma^2)` of its square for `n`
    /// averages (60 % at 0.2 from a 10 s record's 7 Welch segments), is most of the value and
    /// grows as a smoother road lowers the coherence: on busgen the front sprung sensor's
    /// 12-20 Hz band (0.09-0.20 on 21 of 30 buses) flagged healthy drives on smooth roads.
    pub transmissibility_min_coherence: f64,
    /// Floor of the spread of ln(mode frequency) (default 0.05).
    pub floor_frequency: f64,
    /// Floor of the spread of ln(damping ratio) (default 0.35).
    pub floor_damping: f64,
    /// Modes closer than this relative distance belong to one mode of the model set
    /// (default 0.08).
    pub mode_group_tol: f64,
    /// Largest relative distance at which a record's mode is matched to a model-set mode
    /// (default 0.15; never beyond half-way to the next mode of the channel).
    pub mode_match_tol: f64,
    /// Share of nominal records that must contain a mode for it to enter the model set
    /// (default 0.6).
    pub mode_min_share: f64,
    /// Band of the unsprung level ratios (left over right wheel of an axle, front over rear
    /// wheel of a side), Hz (default 8-20: at and above wheel hop, where a wheel station's tyre
    /// and damper set the unsprung response).
    pub ratio_band_hz: [f64; 2],
    /// Floor of the spread of ln(left/right unsprung level) (default 0.10: the left and right
    /// wheels roll on different tracks, so the ratio scatters by about 0.1 between 10 s records).
    pub floor_side_ratio: f64,
    /// Floor of the spread of ln(front/rear unsprung level) of a side (default 0.03).
    pub floor_track_ratio: f64,
    /// Band of the body's cross-spectra (sprung and unsprung channels) kept per record, for the
    /// body's response to the wheel motions, Hz (default 0.4-4: the body modes).
    pub body_band_hz: [f64; 2],
    /// Bands of the body's response to the wheel motions (measured over predicted sprung power),
    /// within `body_band_hz`, Hz (default 2-4: above the body modes, where the measured wheel
    /// motions predict the body's within 2-3 % and a softer spring lowers it by about 20 %).
    pub body_response_bands_hz: Vec<[f64; 2]>,
    /// Floor of the spread of the body response, ln units (default 0.03).
    pub floor_body_response: f64,
    /// Normal drives pooled with the baseline's suspension fit into the reference a drive's
    /// fitted springs and dampers and the spring trend are scored against: the vehicle's first
    /// drives classed `normal` after the baseline, older than the drive checked and its trend
    /// (default 6; 0: the baseline's fit alone). A baseline of 2 drives is most of the spring
    /// trend's variance (docs/fleet.md, "The reference grows with normal drives").
    pub reference_drives: usize,
}

/// Highest order of the fleet's ARMA sweep with vibmode's preset (2..8 at 50 Hz; a standalone
/// analysis sweeps 2..30). Measured (docs/fleet.md, "The fleet's order sweep"): on 26 busgen
/// buses, 416 drives of 8 records (healthy, dampers at 60 and 70 %, springs at 80 %, tyres at
/// 75 %, class D roads), every drive's verdict, corner and component was the same with orders
/// up to 8, 10, 12 and 30; on vibmode's own simulator (`tests/integration/acceptance.rs` with ARMA) every
/// figure was the same at 8 and 30 (10 to 20 lost 1-2 of 24 records of the -20 % damper).
/// The verdicts rest on the fitted suspension, the transmissibility and the levels; the low
/// orders give more modes that recur in 60 % of the records (7 against 3 on the demo bus). The
/// sweep was 60 % of a record's CPU in `fleet ingest`.
pub const FLEET_SWEEP_ORDER_MAX: usize = 8;

/// Where each fit of the fleet's sweep starts with vibmode's preset: from the best-scored
/// candidate only (a standalone analysis searches its small models from every candidate).
/// Measured (docs/fleet.md, "The fleet's order sweep"): on 36 busgen buses every drive's
/// verdict, corner and component the same as with every candidate, and on vibmode's own
/// simulator the acceptance's figures the same; the two extra starts were about three
/// quarters of the sweep's CPU at orders 2..8.
pub const FLEET_SEARCH_STARTS: vibmode_core::SearchStarts = vibmode_core::SearchStarts::Single;

/// The fleet's per-record analysis: the `preset`'s, with ARMA only, the fleet's model-update
/// band and, with vibmode's preset, orders up to [`FLEET_SWEEP_ORDER_MAX`] searched from one
/// start each ([`FLEET_SEARCH_STARTS`]; the paper's preset keeps its own). An `[analysis]`
/// table in the fleet's settings overrides these, key by key.
pub fn fleet_analysis(preset: vibmode_analysis::Preset) -> AnalysisConfig {
    let base = AnalysisConfig::preset(preset);
    let (order_max, starts) = match preset {
        vibmode_analysis::Preset::Vibmode => (FLEET_SWEEP_ORDER_MAX, FLEET_SEARCH_STARTS),
        _ => (base.sweep.order_max, base.sweep.starts),
    };
    AnalysisConfig {
        sweep: vibmode_core::SweepParams {
            order_max,
            starts,
            ..base.sweep.clone()
        },
        // The features use the per-channel modes only: no multichannel identification.
        method: vibmode_core::IdentMethod::Arma.into(),
        // The suspension fitted per drive (a registered vehicle model file): the body
        // still rigid, the manoeuvres below (docs/fleet.md, "The suspension fitted per
        // drive": healthy drives scattered least with 0.7-5 Hz on busgen's buses).
        // The model file's anti-roll bars only: each record's equations are stored and a
        // drive's fit is compared with the baseline's, so every fit of a store keeps the
        // unknowns its first records were stored with (stores made before both bars became
        // the standalone update's default have them), and the comparisons are relative, so
        // a bar the file lacks moves the baseline and the drives alike.
        model_update: vibmode_core::BodyFitParams {
            band_hz: Some(SUSPENSION_BAND_HZ),
            anti_roll_bars: vibmode_core::AntiRollBars::File,
            ..vibmode_core::BodyFitParams::default()
        },
        ..base
    }
}

impl Default for FleetConfig {
    fn default() -> Self {
        FleetConfig {
            analysis: fleet_analysis(vibmode_analysis::Preset::default()),
            bands_hz: vec![
                [0.5, 2.0],
                [2.0, 5.0],
                [5.0, 8.0],
                [8.0, 12.0],
                [12.0, 20.0],
            ],
            false_alarm_rate: 0.01,
            min_nominal: 5,
            floor_level: 0.15,
            road_margin: std::f64::consts::LN_2,
            floor_transmissibility: 0.10,
            transmissibility_min_hz: 2.0,
            transmissibility_min_coherence: 0.2,
            floor_frequency: 0.05,
            floor_damping: 0.35,
            mode_group_tol: 0.08,
            mode_match_tol: 0.15,
            mode_min_share: 0.6,
            ratio_band_hz: [8.0, 20.0],
            floor_side_ratio: 0.10,
            floor_track_ratio: 0.03,
            body_band_hz: [0.4, 4.0],
            body_response_bands_hz: vec![[2.0, 4.0]],
            floor_body_response: 0.03,
            reference_drives: 6,
        }
    }
}

fn bad(key: &'static str, value: impl ToString, fix: &str) -> FleetError {
    FleetError::Config {
        key,
        value: value.to_string(),
        fix: fix.to_string(),
    }
}

/// Smallest `false_alarm_rate`: below one false alarm in 10^9 records the limits only grow
/// (|z| 6.1 for one feature), and the statistics of a few dozen nominal records say nothing there.
pub const FALSE_ALARM_RATE_MIN: f64 = 1e-9;
/// Most nominal records a baseline may ask for.
pub const MIN_NOMINAL_MAX: usize = 100_000;
/// Most bands in `bands_hz` or `body_response_bands_hz`.
pub const BANDS_MAX: usize = 64;
/// Lowest band edge other than 0, Hz (a record must span 4 periods of the lowest: 4000 s).
pub const BAND_EDGE_MIN_HZ: f64 = 1e-3;
/// Largest spread floor, ln units (a factor e^10 = 22 000: beyond it no feature is ever scored).
pub const FLOOR_MAX: f64 = 10.0;
/// Smallest spread floor, ln units (a relative spread of 1e-6: scores stay finite, 1 / floor
/// included).
pub const FLOOR_MIN: f64 = 1e-6;

/// The parser's message, short: serde's "expected one of `a`, `b`, ..." list of every key is
/// dropped (docs/fleet.md lists them), a number given for a name is said in words
/// ([`vibmode_core::settings_message`]), and what remains is cut at its end to 240 bytes.
fn short_reason(message: &str) -> String {
    let one_line = vibmode_core::settings_message(&message.replace('\n', " "));
    let trimmed = one_line.trim();
    let head = trimmed
        .split_once(", expected one of")
        .map_or(trimmed, |(head, _)| head);
    // A value quoted in the message shown as messages show user input, the whole cut at its
    // end (the key it names comes last).
    let clean: String = head.chars().map(vibmode_core::printable).collect();
    vibmode_core::cap_message(&clean, 240)
}

impl FleetConfig {
    /// Parses and validates TOML settings (every key optional: the defaults above; the
    /// per-record analysis under `[analysis]`, with the keys of docs/analysis.md).
    ///
    /// Keys missing from `[analysis]` take the fleet's defaults ([`fleet_analysis`]), not a
    /// standalone analysis's: a table that only sets `[analysis.sweep] order_max` keeps ARMA
    /// only and the fleet's model-update band.
    pub fn from_toml_str(text: &str, path: &str) -> Result<Self> {
        let file_err = |reason: String| FleetError::ConfigFile {
            path: path.to_string(),
            reason,
        };
        let mut value: toml::Value =
            toml::from_str(text).map_err(|e| file_err(short_reason(e.message())))?;
        let analysis = value.as_table_mut().and_then(|t| t.remove("analysis"));
        let mut cfg: FleetConfig = value
            .try_into()
            .map_err(|e: toml::de::Error| file_err(short_reason(e.message())))?;
        if let Some(table) = analysis {
            let text = match table {
                toml::Value::Table(t) => {
                    toml::to_string(&t).map_err(|e| file_err(format!("[analysis]: {e}")))?
                }
                other => {
                    return Err(file_err(format!(
                        "analysis = {other} is not a table; give the analysis keys under [analysis]"
                    )))
                }
            };
            cfg.analysis = AnalysisConfig::from_toml_over(&text, None, &fleet_analysis)
                .map_err(|e| file_err(format!("[analysis]: {}", short_reason(&e.to_string()))))?;
        }
        cfg.validate()?;
        Ok(cfg)
    }

    /// Reads [`FleetConfig::from_toml_str`] from a file of at most 1 MiB.
    pub fn from_path(path: &std::path::Path) -> Result<Self> {
        let shown = path.display().to_string();
        let text =
            vibmode_core::files::read_text_capped(path).map_err(|e| FleetError::ConfigFile {
                path: shown.clone(),
                reason: e.to_string(),
            })?;
        Self::from_toml_str(&text, &shown)
    }

    /// The lowest sampling rate a record may have, Hz: twice the highest band edge
    /// (`bands_hz`, `ratio_band_hz`, `body_band_hz`), so that every band lies below its Nyquist
    /// frequency (40 Hz with the defaults).
    pub fn min_fs_hz(&self) -> f64 {
        2.0 * self
            .bands_hz
            .iter()
            .chain([&self.ratio_band_hz, &self.body_band_hz])
            .map(|b| b[1])
            .fold(0.0, f64::max)
    }

    /// The lowest band edge of `bands_hz` above 0, Hz (none: `None`).
    pub fn lowest_band_edge_hz(&self) -> Option<f64> {
        self.bands_hz
            .iter()
            .map(|b| b[0])
            .filter(|&f| f > 0.0)
            .min_by(f64::total_cmp)
    }

    /// The shortest record the features may be computed from, s: 4 periods of the lowest band
    /// edge of `bands_hz` and one Welch segment at the analysis rate (8 s with the defaults).
    pub fn min_record_s(&self) -> f64 {
        let by_band = self.lowest_band_edge_hz().map_or(0.0, |f| MIN_PERIODS / f);
        let by_welch =
            self.analysis.spectra.nperseg as f64 / self.analysis.preprocess.analysis_fs_hz;
        by_band.max(by_welch)
    }

    /// Checks every value; errors name the key and a valid value.
    pub fn validate(&self) -> Result<()> {
        self.analysis.validate()?;
        let nyquist = self.analysis.preprocess.analysis_fs_hz / 2.0;
        if self.bands_hz.is_empty() {
            return Err(bad(
                "bands_hz",
                "[]",
                "must list at least one band, e.g. [[2, 5]]",
            ));
        }
        for (key, n) in [
            ("bands_hz", self.bands_hz.len()),
            ("body_response_bands_hz", self.body_response_bands_hz.len()),
        ] {
            if n > BANDS_MAX {
                return Err(bad(
                    key,
                    format!("({n} bands)"),
                    &format!("must list at most {BANDS_MAX} bands"),
                ));
            }
        }
        for (key, b) in self.bands_hz.iter().map(|b| ("bands_hz", b)).chain([
            ("ratio_band_hz", &self.ratio_band_hz),
            ("body_band_hz", &self.body_band_hz),
        ]) {
            if !(b[0].is_finite()
                && b[1].is_finite()
                && (b[0] == 0.0 || b[0] >= BAND_EDGE_MIN_HZ)
                && b[0] < b[1]
                && b[1] <= nyquist)
            {
                return Err(bad(
                    key,
                    format!("[{}, {}]", Num(b[0]), Num(b[1])),
                    &format!(
                        "must be increasing bands from 0 (or {BAND_EDGE_MIN_HZ} Hz) to the analysis Nyquist frequency {} Hz",
                        Num(nyquist)
                    ),
                ));
            }
        }
        for b in &self.body_response_bands_hz {
            if !(b[0] < b[1] && self.body_band_hz[0] <= b[0] && b[1] <= self.body_band_hz[1]) {
                return Err(bad(
                    "body_response_bands_hz",
                    format!("[{}, {}]", Num(b[0]), Num(b[1])),
                    &format!(
                        "must be increasing bands within body_band_hz [{}, {}], e.g. [2, 4]",
                        Num(self.body_band_hz[0]),
                        Num(self.body_band_hz[1])
                    ),
                ));
            }
        }
        if !(self.false_alarm_rate >= FALSE_ALARM_RATE_MIN && self.false_alarm_rate < 0.5) {
            return Err(bad(
                "false_alarm_rate",
                Num(self.false_alarm_rate),
                &format!("must be in [{FALSE_ALARM_RATE_MIN:e}, 0.5), e.g. 0.01"),
            ));
        }
        if !(3..=MIN_NOMINAL_MAX).contains(&self.min_nominal) {
            return Err(bad(
                "min_nominal",
                self.min_nominal,
                &format!("must be from 3 to {MIN_NOMINAL_MAX}, e.g. 5"),
            ));
        }
        if self.reference_drives > crate::suspension::REFERENCE_DRIVES_MAX {
            return Err(bad(
                "reference_drives",
                self.reference_drives,
                &format!(
                    "must be from 0 to {}, e.g. 6",
                    crate::suspension::REFERENCE_DRIVES_MAX
                ),
            ));
        }
        let c = self.transmissibility_min_coherence;
        if !(c.is_finite() && (0.0..1.0).contains(&c)) {
            return Err(bad(
                "transmissibility_min_coherence",
                Num(c),
                "must be from 0 (every band kept) to below 1, e.g. 0.1",
            ));
        }
        let t = self.transmissibility_min_hz;
        if !(t.is_finite() && (0.0..=nyquist).contains(&t)) {
            return Err(bad(
                "transmissibility_min_hz",
                Num(t),
                &format!(
                    "must be from 0 to the analysis Nyquist frequency {} Hz, e.g. 2",
                    Num(nyquist)
                ),
            ));
        }
        for (key, v) in [
            ("floor_level", self.floor_level),
            ("floor_transmissibility", self.floor_transmissibility),
            ("floor_frequency", self.floor_frequency),
            ("floor_damping", self.floor_damping),
            ("floor_side_ratio", self.floor_side_ratio),
            ("floor_track_ratio", self.floor_track_ratio),
            ("floor_body_response", self.floor_body_response),
        ] {
            if !(v.is_finite() && (FLOOR_MIN..=FLOOR_MAX).contains(&v)) {
                return Err(bad(
                    key,
                    Num(v),
                    &format!("must be in [{FLOOR_MIN:e}, {FLOOR_MAX}] (a spread of a logarithm), e.g. 0.1"),
                ));
            }
        }
        if !(self.mode_group_tol > 0.0 && self.mode_group_tol < 1.0) {
            return Err(bad(
                "mode_group_tol",
                Num(self.mode_group_tol),
                "must be in (0, 1), e.g. 0.08",
            ));
        }
        if !(self.mode_match_tol > 0.0 && self.mode_match_tol < 1.0) {
            return Err(bad(
                "mode_match_tol",
                Num(self.mode_match_tol),
                "must be in (0, 1), e.g. 0.15",
            ));
        }
        if !(self.road_margin.is_finite() && (0.0..=FLOOR_MAX).contains(&self.road_margin)) {
            return Err(bad(
                "road_margin",
                Num(self.road_margin),
                &format!("must be in [0, {FLOOR_MAX}] (ln units above the nominal road level), e.g. 0.69"),
            ));
        }
        if !(self.mode_min_share > 0.0 && self.mode_min_share <= 1.0) {
            return Err(bad(
                "mode_min_share",
                Num(self.mode_min_share),
                "must be in (0, 1], e.g. 0.6",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratio_settings_parse_validate_and_default_in_old_settings() {
        let c = FleetConfig::from_toml_str(
            "ratio_band_hz = [9, 18]\nfloor_track_ratio = 0.05\n",
            "fleet.toml",
        )
        .expect("valid");
        assert_eq!(c.ratio_band_hz, [9.0, 18.0]);
        assert_eq!(c.floor_track_ratio, 0.05);
        assert_eq!(c.floor_side_ratio, 0.10);
        // Beyond the analysis Nyquist frequency (25 Hz) or reversed: the key is named.
        for text in ["ratio_band_hz = [8, 30]", "ratio_band_hz = [20, 8]"] {
            let e = FleetConfig::from_toml_str(text, "fleet.toml").expect_err(text);
            assert!(e.to_string().contains("ratio_band_hz"), "{e}");
        }
        let e = FleetConfig::from_toml_str("floor_side_ratio = 0", "fleet.toml").expect_err("0");
        assert!(e.to_string().contains("floor_side_ratio"), "{e}");
        // The body response bands lie within the stored body band.
        let e = FleetConfig::from_toml_str("body_response_bands_hz = [[2, 5]]", "fleet.toml")
            .expect_err("beyond 4 Hz");
        assert!(
            e.to_string().contains("body_response_bands_hz") && e.to_string().contains("[2, 5]"),
            "{e}"
        );
        let e = FleetConfig::from_toml_str("floor_body_response = -1", "fleet.toml")
            .expect_err("negative");
        assert!(e.to_string().contains("floor_body_response"), "{e}");
        let c = FleetConfig::from_toml_str(
            "body_band_hz = [0.4, 6]\nbody_response_bands_hz = [[2, 4], [4, 6]]",
            "fleet.toml",
        )
        .expect("valid");
        assert_eq!(c.body_response_bands_hz.len(), 2);
        // Settings stored before the ratios existed (no such keys) read with the defaults.
        let mut old = serde_json::to_value(FleetConfig::default()).expect("json");
        if let Some(map) = old.as_object_mut() {
            for key in [
                "ratio_band_hz",
                "floor_side_ratio",
                "floor_track_ratio",
                "body_band_hz",
                "body_response_bands_hz",
                "floor_body_response",
            ] {
                map.remove(key);
            }
        }
        let back: FleetConfig = serde_json::from_value(old).expect("old settings");
        assert_eq!(back, FleetConfig::default());
    }
}
