//! Declarative description of a figure: [`Figure`] → [`Panel`]s → [`Series`].

use crate::error::ReportError;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Axis scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Scale {
    /// Linear axis (default).
    #[default]
    Linear,
    /// Base-10 logarithmic axis. Non-positive, NaN and infinite values are skipped.
    Log,
}

impl fmt::Display for Scale {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Scale::Linear => "linear",
            Scale::Log => "log",
        })
    }
}

impl FromStr for Scale {
    type Err = ReportError;
    /// Accepts `linear`/`lin` and `log`/`log10` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "linear" | "lin" => Ok(Scale::Linear),
            "log" | "log10" => Ok(Scale::Log),
            _ => Err(ReportError::ParseEnum {
                kind: "scale",
                value: s.to_string(),
                valid: "linear, log",
            }),
        }
    }
}

/// Marker shape of a [`SeriesStyle::Points`] series.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Marker {
    /// Filled circle (default).
    #[default]
    Circle,
    /// Diagonal cross (stroked).
    Cross,
    /// Filled diamond (used for physical-model modes in the paper's Fig. 9-10).
    Diamond,
    /// Filled square.
    Square,
    /// Filled upward triangle.
    Triangle,
}

impl fmt::Display for Marker {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Marker::Circle => "circle",
            Marker::Cross => "cross",
            Marker::Diamond => "diamond",
            Marker::Square => "square",
            Marker::Triangle => "triangle",
        })
    }
}

impl FromStr for Marker {
    type Err = ReportError;
    /// Accepts the lower-case names shown by `Display` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "circle" | "o" => Ok(Marker::Circle),
            "cross" | "x" => Ok(Marker::Cross),
            "diamond" | "d" => Ok(Marker::Diamond),
            "square" | "s" => Ok(Marker::Square),
            "triangle" | "^" => Ok(Marker::Triangle),
            _ => Err(ReportError::ParseEnum {
                kind: "marker",
                value: s.to_string(),
                valid: "circle, cross, diamond, square, triangle",
            }),
        }
    }
}

/// How a [`Series`] is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SeriesStyle {
    /// Polyline through the points in order; NaN/Inf (and non-positive values on log axes) break
    /// the line. `width` in pixels (1..=20), `dashed` draws a dashed line.
    Line {
        /// Stroke width (px).
        width: u32,
        /// Dashed instead of solid.
        dashed: bool,
    },
    /// One marker per point. `size` is the marker half-size (radius) in pixels (1..=30).
    Points {
        /// Marker radius (px).
        size: u32,
        /// Marker shape.
        marker: Marker,
    },
    /// A vertical line across the whole panel height at each `x` (e.g. mode frequencies);
    /// `y` is ignored and may be empty.
    VLines {
        /// Dotted instead of solid.
        dotted: bool,
    },
}

impl Default for SeriesStyle {
    /// `Line { width: 2, dashed: false }`.
    fn default() -> Self {
        SeriesStyle::Line {
            width: 2,
            dashed: false,
        }
    }
}

/// An sRGB colour, 8 bits per channel: `Rgb(red, green, blue)`, each 0-255.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Rgb(pub u8, pub u8, pub u8);

impl Rgb {
    /// Build a colour from its channels (same as `Rgb(r, g, b)`).
    pub const fn new(r: u8, g: u8, b: u8) -> Self {
        Rgb(r, g, b)
    }
    /// Black `#000000`.
    pub const BLACK: Rgb = Rgb::new(0, 0, 0);
    /// White `#ffffff`.
    pub const WHITE: Rgb = Rgb::new(255, 255, 255);
    /// Red `#d62728` (palette red; used for physical-model modes).
    pub const RED: Rgb = Rgb::new(0xd6, 0x27, 0x28);
    /// Blue `#1f77b4`.
    pub const BLUE: Rgb = Rgb::new(0x1f, 0x77, 0xb4);
    /// Green `#2ca02c`.
    pub const GREEN: Rgb = Rgb::new(0x2c, 0xa0, 0x2c);
    /// Orange `#ff7f0e`.
    pub const ORANGE: Rgb = Rgb::new(0xff, 0x7f, 0x0e);
    /// Purple `#9467bd`.
    pub const PURPLE: Rgb = Rgb::new(0x94, 0x67, 0xbd);
    /// Grey `#7f7f7f`.
    pub const GREY: Rgb = Rgb::new(0x7f, 0x7f, 0x7f);
}

/// Default colours given to series without an explicit colour, by series index in the panel
/// (the 10 "tab10" colours familiar from matplotlib).
pub const PALETTE: [Rgb; 10] = [
    Rgb::new(0x1f, 0x77, 0xb4),
    Rgb::new(0xff, 0x7f, 0x0e),
    Rgb::new(0x2c, 0xa0, 0x2c),
    Rgb::new(0xd6, 0x27, 0x28),
    Rgb::new(0x94, 0x67, 0xbd),
    Rgb::new(0x8c, 0x56, 0x4b),
    Rgb::new(0xe3, 0x77, 0xc2),
    Rgb::new(0x7f, 0x7f, 0x7f),
    Rgb::new(0xbc, 0xbd, 0x22),
    Rgb::new(0x17, 0xbe, 0xcf),
];

impl fmt::Display for Rgb {
    /// `#rrggbb`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "#{:02x}{:02x}{:02x}", self.0, self.1, self.2)
    }
}

impl FromStr for Rgb {
    type Err = ReportError;
    /// Accepts `#rrggbb` or the names black, white, red, green, blue, orange, purple, grey/gray.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim().to_ascii_lowercase();
        let named = match t.as_str() {
            "black" => Some(Rgb::BLACK),
            "white" => Some(Rgb::WHITE),
            "red" => Some(Rgb::RED),
            "green" => Some(Rgb::GREEN),
            "blue" => Some(Rgb::BLUE),
            "orange" => Some(Rgb::ORANGE),
            "purple" => Some(Rgb::PURPLE),
            "grey" | "gray" => Some(Rgb::GREY),
            _ => None,
        };
        if let Some(c) = named {
            return Ok(c);
        }
        let hex = t
            .strip_prefix('#')
            .ok_or_else(|| ReportError::ParseColor(s.to_string()))?;
        if hex.len() != 6 || !hex.chars().all(|c| c.is_ascii_hexdigit()) {
            return Err(ReportError::ParseColor(s.to_string()));
        }
        let ch = |i: usize| {
            u8::from_str_radix(&hex[i..i + 2], 16)
                .map_err(|_| ReportError::ParseColor(s.to_string()))
        };
        Ok(Rgb::new(ch(0)?, ch(2)?, ch(4)?))
    }
}

/// One data series of a [`Panel`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Series {
    /// Legend text; `None` keeps the series out of the legend.
    pub label: Option<String>,
    /// Abscissae, in the panel's x unit. NaN/Inf are skipped.
    pub x: Vec<f64>,
    /// Ordinates, in the panel's y unit (same length as `x`; ignored for `VLines`).
    pub y: Vec<f64>,
    /// Drawing style.
    pub style: SeriesStyle,
    /// Colour; `None` takes `PALETTE[index of the series in the panel % 10]`.
    pub color: Option<Rgb>,
    /// Opacity in [0, 1] (1 = opaque). Use e.g. 0.3 for a faint PSD behind a stabilisation diagram.
    pub alpha: f64,
}

impl Default for Series {
    /// No label, no data, `SeriesStyle::default()` (2 px solid line), palette colour, alpha 1.0.
    fn default() -> Self {
        Series {
            label: None,
            x: Vec::new(),
            y: Vec::new(),
            style: SeriesStyle::default(),
            color: None,
            alpha: 1.0,
        }
    }
}

impl Series {
    /// A 2 px solid line through `(x[i], y[i])`.
    pub fn line(x: Vec<f64>, y: Vec<f64>) -> Self {
        Series {
            x,
            y,
            ..Default::default()
        }
    }
    /// Markers of radius 3 px at `(x[i], y[i])`.
    pub fn points(x: Vec<f64>, y: Vec<f64>, marker: Marker) -> Self {
        Series {
            x,
            y,
            style: SeriesStyle::Points { size: 3, marker },
            ..Default::default()
        }
    }
    /// Dotted vertical lines across the panel at each `x` (e.g. mode frequencies in Hz).
    pub fn vlines(x: Vec<f64>) -> Self {
        Series {
            x,
            style: SeriesStyle::VLines { dotted: true },
            ..Default::default()
        }
    }
    /// Set the legend label.
    pub fn with_label(mut self, label: impl Into<String>) -> Self {
        self.label = Some(label.into());
        self
    }
    /// Set the colour.
    pub fn with_color(mut self, color: Rgb) -> Self {
        self.color = Some(color);
        self
    }
    /// Set the opacity in [0, 1].
    pub fn with_alpha(mut self, alpha: f64) -> Self {
        self.alpha = alpha;
        self
    }
    /// Set the style.
    pub fn with_style(mut self, style: SeriesStyle) -> Self {
        self.style = style;
        self
    }
}

/// One set of axes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Panel {
    /// Title drawn above the axes (empty: none).
    pub title: String,
    /// x-axis label with units, e.g. `"Frequency [Hz]"`.
    pub x_label: String,
    /// y-axis label with units, e.g. `"PSD [(m/s²)²/Hz]"`.
    pub y_label: String,
    /// x-axis scale.
    pub x_scale: Scale,
    /// y-axis scale.
    pub y_scale: Scale,
    /// Fixed x range `(lo, hi)` in data units (lo < hi, both > 0 on log axes); `None`: automatic
    /// (data range plus 5 % padding; decades on log axes).
    pub x_range: Option<(f64, f64)>,
    /// Fixed y range; `None`: automatic from the data visible within the x range.
    pub y_range: Option<(f64, f64)>,
    /// Series, drawn in order (first is at the back).
    pub series: Vec<Series>,
    /// Draw a legend (upper right) when at least one series has a label.
    pub legend: bool,
}

impl Default for Panel {
    /// Empty title and labels, linear axes, automatic ranges, no series, `legend: true`.
    fn default() -> Self {
        Panel {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            x_range: None,
            y_range: None,
            series: Vec::new(),
            legend: true,
        }
    }
}

impl Panel {
    /// A panel with a title and axis labels (give units, e.g. `"Time [s]"`), otherwise default.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Panel {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            ..Default::default()
        }
    }
    /// Set both axis scales.
    pub fn with_scales(mut self, x_scale: Scale, y_scale: Scale) -> Self {
        self.x_scale = x_scale;
        self.y_scale = y_scale;
        self
    }
    /// Fix the x range (data units).
    pub fn with_x_range(mut self, lo: f64, hi: f64) -> Self {
        self.x_range = Some((lo, hi));
        self
    }
    /// Fix the y range (data units).
    pub fn with_y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = Some((lo, hi));
        self
    }
    /// Append a series.
    pub fn with_series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }
    /// No legend.
    pub fn without_legend(mut self) -> Self {
        self.legend = false;
        self
    }
}

/// A figure: a grid of panels, filled row by row, with an optional overall title.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Figure {
    /// Overall title drawn above the grid.
    pub title: Option<String>,
    /// Panels, filled row by row.
    pub panels: Vec<Panel>,
    /// Number of grid columns (≥ 1; values above the number of panels are reduced to it).
    pub columns: usize,
    /// Width of the image in px (100..=16384).
    pub width_px: u32,
    /// Height of the image in px (100..=16384).
    pub height_px: u32,
}

impl Default for Figure {
    /// No title, no panels, 1 column, 900 x 600 px.
    fn default() -> Self {
        Figure {
            title: None,
            panels: Vec::new(),
            columns: 1,
            width_px: 900,
            height_px: 600,
        }
    }
}

impl Figure {
    /// A 900 x 600 px figure with one panel.
    pub fn single(panel: Panel) -> Self {
        Figure {
            panels: vec![panel],
            ..Default::default()
        }
    }
    /// A grid of `panels` in `columns` columns, sized 450 x 320 px per panel.
    pub fn grid(title: Option<&str>, panels: Vec<Panel>, columns: usize) -> Self {
        let cols = columns.max(1).min(panels.len().max(1));
        let rows = panels.len().div_ceil(cols).max(1);
        let title_px = if title.is_some() { 40 } else { 0 };
        Figure {
            title: title.map(str::to_string),
            panels,
            columns,
            width_px: (450 * cols as u32).min(16384),
            height_px: (320 * rows as u32 + title_px).min(16384),
        }
    }
}
