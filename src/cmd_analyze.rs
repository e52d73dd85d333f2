//! `vibmode analyze` and `vibmode demo`: the paper's whole analysis and its report.

use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use vibmode_analysis::{AnalysisConfig, AnalysisResults, ConfigText, Preset};
use vibmode_report::TruthRow;
use vibmode_run::{Demo, Progress, Run, RunInput, RunOutput};

/// Arguments of `vibmode analyze`.
#[derive(Args, Debug)]
pub struct AnalyzeArgs {
    /// Record files (one record each), or long recordings cut into records of
    /// `record_length_s` (10.24 s by default), or folders of them (each folder's recordings,
    /// sorted by name).
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Analysis settings (TOML); see docs/analysis.md. Keys not given take the preset's values.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Preset for the defaults: vibmode (50 Hz analysis rate, p = 2..30) or paper (200 Hz, p = 2..60).
    #[arg(long)]
    pub preset: Option<String>,
    /// Full-car parameter file: its modes are drawn and matched to the invariant modes, and its
    /// suspension is fitted to the records (the model update: the measured bus's body modes,
    /// model_update.json, updated_vehicle.toml; settings in the config's `[model_update]`).
    #[arg(long)]
    pub vehicle: Option<PathBuf>,
    #[command(flatten)]
    pub channel: crate::input::ChannelArgs,
    #[command(flatten)]
    pub read: crate::input::ReadArgs,
    /// Output folder for index.html, results.json and figures/.
    #[arg(short = 'o', long = "output", default_value = "vibmode-report")]
    pub output: PathBuf,
    /// Role of a channel, `NAME=sprung|unsprung|other` (repeat for several); overrides the
    /// config's `[[channels]]` and the guess from the name.
    #[arg(long = "role", value_name = "NAME=ROLE")]
    pub roles: Vec<String>,
    /// Corner of a channel, `NAME=FL|FR|RL|RR` (repeat for several).
    #[arg(long = "corner", value_name = "NAME=CORNER")]
    pub corners: Vec<String>,
    /// Identification methods, a comma-separated list: arma (per channel), ssi-cov (all
    /// channels at once, with mode shapes); `both` (the default) is both. Overrides the
    /// config's `method`.
    #[arg(long)]
    pub method: Option<String>,
    /// Records of this length in seconds from long files (overrides the config's
    /// `record_length_s`).
    #[arg(long = "record-length-s")]
    pub record_length_s: Option<f64>,
    #[command(flatten)]
    pub seg: crate::cmd_segment::SegmentOptions,
}

/// `NAME=VALUE` of `--role` / `--corner`.
fn split_assignment<'a>(flag: &str, text: &'a str) -> Result<(&'a str, &'a str)> {
    match text.rsplit_once('=') {
        Some((name, value)) if !name.is_empty() && !value.is_empty() => Ok((name, value)),
        _ => bail!("{flag} '{text}' must be NAME=VALUE, e.g. {flag} FL_wheel=unsprung"),
    }
}

/// Adds the `--role` and `--corner` assignments to the config's channel table.
fn apply_placements(cfg: &mut AnalysisConfig, roles: &[String], corners: &[String]) -> Result<()> {
    use vibmode_analysis::{ChannelRole, Corner, Role};
    fn entry<'c>(cfg: &'c mut AnalysisConfig, name: &str) -> &'c mut ChannelRole {
        let i = match cfg.channels.iter().position(|c| c.name == name) {
            Some(i) => i,
            None => {
                cfg.channels.push(ChannelRole {
                    name: name.to_string(),
                    role: None,
                    corner: None,
                });
                cfg.channels.len() - 1
            }
        };
        &mut cfg.channels[i]
    }
    for r in roles {
        let (name, value) = split_assignment("--role", r)?;
        entry(cfg, name).role = Some(value.parse::<Role>()?);
    }
    for c in corners {
        let (name, value) = split_assignment("--corner", c)?;
        entry(cfg, name).corner = Some(value.parse::<Corner>()?);
    }
    Ok(())
}

/// Reads the config: --config file (with its own preset key) or --preset, else defaults.
fn load_config(config: Option<&Path>, preset: Option<&str>) -> Result<AnalysisConfig> {
    let preset = preset.map(str::parse::<Preset>).transpose()?;
    Ok(AnalysisConfig::load(config.map(ConfigText::Path), preset)?)
}

/// Runs `vibmode analyze`.
pub fn run(a: &AnalyzeArgs) -> Result<()> {
    let mut cfg = load_config(a.config.as_deref(), a.preset.as_deref())?;
    let files = vibmode_signal::expand_folders(&a.inputs)?;
    // The output folder is checked and locked before any work, and written as a whole; it may
    // neither be nor hold an input (a folder given or a file of it).
    let mut inputs = a.inputs.clone();
    inputs.extend(files.iter().cloned());
    inputs.extend(a.seg.gps.iter().cloned());
    let out = crate::output::StagedDir::begin(&a.output, &inputs)?;
    apply_placements(&mut cfg, &a.roles, &a.corners)?;
    if let Some(m) = &a.method {
        cfg.method = m.parse()?;
    }
    let opts = a.read.options()?;
    let sel = a.channel.selectors()?;
    if let Some(l) = a.record_length_s {
        cfg.record_length_s = l;
        cfg.validate()?;
    }
    // With --gps / --by-vibration each file is segmented first (a pass over it), then its
    // records are cut where the segmentation says. Each file is read as a stream and cut into
    // records as it is read; each record is brought to the analysis rate as it arrives, so
    // memory does not grow with the file.
    let segmenting = a.seg.segmenting(false)?;
    let mut run = Run::new(cfg);
    if let Some(p) = &a.vehicle {
        run = run.vehicle(vibmode_vehicle::VehicleParams::from_path(p)?)?;
    }
    let input = match &segmenting {
        Some(segmenting) => RunInput::Segmented {
            paths: &files,
            read: &opts,
            channels: &sel,
            segmenting,
        },
        None => RunInput::files(&files, &opts, &sel),
    };
    let output = with_progress(true, |progress| run.run(input, progress))?;
    output
        .write(out.path(), None)
        .with_context(|| format!("writing the report in {}", out.path().display()))?;
    out.commit()?;
    for note in &output.notes {
        eprintln!("{note}");
    }
    print_modes(&output.results, None)?;
    if let Some(t) = output.update.summary_text(&a.output) {
        crate::output::print_stdout(&t)?;
    }
    eprintln!("report: {}", a.output.join("index.html").display());
    Ok(())
}

/// Runs `f` with a progress bar on a terminal (records read when `streamed`, then records
/// identified, per second, the time left), cleared at the end.
fn with_progress<T>(
    streamed: bool,
    f: impl FnOnce(&Progress<'_>) -> Result<T, vibmode_run::RunError>,
) -> Result<T> {
    let first_phase = if streamed {
        "records read"
    } else {
        "records identified"
    };
    let pb = crate::progress::records_bar(None, first_phase, "records");
    let on_record = |n: usize| pb.set_position(n as u64);
    let started = AtomicBool::new(false);
    let on_identified = |done: usize, total: usize| {
        if !started.swap(true, Ordering::SeqCst) {
            crate::progress::set_phase(&pb, Some(total as u64), "records identified", "records");
        }
        pb.set_position(done as u64);
    };
    let progress = Progress {
        on_record: &on_record,
        on_identified: &on_identified,
    };
    let out = f(&progress)?;
    pb.finish_and_clear();
    Ok(out)
}

/// Prints the invariant-mode table per role; with `truth`, the true modes beside it.
pub fn print_modes(r: &AnalysisResults, truth: Option<&[TruthRow]>) -> Result<()> {
    crate::output::print_stdout(&vibmode_report::modes_table_text(r, truth))
}

/// Arguments of `vibmode demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Output folder for the report (and the simulated records in `records/`).
    #[arg(short = 'o', long = "output", default_value = "vibmode-demo")]
    pub output: PathBuf,
    /// Preset of the analysis: vibmode or paper.
    #[arg(long)]
    pub preset: Option<String>,
    /// Number of simulated records.
    #[arg(long, default_value_t = vibmode_vehicle::SimParams::default().records)]
    pub records: usize,
    /// Random seed of the simulation.
    #[arg(long, default_value_t = vibmode_vehicle::SimParams::default().seed)]
    pub seed: u64,
    /// Also write the simulated records (WAV) and truth.json into `OUTPUT/records/`.
    #[arg(long)]
    pub keep_records: bool,
    /// Identification methods, a comma-separated list of arma and ssi-cov; `both` (the
    /// default) is both.
    #[arg(long)]
    pub method: Option<String>,
}

/// Runs `vibmode demo`: simulate the shipped city bus and analyse it.
pub fn run_demo(a: &DemoArgs) -> Result<()> {
    use crate::cmd_vehicle::{write_simulation, RecordFormat};
    if a.records == 0 {
        bail!("--records 0: give at least one record");
    }
    let mut cfg = load_config(None, a.preset.as_deref())?;
    if let Some(m) = &a.method {
        cfg.method = m.parse()?;
    }
    let out = crate::output::StagedDir::begin(&a.output, &[])?;
    let demo = Demo {
        records: a.records,
        seed: a.seed,
    };
    eprintln!("{}", demo.description());
    let d = demo.simulate()?;
    if a.keep_records {
        let dir = out.path().join("records");
        std::fs::create_dir(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
        write_simulation(&dir, &d.simulation, RecordFormat::Wav)?;
    }
    let run = Run::new(cfg).reference(d.reference).vehicle(d.vehicle)?;
    let output: RunOutput = with_progress(false, |progress| {
        run.run(RunInput::Records(d.records), progress)
    })?;
    output
        .write(out.path(), Some(&d.intro))
        .with_context(|| format!("writing the report in {}", out.path().display()))?;
    out.commit()?;
    let truth = d.truth;
    print_modes(&output.results, Some(&truth))?;
    if let Some(t) = output.update.summary_text(&a.output) {
        crate::output::print_stdout(&t)?;
    }
    eprintln!("report: {}", a.output.join("index.html").display());
    Ok(())
}
