//! `vibmode resample`: the paper's ideal DFT anti-alias filter and resampling.

use crate::input::InputArgs;
use crate::output::ensure_parent;
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::PathBuf;
use vibmode_report::{Figure, Panel, Scale, Series, SeriesStyle};
use vibmode_signal::ResampleRecording;
use vibmode_signal::{Recording, ResampleParams};
use vibmode_spectra::{Detrend, PeriodogramParams, Scaling, Window};

/// Arguments of `vibmode resample`.
#[derive(Args, Debug)]
pub struct ResampleArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Target sampling rate in Hz.
    #[arg(long = "to")]
    pub to_hz: f64,
    /// Skip the anti-alias filter (plain decimation; shows aliasing).
    #[arg(long)]
    pub no_filter: bool,
    /// Output file: .csv (with a time_s column), .wav (32-bit float), or .f32/.f64 (+ .json sidecar).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Plot raw, resampled without and with the filter, in time and frequency (.svg or .png),
    /// as in the paper's Fig. 3-4 (first selected channel).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Seconds of signal shown in the time panel of the plot (default: 0.5 s).
    #[arg(long = "plot-seconds", default_value_t = 0.5)]
    pub plot_seconds: f64,
}

/// Runs `vibmode resample`.
pub fn run(a: &ResampleArgs) -> Result<()> {
    if a.input.resample_to_hz.is_some() {
        bail!("use --to HZ with `vibmode resample` (--resample-to is for the analysis commands)");
    }
    let raw = a.input.load_raw()?;
    let p = ResampleParams {
        to_hz: a.to_hz,
        cutoff_hz: a.input.cutoff_hz,
        filter: !a.no_filter,
    };
    let out = raw.resample(&p)?;
    ensure_parent(&a.output)?;
    vibmode_signal::write_path(&a.output, &out)
        .with_context(|| format!("writing {}", a.output.display()))?;
    eprintln!(
        "{}: {} channel(s), {} samples at {} Hz -> {} samples at {} Hz ({}) written to {}",
        a.input.input.display(),
        raw.channels.len(),
        raw.len(),
        raw.fs_hz,
        out.len(),
        out.fs_hz,
        if a.no_filter {
            "no anti-alias filter".to_string()
        } else {
            format!(
                "ideal DFT low-pass at {} Hz",
                a.input.cutoff_hz.unwrap_or(a.to_hz / 2.0)
            )
        },
        a.output.display()
    );
    if let Some(path) = &a.plot {
        let fig = antialias_figure(&raw, a.to_hz, a.input.cutoff_hz, a.plot_seconds)?;
        ensure_parent(path)?;
        fig.save(path)
            .with_context(|| format!("writing plot {}", path.display()))?;
    }
    Ok(())
}

/// The paper's Fig. 3-4 for the first channel of `raw`: time (top) and periodograms (bottom) of the
/// raw record, the record resampled without filter, and resampled with the ideal filter.
pub fn antialias_figure(
    raw: &Recording,
    to_hz: f64,
    cutoff_hz: Option<f64>,
    seconds: f64,
) -> Result<Figure> {
    let first = raw
        .select(&[vibmode_signal::ChannelSelector::Index(0)])
        .context("the input has no channels")?;
    let ch_name = first.channels[0].name.clone();
    let unit = first.channels[0].unit.clone();
    let plain = first.resample(&ResampleParams {
        to_hz,
        cutoff_hz,
        filter: false,
    })?;
    let filt = first.resample(&ResampleParams {
        to_hz,
        cutoff_hz,
        filter: true,
    })?;
    let cutoff = cutoff_hz.unwrap_or(to_hz / 2.0);
    let t_end = seconds.min(first.duration_s());
    let time_series = |rec: &Recording, label: &str, width: u32, pts: bool| -> Series {
        let n = ((t_end * rec.fs_hz).ceil() as usize + 1).min(rec.len());
        let x: Vec<f64> = (0..n).map(|i| i as f64 / rec.fs_hz).collect();
        Series {
            label: Some(label.to_string()),
            x,
            y: rec.channels[0].samples[..n].to_vec(),
            style: if pts {
                SeriesStyle::Points {
                    size: 3,
                    marker: vibmode_report::Marker::Circle,
                }
            } else {
                SeriesStyle::Line {
                    width,
                    dashed: false,
                }
            },
            color: None,
            alpha: if width == 1 { 0.5 } else { 1.0 },
        }
    };
    let pp = PeriodogramParams {
        window: Window::Hann,
        nfft: None,
        detrend: Detrend::Constant,
        scaling: Scaling::Density,
    };
    let spec = |rec: &Recording, label: &str, width: u32| -> Result<Series> {
        let s = vibmode_spectra::periodogram(&rec.channels[0].samples, rec.fs_hz, &pp)?;
        let (x, y): (Vec<f64>, Vec<f64>) = s
            .freq_hz
            .iter()
            .zip(&s.psd)
            .filter(|(f, _)| **f <= to_hz / 2.0 && **f > 0.0)
            .map(|(f, p)| (*f, *p))
            .unzip();
        Ok(Series {
            label: Some(label.to_string()),
            x,
            y,
            style: SeriesStyle::Line {
                width,
                dashed: false,
            },
            color: None,
            alpha: if width == 1 { 0.6 } else { 1.0 },
        })
    };
    let raw_label = format!("raw {} Hz", raw.fs_hz);
    let plain_label = format!("{to_hz} Hz, no filter");
    let filt_label = format!("{to_hz} Hz, ideal filter {cutoff} Hz");
    let u = if unit.is_empty() { "unit".into() } else { unit };
    Ok(Figure {
        title: Some(format!("Anti-aliasing and resampling: {ch_name}")),
        panels: vec![
            Panel {
                title: "Time domain".into(),
                x_label: "Time [s]".into(),
                y_label: format!("Acceleration [{u}]"),
                x_scale: Scale::Linear,
                y_scale: Scale::Linear,
                x_range: Some((0.0, t_end)),
                y_range: None,
                series: vec![
                    time_series(&first, &raw_label, 1, false),
                    time_series(&plain, &plain_label, 2, false),
                    time_series(&filt, &filt_label, 2, false),
                ],
                legend: true,
            },
            Panel {
                title: "Periodogram (Hann), 0 to the new Nyquist frequency".into(),
                x_label: "Frequency [Hz]".into(),
                y_label: format!("PSD [({u})^2/Hz]"),
                x_scale: Scale::Linear,
                y_scale: Scale::Log,
                x_range: Some((0.0, to_hz / 2.0)),
                y_range: None,
                series: vec![
                    spec(&first, &raw_label, 1)?,
                    spec(&plain, &plain_label, 2)?,
                    spec(&filt, &filt_label, 2)?,
                ],
                legend: true,
            },
        ],
        columns: 1,
        width_px: 1000,
        height_px: 900,
    })
}
