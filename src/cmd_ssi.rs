//! `vibmode ssi`: multichannel SSI-cov of one record, with a stabilisation diagram and the modes
//! that stay over the orders (frequency, damping, shape).

use crate::cmd_sweep::parse_orders;
use crate::input::InputArgs;
use crate::output::write_json;
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use vibmode_core::SsiParams;
use vibmode_ssi::RecordSsiOptions;

/// Arguments of `vibmode ssi`.
#[derive(Args, Debug)]
pub struct SsiArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Block rows i of the Toeplitz matrix of output correlations (lags 1..2i-1; default 20).
    /// At most 1024 / channels, and the record needs 2 (2i - 1) samples beyond the first lag
    /// (docs/ssi.md, "Bounds").
    #[arg(long)]
    pub block_rows: Option<usize>,
    /// First correlation lag of the Toeplitz matrix, samples (default 1; at most 2^30 and
    /// below the record's length). Vehicles: beyond the front-to-rear wheel delay,
    /// `1 + wheelbase / speed * fs`, the road's own correlation no longer biases the body modes
    /// (docs/ssi.md).
    #[arg(long)]
    pub first_lag: Option<usize>,
    /// Model orders (state dimensions), 1 to 1024: a range `2:60:2` (default; the stop on the
    /// step's grid), `2:40`, or a list `10,20,35` (identified as listed). Orders above what
    /// the block rows and channels allow are left out.
    #[arg(long)]
    pub orders: Option<String>,
    /// Reference channels (0-based indices among the selected channels, each once),
    /// comma-separated: reference-based SSI-cov.
    #[arg(long)]
    pub references: Option<String>,
    /// Write JSON results to this path (`-` for standard output).
    #[arg(long)]
    pub json: Option<String>,
    /// Write the stabilisation diagram (.svg or .png).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Identify the channels as they are; by default each is divided by its RMS first (as the
    /// analysis does, so that strong channels do not hide weak ones) and the shapes are scaled
    /// back to the channels' units.
    #[arg(long)]
    pub no_normalise: bool,
    /// Standard deviations of each mode's frequency and damping by first-order propagation
    /// (Döhler-style): the record cut into this many blocks of time, whose scatter is carried
    /// through the identification (20 to 50 are usual; each block needs 2 x block rows
    /// samples). Off by default.
    #[arg(long)]
    pub uncertainty_blocks: Option<usize>,
}

/// The SSI parameters and the orders to identify (`--orders` as given, or the default range).
fn params(a: &SsiArgs) -> Result<(SsiParams, Vec<usize>)> {
    let d = SsiParams::default();
    let orders = match &a.orders {
        Some(o) => parse_orders(o)?,
        None => d.orders(),
    };
    if orders.windows(2).any(|w| w[0] >= w[1]) {
        anyhow::bail!(
            "invalid --orders: {} (list the orders increasing, each once, e.g. 10,20,35)",
            vibmode_core::quoted(a.orders.as_deref().unwrap_or_default())
        );
    }
    let (lo, hi) = (
        orders.iter().copied().min().unwrap_or(d.order_min),
        orders.iter().copied().max().unwrap_or(d.order_max),
    );
    let step = if orders.len() > 1 {
        orders
            .windows(2)
            .map(|w| w[1] - w[0])
            .min()
            .unwrap_or(1)
            .max(1)
    } else {
        1
    };
    let references = match &a.references {
        Some(s) => Some(
            s.split(',')
                .map(|x| {
                    x.trim().parse::<usize>().map_err(|_| {
                        anyhow::anyhow!(
                            "invalid --references: {} (give 0-based channel indices like 0,2)",
                            vibmode_core::quoted(s)
                        )
                    })
                })
                .collect::<Result<Vec<_>>>()?,
        ),
        None => None,
    };
    let p = SsiParams {
        block_rows: a.block_rows.unwrap_or(d.block_rows),
        order_min: lo,
        order_max: hi,
        order_step: step,
        reference_channels: references,
        first_lag: a.first_lag.unwrap_or(d.first_lag),
        ..d
    };
    p.validate()?;
    Ok((p, orders))
}

/// Runs `vibmode ssi`.
pub fn run(a: &SsiArgs) -> Result<()> {
    crate::output::check_outputs(&a.input.input, &[], &[a.plot.as_deref()], a.json.as_deref())?;
    let (p, orders) = params(a)?;
    let (rec, band) = a.input.load_with_band()?;
    let options = RecordSsiOptions {
        normalise: !a.no_normalise,
        valid_max_hz: band.map(|b| b.valid_max_hz()),
        uncertainty_blocks: a.uncertainty_blocks,
        orders: Some(orders),
        ..RecordSsiOptions::default()
    };
    let out = vibmode_run::ssi::ssi(&rec, &a.input.input.display().to_string(), &p, &options)?;
    if let Some(path) = &a.plot {
        let f_max = options.valid_max_hz.unwrap_or(rec.fs_hz / 2.0);
        out.figure(&rec, f_max)?
            .save(path)
            .with_context(|| format!("writing plot {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    match &a.json {
        Some(dest) => write_json(dest, &out)?,
        None => crate::output::print_stdout(&out.summary_text())?,
    }
    Ok(())
}
