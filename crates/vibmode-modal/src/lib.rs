//! # vibmode-modal: invariant modes across model orders and records
//!
//! AR/ARMA models of orders p = 2..60 fitted to many records and channels each give a set of
//! poles, i.e. modes `(frequency_hz, damping_ratio)`. Most of them are artefacts of one fit; the
//! *invariant* modes are those that recur across model orders **and** records (paper section IV,
//! `docs/modal.md`). This crate pools all poles ([`PoleObservation`]), clusters them by density
//! in the plane (log frequency, log10 damping) ([`find_invariant_modes`]), and classifies each
//! cluster as [`ModeClass::Structural`], [`ModeClass::PeriodicDisturbance`] (engine/gear lines:
//! damping ~1e-3, frequency extremely stable) or [`ModeClass::Spurious`] (not supported by enough
//! records/orders). [`match_reference`] compares the structural modes with a physical model, and
//! [`stabilisation()`] gives the classic stabilisation-diagram status of every pole.
//!
//! The crate is independent of the other vibmode crates; it never panics on input data.
//!
//! ```
//! use vibmode_modal::{find_invariant_modes, ClusterParams, ModeClass, PoleObservation};
//!
//! // 4 records x orders 10..=30: a body mode near 1.1 Hz (zeta ~ 0.25, small jitter) and an
//! // engine line at 7 Hz (zeta ~ 1e-3) in every fit, plus one stray pole in record 0.
//! let orders: Vec<usize> = (10..=30).collect();
//! let mut poles = Vec::new();
//! for record in 0..4 {
//!     for &order in &orders {
//!         let j = ((record * 31 + order * 17) % 11) as f64 / 10.0 - 0.5; // -0.5..0.5
//!         poles.push(PoleObservation::new(1.1 * (1.0 + 0.02 * j), 0.25 * (1.0 + 0.3 * j), order, record, "RL"));
//!         poles.push(PoleObservation::new(7.0 * (1.0 + 1e-4 * j), 1e-3 * (1.0 + 0.2 * j), order, record, "RL"));
//!     }
//! }
//! poles.push(PoleObservation::new(4.2, 0.05, 20, 0, "RL"));
//!
//! let modes = find_invariant_modes(&poles, 4, &orders, &ClusterParams::default()).unwrap();
//! assert_eq!(modes.len(), 2); // the stray pole is noise, not a cluster
//! assert_eq!(modes[0].class, ModeClass::Structural);
//! assert!((modes[0].frequency_hz - 1.1).abs() < 0.01);
//! assert_eq!(modes[0].record_share, 1.0);
//! assert_eq!(modes[0].n_poles, 4 * 21);
//! assert_eq!(modes[1].class, ModeClass::PeriodicDisturbance);
//! assert!((modes[1].frequency_hz - 7.0).abs() < 1e-3);
//! ```

#![warn(missing_docs)]

mod cluster;
mod error;
mod matching;
mod params;
pub mod shapes;
mod stabilisation;
pub mod stats;
mod types;

pub use cluster::{analyse_poles, find_invariant_modes, ModalAnalysis};
pub use error::ModalError;
pub use matching::{
    match_reference, match_reference_shapes, MATCH_MAC_MIN, MATCH_MAX_FREQ_DIFF_REL,
};
pub use params::{ClusterParams, StabilityParams};
pub use stabilisation::{stabilisation, Stability};
pub use types::{InvariantMode, ModeClass, ModeMatch, PoleObservation, ReferenceMode};
