//! Error type of the crate.

/// Everything that can go wrong when reading vehicle parameters, building the model or simulating.
///
/// Every message is one line that names the offending value and says how to fix it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum VehicleError {
    /// The TOML text could not be parsed (syntax error, unknown key, missing key, wrong type).
    #[error(
        "invalid vehicle TOML{location}: {message}; see docs/vehicle.md for every key and its unit"
    )]
    Toml {
        /// " at line N" or empty when unknown.
        location: String,
        /// The parser's message (one line), naming the key.
        message: String,
    },
    /// A parameter value is out of its valid range.
    #[error("{key} = {value} {problem}")]
    InvalidParameter {
        /// Dotted key, e.g. `front.spring_stiffness_n_per_m`.
        key: String,
        /// The offending value as written.
        value: String,
        /// What is wrong and how to fix it, e.g. "must be positive; give the stiffness in N/m".
        problem: String,
    },
    /// Reading a parameter file failed.
    #[error("cannot read vehicle file {path}: {source}; check the path")]
    Io {
        /// The path that was given.
        path: String,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// A string could not be parsed into one of the crate's enums.
    #[error("unknown {what} '{value}'; valid values: {valid}")]
    UnknownName {
        /// What kind of name it is, e.g. "road class".
        what: &'static str,
        /// The text that was given.
        value: String,
        /// Comma-separated list of valid values.
        valid: &'static str,
    },
    /// Records cannot be used to fit the model's suspension (a missing sensor, too short a
    /// record, a fit that gives a non-physical value).
    #[error("cannot fit the suspension to the records: {problem}; {fix}")]
    BodyFit {
        /// What is wrong, with the offending value.
        problem: String,
        /// How to fix it.
        fix: &'static str,
    },
    /// A settings struct from `vibmode-core` holds a value out of range.
    #[error(transparent)]
    Param(#[from] vibmode_core::ParamError),
    /// A numerical routine failed (singular matrix, eigenvalue iteration did not converge).
    #[error("numerical failure: {0}; check that masses and stiffnesses are physically plausible")]
    Numerical(String),
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, VehicleError>;

pub(crate) fn invalid(
    key: impl Into<String>,
    value: impl std::fmt::Display,
    problem: impl Into<String>,
) -> VehicleError {
    VehicleError::InvalidParameter {
        key: key.into(),
        value: value.to_string(),
        problem: problem.into(),
    }
}
