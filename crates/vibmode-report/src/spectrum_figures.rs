//! Spectrum figures of the single-file commands: `vibmode psd --plot` (one panel of curves) and
//! `vibmode fit --plot` (per channel periodogram, Welch and model PSD with the modes marked, the
//! paper's Fig. 6-7). The commands compute the spectra with the numeric crates and hand the
//! curves here.

use crate::model::{Figure, Panel, Scale, Series, SeriesStyle};

/// One spectrum curve: a label, its one-sided frequencies (Hz) and values.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// Legend text.
    pub label: String,
    /// Frequencies, Hz.
    pub freq_hz: Vec<f64>,
    /// Values (density or power spectrum).
    pub values: Vec<f64>,
}

impl Curve {
    /// A curve.
    pub fn new(label: impl Into<String>, freq_hz: Vec<f64>, values: Vec<f64>) -> Curve {
        Curve {
            label: label.into(),
            freq_hz,
            values,
        }
    }

    /// The curve as a line; on a log y axis the 0 Hz bin (near zero after detrending, it would
    /// stretch the axis over 20 decades) is left out.
    fn series(&self, y_scale: Scale, width: u32, alpha: f64) -> Series {
        let (x, y): (Vec<f64>, Vec<f64>) = self
            .freq_hz
            .iter()
            .zip(&self.values)
            .filter(|(f, _)| y_scale != Scale::Log || **f > 0.0)
            .map(|(f, v)| (*f, *v))
            .unzip();
        Series::line(x, y)
            .with_label(self.label.clone())
            .with_style(SeriesStyle::Line {
                width,
                dashed: false,
            })
            .with_alpha(alpha)
    }
}

/// `vibmode psd --plot`: faint curves (`background`, e.g. periodograms under Welch) and bold
/// ones in one panel, x from `x_range.0` to `x_range.1` Hz, y labelled `PSD [y_unit]`.
pub fn psd_figure(
    title: &str,
    background: &[Curve],
    curves: &[Curve],
    y_unit: &str,
    scales: (Scale, Scale),
    x_range: (f64, f64),
) -> Figure {
    let (xs, ys) = scales;
    let mut panel = Panel::new(title, "Frequency [Hz]", format!("PSD [{y_unit}]"))
        .with_scales(xs, ys)
        .with_x_range(x_range.0, x_range.1);
    for c in background {
        panel = panel.with_series(c.series(ys, 1, 0.45));
    }
    for c in curves {
        panel = panel.with_series(c.series(ys, 2, 1.0));
    }
    Figure {
        title: None,
        panels: vec![panel],
        columns: 1,
        width_px: 1000,
        height_px: 600,
    }
}

/// One channel of `vibmode fit --plot`.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelSpectrumPanel {
    /// Panel title, e.g. `z: ARMA(12,12)`.
    pub title: String,
    /// Axis label of the density, e.g. `(m/s^2)^2/Hz`.
    pub psd_unit: String,
    /// Periodogram, Welch estimate and model PSD.
    pub periodogram: Curve,
    /// Welch estimate.
    pub welch: Curve,
    /// Model PSD.
    pub model: Curve,
    /// Frequencies of the modes to mark, Hz.
    pub marks_hz: Vec<f64>,
    /// Legend text of the marks.
    pub marks_label: String,
}

/// `vibmode fit --plot`: one panel per channel, 0 to `nyquist_hz`.
pub fn model_spectra_figure(panels: &[ModelSpectrumPanel], nyquist_hz: f64) -> Figure {
    let panels: Vec<Panel> = panels
        .iter()
        .map(|p| {
            Panel::new(
                p.title.clone(),
                "Frequency [Hz]",
                format!("PSD [{}]", p.psd_unit),
            )
            .with_scales(Scale::Linear, Scale::Log)
            .with_x_range(0.0, nyquist_hz)
            .with_series(p.periodogram.series(Scale::Log, 1, 0.4))
            .with_series(p.welch.series(Scale::Log, 2, 1.0))
            .with_series(p.model.series(Scale::Log, 2, 1.0))
            .with_series(
                Series::vlines(p.marks_hz.clone())
                    .with_label(p.marks_label.clone())
                    .with_alpha(0.8),
            )
        })
        .collect();
    let n = panels.len();
    Figure {
        title: None,
        panels,
        columns: 1,
        width_px: 1000,
        height_px: (500 * n.max(1)) as u32,
    }
}
