//! `vibmode fit` as a library: an AR or ARMA model fitted to each channel of a recording, its
//! modes through the analysis' pole filters, the terminal table and the model-spectrum figure
//! (the paper's Fig. 6-7).

use serde::Serialize;
use vibmode_core::{BandLimit, PoleFilterParams, SweepModel};
use vibmode_ident::{ArMethod, ArmaModel, ArmaParams, PoleRejection};
use vibmode_signal::Recording;

use crate::RunError;

/// What to fit to each channel.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum FitModel {
    /// AR(p) by `method`.
    Ar {
        /// The estimator.
        method: ArMethod,
    },
    /// ARMA(p, q) by robust prediction-error minimisation.
    Arma {
        /// The MA order.
        q: usize,
    },
}

/// One mode in the JSON output.
#[derive(Serialize, Clone, Debug)]
pub struct ModeOut {
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio (dimensionless).
    pub damping_ratio: f64,
    /// Damped frequency, Hz.
    pub damped_frequency_hz: f64,
    /// Real part of the discrete-time pole.
    pub pole_re: f64,
    /// Imaginary part of the discrete-time pole.
    pub pole_im: f64,
    /// Why the pole filters leave this pole pair out (`null`: a mode).
    pub filtered_out: Option<PoleRejection>,
}

/// One channel's fitted model in the JSON output: the model's own fields (orders, A and C,
/// noise variance, loss, criteria, standard errors, ...) flattened beside the channel, the
/// estimator's name and the modes.
#[derive(Serialize, Clone, Debug)]
pub struct ChannelFit {
    /// Channel name.
    pub name: String,
    /// Unit of the samples.
    pub unit: String,
    /// Model structure.
    pub model: SweepModel,
    /// Estimator (yule-walker, burg, ls or pem): `fit.estimator`'s name.
    pub method: &'static str,
    /// The fitted model.
    #[serde(flatten)]
    pub fit: ArmaModel,
    /// The modes, each with the pole filters' verdict.
    pub modes: Vec<ModeOut>,
    /// Real poles.
    pub real_poles: Vec<f64>,
    /// Unstable poles, [re, im].
    pub unstable_poles: Vec<[f64; 2]>,
}

/// The fits of a recording (`vibmode fit --json`).
#[derive(Serialize, Clone, Debug)]
pub struct FitOutput {
    /// The file.
    pub source: String,
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Samples per channel.
    pub n_samples: usize,
    /// The robust criterion.
    pub robust: String,
    /// One entry per channel.
    pub channels: Vec<ChannelFit>,
}

/// Fits `model` of AR order `p` to every channel of `rec` (read from `source`); `band` is what
/// the signal carries (the pole filters' band), `params` the prediction-error settings. A fit
/// that fails or gives a non-finite estimate is an error naming the channel.
pub fn fit(
    rec: &Recording,
    source: &str,
    model: FitModel,
    p: usize,
    params: &ArmaParams,
    band: &BandLimit,
) -> Result<FitOutput, RunError> {
    let mut channels = Vec::new();
    for ch in &rec.channels {
        let fail = |source| RunError::FitFailed {
            channel: ch.name.clone(),
            source,
        };
        let (m, kind) = match model {
            FitModel::Ar { method } => (
                vibmode_ident::fit_ar(&ch.samples, p, method).map_err(fail)?,
                SweepModel::Ar,
            ),
            FitModel::Arma { q } => (
                vibmode_ident::fit_arma(&ch.samples, p, q, params).map_err(fail)?,
                SweepModel::Arma,
            ),
        };
        // A non-finite estimate is never printed or written.
        if !(m.noise_variance.is_finite() && m.loss.is_finite())
            || m.a.iter().chain(&m.c).any(|v| !v.is_finite())
        {
            return Err(RunError::NonFiniteFit {
                channel: ch.name.clone(),
                noise_variance: m.noise_variance,
            });
        }
        channels.push(channel_fit(&ch.name, &ch.unit, kind, m, band));
    }
    Ok(FitOutput {
        source: source.to_string(),
        fs_hz: rec.fs_hz,
        n_samples: rec.len(),
        robust: params.robust.to_string(),
        channels,
    })
}

/// Converts a fitted model to its JSON form.
pub fn channel_fit(
    name: &str,
    unit: &str,
    kind: SweepModel,
    m: ArmaModel,
    band: &BandLimit,
) -> ChannelFit {
    let ms = m.modes(band.fs_hz);
    let filtered = vibmode_ident::filter_mode_set(&m, &ms, band, &PoleFilterParams::default());
    ChannelFit {
        name: name.to_string(),
        unit: unit.to_string(),
        model: kind,
        method: m.estimator.name(),
        modes: filtered
            .iter()
            .map(|f| ModeOut {
                frequency_hz: f.mode.frequency_hz,
                damping_ratio: f.mode.damping_ratio,
                damped_frequency_hz: f.mode.damped_frequency_hz,
                pole_re: f.mode.pole_re,
                pole_im: f.mode.pole_im,
                filtered_out: f.rejected,
            })
            .collect(),
        real_poles: ms.real_poles.clone(),
        unstable_poles: ms.unstable_poles.iter().map(|z| [z.re, z.im]).collect(),
        fit: m,
    }
}

/// Unstable poles `[re, im]` as the table lists them: each conjugate pair once (its `im > 0`
/// member) as its frequency (Hz, `fs_hz` the sampling rate) and modulus, each real pole as its
/// value, by frequency.
fn unstable_text(poles: &[[f64; 2]], fs_hz: f64) -> String {
    let mut items: Vec<(f64, String)> = poles
        .iter()
        .filter(|z| z[1] >= 0.0)
        .map(|&[re, im]| {
            let modulus = re.hypot(im);
            if im == 0.0 {
                (
                    if re >= 0.0 { 0.0 } else { fs_hz / 2.0 },
                    format!("real z = {re:.5}"),
                )
            } else {
                let f = fs_hz * im.atan2(re) / std::f64::consts::TAU;
                (f, format!("{f:.4} Hz (|z| = {modulus:.5})"))
            }
        })
        .collect();
    items.sort_by(|a, b| a.0.total_cmp(&b.0));
    items
        .into_iter()
        .map(|(_, t)| t)
        .collect::<Vec<_>>()
        .join(", ")
}

/// The terminal table: per channel a header line and the modes. Modes that pass the shared pole
/// filters with a damping ratio below `zmax` are marked `*`; pole pairs the filters leave out
/// say why; a legend explains the marks.
pub fn table_text(o: &FitOutput, zmax: f64) -> String {
    let mut s = String::new();
    for c in &o.channels {
        s.push_str(&format!(
            "{}: {}({}{}) by {}, {} iterations{}, noise variance {:.6e}, loss {:.6e}, AIC {:.2}\n",
            c.name,
            if c.model == SweepModel::Ar {
                "AR"
            } else {
                "ARMA"
            },
            c.fit.p,
            if c.model == SweepModel::Arma {
                format!(",{}", c.fit.q)
            } else {
                String::new()
            },
            c.method,
            c.fit.iterations,
            if c.fit.converged {
                ""
            } else {
                " (NOT converged)"
            },
            c.fit.noise_variance,
            c.fit.loss,
            c.fit.aic
        ));
        if c.fit.noise_floor_variance > 0.0 {
            s.push_str(&format!(
                "  (the signal has an empty band: a white noise floor of variance {:.3e} was added before fitting, and is included in the noise variance and loss)\n",
                c.fit.noise_floor_variance
            ));
        }
        s.push_str(&format!("  {:>12} {:>14}  \n", "freq_hz", "damping_ratio"));
        let mut edge = 0;
        for m in &c.modes {
            let tag = match m.filtered_out {
                Some(PoleRejection::BandEdge) => {
                    edge += 1;
                    "(above the valid band: empty band)".to_string()
                }
                Some(PoleRejection::PoleZeroCancellation) => {
                    "(cancelled by a zero of C: a notch, no mode)".to_string()
                }
                None if m.damping_ratio < zmax => "*".to_string(),
                None => String::new(),
            };
            s.push_str(&format!(
                "  {:>12.4} {:>14.5}  {}\n",
                m.frequency_hz, m.damping_ratio, tag
            ));
        }
        if edge > 0 {
            s.push_str(&format!(
                "  {edge} pole pair(s) above the valid band lie in the band the ideal filter emptied (or on its edge): \
                 they describe the numerical noise floor added there (docs/identification.md), not \
                 the vehicle\n"
            ));
        }
        if !c.unstable_poles.is_empty() {
            s.push_str(&format!(
                "  {} unstable pole(s), left out: {}; a pole on or outside the unit circle is a pure tone (a periodic line) or a drift, not a damped mode\n",
                c.unstable_poles.len(),
                unstable_text(&c.unstable_poles, o.fs_hz)
            ));
        }
    }
    s.push_str(&format!(
        "* mode: a stable pole pair that passes the pole filters, damping ratio below {zmax} (the modes the analysis clusters)\n"
    ));
    s
}

/// The model-spectrum figure: per channel the periodogram, Welch and the model PSD, with the
/// modes that pass the pole filters below damping `zmax` marked.
#[cfg(feature = "report")]
pub fn fit_figure(
    rec: &Recording,
    fits: &[ChannelFit],
    welch: &vibmode_spectra::WelchParams,
    periodogram: &vibmode_spectra::PeriodogramParams,
    zmax: f64,
) -> Result<vibmode_report::Figure, RunError> {
    use vibmode_report::{Curve, ModelSpectrumPanel};
    let (wp, pp) = (welch, periodogram);
    let nyquist = rec.fs_hz / 2.0;
    let grid: Vec<f64> = (1..=MODEL_GRID_POINTS)
        .map(|i| i as f64 * nyquist / MODEL_GRID_POINTS as f64)
        .collect();
    let mut panels = Vec::new();
    for (ch, f) in rec.channels.iter().zip(fits) {
        let spectrum_err = |source| RunError::Spectrum {
            channel: ch.name.clone(),
            source,
        };
        let per = vibmode_spectra::periodogram(&ch.samples, rec.fs_hz, pp).map_err(spectrum_err)?;
        let wel = vibmode_spectra::welch(&ch.samples, rec.fs_hz, wp).map_err(spectrum_err)?;
        let structure = match f.model {
            SweepModel::Ar => format!("AR({})", f.fit.p),
            SweepModel::Arma => format!("ARMA({},{})", f.fit.p, f.fit.q),
        };
        let unit = if ch.unit.is_empty() {
            "input units"
        } else {
            ch.unit.as_str()
        };
        panels.push(ModelSpectrumPanel {
            title: format!("{}: {structure}", ch.name),
            psd_unit: format!("({unit})^2/Hz"),
            periodogram: Curve::new("periodogram", per.freq_hz, per.psd),
            welch: Curve::new("Welch", wel.freq_hz, wel.psd),
            model: Curve::new("model", grid.clone(), f.fit.model_psd(&grid, rec.fs_hz)),
            marks_hz: f
                .modes
                .iter()
                .filter(|md| md.filtered_out.is_none() && md.damping_ratio < zmax)
                .map(|md| md.frequency_hz)
                .collect(),
            marks_label: format!("modes, damping < {zmax}"),
        });
    }
    Ok(vibmode_report::model_spectra_figure(&panels, nyquist))
}

/// Points of the model-PSD grid of `fit --plot`, 0 to Nyquist.
#[cfg(feature = "report")]
const MODEL_GRID_POINTS: usize = 1000;

#[cfg(test)]
mod tests {
    use super::*;

    fn mode(f: f64, z: f64, filtered_out: Option<PoleRejection>) -> ModeOut {
        ModeOut {
            frequency_hz: f,
            damping_ratio: z,
            damped_frequency_hz: f * (1.0 - z * z).sqrt(),
            pole_re: 0.0,
            pole_im: 0.0,
            filtered_out,
        }
    }

    #[test]
    fn table_marks_modes_and_says_why_pole_pairs_are_left_out() {
        // An ARMA(2,2) model whose header the table prints (the numbers are not checked here).
        let y: Vec<f64> = (0..200).map(|t| ((t * 7919) % 101) as f64 - 50.0).collect();
        let mut model = vibmode_ident::fit_ar(&y, 2, vibmode_ident::ArMethod::Burg).unwrap();
        model.q = 2;
        model.c = vec![1.0; 3];
        model.iterations = 3;
        model.converged = true;
        let out = FitOutput {
            source: "x.csv".into(),
            fs_hz: 200.0,
            n_samples: 1000,
            robust: "off".into(),
            channels: vec![ChannelFit {
                name: "z".into(),
                unit: String::new(),
                model: SweepModel::Arma,
                method: "pem",
                fit: model,
                modes: vec![
                    mode(0.92, 0.34, None),
                    mode(10.58, 0.01, Some(PoleRejection::PoleZeroCancellation)),
                    mode(96.0, 0.01, Some(PoleRejection::BandEdge)),
                    mode(30.0, 0.8, None),
                ],
                real_poles: vec![],
                unstable_poles: vec![],
            }],
        };
        let t = table_text(&out, 0.6);
        let lines: Vec<&str> = t.lines().collect();
        assert!(
            lines[2].contains("0.9200") && lines[2].ends_with('*'),
            "{t}"
        );
        assert!(
            lines[3].contains("10.5800") && lines[3].contains("zero of C"),
            "{t}"
        );
        assert!(
            lines[4].contains("96.0000") && lines[4].contains("valid band"),
            "{t}"
        );
        assert!(
            lines[5].contains("30.0000") && !lines[5].ends_with('*'),
            "{t}"
        );
        assert!(
            lines[6].contains("1 pole pair(s) above the valid band"),
            "{t}"
        );
        assert!(
            t.lines().last().is_some_and(|l| l.starts_with("* mode:")),
            "{t}"
        );
    }

    /// Unstable poles are listed by frequency, a conjugate pair once, by hand: at 200 Hz the
    /// pair `1.0001 e^(+-i pi/10)` is 200 / 20 = 10 Hz with |z| = 1.0001; the real pole -1.2 is
    /// listed as itself.
    #[test]
    fn unstable_poles_are_listed_by_frequency() {
        let (s, c) = (std::f64::consts::PI / 10.0).sin_cos();
        let r = 1.0001;
        let poles = [[-1.2, 0.0], [r * c, -r * s], [r * c, r * s]];
        assert_eq!(
            unstable_text(&poles, 200.0),
            "10.0000 Hz (|z| = 1.00010), real z = -1.20000"
        );
    }
}
