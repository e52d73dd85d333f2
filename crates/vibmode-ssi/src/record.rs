//! One record's SSI-cov from start to end, as `vibmode ssi` and the Python `ssi_cov` run it:
//! channels divided by their RMS, the order sweep, shapes back in the channels' units, the
//! stabilisation labels, and the poles clustered over the orders into the modes that stay.

use serde::{Deserialize, Serialize};
use vibmode_core::{
    ClusterParams, InvariantMode, ModeClass, ModeUncertainty, PoleObservation, SsiParams,
    StabilityParams, UncertaintyMethod,
};

use crate::cov::{SsiCorrelations, SsiCov, SsiResult};
use crate::error::SsiError;
use crate::stability::{stabilisation, Stability};

/// What [`identify_record`] found.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordSsi {
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Samples per channel.
    pub n_samples: usize,
    /// The parameters used (orders above what the data allows are dropped from the sweep, not
    /// from here).
    pub params: SsiParams,
    /// The stabilisation criteria used.
    pub stability_params: StabilityParams,
    /// The span of the correlation lags, s ([`SsiParams::lag_span_s`]): modes below
    /// `1 / lag_span_s` Hz complete less than one period within them and are seldom identified.
    pub lag_span_s: f64,
    /// Every identified order's modes, shapes in the channels' units.
    pub result: SsiResult,
    /// Stability label of every mode of every order against the previous order (same nesting
    /// as `result.orders[o].modes[m]`).
    pub stability: Vec<Vec<Stability>>,
    /// The poles below the valid band's top clustered over the orders (mean shape, spreads):
    /// structural modes first, then the rest, each group by increasing frequency. With
    /// [`RecordSsiOptions::uncertainty_blocks`], each structural mode's `uncertainty` is the
    /// median over its orders of the first-order standard deviations of its pole.
    pub modes: Vec<InvariantMode>,
    /// With [`RecordSsiOptions::uncertainty_blocks`]: the first-order standard deviations
    /// `[frequency Hz, damping]` of every pole (same nesting as `result.orders[o].modes[m]`;
    /// NaN where a perturbed plan lost the pole).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pole_std: Option<Vec<Vec<[f64; 2]>>>,
    /// The blocks of [`RecordSsiOptions::uncertainty_blocks`], when used.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uncertainty_blocks: Option<usize>,
}

/// Options of [`identify_record`] beyond the SSI parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordSsiOptions {
    /// Divide each channel by its RMS before identification (so that strong channels do not
    /// hide weak ones) and scale the shapes back (default true).
    pub normalise: bool,
    /// Poles at or above this frequency, Hz, are not clustered (default: Nyquist); give the
    /// top of the valid band after an anti-alias filter.
    pub valid_max_hz: Option<f64>,
    /// Stabilisation criteria.
    pub stability: StabilityParams,
    /// Clustering of the poles over the orders (its `freq_max_hz` is set from `valid_max_hz`).
    pub cluster: ClusterParams,
    /// Cut the record into this many blocks of time and give every pole the first-order
    /// standard deviations of its frequency and damping from the blocks' scatter
    /// ([`crate::SsiPerturbation`]; default none). 20 to 50 are usual; each block needs
    /// `first_lag + 2 block_rows - 1` samples. Costs two SVDs of the Toeplitz matrix per block.
    pub uncertainty_blocks: Option<usize>,
    /// The model orders to identify, increasing, from 1 to
    /// [`vibmode_core::limits::SSI_ORDER_MAX`] (default none: `params.orders()`, the range
    /// `order_min..=order_max` by `order_step`). A list such as `[10, 20, 35]` is identified as
    /// listed.
    pub orders: Option<Vec<usize>>,
}

impl Default for RecordSsiOptions {
    fn default() -> Self {
        RecordSsiOptions {
            normalise: true,
            valid_max_hz: None,
            stability: StabilityParams::default(),
            cluster: ClusterParams::default(),
            uncertainty_blocks: None,
            orders: None,
        }
    }
}

/// The orders of `list`, checked: not empty, increasing, each in `1..=SSI_ORDER_MAX`.
fn checked_orders(list: &[usize]) -> Result<Vec<usize>, SsiError> {
    let max = vibmode_core::limits::SSI_ORDER_MAX;
    let increasing = list.windows(2).all(|w| w[0] < w[1]);
    match (list.first(), list.last()) {
        (Some(&lo), Some(&hi)) if increasing && lo >= 1 && hi <= max => Ok(list.to_vec()),
        _ => Err(SsiError::OrderList {
            orders: vibmode_core::quoted(&format!("{list:?}")).to_string(),
            max,
        }),
    }
}

/// The RMS about the mean of each channel, 1 where it is zero or not finite.
fn rms_scales(channels: &[&[f64]]) -> Vec<f64> {
    channels
        .iter()
        .map(|c| {
            let n = c.len().max(1) as f64;
            let m = c.iter().sum::<f64>() / n;
            let rms = (c.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / n).sqrt();
            if rms > 0.0 && rms.is_finite() {
                rms
            } else {
                1.0
            }
        })
        .collect()
}

/// SSI-cov of one record (`channels[c]` = channel c's samples at `fs_hz`): the orders of
/// `params` that the data can identify (at most [`SsiCov::max_order`]), each mode labelled
/// against the previous order, and the poles clustered over the orders
/// (`vibmode_modal::find_invariant_modes` with one record: a structural mode must recur in
/// `min_order_share` of the orders).
///
/// Errors: those of [`SsiCov::new`] (channels, samples, parameters), an order list that is not
/// increasing orders from 1 to [`vibmode_core::limits::SSI_ORDER_MAX`] ([`SsiError::OrderList`]),
/// no order of `params` identifiable ([`SsiError::NoOrder`]), a clustering parameter out of
/// range.
pub fn identify_record(
    channels: &[&[f64]],
    fs_hz: f64,
    params: &SsiParams,
    options: &RecordSsiOptions,
) -> Result<RecordSsi, SsiError> {
    params.validate()?;
    let wanted = match &options.orders {
        Some(list) => checked_orders(list)?,
        None => params.orders(),
    };
    // Before the scaling, which would blow a constant channel's rounding up to unit RMS.
    for (channel, ch) in channels.iter().enumerate() {
        if let Some(value) = vibmode_core::stats::constant_value(ch) {
            return Err(SsiError::ConstantChannel { channel, value });
        }
    }
    let scales = if options.normalise {
        rms_scales(channels)
    } else {
        vec![1.0; channels.len()]
    };
    let scaled: Vec<Vec<f64>> = channels
        .iter()
        .zip(&scales)
        .map(|(c, s)| c.iter().map(|v| v / s).collect())
        .collect();
    let chans: Vec<&[f64]> = scaled.iter().map(Vec::as_slice).collect();
    let perturbation = match options.uncertainty_blocks {
        Some(blocks) => {
            Some(SsiCorrelations::blocks(&chans, fs_hz, params, blocks)?.perturbation()?)
        }
        None => None,
    };
    let own_plan;
    let plan = match &perturbation {
        Some(p) => p.plan(),
        None => {
            own_plan = SsiCov::new(&chans, fs_hz, params)?;
            &own_plan
        }
    };
    let orders: Vec<usize> = wanted
        .iter()
        .copied()
        .filter(|&o| o <= plan.max_order())
        .collect();
    if orders.is_empty() {
        return Err(SsiError::NoOrder {
            order_min: wanted.first().copied().unwrap_or(params.order_min),
            n_channels: channels.len(),
            block_rows: params.block_rows,
            max_order: plan.max_order(),
        });
    }
    let mut result = plan.sweep(&orders)?;
    let pole_std = match &perturbation {
        Some(p) => Some(
            orders
                .iter()
                .map(|&o| {
                    Ok(p.poles_at(o)?
                        .iter()
                        .map(|s| [s.frequency_std_hz, s.damping_std])
                        .collect())
                })
                .collect::<Result<Vec<Vec<[f64; 2]>>, SsiError>>()?,
        ),
        None => None,
    };
    for o in &mut result.orders {
        for m in &mut o.modes {
            m.shape = vibmode_modal::shapes::rescaled(&m.shape, &scales);
        }
    }
    let stability = stabilisation(&result, &options.stability);
    let f_max = options.valid_max_hz.unwrap_or(fs_hz / 2.0);
    let obs: Vec<PoleObservation> = result
        .orders
        .iter()
        .flat_map(|o| {
            o.modes
                .iter()
                .filter(|m| m.frequency_hz < f_max)
                .map(move |m| {
                    let mut q = PoleObservation::new(
                        m.frequency_hz,
                        m.damping_ratio,
                        o.order,
                        0,
                        "ssi-cov",
                    );
                    q.shape = Some(m.shape.clone());
                    q
                })
        })
        .collect();
    let cluster = ClusterParams {
        freq_max_hz: Some(f_max),
        ..options.cluster.clone()
    };
    let mut modes = vibmode_modal::find_invariant_modes(&obs, 1, &orders, &cluster)?;
    modes.sort_by_key(|m| m.class != ModeClass::Structural);
    if let Some(std) = &pole_std {
        for m in modes
            .iter_mut()
            .filter(|m| m.class == ModeClass::Structural)
        {
            m.uncertainty = mode_std(m, &result, std);
        }
    }
    Ok(RecordSsi {
        fs_hz,
        n_samples: channels.first().map_or(0, |c| c.len()),
        params: params.clone(),
        stability_params: options.stability.clone(),
        lag_span_s: params.lag_span_s(fs_hz),
        result,
        stability,
        modes,
        pole_std,
        uncertainty_blocks: options.uncertainty_blocks,
    })
}

/// The median first-order standard deviations of a structural mode's poles: at each order the
/// pole nearest the mode's frequency, when within `max(3 std, 1 %)` of it and with a finite
/// standard deviation.
fn mode_std(
    m: &InvariantMode,
    result: &SsiResult,
    std: &[Vec<[f64; 2]>],
) -> Option<ModeUncertainty> {
    let radius = (3.0 * m.frequency_std_hz).max(0.01 * m.frequency_hz);
    let (f, z): (Vec<f64>, Vec<f64>) = result
        .orders
        .iter()
        .zip(std)
        .filter_map(|(o, s)| {
            let (j, pole) = o.modes.iter().enumerate().min_by(|a, b| {
                (a.1.frequency_hz - m.frequency_hz)
                    .abs()
                    .total_cmp(&(b.1.frequency_hz - m.frequency_hz).abs())
            })?;
            let v = s.get(j)?;
            ((pole.frequency_hz - m.frequency_hz).abs() <= radius
                && v[0].is_finite()
                && v[1].is_finite())
            .then_some((v[0], v[1]))
        })
        .unzip();
    (!f.is_empty()).then(|| ModeUncertainty {
        frequency_std_hz: vibmode_modal::stats::median(&f),
        damping_std: vibmode_modal::stats::median(&z),
        replicates: f.len(),
        of: result.orders.len(),
        method: UncertaintyMethod::FirstOrder,
    })
}
