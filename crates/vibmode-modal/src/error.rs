//! Error type of the crate.

/// Everything that can go wrong in `vibmode-modal`. Every message is one line naming the offending
/// value and how to fix it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModalError {
    /// A clustering parameter out of its range (see [`vibmode_core::ClusterParams::validate`]).
    #[error(transparent)]
    Param(#[from] vibmode_core::ParamError),
    /// A pole has a NaN or infinite frequency (Hz).
    #[error("pole {index} has a non-finite frequency_hz ({}); drop or fix that pole before clustering", vibmode_core::num(.value))]
    NonFiniteFrequency {
        /// Index of the pole in the input slice.
        index: usize,
        /// The offending frequency, Hz.
        value: f64,
    },
    /// A pole has a NaN or infinite damping ratio.
    #[error("pole {index} has a non-finite damping_ratio ({}); drop or fix that pole before clustering", vibmode_core::num(.value))]
    NonFiniteDamping {
        /// Index of the pole in the input slice.
        index: usize,
        /// The offending damping ratio (dimensionless).
        value: f64,
    },
    /// A pole refers to a record index that is not below `n_records`.
    #[error(
        "pole {index} has record {record} but n_records is {n_records}; pass n_records >= {needed}"
    )]
    RecordOutOfRange {
        /// Index of the pole in the input slice.
        index: usize,
        /// Record index carried by the pole.
        record: usize,
        /// The `n_records` argument.
        n_records: usize,
        /// Smallest `n_records` that would be accepted.
        needed: usize,
    },
    /// A pole has a model order that is not in the `orders` list.
    #[error("pole {index} has order {order}, which is not in the orders list ({orders_desc}); add it to orders")]
    OrderNotListed {
        /// Index of the pole in the input slice.
        index: usize,
        /// Model order carried by the pole.
        order: usize,
        /// Short description of the orders list.
        orders_desc: String,
    },
    /// Non-empty pole list but `n_records == 0` or an empty `orders` list.
    #[error("{what} is empty but {n_poles} poles were given; pass the number of records and the list of model orders that were fitted")]
    EmptySupport {
        /// Which argument is empty ("n_records" or "orders").
        what: &'static str,
        /// Number of poles given.
        n_poles: usize,
    },
    /// A string could not be parsed into an enum.
    #[error("unknown {what} '{value}'; valid values: {valid}")]
    UnknownName {
        /// What was being parsed, e.g. "mode class".
        what: &'static str,
        /// The string given.
        value: String,
        /// Comma-separated valid spellings.
        valid: &'static str,
    },
}
