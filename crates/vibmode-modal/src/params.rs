//! The clustering's [`ClusterParams`] and the stabilisation diagram's [`StabilityParams`] are
//! defined once, in `vibmode-core`, and re-exported here.

pub use vibmode_core::{ClusterParams, StabilityParams};
