//! `vibmode sweep`: fit every model order and collect every mode (stabilisation diagram).

use crate::cmd_fit::{estimator_parser, ModelKind};
use crate::input::InputArgs;
use crate::output::write_json;
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::PathBuf;
use vibmode_core::{BandLimit, SearchStarts, SweepModel, SweepParams};
use vibmode_ident::{ArMethod, ArmaParams, Estimator, Robust};
use vibmode_run::sweep::SweepOutput;

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
    /// Estimator (default: burg for AR, pem for ARMA). (`--method` is still accepted.)
    #[arg(long, alias = "method", value_parser = estimator_parser())]
    pub estimator: Option<Estimator>,
    /// Robust criterion: a Huber factor (default 1.6, the analysis sweep's) or `off`.
    #[arg(long)]
    pub robust: Option<String>,
    /// Iteration cap of each fit (default 20, the analysis sweep's).
    #[arg(long)]
    pub max_iterations: Option<usize>,
    /// Stopping tolerance of each fit (default 1e-4, the analysis sweep's).
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// Where each ARMA fit's search starts: multi (small models, p + q <= 16, from every
    /// starting candidate; the analysis's default) or single (from the best-scored one only,
    /// as the fleet's records).
    #[arg(long, value_enum)]
    pub starts: Option<StartsArg>,
    /// Write JSON results to this path (`-` for standard output).
    #[arg(long)]
    pub json: Option<String>,
    /// Write the stabilisation diagram (.svg or .png); a frequency-damping plot is written
    /// beside it with `-damping` appended to the file stem.
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

/// `--starts`: [`SearchStarts`] on the command line.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum StartsArg {
    /// From every starting candidate for small models (the default).
    Multi,
    /// From the best-scored candidate only.
    Single,
}

impl From<StartsArg> for SearchStarts {
    fn from(s: StartsArg) -> Self {
        match s {
            StartsArg::Multi => SearchStarts::Multi,
            StartsArg::Single => SearchStarts::Single,
        }
    }
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
        starts: a.starts.map_or(defaults.starts, SearchStarts::from),
        ..defaults
    };
    sweep.validate()?;
    let params = ArmaParams {
        robust: sweep.robust,
        max_iterations: sweep.max_iterations,
        tolerance: sweep.tolerance,
        starts: sweep.starts,
        band,
        ..ArmaParams::default()
    };
    Ok((orders, params))
}

/// The stabilisation diagram at `path` and the frequency-damping plot beside it.
fn write_plots(path: &std::path::Path, out: &SweepOutput) -> Result<()> {
    let (stab, damp) = out.figures();
    stab.save(path)
        .with_context(|| format!("writing plot {}", path.display()))?;
    let dpath = vibmode_report::panels::sibling(path, "-damping");
    damp.save(&dpath)
        .with_context(|| format!("writing plot {}", dpath.display()))?;
    eprintln!("wrote {} and {}", path.display(), dpath.display());
    Ok(())
}

/// The AR estimator of `--model ar` (ARMA is fitted by PEM).
fn ar_method(a: &SweepArgs) -> Result<ArMethod> {
    Ok(match (a.model, a.estimator) {
        (ModelKind::Ar, e) => match e.unwrap_or(Estimator::Burg).ar_method() {
            Some(m) => m,
            None => {
                bail!("--estimator pem is for --model arma; for AR use yule-walker, burg or ls")
            }
        },
        (ModelKind::Arma, None | Some(Estimator::PredictionError)) => ArMethod::Burg,
        (ModelKind::Arma, Some(m)) => {
            bail!(
                "--model arma is fitted by --estimator pem; {} applies to --model ar",
                m.name()
            )
        }
    })
}

/// Runs `vibmode sweep`.
pub fn run(a: &SweepArgs) -> Result<()> {
    crate::output::check_outputs(&a.input.input, &[], &[a.plot.as_deref()], a.json.as_deref())?;
    let (rec, band) = a.input.load_with_band()?;
    let (orders, params) = sweep_settings(a, band)?;
    let filter_band = band.unwrap_or_else(|| BandLimit::full(rec.fs_hz));
    let ar_method = ar_method(a)?;
    let model = match a.model {
        ModelKind::Arma => SweepModel::Arma,
        ModelKind::Ar => SweepModel::Ar,
    };
    let out = vibmode_run::sweep::sweep(
        &rec,
        &a.input.input.display().to_string(),
        model,
        ar_method,
        &orders,
        &params,
        &filter_band,
    )?;
    if let Some(path) = &a.plot {
        write_plots(path, &out)?;
    }
    match &a.json {
        Some(dest) => write_json(dest, &out)?,
        None => crate::output::print_stdout(&out.summary_text())?,
    }
    Ok(())
}
