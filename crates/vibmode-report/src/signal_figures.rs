//! Figures of signals: the paper's Fig. 3-4 (anti-aliasing and resampling).

use vibmode_signal::{ChannelSelector, Recording, ResampleParams, ResampleRecording};
use vibmode_spectra::{Detrend, PeriodogramParams, Scaling, Window};

use crate::error::ReportError;
use crate::model::{Figure, Panel, Scale, Series, SeriesStyle};

fn input_err(e: impl std::fmt::Display) -> ReportError {
    ReportError::Analysis(e.to_string())
}

/// The paper's Fig. 3-4 for the first channel of `raw`: time (top, the first `seconds`) and
/// periodograms (bottom) of the raw record, the record resampled to `fs_out_hz` without filter, and
/// resampled with the ideal filter at `cutoff_hz` (default: the new Nyquist frequency).
pub fn antialias_figure(
    raw: &Recording,
    fs_out_hz: f64,
    cutoff_hz: Option<f64>,
    seconds: f64,
) -> Result<Figure, ReportError> {
    let first = raw
        .select(&[ChannelSelector::Index(0)])
        .map_err(input_err)?;
    let ch_name = first.channels[0].name.clone();
    let unit = first.channels[0].unit.clone();
    let resampled = |filter: bool| {
        first
            .resample(&ResampleParams {
                fs_out_hz,
                cutoff_hz,
                filter,
            })
            .map_err(input_err)
    };
    let plain = resampled(false)?;
    let filt = resampled(true)?;
    let cutoff = cutoff_hz.unwrap_or(fs_out_hz / 2.0);
    let t_end = seconds.min(first.duration_s());
    let time_series = |rec: &Recording, label: &str, width: u32| -> Series {
        let n = ((t_end * rec.fs_hz).ceil() as usize + 1).min(rec.len());
        let x: Vec<f64> = (0..n).map(|i| i as f64 / rec.fs_hz).collect();
        Series::line(x, rec.channels[0].samples[..n].to_vec())
            .with_label(label)
            .with_style(SeriesStyle::Line {
                width,
                dashed: false,
            })
            .with_alpha(if width == 1 { 0.5 } else { 1.0 })
    };
    let pp = PeriodogramParams {
        window: Window::Hann,
        nfft: None,
        detrend: Detrend::Constant,
        scaling: Scaling::Density,
    };
    let spec = |rec: &Recording, label: &str, width: u32| -> Result<Series, ReportError> {
        let s = vibmode_spectra::periodogram(&rec.channels[0].samples, rec.fs_hz, &pp)
            .map_err(input_err)?;
        let (x, y): (Vec<f64>, Vec<f64>) = s
            .freq_hz
            .iter()
            .zip(&s.psd)
            .filter(|(f, _)| **f <= fs_out_hz / 2.0 && **f > 0.0)
            .map(|(f, p)| (*f, *p))
            .unzip();
        Ok(Series::line(x, y)
            .with_label(label)
            .with_style(SeriesStyle::Line {
                width,
                dashed: false,
            })
            .with_alpha(if width == 1 { 0.6 } else { 1.0 }))
    };
    let raw_label = format!("raw {} Hz", raw.fs_hz);
    let plain_label = format!("{fs_out_hz} Hz, no filter");
    let filt_label = format!("{fs_out_hz} Hz, ideal filter {cutoff} Hz");
    let u = if unit.is_empty() {
        "input units".to_string()
    } else {
        unit
    };
    Ok(Figure {
        title: Some(format!("Anti-aliasing and resampling: {ch_name}")),
        panels: vec![
            Panel::new("Time domain", "Time [s]", format!("Acceleration [{u}]"))
                .with_x_range(0.0, t_end)
                .with_series(time_series(&first, &raw_label, 1))
                .with_series(time_series(&plain, &plain_label, 2))
                .with_series(time_series(&filt, &filt_label, 2)),
            Panel::new(
                "Periodogram (Hann), 0 to the new Nyquist frequency",
                "Frequency [Hz]",
                format!("PSD [({u})^2/Hz]"),
            )
            .with_scales(Scale::Linear, Scale::Log)
            .with_x_range(0.0, fs_out_hz / 2.0)
            .with_series(spec(&first, &raw_label, 1)?)
            .with_series(spec(&plain, &plain_label, 2)?)
            .with_series(spec(&filt, &filt_label, 2)?),
        ],
        columns: 1,
        width_px: 1000,
        height_px: 900,
    })
}
