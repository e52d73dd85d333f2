//! The embedded DejaVu Sans font (Bitstream Vera licence, see `assets/DejaVuSans-LICENSE.txt`),
//! registered once with plotters so PNG text renders without any system font.

use crate::error::ReportError;
use std::sync::OnceLock;

/// Bytes of DejaVu Sans (TrueType, ~760 kB).
pub static DEJAVU_SANS_TTF: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// The font family name used for all text. It is also a valid CSS `font-family` list, so SVG
/// viewers without DejaVu Sans fall back to a similar sans-serif font.
pub const FONT_FAMILY: &str = "DejaVu Sans, Verdana, sans-serif";

static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();

/// Register the embedded font with plotters under [`FONT_FAMILY`] (idempotent, thread-safe).
/// Called automatically by every drawing function.
pub fn ensure_font() -> Result<(), ReportError> {
    REGISTERED
        .get_or_init(|| {
            plotters::style::register_font(
                FONT_FAMILY,
                plotters::style::FontStyle::Normal,
                DEJAVU_SANS_TTF,
            )
            .map_err(|_| "DejaVuSans.ttf is not a valid TrueType font".to_string())
        })
        .clone()
        .map_err(ReportError::Font)
}
