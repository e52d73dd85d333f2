//! Stage 3's contracts, identification: models fitted to each (record, channel) signal and their
//! poles ([`Identifier`]; the paper's ARMA/AR order sweep, `vibmode_analysis::SweepIdentifier`,
//! is one implementation), and models fitted to all channels of a record at once, poles with
//! mode shapes ([`MultichannelIdentifier`]; SSI-cov, `vibmode_ssi::SsiCovIdentifier`, is one).

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

/// One pole of one multichannel fit at one model order, with its shape.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShapedPole {
    /// Record index (0 for records identified together).
    pub record: usize,
    /// Model order (state dimension).
    pub order: usize,
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
    /// Modal phase collinearity of the shape (1 = a real, normal mode).
    pub mpc: f64,
    /// Complex shape, one `[re, im]` per channel, in the order the channels were given.
    pub shape: Vec<[f64; 2]>,
}

/// A multichannel identification method: all channels of a record at once, poles with shapes
/// at each model order. SSI-cov (`vibmode_ssi::SsiCovIdentifier`) is one implementation.
///
/// The analysis decides which records and channels it gives (active records, channels scaled
/// to a common level) and what it does with the poles (band edge, clustering, classing); the
/// method only identifies.
pub trait MultichannelIdentifier: Sync {
    /// The method's failure (kept per record in the results).
    type Error: std::error::Error + Clone + Send;
    /// Several records identified together (see [`MultichannelIdentifier::pool`]).
    type Pooled: PooledIdentification<Error = Self::Error>;

    /// Short name: the pseudo-channel of the method's poles in the results.
    fn name(&self) -> &'static str;

    /// The configured orders the method can identify from `n_channels` channels.
    fn orders(&self, n_channels: usize) -> Vec<usize>;

    /// The poles of one record's `channels` (equal lengths, sampled at `fs_hz`) at every order
    /// of `orders`, each with `record` 0.
    fn identify_record(
        &self,
        channels: &[&[f64]],
        fs_hz: f64,
        orders: &[usize],
    ) -> Result<Vec<ShapedPole>, Self::Error>;

    /// Several records (each a list of channels, all at `fs_hz`) prepared for one
    /// identification together. `first_lags`, when given, is one lag per record from which
    /// that record's statistics start (a record seen through a delay).
    fn pool(
        &self,
        records: &[Vec<&[f64]>],
        fs_hz: f64,
        first_lags: Option<&[usize]>,
    ) -> Result<Self::Pooled, Self::Error>;
}

/// Records prepared for one identification together ([`MultichannelIdentifier::pool`]).
pub trait PooledIdentification: Sync {
    /// The method's failure.
    type Error: std::error::Error + Clone + Send;

    /// Number of records pooled.
    fn n_records(&self) -> usize;

    /// The poles of the records together at every order of `orders`, each with `record` 0.
    fn identify(&self, orders: &[usize]) -> Result<Vec<ShapedPole>, Self::Error>;

    /// Delete-a-group jackknife: the records split into `groups` groups of consecutive records
    /// and the identification repeated without each group; one list of poles per repetition.
    fn jackknife(
        &self,
        groups: usize,
        orders: &[usize],
    ) -> Result<Vec<Vec<ShapedPole>>, Self::Error>;
}
