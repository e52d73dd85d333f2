//! `vibmode segment`: cut a long recording into records where the vehicle drives steadily (by a
//! GPS track or by the vibration), writing the records and `segments.json`.

use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};
use vibmode_run::Segmenting;
use vibmode_segment::SegmentParams;
use vibmode_signal::{ChannelSelector, FrameStream, ReadOptions};

/// Segmentation options shared by `segment` and `analyze`.
#[derive(Args, Debug, Clone, Default)]
pub struct SegmentOptions {
    /// GPS track (GPX, NMEA RMC/GGA, or CSV with time,lat,lon,speed): records are cut where the
    /// speed is steady and the heading nearly constant for a whole record.
    #[arg(long)]
    pub gps: Option<PathBuf>,
    /// Seconds added to the GPS times to put them on the recording's clock (the recording's start
    /// is its sidecar's start_time, else the track's first fix).
    #[arg(
        long = "gps-offset-s",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub gps_offset_s: f64,
    /// Without GPS: skip stops, idling and strong manoeuvres found from the vibration itself.
    #[arg(long = "by-vibration")]
    pub by_vibration: bool,
    /// Segmentation tolerances (TOML with keys of docs/segment.md, e.g. `min_speed_kmh = 15`);
    /// keys not given keep their defaults.
    #[arg(long = "segment-config")]
    pub segment_config: Option<PathBuf>,
}

impl SegmentOptions {
    /// The tolerances: the defaults, overridden by `--segment-config`.
    pub fn params(&self) -> Result<SegmentParams> {
        match &self.segment_config {
            None => Ok(SegmentParams::default()),
            Some(p) => {
                let text = vibmode_core::files::read_text_capped(p)
                    .with_context(|| format!("cannot read --segment-config {}", p.display()))?;
                toml::from_str(&text).map_err(|e| {
                    // The message without the echoed source line, quoted short; the line number.
                    let line = e
                        .span()
                        .and_then(|r| text.get(..r.start))
                        .map(|t| t.matches('\n').count() + 1);
                    anyhow::anyhow!(
                        "--segment-config {}{}: {}",
                        p.display(),
                        line.map(|l| format!(" line {l}")).unwrap_or_default(),
                        vibmode_core::quoted(&e.message().replace('\n', " "))
                    )
                })
            }
        }
    }
}

/// Arguments of `vibmode segment`.
#[derive(Args, Debug)]
pub struct SegmentArgs {
    /// The recording (delimited text, WAV, raw + sidecar), of any length.
    pub input: PathBuf,
    #[command(flatten)]
    pub seg: SegmentOptions,
    /// Record length in seconds (default: the analysis's `record_length_s`, 10.24).
    #[arg(long = "record-length-s")]
    pub record_length_s: Option<f64>,
    #[command(flatten)]
    pub channel: crate::input::ChannelArgs,
    #[command(flatten)]
    pub read: crate::input::ReadArgs,
    /// Format of the record files: csv, wav, f32 or f64 (default: f32 for raw input, wav for
    /// WAV, csv for text).
    #[arg(long)]
    pub format: Option<String>,
    /// Only write segments.json, not the records.
    #[arg(long)]
    pub plan_only: bool,
    /// Output folder.
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
}

/// Opens `path` as a stream with `sel` selected.
pub fn open(path: &Path, opts: &ReadOptions, sel: &[ChannelSelector]) -> Result<FrameStream> {
    let mut s = vibmode_signal::open_stream(path, opts)?;
    s.select(sel)?;
    Ok(s)
}

impl SegmentOptions {
    /// How the options say to cut: by GPS, by vibration, or (`consecutive`) consecutive
    /// records; None when neither GPS nor vibration is asked and not `consecutive`.
    pub fn segmenting(&self, consecutive: bool) -> Result<Option<Segmenting>> {
        let params = self.params()?;
        Ok(match (&self.gps, self.by_vibration) {
            (Some(_), true) => bail!("give either --gps TRACK or --by-vibration, not both"),
            (Some(track), false) => Some(Segmenting::Gps {
                track: track.clone(),
                offset_s: self.gps_offset_s,
                params,
            }),
            (None, true) => Some(Segmenting::Vibration { params }),
            (None, false) if consecutive => Some(Segmenting::Consecutive { params }),
            (None, false) => None,
        })
    }
}

/// Runs `vibmode segment`.
pub fn run(a: &SegmentArgs) -> Result<()> {
    // The output folder is checked and locked before any work, and written as a whole.
    let mut inputs = vec![a.input.clone()];
    inputs.extend(a.seg.gps.iter().cloned());
    let out = crate::output::StagedDir::begin(&a.output, &inputs)?;
    let opts = a.read.options()?;
    let sel = a.channel.selectors()?;
    let record_length_s = a
        .record_length_s
        .unwrap_or(vibmode_analysis::AnalysisConfig::default().record_length_s);
    let how = a.seg.segmenting(true)?.context("no segmentation")?;
    let planned = how.plan(&a.input, &opts, &sel, record_length_s)?;
    for note in &planned.notes {
        eprintln!("{note}");
    }
    let mut seg = planned.segmentation;
    let stream = open(&a.input, &opts, &sel)?;
    let ext = match &a.format {
        Some(f) => match f.as_str() {
            "csv" | "wav" | "f32" | "f64" => f.clone(),
            other => bail!("--format {other}: use csv, wav, f32 or f64"),
        },
        None => match stream.info().format {
            vibmode_signal::Format::Raw => "f32".into(),
            // Records are written, not arrays: raw f64 with its sidecar (numpy.fromfile).
            vibmode_signal::Format::Npy => "f64".into(),
            vibmode_signal::Format::Wav => "wav".into(),
            vibmode_signal::Format::Delimited => "csv".into(),
        },
    };
    if a.plan_only {
        let path = out.path().join("segments.json");
        std::fs::write(&path, serde_json::to_string_pretty(&seg)? + "\n")
            .with_context(|| format!("writing {}", path.display()))?;
    } else {
        vibmode_segment::write_segments(stream, &mut seg, out.path(), &ext)?;
    }
    out.commit()?;
    eprintln!("{}", seg.summary());
    eprintln!("written: {}", a.output.join("segments.json").display());
    Ok(())
}
