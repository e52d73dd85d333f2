//! # vibmode-report
//!
//! Figures (SVG and PNG) and self-contained HTML reports for vibmode results. The crate takes
//! plain data (slices, strings) and draws it with plotters, using an embedded DejaVu Sans font so
//! PNG text renders on machines without any system font.
//!
//! A [`Figure`] is a grid of [`Panel`]s (filled row by row, `columns` wide); each panel has axes
//! (linear or log, automatic or fixed ranges) and [`Series`] drawn as lines, markers or vertical
//! lines (e.g. mode frequencies). Data are handled robustly: NaN/Inf, and non-positive values on
//! log axes, are skipped; empty panels show "no data"; long lines are decimated to at most
//! ~4000 points per series keeping every peak (min/max per pixel column).
//!
//! Units: figure sizes in pixels (`width_px`, `height_px`); data are in whatever unit the axis
//! labels state — always put the unit in the label, e.g. `"Frequency [Hz]"`.
//!
//! ```
//! use vibmode_report::{Figure, HtmlReport, Marker, Panel, Rgb, Scale, Series};
//!
//! // A PSD on a log y axis with two mode frequencies marked by dotted vertical lines.
//! let f_hz: Vec<f64> = (0..=500).map(|i| i as f64 * 0.05).collect();
//! let psd: Vec<f64> = f_hz
//!     .iter()
//!     .map(|&f| 1.0 / ((1.0 - (f / 1.1_f64).powi(2)).powi(2) + 0.04) + 0.01 / ((1.0 - (f / 9.0_f64).powi(2)).powi(2) + 0.01))
//!     .collect();
//! let panel = Panel::new("Welch PSD", "Frequency [Hz]", "PSD [(m/s²)²/Hz]")
//!     .with_scales(Scale::Linear, Scale::Log)
//!     .with_series(Series::line(f_hz, psd).with_label("Welch"))
//!     .with_series(Series::vlines(vec![1.1, 9.0]).with_label("modes").with_color(Rgb::RED));
//! let fig = Figure::single(panel);
//! let svg = fig.to_svg_string().unwrap();
//! assert!(svg.starts_with("<svg") && svg.contains("Frequency [Hz]") && svg.contains("Welch PSD"));
//!
//! let mut report = HtmlReport::new("Bus <front> axle");
//! report.figure(&fig, "PSD & modes").unwrap();
//! let html = report.to_html();
//! assert!(html.contains("<title>Bus &lt;front&gt; axle</title>"));
//! assert_eq!(html.matches("<figure>").count(), 1);
//! ```
//!
//! ## Figures the CLI draws
//! * time records: [`Series::line`] per channel, `Scale::Linear` axes;
//! * raw vs resampled in time and frequency: [`Figure::grid`] with 2 columns;
//! * periodogram / Welch / model PSD on a log y axis, mode frequencies as [`Series::vlines`];
//! * stabilisation diagram: [`Series::points`] of (frequency, order) with a faint PSD behind,
//!   mapped onto the order axis with [`axes::rescale_to`] (`alpha` ≈ 0.3-0.6);
//! * frequency vs damping ratio on a log y axis, physical-model modes as red
//!   [`Marker::Diamond`] points.
//!
//! ## Text and fonts
//! All text uses [`FONT_FAMILY`]. PNG text is rasterised from the embedded DejaVu Sans (no
//! system font needed); SVG files name the same family (with `Verdana, sans-serif` fallbacks)
//! and leave rendering to the viewer. plotters writes SVG font sizes as `size / 1.24`, so SVG
//! text looks slightly smaller than PNG text.
//!
//! ## Panics
//! None on input data: every problem is returned as a [`ReportError`]. The only panics left are
//! plotters' internal ones on a poisoned font-table lock (only possible after another thread
//! panicked while drawing) and allocation failure.

#![warn(missing_docs)]

pub mod analysis;
pub mod axes;
mod error;
mod font;
mod html;
mod model;
pub mod panels;
mod render;
pub mod sections;
pub mod shape_figures;
pub mod signal_figures;
pub mod spectrum_figures;

pub use analysis::{modes_csv, modes_table_text, write_analysis_report, ReportFiles, TruthRow};
pub use error::ReportError;
pub use font::{ensure_font, DEJAVU_SANS_TTF, FONT_FAMILY};
pub use html::{escape_html, is_numeric_cell, HtmlReport, INLINE_SVG_MAX_BYTES};
pub use model::{Figure, Marker, Panel, Rgb, Scale, Series, SeriesStyle, PALETTE};
pub use render::{
    MAX_POINTS_PER_SERIES, MAX_SIDE_PX, MIN_CELL_HEIGHT_PX, MIN_CELL_WIDTH_PX, MIN_SIDE_PX,
};
pub use sections::{ReportSection, ReportTable};
pub use signal_figures::antialias_figure;
pub use spectrum_figures::{model_spectra_figure, psd_figure, Curve, ModelSpectrumPanel};

/// Re-export of plotters, so callers of [`Figure::draw_on`] use the same version.
pub use plotters;
