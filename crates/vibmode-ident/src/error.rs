//! Error type of the crate.

/// Everything that can go wrong in identification. Every message is one line naming the offending
/// value and how to fix it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum IdentError {
    /// The input signal has no samples.
    #[error("input signal is empty; pass at least {min_len} samples")]
    Empty {
        /// Smallest useful length for the requested model (samples).
        min_len: usize,
    },
    /// A sample is NaN or infinite.
    #[error(
        "sample {index} is {} (not finite); remove or interpolate non-finite samples first", vibmode_core::num(.value))]
    NonFinite {
        /// Index of the first offending sample.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The signal is constant (all samples equal), so it carries no dynamics.
    #[error(
        "signal is constant (every sample equals {}); identification needs a varying signal", vibmode_core::num(.value))]
    Constant {
        /// The constant value.
        value: f64,
    },
    /// The requested order is too large for the number of samples.
    #[error("{what} = {order} is too high for {n_samples} samples; the largest allowed is {max_order} (N/3); lower the order or use a longer record")]
    OrderTooHigh {
        /// Which order ("AR order p" or "ARMA order p + q").
        what: &'static str,
        /// Requested order.
        order: usize,
        /// Number of samples.
        n_samples: usize,
        /// Largest allowed order for this number of samples.
        max_order: usize,
    },
    /// An MA order above the AR order: the prediction-error criterion sums from t = p, so the
    /// fit needs q <= p.
    #[error("MA order q = {q} is above the AR order p = {p}; vibmode fits ARMA(p, q) with q <= p: lower q or raise p (the paper's ARMA(p, p))")]
    MaOrderAboveAr {
        /// AR order.
        p: usize,
        /// MA order.
        q: usize,
    },
    /// An order of zero where it is meaningless.
    #[error("{what} must be at least 1 (got 0); {fix}")]
    ZeroOrder {
        /// Which order.
        what: &'static str,
        /// How to fix it.
        fix: &'static str,
    },
    /// A polynomial coefficient is NaN or infinite.
    #[error(
        "polynomial coefficient {index} is {} (not finite); all coefficients must be finite", vibmode_core::num(.value))]
    BadCoefficient {
        /// Index of the coefficient.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The leading coefficient of a polynomial is zero (or the polynomial is empty).
    #[error("leading polynomial coefficient is {}; pass coefficients (highest power first) with a nonzero first entry", vibmode_core::num(.value))]
    ZeroLeading {
        /// The leading coefficient.
        value: f64,
    },
    /// The eigenvalue iteration for polynomial roots did not converge.
    #[error("root finding did not converge for the degree-{degree} polynomial; check the coefficients for extreme magnitudes")]
    RootsNotConverged {
        /// Polynomial degree.
        degree: usize,
    },
    /// A parameter value out of range, or an unknown name (an AR method): core's one shape of
    /// a parameter error.
    #[error(transparent)]
    Param(#[from] vibmode_core::ParamError),
    /// A warm-start model has orders that do not fit the requested ones.
    #[error("warm-start model has orders (p={init_p}, q={init_q}) larger than the requested (p={p}, q={q}); pass a lower-order model or none")]
    InitMismatch {
        /// Requested AR order.
        p: usize,
        /// Requested MA order.
        q: usize,
        /// AR order of the initial model.
        init_p: usize,
        /// MA order of the initial model.
        init_q: usize,
    },
    /// Simulation of an unstable model was requested.
    #[error("A(z) has a root of modulus {} >= 1 (unstable); simulation needs every root of A inside the unit circle", vibmode_core::num(.modulus))]
    UnstableModel {
        /// Largest root modulus of A.
        modulus: f64,
    },
}
