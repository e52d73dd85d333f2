//! `vibmode fit`: AR / ARMA identification of each channel, model spectra and modes.

use crate::cmd_psd::SpectralArgs;
use crate::input::InputArgs;
use crate::output::write_json;
use anyhow::{bail, Context, Result};
use clap::builder::TypedValueParser;
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use vibmode_core::{BandLimit, ClusterParams};
use vibmode_ident::{ArmaParams, Estimator, Robust};
use vibmode_run::fit::FitModel;

/// Model structure.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModelKind {
    /// Autoregressive model A(q) y = e.
    Ar,
    /// ARMA model A(q) y = C(q) e, fitted by prediction-error minimisation.
    Arma,
}

/// The values `--estimator` takes (shared by `fit` and `sweep`): the library's
/// [`Estimator`], by the names it parses.
pub fn estimator_parser() -> impl TypedValueParser<Value = Estimator> {
    clap::builder::PossibleValuesParser::new(Estimator::NAMES)
        .try_map(|s: String| s.parse::<Estimator>())
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
    /// Estimator (default: burg for AR, pem for ARMA). (`--method` is still accepted.)
    #[arg(long, alias = "method", value_parser = estimator_parser())]
    pub estimator: Option<Estimator>,
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

fn parse_robust(s: Option<&str>) -> Result<Robust> {
    Ok(s.map_or(Ok(Robust::default()), str::parse::<Robust>)?)
}

/// What `--model`, `--estimator` and `--ma-order` ask for.
fn fit_model(a: &FitArgs) -> Result<FitModel> {
    match a.model {
        ModelKind::Ar => {
            if a.ma_order.is_some_and(|q| q > 0) {
                bail!("--ma-order applies to --model arma; drop it or use --model arma");
            }
            let Some(method) = a.estimator.unwrap_or(Estimator::Burg).ar_method() else {
                bail!("--estimator pem is for --model arma; for AR use yule-walker, burg or ls")
            };
            Ok(FitModel::Ar { method })
        }
        ModelKind::Arma => {
            if let Some(m) = a.estimator {
                if m != Estimator::PredictionError {
                    bail!(
                        "--model arma is fitted by --estimator pem; {} applies to --model ar",
                        m.name()
                    );
                }
            }
            Ok(FitModel::Arma {
                q: a.ma_order.unwrap_or(a.order),
            })
        }
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
    let model = fit_model(a)?;
    let out = vibmode_run::fit::fit(
        &rec,
        &a.input.input.display().to_string(),
        model,
        a.order,
        &params,
        &filter_band,
    )?;
    let zmax = mark_damping_max(a);
    if let Some(path) = &a.plot {
        let fig = vibmode_run::fit::fit_figure(
            &rec,
            &out.channels,
            &a.spectral.welch_params()?,
            &a.spectral.periodogram_params()?,
            zmax,
        )?;
        fig.save(path)
            .with_context(|| format!("writing plot {}", path.display()))?;
    }
    match &a.json {
        Some(dest) => write_json(dest, &out)?,
        None => crate::output::print_stdout(&vibmode_run::fit::table_text(&out, zmax))?,
    }
    Ok(())
}

/// The damping ratio below which modes are marked: the option, else the clustering's
/// `max_damping_ratio` (one definition).
fn mark_damping_max(a: &FitArgs) -> f64 {
    a.mark_damping_max
        .unwrap_or_else(|| ClusterParams::default().max_damping_ratio)
}
