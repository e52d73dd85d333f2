//! Panels of the paper's figures built from results (the numerics know nothing of plotting):
//! stabilisation diagrams, frequency-damping plots, grids.

use crate::model::{Figure, Marker, Panel, Rgb, Scale, Series, SeriesStyle};
use std::path::{Path, PathBuf};

/// Red used for physical-model modes.
pub const RED: Rgb = Rgb(200, 30, 30);

/// Green used to mark the invariant structural modes.
pub const GREEN: Rgb = Rgb(20, 140, 60);

/// Orange used to mark periodic disturbances (engine/gear lines).
pub const ORANGE: Rgb = Rgb(230, 120, 0);

/// Share of the order range added above the highest order of a stabilisation diagram, so that
/// the legend (upper right) covers no pole.
pub const LEGEND_HEADROOM: f64 = 0.3;

/// Vertical dashed lines at the invariant structural modes and periodic disturbances, for a
/// stabilisation diagram or a frequency-damping plot.
pub fn mode_marks(structural_hz: &[f64], disturbances_hz: &[f64]) -> Vec<Series> {
    let mut out = Vec::new();
    if !structural_hz.is_empty() {
        out.push(
            Series::vlines(structural_hz.to_vec())
                .with_label("invariant structural modes")
                .with_color(GREEN)
                .with_style(SeriesStyle::VLines { dotted: false })
                .with_alpha(0.9),
        );
    }
    if !disturbances_hz.is_empty() {
        out.push(
            Series::vlines(disturbances_hz.to_vec())
                .with_label("periodic disturbances")
                .with_color(ORANGE)
                .with_style(SeriesStyle::VLines { dotted: true })
                .with_alpha(0.9),
        );
    }
    out
}

/// `dir/name.svg` -> `dir/name{suffix}.svg`.
pub fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "plot".into());
    let ext = path
        .extension()
        .map(|s| format!(".{}", s.to_string_lossy()))
        .unwrap_or_default();
    path.with_file_name(format!("{stem}{suffix}{ext}"))
}

/// A figure of `panels` in `columns` columns, each panel about `w` x `h` pixels. Many panels
/// (one per channel of a 90-channel file) get more columns, so that the figure stays within
/// [`crate::MAX_SIDE_PX`] (it used to fail after the whole analysis), and panels shrink if even
/// that is not enough.
pub fn grid(panels: Vec<Panel>, columns: usize, w: u32, h: u32) -> Figure {
    let max = crate::MAX_SIDE_PX as usize;
    let (w, h) = (w as usize, h as usize);
    let mut cols = columns.max(1);
    while panels.len().div_ceil(cols) * h > max && (cols + 1) * w <= max {
        cols += 1;
    }
    let rows = panels.len().div_ceil(cols).max(1);
    Figure {
        title: None,
        panels,
        columns: cols,
        width_px: (w * cols).min(max) as u32,
        height_px: (h * rows).min(max) as u32,
    }
}

/// Stabilisation diagram: every pole pair as (frequency, order), with the Welch PSD drawn
/// faintly behind, mapped onto the order axis (log PSD scaled to the order range).
pub fn stabilisation_panel(
    title: &str,
    poles: &[(usize, f64, f64)],
    psd_freq_hz: &[f64],
    psd: &[f64],
    fmax_hz: f64,
) -> Panel {
    let omin = poles.iter().map(|p| p.0).min().unwrap_or(1) as f64;
    let omax = poles.iter().map(|p| p.0).max().unwrap_or(2) as f64;
    let logs: Vec<(f64, f64)> = psd_freq_hz
        .iter()
        .zip(psd)
        .filter(|(f, p)| **f > 0.0 && **f <= fmax_hz && **p > 0.0 && p.is_finite())
        .map(|(f, p)| (*f, p.log10()))
        .collect();
    let lmin = logs.iter().map(|v| v.1).fold(f64::INFINITY, f64::min);
    let lmax = logs.iter().map(|v| v.1).fold(f64::NEG_INFINITY, f64::max);
    let span = (lmax - lmin).max(1e-12);
    let (bx, by): (Vec<f64>, Vec<f64>) = logs
        .iter()
        .map(|(f, l)| (*f, omin + (l - lmin) / span * (omax - omin)))
        .unzip();
    let (px, py): (Vec<f64>, Vec<f64>) = poles
        .iter()
        .filter(|p| p.1 <= fmax_hz)
        .map(|p| (p.1, p.0 as f64))
        .unzip();
    Panel {
        title: title.to_string(),
        x_label: "Frequency [Hz]".into(),
        y_label: "Model order p".into(),
        x_scale: Scale::Linear,
        y_scale: Scale::Linear,
        x_range: Some((0.0, fmax_hz)),
        // Headroom above the highest order: the legend sits there, not on the poles.
        y_range: Some((
            omin - 1.0,
            omax + 1.0 + LEGEND_HEADROOM * (omax - omin + 2.0),
        )),
        series: vec![
            Series {
                label: Some("Welch PSD (log, scaled)".into()),
                x: bx,
                y: by,
                style: SeriesStyle::Line {
                    width: 1,
                    dashed: false,
                },
                color: Some(Rgb(150, 150, 150)),
                alpha: 0.6,
            },
            Series {
                label: Some("pole pairs".into()),
                x: px,
                y: py,
                style: SeriesStyle::Points {
                    size: 2,
                    marker: Marker::Circle,
                },
                color: Some(Rgb(30, 80, 200)),
                alpha: 0.8,
            },
        ],
        legend: true,
    }
}

/// Frequency against damping ratio (log axis), the paper's Fig. 9-10, with reference modes as
/// red diamonds.
pub fn damping_panel(
    title: &str,
    poles: &[(usize, f64, f64)],
    reference: &[(f64, f64, String)],
    fmax_hz: f64,
) -> Panel {
    let (px, py): (Vec<f64>, Vec<f64>) = poles
        .iter()
        .filter(|p| p.1 <= fmax_hz && p.2 > 0.0)
        .map(|p| (p.1, p.2))
        .unzip();
    let mut series = vec![Series {
        label: Some("pole pairs".into()),
        x: px,
        y: py,
        style: SeriesStyle::Points {
            size: 2,
            marker: Marker::Circle,
        },
        color: Some(Rgb(30, 80, 200)),
        alpha: 0.6,
    }];
    if !reference.is_empty() {
        series.push(Series {
            label: Some("physical model".into()),
            x: reference.iter().map(|r| r.0).collect(),
            y: reference.iter().map(|r| r.1).collect(),
            style: SeriesStyle::Points {
                size: 7,
                marker: Marker::Diamond,
            },
            color: Some(RED),
            alpha: 1.0,
        });
    }
    Panel {
        title: title.to_string(),
        x_label: "Frequency [Hz]".into(),
        y_label: "Damping ratio [-]".into(),
        x_scale: Scale::Linear,
        y_scale: Scale::Log,
        x_range: Some((0.0, fmax_hz)),
        // Damping ratios lie below 1; the decade above holds the legend.
        y_range: Some((1e-4, 30.0)),
        series,
        legend: true,
    }
}

/// Drops the DC bin (and any non-positive frequency) so a log PSD axis is not stretched by a
/// detrended, near-zero DC value.
pub fn positive_freq(f: &[f64], p: &[f64]) -> (Vec<f64>, Vec<f64>) {
    f.iter()
        .zip(p)
        .filter(|(f, _)| **f > 0.0)
        .map(|(f, p)| (*f, *p))
        .unzip()
}

#[cfg(test)]
mod grid_tests {
    use super::*;

    /// Up to the 1024 channels a file may have, the figure is within the size limits.
    #[test]
    fn grids_of_many_panels_stay_drawable() {
        for n in [1usize, 2, 7, 63, 64, 90, 200, 1024] {
            let panels: Vec<Panel> = (0..n)
                .map(|i| Panel::new(format!("p{i}"), "x", "y"))
                .collect();
            let f = grid(panels, 2, 600, 260);
            assert!(f.validate().is_ok(), "{n} panels: {:?}", f.validate());
            assert_eq!(f.panels.len(), n);
        }
    }
}
