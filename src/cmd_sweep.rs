//! `vibmode sweep`: fit every model order and collect every mode (stabilisation diagram).

use crate::cmd_fit::{FitMethod, ModelKind};
use crate::input::InputArgs;
use crate::output::write_json;
use anyhow::{bail, Context, Result};
use clap::Args;
use serde::Serialize;
use std::path::PathBuf;
use vibmode_core::{BandLimit, PoleFilterParams, SweepParams};
use vibmode_ident::{ArMethod, ArmaParams, PoleRejection, Robust};
use vibmode_report::panels as figures;

/// Arguments of `vibmode sweep`.
#[derive(Args, Debug)]
pub struct SweepArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Model orders: `2:60` (inclusive range), `2:60:2` (with step; the stop on the step's
    /// grid) or a list `4,8,16` (the orders listed); orders 1 to 1024 (default: the analysis
    /// sweep's, 2:30).
    #[arg(long)]
    pub orders: Option<String>,
    /// Model structure: arma (ARMA(p,p)) or ar.
    #[arg(long, value_enum, default_value_t = ModelKind::Arma)]
    pub model: ModelKind,
    /// Estimation method (default: burg for AR, pem for ARMA).
    #[arg(long, value_enum)]
    pub method: Option<FitMethod>,
    /// Robust criterion: a Huber factor (default 1.6, the analysis sweep's) or `off`.
    #[arg(long)]
    pub robust: Option<String>,
    /// Iteration cap of each fit (default 20, the analysis sweep's).
    #[arg(long)]
    pub max_iterations: Option<usize>,
    /// Stopping tolerance of each fit (default 1e-4, the analysis sweep's).
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// Write JSON results to this path (`-` for standard output).
    #[arg(long)]
    pub json: Option<String>,
    /// Write the stabilisation diagram (.svg or .png); a frequency-damping plot is written
    /// beside it with `-damping` appended to the file stem.
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

/// Highest model order (and most orders) `--orders` takes, for every command.
pub const ORDERS_MAX: usize = vibmode_core::limits::SSI_ORDER_MAX;

/// Parses `--orders`: a range `2:60` (inclusive), a stepped range `2:60:2` (the stop on the
/// step's grid: `2:35:2` is refused, not cut to 34) or a list `10,20,35` (the orders listed).
/// Every order from 1 to [`ORDERS_MAX`], at most [`ORDERS_MAX`] of them.
pub fn parse_orders(s: &str) -> Result<Vec<usize>> {
    let q = vibmode_core::quoted(s);
    let bad = || {
        anyhow::anyhow!(
            "invalid --orders: {q} (give a range 2:60, a stepped range 2:60:2 or a list 4,8,16 of orders from 1 to {ORDERS_MAX})"
        )
    };
    let order = |p: &str| {
        p.trim()
            .parse::<usize>()
            .ok()
            .filter(|v| (1..=ORDERS_MAX).contains(v))
            .ok_or_else(bad)
    };
    if s.contains(':') {
        let parts: Vec<&str> = s.split(':').collect();
        let (lo, hi, step) = match parts.as_slice() {
            [lo, hi] => (order(lo)?, order(hi)?, 1),
            [lo, hi, st] => (order(lo)?, order(hi)?, order(st)?),
            _ => return Err(bad()),
        };
        if hi < lo {
            bail!("invalid --orders: {q} (the stop {hi} is below the start {lo}; give start:stop or start:stop:step with start <= stop)");
        }
        let off = (hi - lo) % step;
        if off != 0 {
            let below = hi - off;
            let above = below + step;
            bail!("invalid --orders: {q} (the stop {hi} is not on the step-{step} grid from {lo}; give {lo}:{below}:{step} or {lo}:{above}:{step}, or list the orders with commas)");
        }
        return Ok((lo..=hi).step_by(step).collect());
    }
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() > ORDERS_MAX {
        bail!(
            "invalid --orders: {q} ({} orders; give at most {ORDERS_MAX})",
            parts.len()
        );
    }
    parts.into_iter().map(order).collect()
}

/// One pole pair of the sweep.
#[derive(Serialize, Clone, Copy, Debug)]
pub struct SweepMode {
    /// Model order p.
    pub order: usize,
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
}

/// A pole pair the pole filters left out, and why.
#[derive(Serialize, Clone, Copy, Debug)]
pub struct FilteredMode {
    /// Model order p.
    pub order: usize,
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
    /// Why it is no mode.
    pub reason: PoleRejection,
}

#[derive(Serialize)]
struct SweepChannel {
    name: String,
    unit: String,
    orders: Vec<usize>,
    loss: Vec<f64>,
    converged: Vec<bool>,
    errors: Vec<Option<String>>,
    modes: Vec<SweepMode>,
    filtered_out: Vec<FilteredMode>,
    welch_freq_hz: Vec<f64>,
    welch_psd: Vec<f64>,
}

#[derive(Serialize)]
struct SweepOutput {
    source: String,
    fs_hz: f64,
    n_samples: usize,
    model: ModelKind,
    channels: Vec<SweepChannel>,
}

/// The orders and fit settings: the options given, else the analysis sweep's defaults (one
/// definition, `vibmode_core::SweepParams`).
fn sweep_settings(a: &SweepArgs, band: Option<BandLimit>) -> Result<(Vec<usize>, ArmaParams)> {
    let defaults = SweepParams::default();
    let orders = match &a.orders {
        Some(o) => parse_orders(o)?,
        None => defaults.orders(),
    };
    let robust: Robust = match &a.robust {
        Some(r) => r.parse()?,
        None => defaults.robust,
    };
    let sweep = SweepParams {
        robust,
        max_iterations: a.max_iterations.unwrap_or(defaults.max_iterations),
        tolerance: a.tolerance.unwrap_or(defaults.tolerance),
        ..defaults
    };
    sweep.validate()?;
    let params = ArmaParams {
        robust: sweep.robust,
        max_iterations: sweep.max_iterations,
        tolerance: sweep.tolerance,
        band,
        ..ArmaParams::default()
    };
    Ok((orders, params))
}

/// The stabilisation diagram at `path` and the frequency-damping plot beside it.
fn write_plots(path: &std::path::Path, out: &SweepOutput) -> Result<()> {
    let mut stab = Vec::new();
    let mut damp = Vec::new();
    for c in &out.channels {
        let pts: Vec<(usize, f64, f64)> = c
            .modes
            .iter()
            .map(|m| (m.order, m.frequency_hz, m.damping_ratio))
            .collect();
        stab.push(figures::stabilisation_panel(
            &format!("{}: stabilisation diagram", c.name),
            &pts,
            &c.welch_freq_hz,
            &c.welch_psd,
            out.fs_hz / 2.0,
        ));
        damp.push(figures::damping_panel(
            &format!("{}: frequency vs damping", c.name),
            &pts,
            &[],
            out.fs_hz / 2.0,
        ));
    }
    figures::grid(stab, 1, 1000, 520)
        .save(path)
        .with_context(|| format!("writing plot {}", path.display()))?;
    let dpath = figures::sibling(path, "-damping");
    figures::grid(damp, 1, 1000, 520)
        .save(&dpath)
        .with_context(|| format!("writing plot {}", dpath.display()))?;
    eprintln!("wrote {} and {}", path.display(), dpath.display());
    Ok(())
}

/// The AR estimator of `--model ar` (ARMA is fitted by PEM).
fn ar_method(a: &SweepArgs) -> Result<ArMethod> {
    Ok(match (a.model, a.method) {
        (ModelKind::Ar, None | Some(FitMethod::Burg)) => ArMethod::Burg,
        (ModelKind::Ar, Some(FitMethod::YuleWalker)) => ArMethod::YuleWalker,
        (ModelKind::Ar, Some(FitMethod::Ls)) => ArMethod::LeastSquares,
        (ModelKind::Ar, Some(FitMethod::Pem)) => {
            bail!("--method pem is for --model arma; for AR use yule-walker, burg or ls")
        }
        (ModelKind::Arma, None | Some(FitMethod::Pem)) => ArMethod::Burg,
        (ModelKind::Arma, Some(m)) => {
            bail!("--model arma is fitted by --method pem; {m:?} applies to --model ar")
        }
    })
}

/// Every fit's loss, convergence or error, and its modes split by the pole filters.
fn collect_fits(
    out: &mut SweepChannel,
    orders: &[usize],
    fits: Vec<Result<vibmode_ident::ArmaModel, vibmode_ident::IdentError>>,
    band: &BandLimit,
    filters: &PoleFilterParams,
) {
    for (&p, f) in orders.iter().zip(fits) {
        match f {
            Ok(m) => {
                out.loss.push(m.loss);
                out.converged.push(m.converged);
                out.errors.push(None);
                for f in vibmode_ident::filter_modes(&m, band, filters) {
                    let (frequency_hz, damping_ratio) = (f.mode.frequency_hz, f.mode.damping_ratio);
                    match f.rejected {
                        None => out.modes.push(SweepMode {
                            order: p,
                            frequency_hz,
                            damping_ratio,
                        }),
                        Some(reason) => out.filtered_out.push(FilteredMode {
                            order: p,
                            frequency_hz,
                            damping_ratio,
                            reason,
                        }),
                    }
                }
            }
            Err(e) => {
                out.loss.push(f64::NAN);
                out.converged.push(false);
                out.errors.push(Some(e.to_string()));
            }
        }
    }
}

/// Runs `vibmode sweep`.
pub fn run(a: &SweepArgs) -> Result<()> {
    crate::output::check_outputs(&a.input.input, &[], &[a.plot.as_deref()], a.json.as_deref())?;
    let (rec, band) = a.input.load_with_band()?;
    let (orders, params) = sweep_settings(a, band)?;
    let filter_band = band.unwrap_or_else(|| BandLimit::full(rec.fs_hz));
    let filters = PoleFilterParams::default();
    let ar_method = ar_method(a)?;
    // Fail early, with the fit's own message, if the highest order cannot be fitted at all.
    let max_order = orders.iter().copied().max().unwrap_or(1);
    let mut channels = Vec::new();
    for ch in &rec.channels {
        let fits = match a.model {
            ModelKind::Arma => vibmode_ident::sweep_arma(&ch.samples, &orders, &params),
            ModelKind::Ar => orders
                .iter()
                .map(|&p| vibmode_ident::fit_ar(&ch.samples, p, ar_method))
                .collect(),
        };
        if fits.iter().all(|f| f.is_err()) {
            if let Some(Err(e)) = fits.into_iter().last() {
                return Err(e).with_context(|| format!("channel '{}', order {max_order}", ch.name));
            }
            bail!("no fits for channel '{}'", ch.name);
        }
        let mut out = SweepChannel {
            name: ch.name.clone(),
            unit: ch.unit.clone(),
            orders: orders.clone(),
            loss: vec![],
            converged: vec![],
            errors: vec![],
            modes: vec![],
            filtered_out: vec![],
            welch_freq_hz: vec![],
            welch_psd: vec![],
        };
        collect_fits(&mut out, &orders, fits, &filter_band, &filters);
        let wp = vibmode_spectra::WelchParams {
            nperseg: Some(256.min(ch.samples.len())),
            ..Default::default()
        };
        let w = vibmode_spectra::welch(&ch.samples, rec.fs_hz, &wp)?;
        out.welch_freq_hz = w.freq_hz;
        out.welch_psd = w.psd;
        channels.push(out);
    }
    let out = SweepOutput {
        source: a.input.input.display().to_string(),
        fs_hz: rec.fs_hz,
        n_samples: rec.len(),
        model: a.model,
        channels,
    };
    if let Some(path) = &a.plot {
        write_plots(path, &out)?;
    }
    match &a.json {
        Some(dest) => write_json(dest, &out)?,
        None => {
            let mut text = String::new();
            for c in &out.channels {
                let nc = c.converged.iter().filter(|x| !**x).count();
                text += &format!(
                    "{}: {} orders, {} pole pairs ({} more left out by the pole filters: cancelled by a zero of C or above the valid band), {} fits not converged, {} failed",
                    c.name,
                    c.orders.len(),
                    c.modes.len(),
                    c.filtered_out.len(),
                    nc,
                    c.errors.iter().filter(|e| e.is_some()).count()
                );
                text.push('\n');
            }
            crate::output::print_stdout(&text)?;
        }
    }
    Ok(())
}
