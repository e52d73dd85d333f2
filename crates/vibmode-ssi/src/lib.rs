//! # vibmode-ssi
//!
//! Covariance-driven stochastic subspace identification (SSI-cov) of multichannel records: the
//! output correlations at lags `1..=2i-1`, their block Toeplitz matrix and its SVD (computed once
//! per record by [`SsiCov::new`]), then for any model order the state matrix from the shift
//! invariance of the observability matrix and its poles: natural frequency, damping ratio,
//! complex mode shape (one entry per channel) and modal phase collinearity
//! ([`SsiCov::poles_at`]). [`ssi_cov`] does both for the orders of an [`SsiParams`];
//! [`stabilisation`] labels each mode against the previous order ([`Stability`]); [`mac`] and
//! [`mpc`] compare and grade mode shapes; [`identify_record`] runs all of it on one record
//! and clusters the poles over the orders (`vibmode ssi`); [`SsiCov::perturbation`] gives each
//! pole's first-order standard deviations from blocks of the record (Döhler-style). The definitions are in `docs/ssi.md`.
//!
//! ## Panics
//!
//! No function panics on input data; bad input gives an [`SsiError`] whose message names the
//! offending value and the fix.

mod cov;
mod eig;
mod error;
mod identifier;
mod perturb;
mod record;
mod shape;
mod stability;
mod svd;

pub use cov::{
    jackknife_std, samples_needed, ssi_cov, SsiCorrelations, SsiCov, SsiMode, SsiOrder, SsiResult,
};
pub use error::SsiError;
pub use identifier::{PooledSsi, SsiCovIdentifier};
pub use perturb::{PoleStd, SsiPerturbation};
pub use record::{identify_record, RecordSsi, RecordSsiOptions};
pub use shape::{mac, mpc};
pub use stability::{stabilisation, Stability};
pub use vibmode_core::{SsiParams, StabilityParams};
