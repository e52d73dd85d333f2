//! Error type of the crate.

use std::path::PathBuf;

/// Every error returned by `vibmode-report`. Messages are one line, name the offending value and
/// say how to fix it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// Figure size outside the supported range (pixels).
    #[error("figure size {width_px}x{height_px} px is out of range; use width_px and height_px between {min_px} and {max_px}")]
    InvalidSize {
        /// Requested width (px).
        width_px: u32,
        /// Requested height (px).
        height_px: u32,
        /// Smallest allowed side (px).
        min_px: u32,
        /// Largest allowed side (px).
        max_px: u32,
    },
    /// A grid cell (one panel) would be too small to draw axes in.
    #[error("each panel would be only {cell_width_px}x{cell_height_px} px ({rows} rows x {columns} columns in {width_px}x{height_px} px); use a larger figure (at least {min_cell_w_px}x{min_cell_h_px} px per panel) or fewer panels")]
    CellTooSmall {
        /// Cell width (px).
        cell_width_px: u32,
        /// Cell height (px).
        cell_height_px: u32,
        /// Grid rows.
        rows: usize,
        /// Grid columns.
        columns: usize,
        /// Figure width (px).
        width_px: u32,
        /// Figure height (px).
        height_px: u32,
        /// Minimum cell width (px).
        min_cell_w_px: u32,
        /// Minimum cell height (px).
        min_cell_h_px: u32,
    },
    /// `Figure::columns` was zero.
    #[error("figure columns ({0}) must be at least 1; use columns: 1")]
    InvalidColumns(usize),
    /// The figure has no panel.
    #[error("figure has no panels; add at least one Panel to Figure::panels")]
    NoPanels,
    /// x and y of a line/points series differ in length.
    #[error("panel '{panel}', series '{series}': x has {x_len} values but y has {y_len}; give x and y the same length")]
    LengthMismatch {
        /// Panel title.
        panel: String,
        /// Series label (or its index).
        series: String,
        /// Length of x.
        x_len: usize,
        /// Length of y.
        y_len: usize,
    },
    /// Series opacity outside [0, 1] or not finite.
    #[error("panel '{panel}', series '{series}': alpha ({}) must be within [0, 1]; use e.g. alpha: 0.3", vibmode_core::num(.alpha))]
    InvalidAlpha {
        /// Panel title.
        panel: String,
        /// Series label (or its index).
        series: String,
        /// The offending opacity.
        alpha: f64,
    },
    /// Line width or marker size of zero or absurdly large.
    #[error("panel '{panel}', series '{series}': {what} ({value}) must be between 1 and {max}; use e.g. {what}: 2")]
    InvalidStyleSize {
        /// Panel title.
        panel: String,
        /// Series label (or its index).
        series: String,
        /// "width" or "size".
        what: &'static str,
        /// The offending value (px).
        value: u32,
        /// Largest allowed value (px).
        max: u32,
    },
    /// An explicit axis range is unusable.
    #[error("panel '{panel}': {axis} range ({}, {}) is invalid: {reason}; {fix}", vibmode_core::num(.lo), vibmode_core::num(.hi))]
    InvalidRange {
        /// Panel title.
        panel: String,
        /// "x" or "y".
        axis: &'static str,
        /// Lower bound as given.
        lo: f64,
        /// Upper bound as given.
        hi: f64,
        /// What is wrong.
        reason: &'static str,
        /// How to fix it.
        fix: String,
    },
    /// `Figure::save` called with an extension other than .svg / .png.
    #[error(
        "unsupported figure file extension '{ext}' in '{path}'; use a path ending in .svg or .png"
    )]
    UnsupportedExtension {
        /// The extension found (empty if none).
        ext: String,
        /// The path given.
        path: PathBuf,
    },
    /// The data a report is drawn from could not be prepared (e.g. a record that cannot be
    /// resampled for a figure).
    #[error("{0}")]
    Analysis(String),
    /// Writing a file failed.
    #[error(
        "could not write '{path}': {message}; check that the directory exists and is writable"
    )]
    Write {
        /// The path written to.
        path: PathBuf,
        /// Underlying error text.
        message: String,
    },
    /// plotters reported a drawing error (should not happen on validated input).
    #[error("drawing failed: {0}; please report this with the figure that caused it")]
    Draw(String),
    /// The embedded font could not be registered with plotters.
    #[error("embedded font could not be loaded: {0}; the crate assets are corrupt, reinstall vibmode-report")]
    Font(String),
    /// Parsing an enum from text failed.
    #[error("unknown {kind} '{value}'; valid values: {valid}")]
    ParseEnum {
        /// What was being parsed ("scale", "marker").
        kind: &'static str,
        /// The text given.
        value: String,
        /// The accepted spellings.
        valid: &'static str,
    },
    /// Parsing a colour from text failed.
    #[error("invalid colour '{0}'; use '#rrggbb' (e.g. '#d62728') or one of: black, white, red, green, blue, orange, purple, grey")]
    ParseColor(String),
}

impl ReportError {
    pub(crate) fn draw<E: std::fmt::Display>(e: E) -> Self {
        ReportError::Draw(e.to_string().replace('\n', " "))
    }
}
