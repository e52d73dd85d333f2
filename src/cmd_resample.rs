//! `vibmode resample`: the paper's ideal DFT anti-alias filter and resampling.

use crate::input::InputArgs;
use anyhow::{bail, Context, Result};
use clap::builder::TypedValueParser;
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::PathBuf;
use vibmode_signal::ResampleRecording;
use vibmode_signal::{ResampleParams, ResamplerKind, StreamResampleParams};

/// Arguments of `vibmode resample`.
#[derive(Args, Debug)]
pub struct ResampleArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// The older spelling of `--fs-out` (hidden; still accepted).
    #[arg(
        long = "to",
        value_name = "HZ",
        hide = true,
        conflicts_with = "fs_out_hz"
    )]
    pub to_hz: Option<f64>,
    /// Skip the anti-alias filter (plain decimation; shows aliasing).
    #[arg(long)]
    pub no_filter: bool,
    /// Output file: .csv (with a time_s column), .wav (32-bit float), or .f32/.f64 (+ .json sidecar; .npy is read, not written).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Plot raw, resampled without and with the filter, in time and frequency (.svg or .png),
    /// as in the paper's Fig. 3-4 (first selected channel).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Seconds of signal shown in the time panel of the plot (default: 0.5 s).
    #[arg(long = "plot-seconds", default_value_t = 0.5)]
    pub plot_seconds: f64,
    /// Resampler: `ideal` (the paper's DFT low-pass over the whole record, in memory), `fir`
    /// (streamed block by block: linear-phase FIR, pass band to the cutoff, >= 100 dB stop band;
    /// any length in bounded memory) or `auto` (ideal up to 64 MiB of input file, fir above).
    /// (`--method` is still accepted.)
    #[arg(long, alias = "method", default_value = "auto", value_parser = resampler_parser())]
    pub resampler: ResamplerKind,
}

/// The values `--resampler` takes: the library's [`ResamplerKind`], by the names it parses.
fn resampler_parser() -> impl TypedValueParser<Value = ResamplerKind> {
    clap::builder::PossibleValuesParser::new(ResamplerKind::NAMES)
        .try_map(|s: String| s.parse::<ResamplerKind>())
}

/// Runs `vibmode resample`.
pub fn run(a: &ResampleArgs) -> Result<()> {
    let Some(fs_out_hz) = a.input.fs_out_hz.or(a.to_hz) else {
        bail!("vibmode resample needs the rate to resample to: --fs-out HZ, e.g. --fs-out 200");
    };
    // Every output checked before any work (an output that is the input would be truncated
    // while still being read).
    crate::output::check_outputs(
        &a.input.input,
        &[Some(a.output.as_path())],
        &[a.plot.as_deref()],
        None,
    )?;
    if !(a.plot_seconds.is_finite() && a.plot_seconds > 0.0) {
        bail!(
            "--plot-seconds {}: the time panel needs a positive number of seconds, e.g. 0.5",
            a.plot_seconds
        );
    }
    let input_bytes = std::fs::metadata(&a.input.input).ok().map(|m| m.len());
    if a.resampler.streams(input_bytes, !a.no_filter) {
        if a.no_filter {
            bail!("--no-filter applies to --resampler ideal (plain decimation of the whole record); drop one of them");
        }
        return run_streamed(a, fs_out_hz);
    }
    let raw = a.input.load_raw()?;
    let p = ResampleParams {
        fs_out_hz,
        cutoff_hz: a.input.cutoff_hz,
        filter: !a.no_filter,
    };
    let out = raw.resample(&p)?;
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
                a.input.cutoff_hz.unwrap_or(fs_out_hz / 2.0)
            )
        },
        a.output.display()
    );
    if let Some(path) = &a.plot {
        let fig =
            vibmode_report::antialias_figure(&raw, fs_out_hz, a.input.cutoff_hz, a.plot_seconds)?;
        fig.save(path)
            .with_context(|| format!("writing plot {}", path.display()))?;
    }
    Ok(())
}

/// `--resampler fir`: read, filter and write block by block.
fn run_streamed(a: &ResampleArgs, fs_out_hz: f64) -> Result<()> {
    let mut stream = a.input.open_stream()?;
    let info = stream.info().clone();
    let p = StreamResampleParams {
        fs_out_hz,
        cutoff_hz: a.input.cutoff_hz,
        ..StreamResampleParams::default()
    };
    let show = crate::progress::shown();
    let pb = ProgressBar::with_draw_target(
        info.n_frames,
        if show {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        },
    );
    if let Ok(style) = ProgressStyle::with_template(
        "{spinner} [{elapsed_precise}] {bar:40} {percent}% {msg} ETA {eta}",
    ) {
        pb.set_style(style);
    }
    let t0 = std::time::Instant::now();
    let fs = info.fs_hz;
    let mut progress = |frames: u64| {
        let secs = t0.elapsed().as_secs_f64().max(1e-9);
        let rt = frames as f64 / fs / secs;
        pb.set_message(format!(
            "{:.1} Mframes/s, {:.0}x real time",
            frames as f64 / secs / 1e6,
            rt
        ));
        pb.set_position(frames);
    };
    let sum = vibmode_signal::resample_stream(&mut stream, &a.output, &p, &mut progress)
        .with_context(|| {
            format!(
                "resampling {} to {}",
                a.input.input.display(),
                a.output.display()
            )
        })?;
    pb.finish_and_clear();
    let secs = t0.elapsed().as_secs_f64();
    let d = &sum.design;
    eprintln!(
        "{}: {} channel(s), {} samples at {} Hz -> {} samples at {} Hz (streamed FIR: pass band 0-{} Hz flat within {:.1e}, stop band from {} Hz at -{} dB, {} taps) written to {} in {:.1} s ({:.0}x real time)",
        a.input.input.display(),
        info.n_channels(),
        sum.frames_in,
        info.fs_hz,
        sum.frames_out,
        d.fs_out_hz,
        d.pass_hz,
        10f64.powf(-d.attenuation_db / 20.0),
        d.stop_hz,
        d.attenuation_db,
        d.n_taps,
        a.output.display(),
        secs,
        sum.frames_in as f64 / info.fs_hz / secs.max(1e-9),
    );
    if let Some(path) = &a.plot {
        // The figure needs the raw signal: the first 20 s of the file.
        let mut head = a.input.open_stream()?;
        let n = (20.0 * info.fs_hz) as usize;
        let block = head
            .next_block(n.max(1))?
            .context("the input has no samples to plot")?;
        let raw = vibmode_signal::Recording {
            fs_hz: info.fs_hz,
            channels: info
                .names
                .iter()
                .zip(&info.units)
                .zip(block.channels)
                .map(|((n, u), d)| vibmode_signal::Channel::new(n.clone(), u.clone(), d))
                .collect(),
            time_axis: None,
        };
        let fig =
            vibmode_report::antialias_figure(&raw, fs_out_hz, a.input.cutoff_hz, a.plot_seconds)?;
        fig.save(path)
            .with_context(|| format!("writing plot {}", path.display()))?;
    }
    Ok(())
}
