//! Plain input and output types, defined once in `vibmode-core` and re-exported here.

pub use vibmode_core::{InvariantMode, ModeClass, ModeMatch, PoleObservation, ReferenceMode};
