//! The error type of this crate.

/// Everything that can go wrong when computing a spectrum.
///
/// Every message is one line that names the offending value and says how to fix it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SpectraError {
    /// The sampling rate is zero, negative, NaN or infinite.
    #[error("sampling rate fs_hz = {} must be positive and finite; check the recording's sampling rate", vibmode_core::num(.fs_hz))]
    InvalidSampleRate {
        /// The rejected sampling rate, Hz.
        fs_hz: f64,
    },
    /// Slepian tapers that cannot be made: fewer than 2 samples, no taper, more tapers than
    /// samples, or a time-half-bandwidth product outside (0, n/2).
    #[error("multitaper settings n = {n}, nw = {}, k = {k} are invalid: need n >= 2, 0 < nw < n/2 and 1 <= k <= n (2 or more for the F-test); use e.g. nw = 4, k = 7", vibmode_core::num(.nw))]
    InvalidTapers {
        /// Record length, samples.
        n: usize,
        /// Time-half-bandwidth product.
        nw: f64,
        /// Number of tapers.
        k: usize,
    },
    /// An input signal has no samples.
    #[error("{name} is empty (0 samples); a spectrum needs at least one sample")]
    EmptyInput {
        /// Which input ("x" or "y").
        name: &'static str,
    },
    /// An input sample is NaN or infinite.
    #[error("{name}[{index}] = {} is not finite; remove or interpolate NaN/Inf samples before computing spectra", vibmode_core::num(.value))]
    NonFiniteSample {
        /// Which input ("x" or "y").
        name: &'static str,
        /// Index (0-based) of the first non-finite sample.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// `nperseg` is zero.
    #[error("nperseg must be at least 1 (got 0); use nperseg = 256")]
    ZeroNperseg,
    /// `noverlap >= nperseg` (after clamping `nperseg` to the record length, as scipy does).
    #[error("noverlap ({noverlap}) must be smaller than nperseg ({nperseg}); use noverlap = {suggested}")]
    NoverlapTooLarge {
        /// The requested overlap, samples.
        noverlap: usize,
        /// The segment length in force, samples.
        nperseg: usize,
        /// A valid overlap to suggest (nperseg / 2), samples.
        suggested: usize,
    },
    /// `nfft < nperseg`.
    #[error("nfft ({nfft}) must be at least nperseg ({nperseg}); use nfft = {nperseg} or larger")]
    NfftTooSmall {
        /// The requested FFT length, samples.
        nfft: usize,
        /// The segment length in force, samples.
        nperseg: usize,
    },
    /// `nfft` is zero.
    #[error("nfft must be at least 1 (got 0); leave nfft unset for the default (nperseg)")]
    ZeroNfft,
    /// `x` and `y` of a cross-spectrum have different lengths.
    #[error("x has {len_x} samples but y has {len_y}; csd and coherence need records of equal length, trim the longer one to {min}", min = .len_x.min(.len_y))]
    LengthMismatch {
        /// Samples in x.
        len_x: usize,
        /// Samples in y.
        len_y: usize,
    },
    /// The record is shorter than one segment and [`crate::ShortRecord::Error`] was asked for.
    #[error("record has {n_samples} samples, shorter than one segment (nperseg = {nperseg}); use nperseg <= {n_samples}")]
    ShortRecord {
        /// Samples in the record.
        n_samples: usize,
        /// The requested segment length, samples.
        nperseg: usize,
    },
    /// A Tukey window's alpha is outside [0, 1] or not finite.
    #[error("tukey alpha ({}) must be in [0, 1]; use e.g. tukey:0.5", vibmode_core::num(.alpha))]
    InvalidTukeyAlpha {
        /// The rejected alpha.
        alpha: f64,
    },
    /// A Kaiser window's beta is not finite or beyond 700 in magnitude (I0 overflows).
    #[error("kaiser beta ({}) must be finite with |beta| <= 700; use e.g. kaiser:8.6", vibmode_core::num(.beta))]
    InvalidKaiserBeta {
        /// The rejected beta.
        beta: f64,
    },
    /// A window name that [`crate::Window`]'s `FromStr` does not know.
    #[error("unknown window '{name}'; valid windows: hann, hamming, blackman, boxcar (or rect), flattop, tukey (alpha 0.5), tukey:ALPHA with ALPHA in [0, 1], kaiser:BETA (e.g. kaiser:8.6), or custom coefficients")]
    UnknownWindow {
        /// The rejected name.
        name: String,
    },
    /// Custom window coefficients ([`crate::WindowSpec::Custom`]) with no coefficient.
    #[error("the window has 0 coefficients; give at least one coefficient, or a window name such as hann")]
    EmptyWindow,
    /// A custom window coefficient is NaN or infinite.
    #[error("window[{index}] = {} is not finite; window coefficients must be finite numbers", vibmode_core::num(.value))]
    NonFiniteWindow {
        /// Index (0-based) of the first non-finite coefficient.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// Every custom window coefficient is zero.
    #[error("the window's {len} coefficients are all 0; a window needs a non-zero coefficient (e.g. hann or boxcar)")]
    ZeroWindow {
        /// Number of coefficients.
        len: usize,
    },
    /// The window's scale factor is 0: `sum(w)` with [`crate::Scaling::Spectrum`] (a window
    /// whose positive and negative coefficients cancel), or `sum(w^2)` underflowing.
    #[error("the window's {what} is 0 (scaling = {scaling} divides by it); use a window whose {what} is not 0, e.g. hann")]
    WindowScaleZero {
        /// "sum(w)" or "sum(w^2)".
        what: &'static str,
        /// The scaling in force ("spectrum" or "density").
        scaling: &'static str,
    },
    /// `nperseg` was given and differs from the length of custom window coefficients
    /// (scipy: "value specified for nperseg is different from length of window").
    #[error("nperseg = {nperseg} differs from the window's length {window_len}; leave nperseg unset (it defaults to the window's length) or give a window of {nperseg} coefficients")]
    WindowLengthMismatch {
        /// Number of window coefficients.
        window_len: usize,
        /// The requested segment length, samples.
        nperseg: usize,
    },
    /// Custom window coefficients longer than the record (scipy: "window is longer than input
    /// signal"); a custom window is never shortened.
    #[error("the window has {window_len} coefficients but the record only {n_samples} samples; give a window of at most {n_samples} coefficients")]
    WindowLongerThanRecord {
        /// Number of window coefficients.
        window_len: usize,
        /// Samples in the record.
        n_samples: usize,
    },
    /// A periodogram's custom window must have one coefficient per sample used.
    #[error("the window has {window_len} coefficients but the periodogram uses {n_samples} samples (the record, or nfft if smaller); give a window of {n_samples} coefficients")]
    PeriodogramWindowLength {
        /// Number of window coefficients.
        window_len: usize,
        /// Samples the periodogram uses.
        n_samples: usize,
    },
    /// An unknown detrend name.
    #[error("unknown detrend '{name}'; valid values: none, constant, linear")]
    UnknownDetrend {
        /// The rejected name.
        name: String,
    },
    /// An unknown scaling name.
    #[error("unknown scaling '{name}'; valid values: density, spectrum")]
    UnknownScaling {
        /// The rejected name.
        name: String,
    },
    /// An unknown average name.
    #[error("unknown average '{name}'; valid values: mean, median")]
    UnknownAverage {
        /// The rejected name.
        name: String,
    },
    /// An unknown short-record policy name.
    #[error("unknown short-record policy '{name}'; valid values: clamp, error")]
    UnknownShortRecord {
        /// The rejected name.
        name: String,
    },
    /// A [`crate::WelchPlan`] was given a record of another length than it was built for.
    #[error("the WelchPlan was built for {expected} samples but {name} has {got}; build a new plan for this record length")]
    PlanLengthMismatch {
        /// Which input ("x" or "y").
        name: &'static str,
        /// Samples the plan was built for.
        expected: usize,
        /// Samples received.
        got: usize,
    },
}
