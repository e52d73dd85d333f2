//! Plain input and output types, defined once in `vibmode-core` and re-exported here.

pub use vibmode_core::{InvariantMode, ModeClass, ModeMatch, PoleObservation, ReferenceMode};

use crate::ModalError;

/// Checks that a pole's frequency and damping ratio are finite; `index` (the pole's position in
/// the caller's slice) goes into the error. Shared by clustering and the stabilisation diagram.
pub(crate) fn check_finite(pole: &PoleObservation, index: usize) -> Result<(), ModalError> {
    if !pole.frequency_hz.is_finite() {
        return Err(ModalError::NonFiniteFrequency {
            index,
            value: pole.frequency_hz,
        });
    }
    if !pole.damping_ratio.is_finite() {
        return Err(ModalError::NonFiniteDamping {
            index,
            value: pole.damping_ratio,
        });
    }
    Ok(())
}
