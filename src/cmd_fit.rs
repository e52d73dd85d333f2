//! `vibmode fit`: AR / ARMA identification of each channel, model spectra and modes.

use crate::cmd_psd::SpectralArgs;
use crate::input::InputArgs;
use crate::output::write_json;
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use serde::Serialize;
use std::path::PathBuf;
use vibmode_core::{BandLimit, ClusterParams, PoleFilterParams};
use vibmode_ident::{ArMethod, ArmaModel, ArmaParams, PoleRejection, Robust};
use vibmode_report::{Curve, Figure, ModelSpectrumPanel};

/// Model structure.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ModelKind {
    /// Autoregressive model A(q) y = e.
    Ar,
    /// ARMA model A(q) y = C(q) e, fitted by prediction-error minimisation.
    Arma,
}

/// Estimation method.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum FitMethod {
    /// Yule-Walker (AR only).
    YuleWalker,
    /// Burg (AR only).
    Burg,
    /// Forward-backward least squares (AR only).
    Ls,
    /// Prediction-error minimisation (ARMA; the default for --model arma).
    Pem,
}

/// Arguments of `vibmode fit`.
#[derive(Args, Debug)]
pub struct FitArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Model structure: ar or arma.
    #[arg(long, value_enum, default_value_t = ModelKind::Arma)]
    pub model: ModelKind,
    /// AR order p (number of poles).
    #[arg(long)]
    pub order: usize,
    /// MA order q for ARMA (default: p, the paper's ARMA(p,p)).
    #[arg(long = "ma-order")]
    pub ma_order: Option<usize>,
    /// Estimation method (default: burg for AR, pem for ARMA).
    #[arg(long, value_enum)]
    pub method: Option<FitMethod>,
    /// Robust criterion for PEM: a Huber factor (default 1.6, times the robust std of the
    /// initial residuals) or `off` for the purely quadratic criterion.
    #[arg(long)]
    pub robust: Option<String>,
    /// Write JSON results to this path (`-` for standard output).
    #[arg(long)]
    pub json: Option<String>,
    /// Plot periodogram, Welch and the model PSD with the modes (.svg or .png), paper Fig. 6-7.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Modes that pass the pole filters with a damping ratio below this are marked `*` in the
    /// table and drawn in the plot (default 0.6, the clustering's `max_damping_ratio`).
    #[arg(long = "mark-damping-max")]
    pub mark_damping_max: Option<f64>,
    #[command(flatten)]
    pub spectral: SpectralArgs,
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

/// One channel's fitted model in the JSON output.
#[derive(Serialize, Clone, Debug)]
pub struct ChannelFit {
    name: String,
    unit: String,
    model: ModelKind,
    method: String,
    p: usize,
    q: usize,
    a: Vec<f64>,
    c: Vec<f64>,
    noise_variance: f64,
    loss: f64,
    iterations: usize,
    converged: bool,
    aic: f64,
    bic: f64,
    fpe: f64,
    std_errors: Vec<f64>,
    outliers_replaced: usize,
    noise_floor_variance: f64,
    modes: Vec<ModeOut>,
    real_poles: Vec<f64>,
    unstable_poles: Vec<[f64; 2]>,
}

#[derive(Serialize)]
struct FitOutput {
    source: String,
    fs_hz: f64,
    n_samples: usize,
    robust: String,
    channels: Vec<ChannelFit>,
}

fn parse_robust(s: Option<&str>) -> Result<Robust> {
    Ok(s.map_or(Ok(Robust::default()), str::parse::<Robust>)?)
}

/// Fits one channel. Shared with other commands.
pub fn fit_channel(
    y: &[f64],
    kind: ModelKind,
    method: Option<FitMethod>,
    p: usize,
    q: usize,
    params: &ArmaParams,
) -> Result<(ArmaModel, String)> {
    match kind {
        ModelKind::Ar => {
            let m = match method.unwrap_or(FitMethod::Burg) {
                FitMethod::YuleWalker => ArMethod::YuleWalker,
                FitMethod::Burg => ArMethod::Burg,
                FitMethod::Ls => ArMethod::LeastSquares,
                FitMethod::Pem => {
                    bail!("--method pem is for --model arma; for AR use yule-walker, burg or ls")
                }
            };
            Ok((vibmode_ident::fit_ar(y, p, m)?, m.to_string()))
        }
        ModelKind::Arma => {
            if let Some(m) = method {
                if m != FitMethod::Pem {
                    bail!("--model arma is fitted by --method pem; {m:?} applies to --model ar");
                }
            }
            Ok((vibmode_ident::fit_arma(y, p, q, params)?, "pem".into()))
        }
    }
}

/// Converts a fitted model to its JSON form.
pub fn channel_fit(
    name: &str,
    unit: &str,
    kind: ModelKind,
    method: String,
    m: &ArmaModel,
    band: &BandLimit,
) -> ChannelFit {
    let ms = m.modes(band.fs_hz);
    let filtered = vibmode_ident::filter_mode_set(m, &ms, band, &PoleFilterParams::default());
    ChannelFit {
        name: name.to_string(),
        unit: unit.to_string(),
        model: kind,
        method,
        p: m.p,
        q: m.q,
        a: m.a.clone(),
        c: m.c.clone(),
        noise_variance: m.noise_variance,
        loss: m.loss,
        iterations: m.iterations,
        converged: m.converged,
        aic: m.aic,
        bic: m.bic,
        fpe: m.fpe,
        std_errors: m.std_errors.clone(),
        outliers_replaced: m.outliers_replaced,
        noise_floor_variance: m.noise_floor_variance,
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
    }
}

/// Runs `vibmode fit`.
pub fn run(a: &FitArgs) -> Result<()> {
    crate::output::check_outputs(&a.input.input, &[], &[a.plot.as_deref()], a.json.as_deref())?;
    let (rec, band) = a.input.load_with_band()?;
    let robust = parse_robust(a.robust.as_deref())?;
    let params = ArmaParams {
        robust,
        band,
        ..ArmaParams::default()
    };
    let filter_band = band.unwrap_or_else(|| BandLimit::full(rec.fs_hz));
    let q = match a.model {
        ModelKind::Ar => 0,
        ModelKind::Arma => a.ma_order.unwrap_or(a.order),
    };
    if a.model == ModelKind::Ar && a.ma_order.is_some_and(|q| q > 0) {
        bail!("--ma-order applies to --model arma; drop it or use --model arma");
    }
    let mut channels = Vec::new();
    let mut models = Vec::new();
    for ch in &rec.channels {
        let (m, method) = fit_channel(&ch.samples, a.model, a.method, a.order, q, &params)
            .with_context(|| format!("channel '{}'", ch.name))?;
        // A non-finite estimate is never printed or written (it used to read "noise variance
        // NaN").
        if !(m.noise_variance.is_finite() && m.loss.is_finite())
            || m.a.iter().chain(&m.c).any(|v| !v.is_finite())
        {
            bail!(
                "channel '{}': the fit produced a non-finite estimate (noise variance {}); rescale the signal or lower the order",
                ch.name,
                m.noise_variance
            );
        }
        channels.push(channel_fit(
            &ch.name,
            &ch.unit,
            a.model,
            method,
            &m,
            &filter_band,
        ));
        models.push(m);
    }
    let out = FitOutput {
        source: a.input.input.display().to_string(),
        fs_hz: rec.fs_hz,
        n_samples: rec.len(),
        robust: robust.to_string(),
        channels,
    };
    if let Some(path) = &a.plot {
        let fig = fit_figure(&rec, &models, &out.channels, a)?;
        fig.save(path)
            .with_context(|| format!("writing plot {}", path.display()))?;
    }
    match &a.json {
        Some(dest) => write_json(dest, &out)?,
        None => crate::output::print_stdout(&table_text(&out, mark_damping_max(a)))?,
    }
    Ok(())
}

/// The damping ratio below which modes are marked: the option, else the clustering's
/// `max_damping_ratio` (one definition).
fn mark_damping_max(a: &FitArgs) -> f64 {
    a.mark_damping_max
        .unwrap_or_else(|| ClusterParams::default().max_damping_ratio)
}

/// The terminal table: per channel a header line and the modes. Modes that pass the shared pole
/// filters with a damping ratio below `zmax` are marked `*`; pole pairs the filters leave out
/// say why; a legend explains the marks.
fn table_text(o: &FitOutput, zmax: f64) -> String {
    let mut s = String::new();
    for c in &o.channels {
        s.push_str(&format!(
            "{}: {}({}{}) by {}, {} iterations{}, noise variance {:.6e}, loss {:.6e}, AIC {:.2}\n",
            c.name,
            if c.model == ModelKind::Ar {
                "AR"
            } else {
                "ARMA"
            },
            c.p,
            if c.model == ModelKind::Arma {
                format!(",{}", c.q)
            } else {
                String::new()
            },
            c.method,
            c.iterations,
            if c.converged { "" } else { " (NOT converged)" },
            c.noise_variance,
            c.loss,
            c.aic
        ));
        if c.noise_floor_variance > 0.0 {
            s.push_str(&format!(
                "  (the signal has an empty band: a white noise floor of variance {:.3e} was added before fitting, and is included in the noise variance and loss)\n",
                c.noise_floor_variance
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
            s.push_str(&format!("  {} unstable pole(s)\n", c.unstable_poles.len()));
        }
    }
    s.push_str(&format!(
        "* mode: a stable pole pair that passes the pole filters, damping ratio below {zmax} (the modes the analysis clusters)\n"
    ));
    s
}

fn fit_figure(
    rec: &vibmode_signal::Recording,
    models: &[ArmaModel],
    fits: &[ChannelFit],
    a: &FitArgs,
) -> Result<Figure> {
    let wp = a.spectral.welch_params()?;
    let pp = a.spectral.periodogram_params()?;
    let zmax = mark_damping_max(a);
    let nyquist = rec.fs_hz / 2.0;
    let grid: Vec<f64> = (1..=MODEL_GRID_POINTS)
        .map(|i| i as f64 * nyquist / MODEL_GRID_POINTS as f64)
        .collect();
    let mut panels = Vec::new();
    for ((ch, m), f) in rec.channels.iter().zip(models).zip(fits) {
        let per = vibmode_spectra::periodogram(&ch.samples, rec.fs_hz, &pp)?;
        let wel = vibmode_spectra::welch(&ch.samples, rec.fs_hz, &wp)?;
        let structure = match f.model {
            ModelKind::Ar => format!("AR({})", f.p),
            ModelKind::Arma => format!("ARMA({},{})", f.p, f.q),
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
            model: Curve::new("model", grid.clone(), m.model_psd(&grid, rec.fs_hz)),
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
        let out = FitOutput {
            source: "x.csv".into(),
            fs_hz: 200.0,
            n_samples: 1000,
            robust: "off".into(),
            channels: vec![ChannelFit {
                name: "z".into(),
                unit: String::new(),
                model: ModelKind::Arma,
                method: "pem".into(),
                p: 2,
                q: 2,
                a: vec![1.0; 3],
                c: vec![1.0; 3],
                noise_variance: 1.0,
                loss: 1.0,
                iterations: 3,
                converged: true,
                aic: 0.0,
                bic: 0.0,
                fpe: 1.0,
                std_errors: vec![],
                outliers_replaced: 0,
                noise_floor_variance: 0.0,
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
}
