//! Stage 3's contract, identification: models fitted to each (record, channel) signal and their
//! poles ([`Identifier`]). The paper's ARMA/AR order sweep (`vibmode_analysis::SweepIdentifier`)
//! is one implementation.

use serde::{Deserialize, Serialize};

use crate::modes::{FitSummary, ModelCoefficients};
use crate::params::BandLimit;

/// One pole pair of one fit that passed the pole filters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoleOut {
    /// Record index.
    pub record: usize,
    /// Model order p.
    pub order: usize,
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
}

/// What identification found in one signal.
#[derive(Clone, Debug, Default)]
pub struct SignalFits {
    /// Poles of every fit that passed the pole filters.
    pub poles: Vec<PoleOut>,
    /// Every fit's summary (failed fits keep their reason).
    pub fits: Vec<FitSummary>,
    /// Coefficients of the fits at the requested orders.
    pub models: Vec<ModelCoefficients>,
}

/// An identification method for one signal of one record.
pub trait Identifier: Sync {
    /// Fits the signal `y` of record `record`, which carries the band `band`; keeps the
    /// coefficients of the fits whose order is in `keep_orders`.
    fn identify(
        &self,
        y: &[f64],
        band: &BandLimit,
        record: usize,
        keep_orders: &[usize],
    ) -> SignalFits;
}
