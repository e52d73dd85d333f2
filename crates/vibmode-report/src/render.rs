//! Drawing a [`Figure`] with plotters (SVG string/file, PNG file, in-memory RGB buffer).

use crate::axes::{
    clip_polyline, decimate_minmax, format_tick, from_axis, is_valid, log_ticks, nice_ticks,
    padded_axis_range, to_axis,
};
use crate::error::ReportError;
use crate::font::{ensure_font, FONT_FAMILY};
use crate::model::{Figure, Marker, Panel, Scale, SeriesStyle, PALETTE};
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Smallest figure side (px).
pub const MIN_SIDE_PX: u32 = 100;
/// Largest figure side (px).
pub const MAX_SIDE_PX: u32 = 16384;
/// Smallest panel cell width (px).
pub const MIN_CELL_WIDTH_PX: u32 = 160;
/// Smallest panel cell height (px).
pub const MIN_CELL_HEIGHT_PX: u32 = 120;
/// Line series longer than this are decimated (min/max per pixel column) before drawing.
pub const MAX_POINTS_PER_SERIES: usize = 4000;
/// Most pixel columns used by the decimation (so at most ~4 · 1000 points are kept).
const MAX_COLUMNS: usize = 1000;

/// Geometry of one series, in axis coordinates (log10 on log axes), already clipped.
enum Geometry {
    Lines(Vec<Vec<(f64, f64)>>),
    Points(Vec<(f64, f64)>),
    VLines(Vec<f64>),
}

struct PreparedSeries {
    label: Option<String>,
    color: RGBAColor,
    style: SeriesStyle,
    geometry: Geometry,
}

struct PreparedPanel {
    x_axis: (f64, f64),
    y_axis: (f64, f64),
    has_data: bool,
    series: Vec<PreparedSeries>,
}

fn series_name(label: &Option<String>, index: usize) -> String {
    label.clone().unwrap_or_else(|| format!("#{index}"))
}

fn check_range(
    panel: &Panel,
    axis: &'static str,
    range: (f64, f64),
    scale: Scale,
) -> Result<(f64, f64), ReportError> {
    let (lo, hi) = range;
    let err = |reason: &'static str, fix: String| ReportError::InvalidRange {
        panel: panel.title.clone(),
        axis,
        lo,
        hi,
        reason,
        fix,
    };
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(err(
            "bounds must be finite",
            format!("use e.g. {axis}_range: Some((0.0, 10.0)) or None for automatic"),
        ));
    }
    if lo >= hi {
        return Err(err(
            "lo must be smaller than hi",
            format!(
                "use {axis}_range: Some(({}, {}))",
                hi.min(lo),
                hi.max(lo) + f64::from(u8::from(lo == hi))
            ),
        ));
    }
    if scale == Scale::Linear
        && (lo.abs() > crate::axes::MAX_LINEAR_ABS || hi.abs() > crate::axes::MAX_LINEAR_ABS)
    {
        return Err(err(
            "linear bounds must be within ±1e300",
            format!("use a smaller {axis}_range or a log scale"),
        ));
    }
    if scale == Scale::Log && lo <= 0.0 {
        return Err(err(
            "a log axis needs lo > 0",
            format!(
                "use e.g. {axis}_range: Some(({}, {hi})) or a linear scale",
                hi / 1000.0
            ),
        ));
    }
    Ok((to_axis(lo, scale), to_axis(hi, scale)))
}

fn validate_series(panel: &Panel) -> Result<(), ReportError> {
    for (i, s) in panel.series.iter().enumerate() {
        let name = || series_name(&s.label, i);
        if !(s.alpha.is_finite() && (0.0..=1.0).contains(&s.alpha)) {
            return Err(ReportError::InvalidAlpha {
                panel: panel.title.clone(),
                series: name(),
                alpha: s.alpha,
            });
        }
        let size_err = |what: &'static str, value: u32, max: u32| ReportError::InvalidStyleSize {
            panel: panel.title.clone(),
            series: name(),
            what,
            value,
            max,
        };
        match s.style {
            SeriesStyle::Line { width, .. } if !(1..=20).contains(&width) => {
                return Err(size_err("width", width, 20))
            }
            SeriesStyle::Points { size, .. } if !(1..=30).contains(&size) => {
                return Err(size_err("size", size, 30))
            }
            _ => {}
        }
        if !matches!(s.style, SeriesStyle::VLines { .. }) && s.x.len() != s.y.len() {
            return Err(ReportError::LengthMismatch {
                panel: panel.title.clone(),
                series: name(),
                x_len: s.x.len(),
                y_len: s.y.len(),
            });
        }
    }
    Ok(())
}

/// Axis coordinates of point i, if drawable on these scales.
fn axis_point(x: f64, y: f64, xs: Scale, ys: Scale) -> Option<(f64, f64)> {
    if is_valid(x, xs) && is_valid(y, ys) {
        Some((to_axis(x, xs), to_axis(y, ys)))
    } else {
        None
    }
}

fn prepare_panel(panel: &Panel, plot_width_px: u32) -> Result<PreparedPanel, ReportError> {
    validate_series(panel)?;
    let (xs, ys) = (panel.x_scale, panel.y_scale);
    let explicit_x = match panel.x_range {
        Some(r) => Some(check_range(panel, "x", r, xs)?),
        None => None,
    };
    let explicit_y = match panel.y_range {
        Some(r) => Some(check_range(panel, "y", r, ys)?),
        None => None,
    };

    // Automatic x range from every drawable point (and every vline).
    let mut has_data = false;
    let (mut xlo, mut xhi) = (f64::INFINITY, f64::NEG_INFINITY);
    for s in &panel.series {
        match s.style {
            SeriesStyle::VLines { .. } => {
                for &x in s.x.iter().filter(|&&x| is_valid(x, xs)) {
                    let t = to_axis(x, xs);
                    xlo = xlo.min(t);
                    xhi = xhi.max(t);
                    has_data = true;
                }
            }
            _ => {
                for (&x, &y) in s.x.iter().zip(&s.y) {
                    if let Some((tx, _)) = axis_point(x, y, xs, ys) {
                        xlo = xlo.min(tx);
                        xhi = xhi.max(tx);
                        has_data = true;
                    }
                }
            }
        }
    }
    let x_axis = explicit_x.unwrap_or_else(|| padded_axis_range(xlo, xhi, xs));

    // Automatic y range from the points visible in the x range.
    let (mut ylo, mut yhi) = (f64::INFINITY, f64::NEG_INFINITY);
    let xtol = 1e-9 * (x_axis.1 - x_axis.0);
    for s in &panel.series {
        if matches!(s.style, SeriesStyle::VLines { .. }) {
            continue;
        }
        for (&x, &y) in s.x.iter().zip(&s.y) {
            if let Some((tx, ty)) = axis_point(x, y, xs, ys) {
                if tx >= x_axis.0 - xtol && tx <= x_axis.1 + xtol {
                    ylo = ylo.min(ty);
                    yhi = yhi.max(ty);
                }
            }
        }
    }
    let y_axis = explicit_y.unwrap_or_else(|| padded_axis_range(ylo, yhi, ys));
    let ytol = 1e-9 * (y_axis.1 - y_axis.0);
    let bounds = (
        x_axis.0 - xtol,
        x_axis.1 + xtol,
        y_axis.0 - ytol,
        y_axis.1 + ytol,
    );
    let n_columns = (plot_width_px as usize).clamp(1, MAX_COLUMNS);

    let mut series = Vec::with_capacity(panel.series.len());
    for (i, s) in panel.series.iter().enumerate() {
        let base = s.color.unwrap_or(PALETTE[i % PALETTE.len()]);
        let color = RGBColor(base.0, base.1, base.2).mix(s.alpha);
        let geometry = match s.style {
            SeriesStyle::VLines { .. } => Geometry::VLines(
                s.x.iter()
                    .filter(|&&x| is_valid(x, xs))
                    .map(|&x| to_axis(x, xs))
                    .filter(|&t| t >= bounds.0 && t <= bounds.1)
                    .collect(),
            ),
            SeriesStyle::Line { .. } => {
                let pts: Vec<Option<(f64, f64)>> =
                    s.x.iter()
                        .zip(&s.y)
                        .map(|(&x, &y)| axis_point(x, y, xs, ys))
                        .collect();
                let pts = if pts.len() > MAX_POINTS_PER_SERIES {
                    let tx: Vec<f64> = pts.iter().map(|p| p.map_or(f64::NAN, |p| p.0)).collect();
                    let ty: Vec<f64> = pts.iter().map(|p| p.map_or(f64::NAN, |p| p.1)).collect();
                    decimate_minmax(&tx, &ty, x_axis.0, x_axis.1, n_columns)
                        .into_iter()
                        .map(|k| pts[k])
                        .collect()
                } else {
                    pts
                };
                Geometry::Lines(clip_polyline(&pts, bounds))
            }
            SeriesStyle::Points { .. } => {
                let mut pts: Vec<(f64, f64)> =
                    s.x.iter()
                        .zip(&s.y)
                        .filter_map(|(&x, &y)| axis_point(x, y, xs, ys))
                        .filter(|p| {
                            p.0 >= bounds.0 && p.0 <= bounds.1 && p.1 >= bounds.2 && p.1 <= bounds.3
                        })
                        .collect();
                if pts.len() > MAX_POINTS_PER_SERIES {
                    // Keep one point per pixel cell (markers on the same pixel are identical).
                    let n = n_columns as f64;
                    let cell = |p: &(f64, f64)| {
                        (
                            ((p.0 - x_axis.0) / (x_axis.1 - x_axis.0) * n).floor() as i64,
                            ((p.1 - y_axis.0) / (y_axis.1 - y_axis.0) * n).floor() as i64,
                        )
                    };
                    let mut seen = std::collections::HashSet::new();
                    pts.retain(|p| seen.insert(cell(p)));
                }
                Geometry::Points(pts)
            }
        };
        series.push(PreparedSeries {
            label: s.label.clone(),
            color,
            style: s.style,
            geometry,
        });
    }
    Ok(PreparedPanel {
        x_axis,
        y_axis,
        has_data,
        series,
    })
}

/// Tick positions (axis coordinates) `(major, minor)` for an axis range in axis coordinates.
fn ticks(axis: (f64, f64), scale: Scale, max_ticks: usize) -> (Vec<f64>, Vec<f64>) {
    match scale {
        Scale::Linear => {
            // Prefer at least two labelled ticks, allowing a few more than max_ticks for that.
            let mut t = nice_ticks(axis.0, axis.1, max_ticks);
            let mut m = max_ticks;
            while t.len() < 2 && m < max_ticks + 4 {
                m += 1;
                t = nice_ticks(axis.0, axis.1, m);
            }
            (t, Vec::new())
        }
        Scale::Log => {
            let (ma, mi) = log_ticks(
                from_axis(axis.0, scale),
                from_axis(axis.1, scale),
                max_ticks,
            );
            (
                ma.into_iter().map(|v| v.log10()).collect(),
                mi.into_iter().map(|v| v.log10()).collect(),
            )
        }
    }
}

/// A linear coordinate in axis space (log10 already applied) with explicit tick positions.
#[derive(Clone)]
struct AxisCoord {
    lo: f64,
    hi: f64,
    major: Vec<f64>,
    minor: Vec<f64>,
}

impl Ranged for AxisCoord {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let span = self.hi - self.lo;
        if span.is_nan() || span <= 0.0 || !v.is_finite() {
            return limit.0;
        }
        let frac = ((*v - self.lo) / span).clamp(-4.0, 5.0);
        let px = f64::from(limit.0) + f64::from(limit.1 - limit.0) * frac;
        (px + 1e-3).floor() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.minor.clone()
        } else {
            self.major.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

fn font(px: f64) -> FontDesc<'static> {
    (FONT_FAMILY, px).into_font()
}

/// Draw markers at `$pts` (axis coordinates) and register the legend entry; `$shape` is an
/// element in pixel offsets relative to the marker centre.
macro_rules! draw_markers {
    ($chart:expr, $pts:expr, $label:expr, $shape:expr) => {{
        let a = $chart
            .draw_series($pts.iter().map(|&p| EmptyElement::at(p) + $shape))
            .map_err(ReportError::draw)?;
        $label.map(|l| {
            a.label(l.as_str())
                .legend(move |(x, y)| EmptyElement::at((x + 10, y)) + $shape);
        })
    }};
}

/// Draws one prepared series on `chart` and registers its legend entry; true when it has one.
fn draw_one_series<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<AxisCoord, AxisCoord>>,
    s: &PreparedSeries,
    (ylo, yhi): (f64, f64),
) -> Result<bool, ReportError> {
    let color = s.color;
    let anno = match (&s.geometry, s.style) {
        (Geometry::Lines(pieces), SeriesStyle::Line { width, dashed }) => {
            let st = color.stroke_width(width);
            let a = if dashed {
                let dash = (4 * width).max(6) as i32;
                chart.draw_series(
                    pieces
                        .iter()
                        .map(move |p| DashedPathElement::new(p.clone(), dash, dash * 2 / 3, st)),
                )
            } else {
                chart.draw_series(pieces.iter().map(move |p| PathElement::new(p.clone(), st)))
            }
            .map_err(ReportError::draw)?;
            s.label.as_ref().map(|l| {
                let gap = if dashed { 4 } else { 0 };
                a.label(l.as_str()).legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (8, 0)], st)
                        + PathElement::new(vec![(8 + gap, 0), (20, 0)], st)
                });
            })
        }
        (Geometry::Points(pts), SeriesStyle::Points { size, marker }) => {
            let r = size as i32;
            let d = r + r / 3;
            let fill = color.filled();
            let st = color.stroke_width(size.div_ceil(2).max(1));
            let label = s.label.as_ref();
            match marker {
                Marker::Circle => {
                    draw_markers!(chart, pts, label, Circle::new((0, 0), r, fill))
                }
                Marker::Cross => {
                    draw_markers!(chart, pts, label, Cross::new((0, 0), r, st))
                }
                Marker::Diamond => draw_markers!(
                    chart,
                    pts,
                    label,
                    Polygon::new(vec![(0, -d), (d, 0), (0, d), (-d, 0)], fill)
                ),
                Marker::Square => {
                    draw_markers!(chart, pts, label, Rectangle::new([(-r, -r), (r, r)], fill))
                }
                Marker::Triangle => draw_markers!(
                    chart,
                    pts,
                    label,
                    Polygon::new(vec![(0, -d), (d, d * 3 / 4), (-d, d * 3 / 4)], fill)
                ),
            }
        }
        (Geometry::VLines(xv), SeriesStyle::VLines { dotted }) => {
            let st = color.stroke_width(1);
            let a = if dotted {
                chart.draw_series(
                    xv.iter()
                        .map(move |&x| DashedPathElement::new(vec![(x, ylo), (x, yhi)], 3, 3, st)),
                )
            } else {
                chart.draw_series(
                    xv.iter()
                        .map(move |&x| PathElement::new(vec![(x, ylo), (x, yhi)], st)),
                )
            }
            .map_err(ReportError::draw)?;
            s.label.as_ref().map(|l| {
                a.label(l.as_str()).legend(move |(x, y)| {
                    let gap = if dotted { 3 } else { 0 };
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (8, 0)], st)
                        + PathElement::new(vec![(8 + gap, 0), (12, 0)], st)
                        + PathElement::new(vec![(12 + gap, 0), (20, 0)], st)
                });
            })
        }
        _ => None,
    };
    Ok(anno.is_some())
}

/// Pixel sizes of the y label area (tick labels and axis label) and of the x label area.
fn label_areas(
    panel: &Panel,
    y_major: &[f64],
    ys: Scale,
    tick_px: f64,
    label_px: f64,
) -> (u32, u32) {
    let y_label_chars = y_major
        .iter()
        .map(|&t| format_tick(from_axis(t, ys)).chars().count())
        .max()
        .unwrap_or(1);
    let y_area: u32 = (y_label_chars as f64 * 0.62 * tick_px
        + if panel.y_label.is_empty() {
            0.0
        } else {
            label_px * 1.8
        }
        + 10.0) as u32;
    let x_area: u32 = (tick_px * 1.6
        + if panel.x_label.is_empty() {
            0.0
        } else {
            label_px * 1.8
        }
        + 6.0) as u32;

    (y_area, x_area)
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
) -> Result<(), ReportError> {
    let (w, h) = area.dim_in_pixel();
    let sc = (f64::from(w.min(h)) / 360.0).clamp(0.85, 1.8);
    let (tick_px, label_px, title_px) = (13.0 * sc, 14.5 * sc, 16.0 * sc);

    let prepared = prepare_panel(panel, w)?;
    let (xs, ys) = (panel.x_scale, panel.y_scale);
    let max_x_ticks = ((f64::from(w) * 0.8) / (7.0 * tick_px)).clamp(2.0, 10.0) as usize;
    let max_y_ticks = ((f64::from(h) * 0.7) / (3.5 * tick_px)).clamp(2.0, 10.0) as usize;
    let (x_major, x_minor) = ticks(prepared.x_axis, xs, max_x_ticks);
    let (y_major, y_minor) = ticks(prepared.y_axis, ys, max_y_ticks);

    let (y_area, x_area) = label_areas(panel, &y_major, ys, tick_px, label_px);
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(6)
        .margin_right(14)
        .x_label_area_size(x_area)
        .y_label_area_size(y_area);
    if !panel.title.is_empty() {
        builder.caption(&panel.title, font(title_px));
    }
    let mut chart = builder
        .build_cartesian_2d(
            AxisCoord {
                lo: prepared.x_axis.0,
                hi: prepared.x_axis.1,
                major: x_major,
                minor: x_minor,
            },
            AxisCoord {
                lo: prepared.y_axis.0,
                hi: prepared.y_axis.1,
                major: y_major,
                minor: y_minor,
            },
        )
        .map_err(ReportError::draw)?;

    let fx = move |v: &f64| format_tick(from_axis(*v, xs));
    let fy = move |v: &f64| format_tick(from_axis(*v, ys));
    let mut mesh = chart.configure_mesh();
    mesh.label_style(font(tick_px))
        .axis_desc_style(font(label_px))
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .bold_line_style(RGBColor(205, 205, 205))
        .light_line_style(RGBColor(238, 238, 238));
    if !panel.x_label.is_empty() {
        mesh.x_desc(panel.x_label.as_str());
    }
    if !panel.y_label.is_empty() {
        mesh.y_desc(panel.y_label.as_str());
    }
    mesh.draw().map_err(ReportError::draw)?;

    let (ylo, yhi) = prepared.y_axis;
    let mut any_label = false;
    for s in &prepared.series {
        any_label |= draw_one_series(&mut chart, s, (ylo, yhi))?;
    }

    if !prepared.has_data {
        let mid = (
            0.5 * (prepared.x_axis.0 + prepared.x_axis.1),
            0.5 * (ylo + yhi),
        );
        let style = TextStyle::from(font(label_px))
            .color(&RGBColor(120, 120, 120))
            .pos(Pos::new(HPos::Center, VPos::Center));
        chart
            .plotting_area()
            .draw(&Text::new("no data", mid, style))
            .map_err(ReportError::draw)?;
    }

    if panel.legend && any_label {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .margin(8)
            .label_font(font(tick_px))
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(160, 160, 160))
            .draw()
            .map_err(ReportError::draw)?;
    }
    Ok(())
}

fn png_extension_ok(path: &Path) -> Result<(), ReportError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext == "png" {
        Ok(())
    } else {
        Err(ReportError::UnsupportedExtension {
            ext,
            path: path.to_path_buf(),
        })
    }
}

impl Figure {
    /// Grid shape `(rows, columns)`: columns = min(self.columns, number of panels).
    pub fn grid_shape(&self) -> (usize, usize) {
        let cols = self.columns.max(1).min(self.panels.len().max(1));
        (self.panels.len().div_ceil(cols).max(1), cols)
    }

    /// Height of the overall title band (px) for an image `height_px` tall (0 without title).
    fn title_band_px(&self, width_px: u32, height_px: u32) -> u32 {
        match &self.title {
            Some(t) if !t.is_empty() => {
                ((f64::from(width_px.min(height_px)) / 400.0).clamp(0.8, 2.0) * 34.0) as u32
            }
            _ => 0,
        }
    }

    /// Check sizes, grid and every panel/series without drawing (the draw functions call this).
    pub fn validate(&self) -> Result<(), ReportError> {
        self.validate_for(self.width_px, self.height_px)
    }

    fn validate_for(&self, w: u32, h: u32) -> Result<(), ReportError> {
        if !(MIN_SIDE_PX..=MAX_SIDE_PX).contains(&w) || !(MIN_SIDE_PX..=MAX_SIDE_PX).contains(&h) {
            return Err(ReportError::InvalidSize {
                width_px: w,
                height_px: h,
                min_px: MIN_SIDE_PX,
                max_px: MAX_SIDE_PX,
            });
        }
        if self.columns == 0 {
            return Err(ReportError::InvalidColumns(0));
        }
        if self.panels.is_empty() {
            return Err(ReportError::NoPanels);
        }
        let (rows, cols) = self.grid_shape();
        let as_u32 = |n: usize| u32::try_from(n).unwrap_or(u32::MAX).max(1);
        let cell_w = w / as_u32(cols);
        let cell_h = (h - self.title_band_px(w, h).min(h)) / as_u32(rows);
        if cell_w < MIN_CELL_WIDTH_PX || cell_h < MIN_CELL_HEIGHT_PX {
            return Err(ReportError::CellTooSmall {
                cell_width_px: cell_w,
                cell_height_px: cell_h,
                rows,
                columns: cols,
                width_px: w,
                height_px: h,
                min_cell_w_px: MIN_CELL_WIDTH_PX,
                min_cell_h_px: MIN_CELL_HEIGHT_PX,
            });
        }
        for p in &self.panels {
            validate_series(p)?;
            if let Some(r) = p.x_range {
                check_range(p, "x", r, p.x_scale)?;
            }
            if let Some(r) = p.y_range {
                check_range(p, "y", r, p.y_scale)?;
            }
        }
        Ok(())
    }

    /// Draw the figure onto any plotters drawing area (its pixel size is used, not
    /// `width_px`/`height_px`). Fills the background white.
    pub fn draw_on<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), ReportError> {
        ensure_font()?;
        let (w, h) = root.dim_in_pixel();
        self.validate_for(w, h)?;
        root.fill(&WHITE).map_err(ReportError::draw)?;
        let band = self.title_band_px(w, h);
        let grid_area = if band > 0 {
            let (top, rest) = root.split_vertically(band);
            let px = f64::from(band) * 0.55;
            let style = TextStyle::from(font(px))
                .color(&BLACK)
                .pos(Pos::new(HPos::Center, VPos::Center));
            let title = self.title.as_deref().unwrap_or("");
            top.draw(&Text::new(
                title,
                ((w / 2) as i32, (band / 2) as i32),
                style,
            ))
            .map_err(ReportError::draw)?;
            rest
        } else {
            root.clone()
        };
        let (rows, cols) = self.grid_shape();
        let cells = grid_area.split_evenly((rows, cols));
        for (panel, cell) in self.panels.iter().zip(cells.iter()) {
            draw_panel(cell, panel)?;
        }
        Ok(())
    }

    /// Render to an SVG document (text uses [`FONT_FAMILY`]).
    pub fn to_svg_string(&self) -> Result<String, ReportError> {
        self.validate()?;
        let mut out = String::new();
        {
            let root = SVGBackend::with_string(&mut out, (self.width_px, self.height_px))
                .into_drawing_area();
            self.draw_on(&root)?;
            root.present().map_err(ReportError::draw)?;
        }
        Ok(out)
    }

    /// Write the SVG document to `path` (any extension).
    pub fn save_svg(&self, path: impl AsRef<Path>) -> Result<(), ReportError> {
        let path = path.as_ref();
        let svg = self.to_svg_string()?;
        std::fs::write(path, svg).map_err(|e| ReportError::Write {
            path: path.to_path_buf(),
            message: e.to_string(),
        })
    }

    /// Render into an in-memory RGB buffer (`width_px · height_px · 3` bytes, row-major).
    pub fn render_rgb(&self) -> Result<Vec<u8>, ReportError> {
        self.validate()?;
        let (w, h) = (self.width_px, self.height_px);
        let mut buf = vec![255u8; w as usize * h as usize * 3];
        {
            let backend = BitMapBackend::<plotters::backend::RGBPixel>::with_buffer_and_format(
                &mut buf,
                (w, h),
            )
            .map_err(ReportError::draw)?;
            let root = backend.into_drawing_area();
            self.draw_on(&root)?;
            root.present().map_err(ReportError::draw)?;
        }
        Ok(buf)
    }

    /// Write a PNG image to `path`, which must end in `.png` (text uses the embedded font).
    pub fn save_png(&self, path: impl AsRef<Path>) -> Result<(), ReportError> {
        let path = path.as_ref();
        png_extension_ok(path)?;
        self.validate()?;
        let root = BitMapBackend::new(path, (self.width_px, self.height_px)).into_drawing_area();
        self.draw_on(&root)?;
        root.present().map_err(|e| ReportError::Write {
            path: path.to_path_buf(),
            message: e.to_string().replace('\n', " "),
        })
    }

    /// Write SVG or PNG chosen by the extension of `path` (`.svg` / `.png`, case-insensitive);
    /// any other extension is an error naming it.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), ReportError> {
        let path = path.as_ref();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        if !matches!(ext.as_str(), "svg" | "png") {
            return Err(ReportError::UnsupportedExtension {
                ext,
                path: path.to_path_buf(),
            });
        }
        self.validate()?;
        // Drawn under a temporary name and renamed when complete (never half a figure).
        let on_io = |e: std::io::Error| ReportError::Write {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        vibmode_core::files::write_atomic(path, on_io, |tmp| match ext.as_str() {
            "svg" => self.save_svg(tmp),
            _ => self.save_png(tmp),
        })
    }
}
