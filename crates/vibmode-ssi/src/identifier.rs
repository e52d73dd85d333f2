//! SSI-cov as a [`MultichannelIdentifier`]: the analysis's multichannel method.

use rayon::prelude::*;
use vibmode_core::{MultichannelIdentifier, PooledIdentification, ShapedPole, SsiParams};

use crate::{SsiCorrelations, SsiCov, SsiError, SsiResult};

/// SSI-cov with its parameters, as the analysis's multichannel identifier.
#[derive(Clone, Debug)]
pub struct SsiCovIdentifier {
    /// Block rows, orders, reference channels, ...
    pub params: SsiParams,
}

/// Records pooled for SSI-cov: their correlations, kept per record for the jackknife.
#[derive(Clone, Debug)]
pub struct PooledSsi {
    correlations: SsiCorrelations,
}

/// The poles of an SSI result as [`ShapedPole`]s of record 0.
fn shaped(res: SsiResult) -> Vec<ShapedPole> {
    res.orders
        .into_iter()
        .flat_map(|o| {
            let order = o.order;
            o.modes.into_iter().map(move |m| ShapedPole {
                record: 0,
                order,
                frequency_hz: m.frequency_hz,
                damping_ratio: m.damping_ratio,
                mpc: m.mpc,
                shape: m.shape,
            })
        })
        .collect()
}

impl MultichannelIdentifier for SsiCovIdentifier {
    type Error = SsiError;
    type Pooled = PooledSsi;

    fn name(&self) -> &'static str {
        "ssi-cov"
    }

    /// The configured orders up to the block Toeplitz matrix's rank bound,
    /// `(block_rows - 1) * n_channels`.
    fn orders(&self, n_channels: usize) -> Vec<usize> {
        let max = self.params.block_rows.saturating_sub(1) * n_channels;
        self.params
            .orders()
            .into_iter()
            .filter(|&o| o <= max)
            .collect()
    }

    fn identify_record(
        &self,
        channels: &[&[f64]],
        fs_hz: f64,
        orders: &[usize],
    ) -> Result<Vec<ShapedPole>, SsiError> {
        let plan = SsiCov::new(channels, fs_hz, &self.params)?;
        Ok(shaped(plan.sweep(orders)?))
    }

    fn pool(
        &self,
        records: &[Vec<&[f64]>],
        fs_hz: f64,
        first_lags: Option<&[usize]>,
    ) -> Result<PooledSsi, SsiError> {
        let correlations = match first_lags {
            Some(lags) => SsiCorrelations::with_first_lags(records, fs_hz, &self.params, lags),
            None => SsiCorrelations::new(records, fs_hz, &self.params),
        }?;
        Ok(PooledSsi { correlations })
    }
}

impl PooledIdentification for PooledSsi {
    type Error = SsiError;

    fn n_records(&self) -> usize {
        self.correlations.n_segments()
    }

    fn identify(&self, orders: &[usize]) -> Result<Vec<ShapedPole>, SsiError> {
        Ok(shaped(self.correlations.plan()?.sweep(orders)?))
    }

    /// The repetitions from [`SsiCorrelations::jackknife`]'s plans, in parallel.
    fn jackknife(&self, groups: usize, orders: &[usize]) -> Result<Vec<Vec<ShapedPole>>, SsiError> {
        self.correlations
            .jackknife(groups)?
            .par_iter()
            .map(|p| p.sweep(orders).map(shaped))
            .collect()
    }
}
