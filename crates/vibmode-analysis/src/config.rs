//! Analysis settings: every knob of the paper's method, with documented defaults and presets.

use serde::{Deserialize, Serialize};
use std::path::Path;

use crate::AnalysisError;
use vibmode_core::{
    BodyFitParams, BodySsiParams, ClusterParams, Corner, IdentMethod, IdentMethods, LineParams,
    PoleFilterParams, PreprocessParams, Role, SpectrumParams, SsiParams, StopParams, SweepParams,
};

/// Named sets of defaults.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Preset {
    /// vibmode's defaults: 25 Hz ideal cutoff, analysis at 50 Hz (twice the cutoff, so no empty
    /// band), ARMA(p,p) for p = 2..30 (the same pole density per Hz as p = 2..120 at 200 Hz),
    /// robust criterion. See `docs/analysis.md` for the measurements behind the choice.
    #[default]
    Vibmode,
    /// The paper's exact settings: 25 Hz ideal cutoff, resampling to 200 Hz, ARMA(p,p) for
    /// p = 2..60, robust criterion. At 200 Hz the band 25-100 Hz is empty, which makes high
    /// orders ill-conditioned and spends most poles outside the band of interest.
    Paper,
}

impl Preset {
    /// The preset's name as configs and the command line spell it.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Vibmode => "vibmode",
            Preset::Paper => "paper",
        }
    }
}

/// Where a config's TOML comes from ([`AnalysisConfig::load`]).
#[derive(Clone, Copy, Debug)]
pub enum ConfigText<'a> {
    /// A TOML file.
    Path(&'a Path),
    /// TOML text.
    Text(&'a str),
}

impl std::str::FromStr for Preset {
    type Err = AnalysisError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "vibmode" | "default" => Ok(Preset::Vibmode),
            "paper" => Ok(Preset::Paper),
            _ => Err(AnalysisError::Param(
                vibmode_core::ParamError::UnknownName {
                    what: "preset",
                    value: s.to_string(),
                    valid: "vibmode, paper",
                },
            )),
        }
    }
}

/// A channel's role and corner, given in the `[[channels]]` table of the config.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelRole {
    /// Channel name as in the input files.
    pub name: String,
    /// sprung, unsprung or other; `None` (key left out, or `--corner` alone): the role the
    /// record source gave, else one guessed from the name. An explicit `other` also keeps the
    /// channel out of the model update.
    #[serde(default)]
    pub role: Option<Role>,
    /// Corner (FL, FR, RL, RR) if any.
    #[serde(default)]
    pub corner: Option<Corner>,
}

/// What the report draws besides the results (kept out of the numerical stages).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReportParams {
    /// Orders whose model PSD of the first record is drawn over the Welch estimate (the paper's
    /// Fig. 6-7: 10 and 20; vibmode's preset 5 and 10). Their coefficients are kept in the results.
    pub model_psd_orders: Vec<usize>,
}

impl Default for ReportParams {
    fn default() -> Self {
        ReportParams {
            model_psd_orders: vec![5, 10],
        }
    }
}

/// Every setting of the analysis, one section per stage, readable from a TOML file.
///
/// Each section is the stage's own parameter struct from `vibmode-core`, so the library, the
/// TOML file, the CLI and Python read the same defaults. Keys not given take the preset's value;
/// unknown keys are an error. The flat keys of vibmode 0.1 (`order_max = 12`, `cutoff_hz = 20`,
/// `robust_factor = 0`, ...) are still read and moved to their section.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AnalysisConfig {
    /// Preset the defaults come from (vibmode or paper).
    pub preset: Preset,
    /// Record source: length of one record in seconds when long recordings are cut (default
    /// 10.24 s, the paper's).
    pub record_length_s: f64,
    /// Roles of the channels; channels not listed keep the placement their source gave, else
    /// one guessed from the name (containing "unsprung"/"wheel"/"axle" -> unsprung,
    /// "sprung"/"body"/"floor" -> sprung, corner FL/FR/RL/RR as a token).
    pub channels: Vec<ChannelRole>,
    /// Identification methods: a list of `"arma"` (per channel) and `"ssi-cov"` (all channels
    /// at once, with mode shapes); one name, or `"both"`, is read too.
    pub method: IdentMethods,
    /// Pre-processing: ideal anti-alias filter and resampling.
    pub preprocess: PreprocessParams,
    /// Spectra of every record.
    pub spectra: SpectrumParams,
    /// Identification: the order sweep.
    pub sweep: SweepParams,
    /// Pole filters applied to every fit.
    pub poles: PoleFilterParams,
    /// Multichannel identification (SSI-cov).
    pub ssi: SsiParams,
    /// Stop detection.
    pub stops: StopParams,
    /// Clustering and classification.
    pub cluster: ClusterParams,
    /// Periodic line detection and tracking.
    pub lines: LineParams,
    /// What the report draws.
    pub report: ReportParams,
    /// The model update with a vehicle file (`analyze --vehicle`): band and record edges of the
    /// fit of the suspension to the records.
    pub model_update: BodyFitParams,
    /// Body modes by SSI-cov at a low rate, each record beyond its own front-to-rear wheel
    /// delay (`[body_ssi]`).
    pub body_ssi: BodySsiParams,
}

impl Default for AnalysisConfig {
    fn default() -> Self {
        AnalysisConfig::preset(Preset::Vibmode)
    }
}

/// Flat keys of vibmode 0.1 and the section each moved to.
const LEGACY_KEYS: &[(&str, &str, &str)] = &[
    ("cutoff_hz", "preprocess", "cutoff_hz"),
    ("analysis_fs_hz", "preprocess", "analysis_fs_hz"),
    ("model", "sweep", "model"),
    ("order_min", "sweep", "order_min"),
    ("order_max", "sweep", "order_max"),
    ("robust_factor", "sweep", "robust"),
    ("max_iterations", "sweep", "max_iterations"),
    ("tolerance", "sweep", "tolerance"),
    ("welch_nperseg", "spectra", "nperseg"),
    ("psd_orders", "report", "model_psd_orders"),
    ("stop_rms_ratio", "stops", "stop_rms_ratio"),
    ("activity_min_hz", "stops", "activity_min_hz"),
];

/// Moves the flat keys of vibmode 0.1 into their sections (and `cluster.pole_zero_tol` to
/// `poles`).
fn migrate_legacy(value: &mut toml::Value) {
    let Some(table) = value.as_table_mut() else {
        return;
    };
    for (old, section, new) in LEGACY_KEYS {
        if let Some(v) = table.remove(*old) {
            let sec = table
                .entry(section.to_string())
                .or_insert_with(|| toml::Value::Table(toml::map::Map::new()));
            if let Some(t) = sec.as_table_mut() {
                t.entry(new.to_string()).or_insert(v);
            }
        }
    }
    let moved = table
        .get_mut("cluster")
        .and_then(|c| c.as_table_mut())
        .and_then(|c| c.remove("pole_zero_tol"));
    if let Some(v) = moved {
        let sec = table
            .entry("poles".to_string())
            .or_insert_with(|| toml::Value::Table(toml::map::Map::new()));
        if let Some(t) = sec.as_table_mut() {
            t.entry("pole_zero_tol".to_string()).or_insert(v);
        }
    }
}

/// Longest record cut from a long recording, s (one day).
pub const RECORD_LENGTH_S_MAX: f64 = 86_400.0;

/// The rule of `record_length_s`, as its error states it ([`RECORD_LENGTH_S_MAX`]).
const RECORD_LENGTH_S_RULE: &str = "must be in (0, 86400] s";

impl AnalysisConfig {
    /// The defaults of a preset.
    pub fn preset(p: Preset) -> Self {
        let base = AnalysisConfig {
            preset: p,
            record_length_s: 10.24,
            channels: Vec::new(),
            preprocess: PreprocessParams::default(),
            spectra: SpectrumParams::default(),
            sweep: SweepParams::default(),
            poles: PoleFilterParams::default(),
            stops: StopParams::default(),
            cluster: ClusterParams::default(),
            lines: LineParams::default(),
            method: IdentMethods::default(),
            // Not the single-record default: more block rows, pooled (`ANALYSIS_BLOCK_ROWS`).
            ssi: SsiParams::for_analysis(),
            report: ReportParams::default(),
            model_update: BodyFitParams::default(),
            body_ssi: BodySsiParams::default(),
        };
        match p {
            Preset::Vibmode => base,
            Preset::Paper => AnalysisConfig {
                preprocess: PreprocessParams {
                    analysis_fs_hz: 200.0,
                    ..base.preprocess
                },
                sweep: SweepParams {
                    order_max: 60,
                    ..base.sweep
                },
                spectra: SpectrumParams { nperseg: 256 },
                // The same 1.92 s slices every 0.32 s at four times the rate.
                lines: LineParams {
                    stft_nperseg: 4 * base.lines.stft_nperseg,
                    stft_noverlap: 4 * base.lines.stft_noverlap,
                    ..base.lines.clone()
                },
                report: ReportParams {
                    model_psd_orders: vec![10, 20],
                },
                method: IdentMethod::Arma.into(),
                ..base
            },
        }
    }

    /// Reads a TOML config. A `preset = "paper"` key selects the base the other keys override.
    pub fn from_toml_str(text: &str) -> Result<Self, AnalysisError> {
        Self::from_toml_with_preset(text, None)
    }

    /// The config of a run: `toml` (a file, text, or none) over the defaults of `preset` (else of
    /// the TOML's own `preset` key, else vibmode's). A preset given here and a different
    /// `preset` key in the TOML is an error. The one place the CLI, Python and the fleet load
    /// an analysis config.
    pub fn load(
        toml: Option<ConfigText<'_>>,
        preset: Option<Preset>,
    ) -> Result<Self, AnalysisError> {
        let cfg = match toml {
            Some(ConfigText::Path(path)) => {
                let text = vibmode_core::files::read_text_capped(path).map_err(|e| {
                    AnalysisError::ConfigFile {
                        path: path.display().to_string(),
                        message: e.to_string(),
                    }
                })?;
                Self::from_toml_with_preset(&text, preset).map_err(|e| match e {
                    AnalysisError::Config { message, .. } => AnalysisError::ConfigFile {
                        path: path.display().to_string(),
                        message,
                    },
                    other => other,
                })?
            }
            Some(ConfigText::Text(text)) => Self::from_toml_with_preset(text, preset)?,
            None => Self::preset(preset.unwrap_or_default()),
        };
        cfg.validate()?;
        Ok(cfg)
    }

    /// As [`AnalysisConfig::from_toml_str`], with `preset` (when given) as the base.
    fn from_toml_with_preset(text: &str, given: Option<Preset>) -> Result<Self, AnalysisError> {
        Self::from_toml_over(text, given, &AnalysisConfig::preset)
    }

    /// Reads a TOML config over the defaults `base(preset)` instead of the preset's own: for a
    /// caller whose defaults differ from the presets' (the fleet runs ARMA only, with its own
    /// model-update band), so that a file giving one key keeps the caller's other defaults.
    /// The preset is `given`, else the TOML's `preset` key, else vibmode's; validated.
    pub fn from_toml_over(
        text: &str,
        given: Option<Preset>,
        base: &dyn Fn(Preset) -> AnalysisConfig,
    ) -> Result<Self, AnalysisError> {
        let mut value: toml::Value = toml::from_str(text).map_err(|e| AnalysisError::Config {
            key: None,
            message: e.to_string().replace('\n', " "),
        })?;
        migrate_legacy(&mut value);
        let in_file = match value.get("preset").and_then(|v| v.as_str()) {
            Some(s) => Some(s.parse::<Preset>()?),
            None => None,
        };
        let preset = match (given, in_file) {
            (Some(g), Some(f)) if g != f => {
                return Err(AnalysisError::PresetConflict {
                    in_file: f.name(),
                    given: g.name(),
                })
            }
            (g, f) => g.or(f).unwrap_or_default(),
        };
        // Merge the file over the preset's defaults.
        let mut base = toml::Value::try_from(base(preset)).map_err(|e| AnalysisError::Config {
            key: None,
            message: e.to_string(),
        })?;
        merge(&mut base, value);
        let cfg: AnalysisConfig =
            base.try_into()
                .map_err(|e: toml::de::Error| AnalysisError::Config {
                    key: None,
                    message: vibmode_core::settings_message(&e.to_string().replace('\n', " ")),
                })?;
        cfg.validate()?;
        Ok(cfg)
    }

    /// Reads a TOML config file.
    pub fn from_path(path: &Path) -> Result<Self, AnalysisError> {
        let text =
            vibmode_core::files::read_text_capped(path).map_err(|e| AnalysisError::ConfigFile {
                path: path.display().to_string(),
                message: e.to_string(),
            })?;
        Self::from_toml_str(&text).map_err(|e| match e {
            AnalysisError::Config { message, .. } => AnalysisError::ConfigFile {
                path: path.display().to_string(),
                message,
            },
            other => other,
        })
    }

    /// The model orders of the sweep.
    pub fn orders(&self) -> Vec<usize> {
        self.sweep.orders()
    }

    /// Checks every section; errors name the key and a valid value.
    pub fn validate(&self) -> Result<(), AnalysisError> {
        if !(self.record_length_s.is_finite()
            && self.record_length_s > 0.0
            && self.record_length_s <= RECORD_LENGTH_S_MAX)
        {
            return Err(AnalysisError::Param(vibmode_core::ParamError::OutOfRange {
                name: "record_length_s",
                value: vibmode_core::Num(self.record_length_s).to_string(),
                requirement: RECORD_LENGTH_S_RULE,
                suggestion: "10.24".into(),
            }));
        }
        self.preprocess.validate()?;
        self.spectra.validate()?;
        self.sweep.validate()?;
        self.poles.validate()?;
        self.stops.validate(self.preprocess.cutoff_hz)?;
        self.cluster.validate()?;
        self.lines.validate()?;
        self.ssi.validate()?;
        self.model_update.validate()?;
        self.body_ssi.validate()?;
        Ok(())
    }

    /// Placement of a channel: the `channels` table first, else the placement the record source
    /// gave it, else one guessed from its name.
    pub fn placement_of(&self, channel: &vibmode_core::Channel) -> vibmode_core::Placement {
        let own = if channel.placement != vibmode_core::Placement::default() {
            channel.placement
        } else {
            vibmode_core::Placement::guess_from_name(&channel.name)
        };
        match self.channels.iter().find(|c| c.name == channel.name) {
            Some(c) => vibmode_core::Placement {
                role: c.role.unwrap_or(own.role),
                corner: c.corner.or(own.corner),
                direction: channel.placement.direction,
            },
            None => own,
        }
    }

    /// Placement of a channel for the model update (`vibmode_vehicle::update`): `None` when the
    /// `channels` table (or `--role`) marks it `other`, which leaves it out even where the
    /// vehicle file names a sensor like it; else [`AnalysisConfig::placement_of`].
    pub fn placement_for_update(
        &self,
        channel: &vibmode_core::Channel,
    ) -> Option<vibmode_core::Placement> {
        match self.channels.iter().find(|c| c.name == channel.name) {
            Some(c) if c.role == Some(Role::Other) => None,
            _ => Some(self.placement_of(channel)),
        }
    }
}

fn merge(base: &mut toml::Value, over: toml::Value) {
    match (base, over) {
        (toml::Value::Table(b), toml::Value::Table(o)) => {
            for (k, v) in o {
                match b.get_mut(&k) {
                    Some(bv) if bv.is_table() && v.is_table() => merge(bv, v),
                    _ => {
                        b.insert(k, v);
                    }
                }
            }
        }
        (b, o) => *b = o,
    }
}

#[cfg(test)]
mod tests {
    /// The rule stated in `record_length_s`'s error is the bound the check uses.
    #[test]
    fn record_length_rule_states_the_bound() {
        use super::*;
        assert!(RECORD_LENGTH_S_RULE.ends_with(&format!(", {}] s", RECORD_LENGTH_S_MAX)));
        let cfg = AnalysisConfig {
            record_length_s: 2.0 * RECORD_LENGTH_S_MAX,
            ..AnalysisConfig::default()
        };
        let e = cfg.validate().unwrap_err().to_string();
        assert!(
            e.contains("record_length_s = 172800 must be in (0, 86400] s"),
            "{e}"
        );
    }

    use super::*;

    /// `load`: the preset is the base the TOML's keys override; a TOML `preset` key that differs
    /// from the given preset is an error naming both; no TOML is the preset itself.
    #[test]
    fn load_merges_the_preset_under_the_toml() {
        let cfg = AnalysisConfig::load(
            Some(ConfigText::Text("record_length_s = 5.12")),
            Some(Preset::Paper),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(cfg.preset, Preset::Paper);
        assert_eq!(cfg.record_length_s, 5.12);
        assert_eq!(cfg.orders(), AnalysisConfig::preset(Preset::Paper).orders());
        let same = AnalysisConfig::load(
            Some(ConfigText::Text("preset = \"paper\"")),
            Some(Preset::Paper),
        );
        assert!(same.is_ok());
        let err = AnalysisConfig::load(
            Some(ConfigText::Text("preset = \"paper\"")),
            Some(Preset::Vibmode),
        )
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
        assert!(
            err.contains("preset = \"paper\"") && err.contains("preset vibmode"),
            "{err}"
        );
        let none =
            AnalysisConfig::load(None, Some(Preset::Paper)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            none.orders(),
            AnalysisConfig::preset(Preset::Paper).orders()
        );
        let missing = AnalysisConfig::load(
            Some(ConfigText::Path(Path::new("/nonexistent/x.toml"))),
            None,
        );
        assert!(matches!(missing, Err(AnalysisError::ConfigFile { .. })));
    }
    use vibmode_core::Robust;

    #[test]
    fn legacy_flat_keys_are_read_into_their_sections() {
        let c = AnalysisConfig::from_toml_str(
            "order_max = 12\ncutoff_hz = 20\nrobust_factor = 0\nwelch_nperseg = 64\n[cluster]\npole_zero_tol = 0.5\nmin_order_share = 0.4\n",
        )
        .unwrap();
        assert_eq!(c.sweep.order_max, 12);
        assert_eq!(c.preprocess.cutoff_hz, 20.0);
        assert_eq!(c.sweep.robust, Robust::Off);
        assert_eq!(c.spectra.nperseg, 64);
        assert_eq!(c.poles.pole_zero_tol, 0.5);
        assert_eq!(c.cluster.min_order_share, 0.4);
    }

    #[test]
    fn sections_override_the_preset_and_unknown_keys_fail() {
        let c =
            AnalysisConfig::from_toml_str("preset = \"paper\"\n[sweep]\norder_max = 40\n").unwrap();
        assert_eq!(c.preprocess.analysis_fs_hz, 200.0);
        assert_eq!(c.sweep.order_max, 40);
        let e = AnalysisConfig::from_toml_str("[sweep]\nordermax = 40\n").unwrap_err();
        assert!(e.to_string().contains("ordermax"), "{e}");
        let e = AnalysisConfig::from_toml_str("[preprocess]\ncutoff_hz = 40\n").unwrap_err();
        assert!(e.to_string().contains("cutoff_hz = 40"), "{e}");
    }

    /// A partial `[ssi]` section keeps the analysis' SSI settings (40 block rows, pooled) for
    /// the keys it does not set, not the single-record defaults (20, per record).
    #[test]
    fn a_partial_ssi_section_keeps_the_analysis_settings() {
        let c = AnalysisConfig::from_toml_str("[ssi]\norder_max = 40\n").unwrap();
        assert_eq!(c.ssi.order_max, 40);
        assert_eq!(c.ssi.block_rows, vibmode_core::ANALYSIS_BLOCK_ROWS);
        assert!(c.ssi.pool_records);
        assert_ne!(c.ssi.block_rows, SsiParams::default().block_rows);
        for p in [Preset::Vibmode, Preset::Paper] {
            assert_eq!(AnalysisConfig::preset(p).ssi, SsiParams::for_analysis());
        }
    }

    #[test]
    fn the_sweep_defaults_are_the_library_defaults() {
        // `vibmode sweep` and `analyze` read the same struct: one definition.
        assert_eq!(AnalysisConfig::default().sweep, SweepParams::default());
        assert_eq!(AnalysisConfig::default().cluster, ClusterParams::default());
    }

    /// The `[[channels]]` table over the record's own placements: a corner alone keeps the
    /// source's role (or the name's guess); an explicit role wins; an explicit `other` keeps
    /// the channel out of the model update, a guessed one does not.
    #[test]
    fn channel_table_roles_and_corners() {
        use vibmode_core::{Channel, Placement};
        let c = AnalysisConfig::from_toml_str(
            "[[channels]]\nname = \"acc3\"\ncorner = \"RL\"\n\n[[channels]]\nname = \"acc4\"\nrole = \"other\"\n\n[[channels]]\nname = \"FR_sprung\"\nrole = \"unsprung\"\n",
        )
        .unwrap();
        let wheel = Placement {
            role: Role::Unsprung,
            corner: Some(Corner::FL),
            direction: None,
        };
        let acc3 = Channel::new("acc3", "m/s^2", vec![0.0]).with_placement(wheel);
        let p = c.placement_of(&acc3);
        assert_eq!((p.role, p.corner), (Role::Unsprung, Some(Corner::RL)));
        assert_eq!(c.placement_for_update(&acc3), Some(p));
        // No placement from the source and no hint in the name: other, but only guessed.
        let bare = Channel::new("acc3", "m/s^2", vec![0.0]);
        let p = c.placement_of(&bare);
        assert_eq!((p.role, p.corner), (Role::Other, Some(Corner::RL)));
        assert!(c.placement_for_update(&bare).is_some());
        let acc4 = Channel::new("acc4", "m/s^2", vec![0.0]).with_placement(wheel);
        assert_eq!(c.placement_of(&acc4).role, Role::Other);
        assert_eq!(c.placement_for_update(&acc4), None);
        // The name's corner stays when the table gives only the role.
        let fr = Channel::new("FR_sprung", "m/s^2", vec![0.0]);
        let p = c.placement_of(&fr);
        assert_eq!((p.role, p.corner), (Role::Unsprung, Some(Corner::FR)));
    }
}
