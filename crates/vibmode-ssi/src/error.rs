//! Error type of the crate.

use vibmode_core::ParamError;

/// Everything that can go wrong in SSI-cov. Every message is one line naming the offending value
/// and how to fix it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SsiError {
    /// No channel was given.
    #[error("no channels given; pass at least one channel of samples")]
    NoChannels,
    /// A channel with fewer than two samples.
    #[error("channel {channel} has {n_samples} samples; every channel needs at least 2")]
    TooShort {
        /// 0-based channel index.
        channel: usize,
        /// Its number of samples.
        n_samples: usize,
    },
    /// Channels of different lengths.
    #[error("channel {channel} has {found} samples but channel 0 has {expected}; all channels must have the same length")]
    LengthMismatch {
        /// 0-based index of the offending channel.
        channel: usize,
        /// Its length.
        found: usize,
        /// The length of channel 0.
        expected: usize,
    },
    /// A NaN or infinite sample.
    #[error("channel {channel} sample {index} is {}; remove or interpolate non-finite samples first", vibmode_core::num(.value))]
    NonFinite {
        /// 0-based channel index.
        channel: usize,
        /// 0-based sample index.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A channel that carries no vibration: every sample 0 or one other value
    /// ([`vibmode_core::stats::constant_value`]): a dead or stuck sensor.
    #[error("channel {channel} is constant (every sample is {}): a dead or stuck sensor has no vibration to identify; check the sensor, or leave the channel out", vibmode_core::num(.value))]
    ConstantChannel {
        /// Index of the channel.
        channel: usize,
        /// Its one value.
        value: f64,
    },
    /// A sampling rate that is not a positive finite number.
    #[error("sampling rate {} Hz must be a positive finite number", vibmode_core::num(.fs_hz))]
    InvalidSampleRate {
        /// The value.
        fs_hz: f64,
    },
    /// A jackknife with fewer than two groups, or more groups than segments.
    #[error("a jackknife of {groups} groups over {n_segments} segments: give 2 to {n_segments} groups, and at least 2 segments")]
    TooFewSegments {
        /// Segments given.
        n_segments: usize,
        /// Groups asked for.
        groups: usize,
    },
    /// A perturbation-based uncertainty needs the scatter of at least two blocks.
    #[error("{n_blocks} data block(s) give no scatter to propagate; cut the data into at least 2 blocks (20 to 50 is usual)")]
    TooFewBlocks {
        /// Blocks (or segments) given.
        n_blocks: usize,
    },
    /// Blocks of one record too short for the lags of the block Toeplitz matrix.
    #[error("{n_samples} samples cut into {n_blocks} blocks give {block_len} samples per block, fewer than the {min_block_len} the lags need; use at most {max_blocks} blocks or lower block_rows")]
    BlocksTooShort {
        /// Samples per channel of the record.
        n_samples: usize,
        /// Blocks asked for.
        n_blocks: usize,
        /// Samples per block.
        block_len: usize,
        /// Samples a block needs (`first_lag + 2 block_rows - 1`).
        min_block_len: usize,
        /// Most blocks the record allows.
        max_blocks: usize,
    },
    /// Per-segment first lags that are not one positive lag per segment.
    #[error("{n_lags} first lags for {n_segments} segments; give one first lag (at least 1 sample) per segment")]
    FirstLags {
        /// First lags given.
        n_lags: usize,
        /// Segments given.
        n_segments: usize,
    },
    /// Too few samples for the lags of the block Toeplitz matrix: a record (or segment) needs
    /// `first_lag - 1 + 2 (2 block_rows - 1)` samples
    /// ([`vibmode_core::limits::SSI_SAMPLES_PER_LAG_MIN`]), so that its largest lag's
    /// correlation still averages as many products as the matrix has lags.
    #[error("{n_samples} samples per channel are too few for block_rows = {block_rows} from first_lag = {first_lag} (lags {first_lag}..={max_lag}); pass at least {min_samples} samples, or lower block_rows or first_lag")]
    TooFewSamples {
        /// Samples per channel.
        n_samples: usize,
        /// Block rows asked for.
        block_rows: usize,
        /// First lag of the Toeplitz matrix.
        first_lag: usize,
        /// Largest lag of the Toeplitz matrix, `first_lag + 2 * block_rows - 2`.
        max_lag: usize,
        /// Smallest number of samples accepted, `first_lag - 1 + 2 (2 block_rows - 1)`.
        min_samples: usize,
    },
    /// A block Toeplitz matrix with more than
    /// [`vibmode_core::limits::SSI_TOEPLITZ_ROWS_MAX`] rows (`block_rows x channels`).
    #[error("block_rows = {block_rows} with {n_channels} channels makes a Toeplitz matrix of more than {max_rows} rows (block_rows x channels), too large to decompose; use at most block_rows = {max_block_rows} or fewer channels")]
    MatrixTooLarge {
        /// Block rows asked for.
        block_rows: usize,
        /// Number of channels.
        n_channels: usize,
        /// Most rows accepted.
        max_rows: usize,
        /// Most block rows for these channels.
        max_block_rows: usize,
    },
    /// Lags whose arithmetic overflows (a first lag far beyond any record).
    #[error("first_lag = {first_lag} with block_rows = {block_rows} puts the Toeplitz matrix's lags beyond any record (at most 2^30 samples); lower first_lag")]
    LagsTooLarge {
        /// Block rows asked for.
        block_rows: usize,
        /// First lag asked for.
        first_lag: usize,
    },
    /// More uncertainty blocks than [`vibmode_core::limits::SSI_SVD_WORK_MAX`] allows for the
    /// size of the Toeplitz matrix (two SVDs per block).
    #[error("{n_blocks} uncertainty blocks need {n_blocks} x 2 SVDs of a {rows} x {cols} Toeplitz matrix, too much work; use at most {max_blocks} blocks or lower block_rows")]
    TooManyBlocks {
        /// Blocks asked for.
        n_blocks: usize,
        /// Rows of the Toeplitz matrix.
        rows: usize,
        /// Columns of the Toeplitz matrix.
        cols: usize,
        /// Most blocks allowed at this size.
        max_blocks: usize,
    },
    /// A list of model orders that is empty, not increasing, or holds an order outside
    /// `1..=`[`vibmode_core::limits::SSI_ORDER_MAX`].
    #[error("model orders {orders} must be increasing orders from 1 to {max}, e.g. 2, 4, 6")]
    OrderList {
        /// The list given (its start, at most 60 characters).
        orders: String,
        /// Highest order accepted.
        max: usize,
    },
    /// A reference channel index that is not a channel of the data.
    #[error("reference channel {index} does not exist: there are {n_channels} channels (0-based indices 0..={last}); list existing channels in reference_channels")]
    ReferenceChannel {
        /// The index given.
        index: usize,
        /// Number of channels.
        n_channels: usize,
        /// Largest valid index.
        last: usize,
    },
    /// A correlation overflowed (samples so large that their products are not finite).
    #[error("the correlation at lag {lag} is not finite (largest sample magnitude {max_abs:e}); scale the channels to a moderate range (e.g. divide by {max_abs:e})")]
    Overflow {
        /// Lag of the first non-finite correlation.
        lag: usize,
        /// Largest absolute sample value (after mean removal).
        max_abs: f64,
    },
    /// A parameter out of range.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// A model order of zero.
    #[error("model order 0 identifies nothing; ask for an order >= 1 (2 per mode)")]
    ZeroOrder,
    /// An order above what the shift invariance of the observability matrix can determine.
    #[error("order {order} is too high for block_rows = {block_rows} with {n_channels} channels and {n_references} references: the largest is min((block_rows - 1) x channels, block_rows x references) = {max_order}; lower the order or raise block_rows to {needed_block_rows}")]
    OrderTooHigh {
        /// Order asked for.
        order: usize,
        /// Block rows of the Toeplitz matrix.
        block_rows: usize,
        /// Number of channels.
        n_channels: usize,
        /// Number of reference channels (all channels unless references are given).
        n_references: usize,
        /// Largest order for these block rows,
        /// `min((block_rows - 1) * n_channels, block_rows * n_references)`.
        max_order: usize,
        /// Smallest number of block rows that allows the order.
        needed_block_rows: usize,
    },
    /// An order above the numerical rank of the block Toeplitz matrix (noise-free or degenerate
    /// data: fewer independent components than states asked for).
    #[error("order {order} is above the numerical rank {rank} of the block Toeplitz matrix (singular values below {tolerance:e} are treated as zero); ask for an order <= {rank}")]
    OrderAboveRank {
        /// Order asked for.
        order: usize,
        /// Numerical rank of the Toeplitz matrix.
        rank: usize,
        /// Singular values at or below this are zero.
        tolerance: f64,
    },
    /// An iterative decomposition (SVD or Schur) did not converge.
    #[error("the {what} of a {size}x{size} matrix did not converge within {iterations} iterations; check the data for extreme magnitudes (scale the channels)")]
    NotConverged {
        /// Which decomposition ("SVD of the Toeplitz matrix", "Schur form of A").
        what: &'static str,
        /// Matrix size.
        size: usize,
        /// Iteration cap.
        iterations: usize,
    },
    /// None of the orders asked for is identifiable from the data.
    #[error("no order from {order_min} up is identifiable from {n_channels} channel(s) with {block_rows} block rows (the highest is {max_order}); raise block_rows or lower the orders")]
    NoOrder {
        /// Lowest order asked for.
        order_min: usize,
        /// Number of channels.
        n_channels: usize,
        /// Block rows used.
        block_rows: usize,
        /// Highest identifiable order.
        max_order: usize,
    },
    /// Clustering the poles over the orders failed (a clustering parameter out of range).
    #[error(transparent)]
    Modal(#[from] vibmode_modal::ModalError),
}
