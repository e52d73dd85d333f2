//! Features of one record: band levels per channel (and the level at and above wheel hop for
//! the unsprung level ratios), transmissibility per corner, and the modes identified per
//! channel. See docs/fleet.md for the formulas.

use serde::{Deserialize, Serialize};
use vibmode_analysis::{analyze, cut_records, AnalysisConfig, Corner, Role};
use vibmode_core::{ModeClass, Recording};
use vibmode_spectra::{band_rms, WelchParams, Window};

use crate::body::{body_spectra, BodySpectra};

use crate::config::FleetConfig;
use crate::error::{FleetError, Result};

/// One identified mode of a channel.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModeEstimate {
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
}

/// Features of one channel.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChannelFeatures {
    /// Channel name.
    pub name: String,
    /// Sprung, unsprung or other.
    pub role: Role,
    /// Corner, if known.
    pub corner: Option<Corner>,
    /// RMS in each band of [`RecordFeatures::bands_hz`] (units of the channel), `None` where the
    /// band holds no power or no bin.
    pub band_rms: Vec<Option<f64>>,
    /// Structural invariant modes of the file in this channel.
    pub modes: Vec<ModeEstimate>,
    /// RMS in `ratio_band_hz` (units of the channel), for the unsprung level ratios; absent in
    /// records stored before it existed (their model sets then lack the ratios).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ratio_band_rms: Option<f64>,
}

/// Transmissibility of one corner: sprung over unsprung.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CornerTransmissibility {
    /// The corner.
    pub corner: Corner,
    /// The sprung channel.
    pub sprung: String,
    /// The unsprung channel.
    pub unsprung: String,
    /// `sqrt(sum_band S_sprung / sum_band S_unsprung)` per band; `None` where the unsprung band
    /// holds no power.
    pub values: Vec<Option<f64>>,
}

/// Everything the fleet store keeps of one record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordFeatures {
    /// Rate of the analysed signals, Hz.
    pub analysis_fs_hz: f64,
    /// Duration of the file, s.
    pub duration_s: f64,
    /// Records of `record_length_s` the file was cut into.
    pub n_segments: usize,
    /// The bands, Hz.
    pub bands_hz: Vec<[f64; 2]>,
    /// Per channel.
    pub channels: Vec<ChannelFeatures>,
    /// Per corner with a sprung and an unsprung channel.
    pub transmissibility: Vec<CornerTransmissibility>,
    /// Why some features are missing.
    pub notes: Vec<String>,
    /// Cross-spectra of the sprung and unsprung channels in `body_band_hz`, for the body's
    /// response to the wheel motions; absent in records stored before it existed and in records
    /// without both a sprung and an unsprung channel with a corner.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body_spectra: Option<BodySpectra>,
}

fn finite(x: f64) -> Option<f64> {
    (x.is_finite() && x > 0.0).then_some(x)
}

/// Computes the features of `rec` (a file's recording, named `name` in messages).
///
/// Errors: the analysis fails (too short a record, bad settings), or no feature can be
/// computed (no channel with a role: name channels like `FL_unsprung`, `RR_sprung`).
pub fn compute_features(name: &str, rec: &Recording, cfg: &FleetConfig) -> Result<RecordFeatures> {
    cfg.validate()?;
    let acfg: &AnalysisConfig = &cfg.analysis;
    let records = cut_records(name, rec, acfg.record_length_s);
    let fail = |reason: String| FleetError::Features {
        record: name.to_string(),
        reason,
    };
    let mut notes = Vec::new();
    // Mean Welch PSD over the records, per channel, at the analysis rate.
    let mut psd: Vec<Vec<f64>> = Vec::new();
    let mut freq: Vec<f64> = Vec::new();
    let mut fs = acfg.preprocess.analysis_fs_hz;
    // Sprung and unsprung channels with a corner, in corner order: the body's outputs and
    // inputs.
    let by_role = |role: Role| -> Vec<usize> {
        Corner::ALL
            .iter()
            .filter_map(|corner| {
                rec.channels.iter().position(|ch| {
                    let p = acfg.placement_of(ch);
                    p.role == role && p.corner == Some(*corner)
                })
            })
            .collect()
    };
    let (body_u, body_y) = (by_role(Role::Unsprung), by_role(Role::Sprung));
    let mut body: Option<BodySpectra> = None;
    for r in &records {
        let pre = vibmode_signal::preprocess(&r.recording, &acfg.preprocess)
            .map_err(|e| fail(e.to_string()))?;
        fs = pre.band.fs_hz;
        if !body_u.is_empty() && !body_y.is_empty() {
            let samples = |idx: &[usize]| -> Vec<&[f64]> {
                idx.iter()
                    .map(|&c| pre.recording.channels[c].samples.as_slice())
                    .collect()
            };
            let names = |idx: &[usize]| -> Vec<String> {
                idx.iter().map(|&c| rec.channels[c].name.clone()).collect()
            };
            let s = body_spectra(
                &samples(&body_u),
                &samples(&body_y),
                names(&body_u),
                names(&body_y),
                fs,
                cfg.body_band_hz,
            )
            .map_err(|e| fail(e.to_string()))?;
            body = Some(match body.take() {
                None => s.scaled(1.0 / records.len() as f64),
                Some(acc) => acc.add_scaled(&s, 1.0 / records.len() as f64).ok_or_else(|| {
                    fail("its records give body spectra of different bins; give records of one length".into())
                })?,
            });
        }
        for (c, ch) in pre.recording.channels.iter().enumerate() {
            let wp = WelchParams {
                window: Window::Hann,
                nperseg: Some(acfg.spectra.nperseg.min(ch.samples.len())),
                ..WelchParams::default()
            };
            let w = vibmode_spectra::welch(&ch.samples, pre.band.fs_hz, &wp)
                .map_err(|e| fail(e.to_string()))?;
            if psd.len() <= c {
                psd.push(vec![0.0; w.psd.len()]);
                freq = w.freq_hz.clone();
            }
            if psd[c].len() != w.psd.len() {
                return Err(fail(format!(
                    "its segments give spectra of {} and {} bins; give records of one length",
                    psd[c].len(),
                    w.psd.len()
                )));
            }
            for (a, b) in psd[c].iter_mut().zip(&w.psd) {
                *a += b / records.len() as f64;
            }
        }
    }
    let results = analyze(&records, acfg, &[], &|_, _| {}).map_err(|e| fail(e.to_string()))?;
    let mut channels = Vec::new();
    for (c, ch) in rec.channels.iter().enumerate() {
        let placement = acfg.placement_of(ch);
        let levels: Vec<Option<f64>> = cfg
            .bands_hz
            .iter()
            .map(|b| {
                psd.get(c)
                    .and_then(|p| finite(band_rms(&freq, p, b[0], b[1])))
            })
            .collect();
        let modes = results
            .channels
            .iter()
            .find(|a| a.name == ch.name)
            .map(|a| {
                a.invariant_modes
                    .iter()
                    .filter(|m| m.class == ModeClass::Structural)
                    .map(|m| ModeEstimate {
                        frequency_hz: m.frequency_hz,
                        damping_ratio: m.damping_ratio,
                    })
                    .collect()
            })
            .unwrap_or_default();
        let [rlo, rhi] = cfg.ratio_band_hz;
        channels.push(ChannelFeatures {
            name: ch.name.clone(),
            role: placement.role,
            corner: placement.corner,
            band_rms: levels,
            modes,
            ratio_band_rms: psd
                .get(c)
                .and_then(|p| finite(band_rms(&freq, p, rlo, rhi))),
        });
    }
    let mut transmissibility = Vec::new();
    for corner in Corner::ALL {
        let find = |role: Role| {
            channels
                .iter()
                .find(|c| c.corner == Some(corner) && c.role == role)
        };
        match (find(Role::Sprung), find(Role::Unsprung)) {
            (Some(s), Some(u)) => {
                let values = s
                    .band_rms
                    .iter()
                    .zip(&u.band_rms)
                    .map(|(a, b)| match (a, b) {
                        (Some(a), Some(b)) => finite(a / b),
                        _ => None,
                    })
                    .collect();
                transmissibility.push(CornerTransmissibility {
                    corner,
                    sprung: s.name.clone(),
                    unsprung: u.name.clone(),
                    values,
                });
            }
            (Some(s), None) => notes.push(format!(
                "corner {corner}: sprung channel {} has no unsprung partner, no transmissibility",
                s.name
            )),
            (None, Some(u)) => notes.push(format!(
                "corner {corner}: unsprung channel {} has no sprung partner, no transmissibility",
                u.name
            )),
            (None, None) => {}
        }
    }
    if !channels.iter().any(|c| c.role == Role::Unsprung) {
        notes.push("no unsprung channel: no excitation levels".into());
    }
    let n_modes: usize = channels.iter().map(|c| c.modes.len()).sum();
    if transmissibility.is_empty() && n_modes == 0 {
        return Err(fail(format!(
            "no corner has both a sprung and an unsprung channel and no structural mode was found in channels [{}]; name channels by role and corner (e.g. FL_unsprung, FL_sprung) or give longer records",
            rec.names().join(", ")
        )));
    }
    Ok(RecordFeatures {
        analysis_fs_hz: fs,
        duration_s: rec.duration_s(),
        n_segments: records.len(),
        bands_hz: cfg.bands_hz.clone(),
        channels,
        transmissibility,
        notes,
        body_spectra: body,
    })
}
